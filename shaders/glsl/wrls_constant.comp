#version 460
// The paper's Fig. 8 ablations without the temporal feature (`wrls-nf`, `rls-nf`): per
// pixel, a weighted-RLS model p = [1] (its RGB coefficient β and scalar P) reprojected
// from last frame and updated with this frame's noisy colour. A residual far above the
// model's running noise level twice in a row restarts it (a jump); a single far residual
// is a spike and is given little weight (`wrls-nf`; `rls-nf` weighs every sample 1).
//
// State, two images: model (rgba32f: rgb β, a P) and stats (rg32f: x running noise level,
// the mean squared a-priori residual over the three channels; y frames in a row with a
// far residual). Output for the spatial pass: the prediction (rgb) with its variance (a).
#include "common.glsl"
#include "reproject.glsl"
#include "wrls.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2) uniform sampler2D model_prev;
layout(binding = 3) uniform sampler2D stats_prev;
layout(binding = 4, rgba32f) uniform writeonly image2D model_cur;
layout(binding = 5, rg32f) uniform writeonly image2D stats_cur;
layout(binding = 6, rgba32f) uniform writeonly image2D prediction;  // rgb, a variance
layout(binding = 9, rgba32f) uniform readonly image2D moments;       // x mean, y 2nd moment of luminance

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
    float spp;            // samples per pixel of the noisy frame
    float lambda_moving;  // forgetting factor of a pixel whose surface moved on screen
    float pad0;
    float pad1;
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
    if (r.valid) {
        vec4 m = history_fetch(model_prev, r);
        vec4 st = history_fetch(stats_prev, r);
        beta = m.rgb;
        P = m.a;
        noise_level = st.x;
        streak = st.y;
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
}
