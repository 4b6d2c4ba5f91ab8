// What ours' update passes (wrls_update.comp, wrls_constant.comp) learn of a change
// before they update the models: the temporal gradients around a pixel (a light or TF
// change measured on re-traced samples) and the pooled lag of its neighbourhood.
#ifndef DVR_WRLS_CHANGE_GLSL
#define DVR_WRLS_CHANGE_GLSL

#include "common.glsl"

// Temporal gradients (wrls_gradient.comp), per S×S stratum of last frame's image: last
// frame's samples re-traced in this frame's scene, and what they measured last frame.
layout(binding = 23, rgba32f) uniform readonly image2D gradient_new;
layout(binding = 24, rgba32f) uniform readonly image2D gradient_old;

// What the temporal gradients say about the scene around last frame's texture coordinate
// `uv`: per channel, the ratio of this frame's radiance to last frame's (the same paths
// traced in both scenes, summed over the 3×3 strata around it), and the relative change
// of luminance. No measurement (`measured` false): ratio 1, change 0. `shrink`: squared
// standard errors of the ratio that halve its departure from the prior. `prior`: the log
// luminance ratio expected (last frame's, reprojected: under a moving light the change
// goes on, and a dark, noisy region's measurement alone is shrunk so far towards 1 that
// the model lags; measured on the suite's mri/area-light, worst frame −0.52 → +0.4 dB).
struct SceneChange {
    vec3 ratio;
    float change;
    float log_ratio;  // the luminance ratio applied, as a log: next frame's prior
};

SceneChange scene_change(vec2 uv, ivec2 size, bool measured, uint stratum, float shrink,
                         float prior) {
    SceneChange sc;
    sc.ratio = vec3(1.0);
    sc.change = 0.0;
    sc.log_ratio = 0.0;
    if (!measured) return sc;
    ivec2 strata = imageSize(gradient_new);
    ivec2 centre = ivec2(floor(uv * vec2(size) / float(stratum)));
    vec3 sum_new = vec3(0.0), sum_old = vec3(0.0);
    float nn = 0.0, no = 0.0, oo = 0.0;  // sums of products of the luminances
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 k = clamp(centre + ivec2(dx, dy), ivec2(0), strata - 1);
            vec3 n = imageLoad(gradient_new, k).rgb, o = imageLoad(gradient_old, k).rgb;
            sum_new += n;
            sum_old += o;
            float yn = luminance(n), yo = luminance(o);
            nn += yn * yn;
            no += yn * yo;
            oo += yo * yo;
        }
    }
    float y_new = luminance(sum_new), y_old = luminance(sum_old);
    float y_max = max(y_new, y_old);
    if (y_max <= 1e-6 || y_old <= 1e-6) return sc;
    // The luminance ratio and its standard error from the strata's scatter about it
    // (a ratio estimator's sandwich variance): a ratio within its noise of the prior is
    // shrunk towards it, so noise is not mistaken for change and the history is kept.
    float R = y_new / y_old;
    float scatter = max(nn - 2.0 * R * no + R * R * oo, 0.0);
    float var_r = scatter / (y_old * y_old) * (9.0 / 8.0);
    // Shrunk towards the prior (last frame's ratio here: a change under way goes on)
    // in log space, where a steady change is a constant.
    float L = log(clamp(R, 0.25, 4.0));
    float var_l = var_r / (R * R + 1e-12);
    // The prior only where this frame's measurement goes the same way, and never beyond
    // it: the trend lends the measured change confidence, it does not extrapolate.
    prior = L * prior > 0.0 ? sign(L) * min(abs(prior), abs(L)) : 0.0;
    float d = L - prior;
    float keep = d * d / (d * d + shrink * var_l + 1e-12);
    sc.log_ratio = prior + keep * d;
    float Ra = exp(sc.log_ratio);
    sc.change = abs(Ra - 1.0) / max(Ra, 1.0);
    // Channels far darker than the luminance are damped towards no change.
    float eps = 0.01 * y_max;
    vec3 ratio = clamp((sum_new + eps) / (sum_old + eps), vec3(0.25), vec3(4.0));
    // The colour of the change (each channel's ratio over the luminance's) is shrunk
    // towards grey by the measurement alone: the prior knows only the luminance.
    float keep0 = L * L / (L * L + shrink * var_l + 1e-12);
    sc.ratio = mix(vec3(1.0), ratio / exp(L), keep0) * Ra;
    return sc;
}

// Last frame's pooled residual `drift` (rgb mean, a its variance; wrls_drift.comp) as a
// correction to add to the models: nothing within `z` standard errors of zero, all of it
// beyond 2z, a smooth step between (so noise is not mistaken for lag).
vec3 significant_drift(vec4 drift, float z) {
    float z2 = dot(drift.rgb, drift.rgb) / 3.0 / max(drift.a, 1e-12);
    return smoothstep(z * z, 4.0 * z * z, z2) * drift.rgb;
}

#endif
