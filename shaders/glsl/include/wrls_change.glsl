// What ours' update passes (wrls_update.comp, wrls_constant.comp) learn of a change
// before they update the models: the temporal gradients around a pixel (a light or TF
// change measured on re-traced samples) and the pooled lag of its neighbourhood.
#ifndef DVR_WRLS_CHANGE_GLSL
#define DVR_WRLS_CHANGE_GLSL

#include "common.glsl"

// Temporal gradients pooled per S×S stratum of last frame's image (wrls_gradient.comp
// re-traced one pixel per stratum, wrls_gradient_pool.comp pooled and shrunk 3×3, 5×5 and
// 9×9 strata): the log luminance ratio of this frame's radiance to last frame's, and the
// colour of the change (0 and 1 where nothing was measured).
layout(binding = 23, rgba32f) uniform readonly image2D gradient_ratio;  // rgb colour, a log ratio

// What the temporal gradients say about the scene around last frame's texture coordinate
// `uv`: per channel, the ratio of this frame's radiance to last frame's (the same paths
// traced in both scenes), and the relative change of luminance. No measurement
// (`measured` false): ratio 1, change 0.
struct SceneChange {
    vec3 ratio;
    float change;
};

SceneChange scene_change(vec2 uv, ivec2 size, bool measured, uint stratum) {
    SceneChange sc;
    sc.ratio = vec3(1.0);
    sc.change = 0.0;
    if (!measured) return sc;
    ivec2 k = clamp(ivec2(floor(uv * vec2(size) / float(stratum))), ivec2(0),
                    imageSize(gradient_ratio) - 1);
    vec4 pooled = imageLoad(gradient_ratio, k);
    float Ra = exp(pooled.a);
    sc.change = abs(Ra - 1.0) / max(Ra, 1.0);
    sc.ratio = pooled.rgb * Ra;
    return sc;
}

// How significant last frame's pooled residual `drift` (rgb mean, a its variance;
// wrls_drift.comp) is: 0 within `z` standard errors of zero, 1 beyond 2z, a smooth step
// between (so noise is not mistaken for lag).
float drift_significance(vec4 drift, float z) {
    float z2 = dot(drift.rgb, drift.rgb) / 3.0 / max(drift.a, 1e-12);
    return smoothstep(z * z, 4.0 * z * z, z2);
}

// The drift as a correction to add to the models.
vec3 significant_drift(vec4 drift, float z) {
    return drift_significance(drift, z) * drift.rgb;
}

// The a-posteriori residual an update pass hands to the pooled lag test (wrls_drift.comp):
// rgb the residual, a its variance; a < 0 where there is none (a new model, or a value
// that is not finite), so the lag test need not check its taps.
vec4 lag_residual(bool has_history, vec3 residual, float variance) {
    vec4 r = vec4(residual, variance);
    return has_history && all_finite(r.rgb) && all_finite(r.aaa) ? r : vec4(0.0, 0.0, 0.0, -1.0);
}

// Last frame's running residual `prev` (reprojected) carried into this frame: it follows
// the measured change `ratio`, and the `correction` this frame's update added to the
// models (significant_drift) is no longer a lag.
vec4 carried_lag(vec4 prev, vec3 ratio, vec3 correction) {
    return vec4(prev.rgb * ratio - correction, prev.a);
}

// The running residual the pooled lag test averages (wrls_drift.comp): this frame's
// a-posteriori residual `residual` (variance `variance`) blended with last frame's running
// one `prev` (carried_lag; a < 0 or not finite: none) by `alpha`. A lag
// persists from frame to frame while the noise does not, so the running residual shows a
// lag too small for one frame's neighbourhood: with alpha 0.5 its variance is a third of
// one frame's.
vec4 running_lag(bool has_history, vec4 prev, vec3 residual, float variance, float alpha) {
    if (prev.a > 0.0 && all_finite(prev.rgb) && !isinf(prev.a)) {
        float b = 1.0 - alpha;
        residual = b * prev.rgb + alpha * residual;
        variance = b * b * prev.a + alpha * alpha * variance;
    }
    return lag_residual(has_history, residual, variance);
}

// The variance of this frame's pixel mean from its samples' luminance moments (x mean,
// y second moment over `spp` samples): the sampling noise alone, which a change does not
// inflate as it inflates the running residual.
float sample_variance(vec2 moments, float spp) {
    return max(moments.y - moments.x * moments.x, 0.0) / max(spp - 1.0, 1.0);
}

#endif
