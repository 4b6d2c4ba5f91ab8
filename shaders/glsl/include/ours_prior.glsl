// ours' spatial prior (ours_prior_fit.comp, ours_prior.comp): the grid of fits, the
// model's features and the small solver.
#ifndef DVR_OURS_PRIOR_GLSL
#define DVR_OURS_PRIOR_GLSL
// [[unroll]] where a packed array is read or written: unrolled, its indices are constants
// and it stays in registers (lavapipe otherwise keeps it in memory, at twice the cost).
#extension GL_EXT_control_flow_attributes : require

// Pixels between two fits' centres (set by the engine, which sizes the grid: its
// `prior::PRIOR_STRIDE`), and the side of a fit's window, 3×3 blocks of PRIOR_STRIDE
// pixels: 12×12 pixels hold 144 estimates for the 7 coefficients of each channel.
layout(constant_id = 0) const int PRIOR_STRIDE = 4;
const int PRIOR_WINDOW = 12;
// The model's features: 1, the guide albedo's luminance, the pixel's position (x, y) and
// the gradient normal (x, y, z), from the guides' footprint (ours_guide.comp).
const int PRIOR_FEATURES = 7;
const int FEATURE_X = 2;  // the position's
const int FEATURE_Y = 3;
// Positions in units of half a window, so that every feature varies by about 1 over it
// (the normal equations stay well conditioned).
const float PRIOR_POSITION_UNIT = float(PRIOR_WINDOW / 2);
// The sums of a block (ours_prior_sums.comp), packed: the lower triangle of Σ f fᵀ, then
// Σ f x (rgb per feature), then Σ x² (rgb).
const int SUM_A = 0;
const int SUM_B = PRIOR_FEATURES * (PRIOR_FEATURES + 1) / 2;
const int SUM_XX = SUM_B + 3 * PRIOR_FEATURES;
const int PRIOR_SUM_TEXELS = (SUM_XX + 3 + 3) / 4;

// A cell's centre in pixels (cell i's centre is pixel PRIOR_STRIDE·i + (PRIOR_STRIDE − 1)/2).
vec2 cell_centre(ivec2 cell) {
    return vec2(cell * PRIOR_STRIDE) + 0.5 * float(PRIOR_STRIDE - 1);
}

// The features of a pixel with guides g (x albedo's luminance, yzw normal) at position o
// (relative to a centre, in PRIOR_POSITION_UNIT); the first four, then the normal's.
vec4 features_lo(vec4 g, vec2 o) { return vec4(1.0, g.x, o); }
vec3 features_hi(vec4 g) { return g.yzw; }

// Where there is no fit (no finite estimate in the window): V so large that the prior
// leaves the pixels near the cell as they are.
const float NO_FIT = 1e30;

// Solves (A + ridge·diag(0, 1, …, 1)) β = B for three right-hand sides (the colour
// channels) by Cholesky; false if that matrix is not positive definite. A is symmetric
// (only its lower triangle, A[i][j] with j ≤ i, is read).
bool solve_ridge(float A[PRIOR_FEATURES][PRIOR_FEATURES], vec3 B[PRIOR_FEATURES], float ridge,
                 out vec3 beta[PRIOR_FEATURES]) {
    const int D = PRIOR_FEATURES;
    float L[D][D];
    for (int j = 0; j < D; ++j) {
        float d = A[j][j] + (j > 0 ? ridge : 0.0);
        for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
        if (!(d > 1e-20)) return false;
        L[j][j] = sqrt(d);
        for (int i = j + 1; i < D; ++i) {
            float s = A[i][j];
            for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
            L[i][j] = s / L[j][j];
        }
    }
    vec3 z[D];
    for (int i = 0; i < D; ++i) {
        vec3 s = B[i];
        for (int k = 0; k < i; ++k) s -= L[i][k] * z[k];
        z[i] = s / L[i][i];
    }
    for (int i = D - 1; i >= 0; --i) {
        vec3 s = z[i];
        for (int k = i + 1; k < D; ++k) s -= L[k][i] * beta[k];
        beta[i] = s / L[i][i];
    }
    return true;
}

#endif
