#version 460
// ours' temporal pass: per pixel, a local-level Kalman filter on the pixel's radiance.
//
// Model. State x_t (rgb, the pixel's true radiance), observed through this frame's noisy
// pixel mean y_t:
//     x_t = g_t ∘ x_{t−1} + w_t,   w_t ~ N(0, Q_t)      (the scene changes by g_t)
//     y_t = x_t + v_t,             v_t ~ N(0, R_t)      (Monte Carlo noise)
// with one variance per pixel shared by the channels (P for the estimate, Q, R), each in
// one unit: the mean over the three channels of each channel's variance, E|v|²/3, the
// unit of the innovation's |y − x⁻|²/3, the lag test's residuals, the à-trous' range term
// and the prior's V:
//   - g_t, the measured change: the temporal gradients' ratio of this frame's radiance to
//     last frame's on re-traced paths (ours_gradient*.comp), 1 where nothing changed;
//   - Q_t, what the prediction may have missed: (change_q · change · level)² for a
//     change the gradients measured (their ratio is a neighbourhood's, the pixel's own may
//     differ in proportion; the level is the larger of the pixel's RMS colour |x|/√3 and
//     its 5×5 neighbourhood's mean colour's in this frame), motion_q · R for a pixel whose
//     surface moved on screen (the view-dependent change of a semi-transparent volume),
//     and a shift the pooled lag test found (its own size, |shift|²/3);
//   - R_t, the variance of one frame's pixel mean: the samples' luminance moments over
//     5×5 pixels give Var(L), and a pixel's samples share a hue, so each channel's
//     variance is (m_c / L(m))² Var(L) with m the neighbourhood's mean colour, and
//     R = Var(L) (|m|²/3) / L(m)² (at 1 spp: the 5×5 colours' spread, directly in the
//     unit); scaled with the radiance by g_t and averaged over the filter's memory; this
//     frame's measurement joins before the gain uses it, with the weight P⁻ / (P⁻ + R).
//     Where the lag test shifted the level, the carried R was the old level's: a lower
//     measurement replaces it (a surface that fell into shadow has no noise left there).
// Predict: x⁻ = g ∘ x, P⁻ = ḡ² P + Q. Update: K = P⁻ / (P⁻ + R), x = x⁻ + K (y − x⁻),
// P = (1 − K) P⁻. With nothing changing Q = 0 and K = 1/n: the running mean, which only
// improves.
// Jumps from the pooled lag test: a residual the neighbourhood shares beyond jump_z
// standard errors of its mean is a moved level, and its square is added to P⁻ so the
// filter follows it: a change of the scene moves a region, where a firefly is one
// pixel's (the lag test pools 5×5 pixels, and R is measured over 5×5). A weight that
// clipped a pixel's own outlying innovations changed nothing measurable on the
// development set and no test (the book's results, "every mechanism").
//
// State, two images: model (rgba32f: rgb the estimate, a its variance P) and noise (rg32f:
// the measurement noise R, and D, the part of P that process noise put there: the update
// splits P = (1 − K)² P⁻ + K² R, so D = (1 − K)² (ḡ² D + Q + J), J a jump's e² (below),
// the process noise of the frames the filter's memory still spans; a filter that
// restarted (K ≈ 1) carries none).
// Outputs: the state itself is the estimate the prior and the à-trous read (each clamps its
// radiance at zero as it reads it), and the a-posteriori residual with its variance for the
// pooled lag test (ours_lag.comp).
#include "common.glsl"
#include "reproject.glsl"
#include "ours_change.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2) uniform sampler2D model_prev;
layout(binding = 3) uniform sampler2D noise_prev;
layout(binding = 4, rgba32f) uniform writeonly image2D model_cur;
layout(binding = 5, rg32f) uniform writeonly image2D noise_cur;
layout(binding = 7, rgba32f) uniform writeonly image2D residual;    // rgb, a variance (< 0: none)
layout(binding = 8) uniform sampler2D lag_prev;                      // rgb mean, a variance
layout(binding = 9, rgba32f) uniform readonly image2D noise_rows;    // ours_noise.comp: row sums of R's measurement
layout(binding = 10) uniform sampler2D residual_prev;                // last frame's `residual`

layout(push_constant) uniform OursUpdatePush {
    vec4 camera;          // xyz camera position
    uint width;
    uint height;
    uint history_valid;
    uint gradient_valid;  // the gradient images were measured this frame
    uint lag_valid;       // lag_prev holds last frame's pooled residuals
    uint stratum;         // the gradients' stratum edge in pixels
    float spp;            // samples per pixel of the noisy frame
    float tolerance;      // disocclusion tolerance in pixels
    float change_q;       // share of a measured change the pixel's own may differ by
    float motion_q;       // process noise of a moving pixel, in units of R
    float lag_z;          // pooled residual, in standard errors, that is a shift
    float jump_z;         // pooled residual, in standard errors, beyond which it is a jump
    uint shift;           // a significant pooled residual shifts the state (0: ours-no-lag)
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

// The lag test's running residual (LAG_BLEND of this frame's, the rest last frame's,
// carried along with the change and less the shift it caused): a lag persists from frame
// to frame while the noise does not, so at one half the running residual has a third of
// one frame's noise variance.

// This frame's sums over the 5×5 neighbourhood (ours_noise.comp summed each row's 5
// pixels; this sums 5 rows): x what R is measured from, yzw the colour.
vec4 neighbourhood_sums(ivec2 p, ivec2 size) {
    vec4 s = vec4(0.0);
    for (int dy = -NOISE_RADIUS; dy <= NOISE_RADIUS; ++dy) {
        s += imageLoad(noise_rows, ivec2(p.x, clamp(p.y + dy, 0, size.y - 1)));
    }
    return s;
}

// The 5×5 neighbourhood's mean colour, from the sums neighbourhood_sums returns.
vec3 neighbourhood_mean(vec4 s) { return s.yzw / float(NOISE_TAPS); }

// R of a pixel without history, and this frame's measurement of R, in the filter's unit
// (the mean over the channels of each channel's variance): from the moments' luminance
// noise over the 5×5 neighbourhood (one pixel's two samples say too little), turned into
// that unit by the neighbourhood's colour m. A pixel's samples share a hue (the TF's
// colours along one path scale each sample's radiance as a whole), so each channel's
// noise is its share of the luminance's: Var(y_c) = (m_c / L(m))² Var(L), and the unit's
// variance is Var(L)·(|m|²/3) / L(m)² (grey: Var(L); a saturated blue: 64 Var(L)). Where
// the neighbourhood is black the ratio is 1. At 1 spp, which has no moments, the spread of
// the 5×5 pixels' colours in the same unit (signal detail included: an overestimate,
// which only slows the first frames). Under heavy tails 3×3 was too few: where no bright
// path landed in 18 samples R came out near zero, the filter looked converged on a low
// mean, and the à-trous kept it as a dark blotch (static views). `s`: the sums
// neighbourhood_sums returns.
float fresh_noise(vec4 s) {
    const float n = float(NOISE_TAPS);
    vec3 m = neighbourhood_mean(s);
    float level2 = dot(m, m) / 3.0;
    if (pc.spp >= 2.0) {
        float L = luminance(m);
        float colour_share = L * L > VARIANCE_FLOOR ? level2 / (L * L) : 1.0;
        return s.x / n * colour_share + VARIANCE_FLOOR;
    }
    return max(s.x / n - level2, 0.0) * n / float(NOISE_TAPS - 1) + VARIANCE_FLOOR;
}

// The history's estimate resampled by Catmull-Rom over the 4×4 texels around `r.uv`
// where the bilinear footprint's four taps all show this pixel's surface (elsewhere, and
// for the variance, the bilinear blend of the taps that do). A bilinear fetch averages
// four estimates whenever the camera moves by a fraction of a pixel, and a filter with a
// long memory averages those averages frame after frame: the detail blurs. Catmull-Rom
// interpolates (it returns each texel's value at its centre) and keeps it; its result is
// clamped to the four taps' range, so its negative lobes cannot ring at an edge.
vec4 history_fetch_sharp(sampler2D history, Reprojection r) {
    if (!all(greaterThan(r.weights, vec4(0.0)))) return history_fetch(history, r);
    ivec2 hi = textureSize(history, 0) - 1;
    vec2 f = r.uv * vec2(textureSize(history, 0)) - 0.5 - vec2(r.tap);
    vec2 w[4] = vec2[](f * (-0.5 + f * (1.0 - 0.5 * f)), 1.0 + f * f * (-2.5 + 1.5 * f),
                       f * (0.5 + f * (2.0 - 1.5 * f)), f * f * (-0.5 + 0.5 * f));
    vec3 sum = vec3(0.0);
    vec3 lo = vec3(HUGE), up = vec3(-HUGE);
    // The four central texels are the bilinear footprint: their blend (the same sum
    // history_fetch makes) gives the variance and the fallback.
    vec4 bilinear = vec4(0.0);
    bool finite = true;
    for (int j = 0; j < 4; ++j) {
        for (int i = 0; i < 4; ++i) {
            vec4 t = texelFetch(history, clamp(r.tap + ivec2(i - 1, j - 1), ivec2(0), hi), 0);
            finite = finite && all_finite(t.rgb);
            sum += w[i].x * w[j].y * t.rgb;
            if (i >= 1 && i <= 2 && j >= 1 && j <= 2) {
                bilinear += r.weights[(i - 1) + 2 * (j - 1)] * t;
                lo = min(lo, t.rgb);
                up = max(up, t.rgb);
            }
        }
    }
    return finite ? vec4(clamp(sum, lo, up), bilinear.a) : bilinear;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;

    vec3 y = imageLoad(noisy, p).rgb;
    if (!all_finite(y)) y = vec3(0.0);
    vec4 sums = neighbourhood_sums(p, size);
    Reprojection r = reproject(p, size, pc.history_valid != 0u, pc.camera.xyz, pc.tolerance);

    vec3 x;
    float P, R;
    float D = 0.0;  // the part of P that process noise put there (none in a fresh filter)
    vec4 res = vec4(0.0, 0.0, 0.0, -1.0);  // no residual (a new filter has no history to lag)
    vec4 m = r.valid ? history_fetch_sharp(model_prev, r) : vec4(0.0);
    bool fresh = !r.valid || !all_finite(m.rgb) || !(m.a >= 0.0) || isinf(m.a);
    if (fresh) {
        x = y;
        R = fresh_noise(sums);
        P = R;
    } else {
        vec2 noise_state = history_fetch(noise_prev, r).xy;
        float noise = noise_state.x;
        // Predict: the measured change scales the estimate, its variance and the noise.
        SceneChange sc = scene_change(r.uv, size, pc.gradient_valid != 0u, pc.stratum);
        float g = dot(sc.ratio, vec3(1.0 / 3.0));
        x = m.rgb * sc.ratio;
        P = m.a * g * g;
        R = max(noise * g * g, VARIANCE_FLOOR);
        D = max(noise_state.y, 0.0) * g * g;
        float P_carried = P;
        // The change's scale: the larger of the pixel's level and its neighbourhood's in
        // this frame. A pixel the light is about to reach is dark (x ≈ 0), and its own
        // level would keep Q ≈ 0 while its neighbours brighten: the gain must open
        // there too.
        vec3 level_x = max(x, vec3(0.0));
        vec3 level_m = neighbourhood_mean(sums);
        float level = sqrt(max(dot(level_x, level_x), dot(level_m, level_m)) / 3.0);
        float Q = pc.change_q * sc.change * level;
        Q *= Q;
        if (length(r.motion) > STILL_PX) Q += pc.motion_q * R;
        vec3 shift = vec3(0.0);
        bool shifted = false;
        bool jump = false;
        if (pc.lag_valid != 0u) {
            // A residual the neighbourhood shares, beyond lag_z standard errors, is a
            // measurement of what the prediction missed, whose prior variance B is the
            // process noise the estimate carries, D + Q: it is added with the gain
            // B / (B + its variance), and its size is uncertain. The residual shows a
            // change's miss in the frames after it, when Q may be 0 again; D still holds
            // it.
            // Where nothing ever changed (D = Q = 0) nothing is added: a static view
            // only averages.
            vec4 lag = history_fetch(lag_prev, r);
            float z2 = dot(lag.rgb, lag.rgb) / 3.0 / max(lag.a, VARIANCE_FLOOR);
            float B = D + Q;
            shifted = pc.shift != 0u && z2 > pc.lag_z * pc.lag_z && B > 0.0;
            if (shifted) shift = B / (B + max(lag.a, VARIANCE_FLOOR)) * lag.rgb;
            x += shift;
            Q += dot(shift, shift) / 3.0;
            // A shared residual beyond jump_z standard errors is a jump, announced or not
            // (below).
            jump = z2 > pc.jump_z * pc.jump_z;
        }
        float P_prior = P + Q;

        // Update, with jumps followed.
        vec3 e = y - x;
        float e2 = dot(e, e) / 3.0;
        // At a jump the level moved by about the innovation: its square joins the
        // prediction's variance and the update follows this frame's samples.
        if (jump) P_prior += e2;
        // This frame's noise measurement joins R before the gain uses it, weighted as the
        // prediction leaves room for it: where a change made the prediction uncertain
        // (P⁻ ≫ R) R is this frame's, as a fresh pixel's; converged, it moves by about 1/n.
        // Where the level shifted, a lower measurement replaces R outright: the carried R
        // is the old level's noise (a lit surface under a binary shadow ray, now in
        // shadow, has none), and averaged in at the gain's weight it would keep the gain
        // small while the estimate still shows the light that left. A higher one is
        // averaged in as usual (a single frame's high measurement would shut the gain).
        float R_now = fresh_noise(sums);
        R = max(shifted && R_now < R ? R_now : R + P_prior / (P_prior + R) * (R_now - R),
                VARIANCE_FLOOR);
        P = P_prior;
        float K = P / (P + R);
        x += K * e;
        D = (1.0 - K) * (1.0 - K) * (D + P_prior - P_carried);
        P = (1.0 - K) * P;
        // What the update left unexplained, for the pooled lag test.
        res = vec4((1.0 - K) * e, (1.0 - K) * (1.0 - K) * (P_prior + R));
        vec4 prev = history_fetch(residual_prev, r);
        if (pc.lag_valid != 0u && !jump && prev.a > 0.0 && all_finite(prev.rgb)) {
            vec3 carried = prev.rgb * sc.ratio - shift;
            res.rgb = mix(carried, res.rgb, LAG_BLEND);
        }
        if (!all_finite(res.rgb) || !all_finite(res.aaa)) res = vec4(0.0, 0.0, 0.0, -1.0);
    }
    if (!all_finite(x) || !(P >= 0.0) || isinf(P)) {
        x = y;
        R = fresh_noise(sums);
        P = R;
        D = 0.0;
    }
    imageStore(model_cur, p, vec4(x, P));
    imageStore(noise_cur, p, vec4(R, D, 0.0, 0.0));
    imageStore(residual, p, res);
}
