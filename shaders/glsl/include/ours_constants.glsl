#ifndef DVR_OURS_CONSTANTS_GLSL
#define DVR_OURS_CONSTANTS_GLSL
// ours' fixed constants: every number in ours' shaders that changes its output and is
// not one of its knobs (OursParams), each named once here. Why each has its value is the
// table "Fixed constants" of the book's denoisers page; the Rust side's (the lag window,
// the à-trous levels, the prior's stride) are beside OursParams in
// engine/src/denoise/ours/. A test (engine/src/denoise/ours/constants.rs) fails on a
// numeric literal in ours' shaders that is neither here nor structural (0, 1, 2, 3 and
// the Catmull-Rom weights).

// The noise measurement and the level of a change: over the (2r + 1)² pixels around
// a pixel (ours_noise.comp sums rows, ours_update.comp the rows' sums).
const int NOISE_RADIUS = 2;
const int NOISE_TAPS = (2 * NOISE_RADIUS + 1) * (2 * NOISE_RADIUS + 1);

// A variance floor, in radiance² (a guard against dividing by zero, below any noise a
// frame resolves).
const float VARIANCE_FLOOR = 1e-12;

// Motion on screen, in pixels, below which a pixel counts as still.
const float STILL_PX = 0.01;

// The residual the lag test pools is a running one: this share of this frame's, the rest
// last frame's.
const float LAG_BLEND = 0.5;
// Share of the lag window that must hold a residual for its mean to count.
const float LAG_MIN_SHARE = 0.5;

// Beyond any radiance or variance: the start of a running minimum, and the variance that
// makes nothing significant (no estimate, no fit).
const float HUGE = 1e30;
const float NO_ESTIMATE = HUGE;

// The temporal gradients' pools, in strata around each stratum: 3×3, 5×5 and 9×9.
const int POOL_RADIUS_NEAR = 1;
const int POOL_RADIUS_MID = 2;
const int POOL_RADIUS_WIDE = 4;
// The largest change of a pooled ratio per frame (and the smallest, its inverse).
const float RATIO_MAX = 4.0;
// Channels darker than this share of the luminance are damped towards no change.
const float DARK_CHANNEL = 0.01;
// Pooled luminance, in radiance, below which a pool holds nothing lit to compare.
const float LIT_MIN = 1e-6;

// The guides' footprint: a tent over the 3×3 pixels around each pixel.
const int FOOTPRINT_RADIUS = 1;
// The prior's window, in blocks of PRIOR_STRIDE² pixels around each fit: 3×3.
const int FIT_RADIUS = 1;
// The prior's ridge, as a share of the window's pixel count.
const float RIDGE = 1e-3;
// Smallest pivot of the prior's Cholesky solve: below it the window has no fit.
const float PIVOT_MIN = 1e-20;

// The feedback (ours_feedback.comp): a state whose effective history R / P is under this
// many frames restarted this frame and takes the first à-trous level's estimate.
const float FEEDBACK_HISTORY = 1.5;

#endif
