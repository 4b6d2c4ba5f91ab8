#version 460
// ours' temporal pass: per pixel, a weighted-RLS model p = [1] (its RGB coefficient β and
// scalar P) reprojected from last frame, adjusted for what changed, then updated with
// this frame's noisy colour. What changed is measured twice, before the update: the
// temporal gradients scale the model by the ratio the re-traced samples show and lower
// its forgetting factor in proportion (a light or TF change), and last frame's pooled
// residual, where significant, is added to it and lowers the forgetting factor too (a
// lag no single pixel's noise reveals).
// A residual far above the model's running noise level twice in a row restarts it (a
// jump); a single far residual is a spike and is given little weight.
//
// State, two images: model (rgba32f: rgb β, a P) and stats (rg32f: x running noise level,
// the mean squared a-priori residual over the three channels; y frames in a row with a
// far residual).
// Outputs for the spatial pass: the prediction (rgb) with its variance (a), and for the
// pooled lag test (wrls_drift.comp) the running a-posteriori residual (a history: this
// frame's blended with last frame's, wrls_change.glsl running_lag).
#include "common.glsl"
#include "reproject.glsl"
#include "wrls.glsl"
#include "wrls_change.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2) uniform sampler2D model_prev;
layout(binding = 3) uniform sampler2D stats_prev;
layout(binding = 4, rgba32f) uniform writeonly image2D model_cur;
layout(binding = 5, rg32f) uniform writeonly image2D stats_cur;
layout(binding = 6, rgba32f) uniform writeonly image2D prediction;  // rgb, a variance
layout(binding = 7, rgba32f) uniform writeonly image2D residual;    // rgb, a variance (< 0: none)
layout(binding = 8) uniform sampler2D drift_prev;                    // rgb mean, a variance
layout(binding = 9, rgba32f) uniform readonly image2D moments;       // x mean, y 2nd moment of luminance
layout(binding = 10) uniform sampler2D residual_prev;                // last frame's `residual`

layout(push_constant) uniform WrlsConstantPush {
    vec4 camera;          // xyz camera position
    uint width;
    uint height;
    uint history_valid;
    float lambda;         // forgetting factor where nothing changed
    float delta;          // P of a model that has seen nothing
    float tolerance;      // disocclusion tolerance in pixels
    float change_ratio;   // squared residual over the noise level that counts as far
    float outlier_sigmas; // k in the weights exp(-r²/(k²·noise level))
    uint gradient_valid;  // the gradient images were measured this frame
    uint drift_valid;     // drift_prev holds last frame's pooled residuals
    uint stratum;         // the gradients' stratum edge in pixels
    float lambda_min;     // forgetting factor at a sudden change
    float change_gain;    // change per frame over the noise at which the history is forgotten: 1/gain
    float drift_z;        // pooled residual, in standard errors, that starts to count
    float spp;            // samples per pixel of the noisy frame
    float lambda_moving;  // forgetting factor of a pixel whose surface moved on screen
    float drift_forget;   // share of the way to lambda_min at a clearly significant lag
    float drift_forget_z; // pooled residual, in standard errors, from which it forgets
    float lag_alpha;      // weight of this frame's residual in the running one (1: its own)
    float pad0;
} pc;

const float P_MAX = 1e6;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;

    vec3 I = imageLoad(noisy, p).rgb;
    if (!all_finite(I)) I = vec3(0.0);

    Reprojection r = reproject(p, size, pc.history_valid != 0u, pc.camera.xyz, pc.tolerance);
    // A moving pixel's history is only approximately the same radiance: through a
    // semi-transparent volume the path of its ray changes with the view, so a long
    // memory under camera motion accumulates the difference. It keeps a shorter one.
    float lambda = length(r.motion) > 0.01 ? min(pc.lambda, pc.lambda_moving) : pc.lambda;

    vec3 beta = vec3(0.0);
    float P = pc.delta;
    float noise_level = -1.0;  // none yet
    float streak = 0.0;
    vec4 lag_prev = vec4(0.0, 0.0, 0.0, -1.0);  // the running residual: none
    if (r.valid) {
        vec4 m = history_fetch(model_prev, r);
        vec4 st = history_fetch(stats_prev, r);
        // The scene changed: scale the model by the ratio the gradients measured, so it
        // follows the change instead of lagging, and forget in proportion to what the
        // scaling may have missed (below).
        SceneChange sc = scene_change(r.uv, size, pc.gradient_valid != 0u, pc.stratum);
        float mean_ratio = dot(sc.ratio, vec3(1.0 / 3.0));
        beta = m.rgb * sc.ratio;
        P = m.a;
        noise_level = st.x * mean_ratio * mean_ratio;
        streak = st.y;
        // Forget in proportion to the change per frame against this pixel's noise (a
        // steady-state Kalman gain grows as the change over the noise): a bright pixel
        // under a moving light keeps a short history, a dim, noisy one a longer one.
        float sigma = sqrt(max(noise_level, 0.0) / 3.0);
        float forget = min(1.0, pc.change_gain * sc.change * luminance(beta) / (sigma + 1e-6));
        lambda = mix(lambda, pc.lambda_min, forget);
        if (pc.drift_valid != 0u) {
            vec4 drift = history_fetch(drift_prev, r);
            vec3 correction = significant_drift(drift, pc.drift_z);
            beta += correction;
            if (pc.lag_alpha < 1.0) {
                lag_prev = carried_lag(history_fetch(residual_prev, r), sc.ratio, correction);
            }
            // A lag the neighbourhood shares is a change the gradients missed: forget in
            // proportion too, from a lower significance than the correction needs.
            float lag = drift_significance(drift, pc.drift_forget_z);
            lambda = mix(lambda, pc.lambda_min, pc.drift_forget * lag);
        }
    }

    vec3 e = I - beta;
    float r2 = dot(e, e);
    bool fresh = noise_level < 0.0;
    if (fresh) {
        // A new model has no residuals yet: its noise level is the variance of this
        // frame's pixel mean, from the samples' luminance moments over the 3×3
        // neighbourhood (one pixel's two samples say too little), over three channels.
        float v = 0.0;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                vec2 m = imageLoad(moments, clamp(p + ivec2(dx, dy), ivec2(0), size - 1)).xy;
                v += max(m.y - m.x * m.x, 0.0);
            }
        }
        noise_level = 3.0 * v / 9.0 / max(pc.spp - 1.0, 1.0) + 1e-6;
    }
    // The change threshold, fixed before this frame's restart may raise the noise level.
    float cap = pc.change_ratio * (noise_level + 1e-6);
    bool far = r2 > cap;
    streak = far ? streak + 1.0 : 0.0;
    // The residual in units of the model's own running noise level: only samples many
    // standard deviations out (spikes) lose weight; a residual that stays high (a change,
    // streak ≥ 2) is learned at full weight.
    float w = 1.0;
    if (WEIGHTED && !fresh && streak < 2.0) {
        w = max(exp(-r2 / (pc.outlier_sigmas * pc.outlier_sigmas * (noise_level + 1e-6))), 1e-6);
    }
    if (RESTART_ON_CHANGE && streak >= 2.0) {
        // A confirmed jump: start over from this sample, and take the residual as the
        // noise level until the new state's own is measured.
        beta = vec3(0.0);
        P = pc.delta;
        e = I;
        noise_level = max(noise_level, r2);
        streak = 0.0;
    }
    // Without restarts, a residual that stays high becomes the new noise level.
    if (streak > 4.0) {
        noise_level = r2;
        streak = 0.0;
    }
    // Spikes barely move the noise level; ordinary residuals track it.
    noise_level = mix(noise_level, r2, far ? 0.02 : 0.1);

    float q = P / (lambda / w + P);
    beta += q * e;
    P = clamp((P - q * P) / lambda, 1e-8, P_MAX);
    if (!all_finite(beta) || isnan(P)) {
        beta = I;
        P = pc.delta;
    }
    float noise = max(noise_level, 0.0) / 3.0;  // per channel
    imageStore(model_cur, p, vec4(beta, P));
    imageStore(stats_cur, p, vec4(noise_level, streak, 0.0, 0.0));
    imageStore(prediction, p, vec4(max(beta, vec3(0.0)), noise * P));
    // What this frame's update left unexplained, for the pooled lag test; a fresh model
    // has no history to lag.
    float keep = 1.0 - q;
    float variance = sample_variance(imageLoad(moments, p).xy, pc.spp) + noise * P;
    imageStore(residual, p, running_lag(r.valid && !fresh, lag_prev, keep * e,
                                        keep * keep * variance, pc.lag_alpha));
}
