#version 460
// The paper's denoiser, temporal part (TVCG §5): per pixel, build the temporal feature z
// from the reprojected history (clamped to this frame's 3×3 neighbourhood), then update
// the reprojected linear models β (one per channel) and their shared P by weighted
// recursive least squares with this frame's noisy colour as the target. Models, not
// colours, are reprojected.
#include "common.glsl"
#include "reproject.glsl"
#include "wrls.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2) uniform sampler2D z_prev;
layout(binding = 3) uniform sampler2D beta_r_prev;
layout(binding = 4) uniform sampler2D beta_g_prev;
layout(binding = 5) uniform sampler2D beta_b_prev;
layout(binding = 6) uniform sampler2D p0_prev;
layout(binding = 7) uniform sampler2D p1_prev;
layout(binding = 8) uniform sampler2D p2_prev;
layout(binding = 9, rgba32f) uniform writeonly image2D z_cur;
layout(binding = 10, rgba32f) uniform writeonly image2D beta_r_cur;
layout(binding = 11, rgba32f) uniform writeonly image2D beta_g_cur;
layout(binding = 12, rgba32f) uniform writeonly image2D beta_b_cur;
layout(binding = 13, rgba32f) uniform writeonly image2D p0_cur;
layout(binding = 14, rgba32f) uniform writeonly image2D p1_cur;
layout(binding = 15, rgba32f) uniform writeonly image2D p2_cur;

layout(push_constant) uniform WrlsUpdatePush {
    vec4 camera;          // xyz camera position
    uint width;
    uint height;
    uint history_valid;
    float lambda;         // forgetting factor (0.998)
    float alpha;          // temporal feature blend (0.75)
    float h;              // weight bandwidth (0.75)
    float delta;          // initial P = delta · I
    float tolerance;      // disocclusion tolerance, relative to camera distance
    float lambda_min;     // forgetting factor during a detected change
    float change_ratio;   // residual / noise-level ratio that counts as a change
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
    vec3 lo = I, hi = I;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            vec3 c = imageLoad(noisy, clamp(p + ivec2(dx, dy), ivec2(0), size - 1)).rgb;
            if (all_finite(c)) { lo = min(lo, c); hi = max(hi, c); }
        }
    }

    Reprojection r = reproject(p, size, pc.history_valid != 0u, pc.camera.xyz, pc.tolerance);
    vec3 z;
    vec3 z_hist;
    vec4 beta[3];
    mat4 P;
    float age;
    float noise_level = -1.0;  // running mean of the squared a-priori residual
    float streak = 0.0;        // consecutive frames far above the noise level
    if (r.valid) {
        vec4 zq = texture(z_prev, r.uv);
        z_hist = clamp(zq.rgb, lo, hi);
        z = pc.alpha * z_hist + (1.0 - pc.alpha) * I;
        age = zq.w + 1.0;
        beta[0] = texture(beta_r_prev, r.uv);
        beta[1] = texture(beta_g_prev, r.uv);
        beta[2] = texture(beta_b_prev, r.uv);
        vec4 p2 = texture(p2_prev, r.uv);
        P = unpack_p(texture(p0_prev, r.uv), texture(p1_prev, r.uv), p2);
        noise_level = p2.z;
        streak = p2.w;
    } else {
        // A new surface: start the models over.
        z = I;
        z_hist = I;
        age = 1.0;
        beta[0] = vec4(0.0);
        beta[1] = vec4(0.0);
        beta[2] = vec4(0.0);
        P = mat4(pc.delta);
        if (!USE_FEATURE) P = mat4(pc.delta, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
    }

    vec3 feature = PAPER_PREDICTOR ? z : z_hist;
    vec4 x = predictor(feature);
    float w = 1.0;
    if (WEIGHTED) {
        float d = length(I - feature) / (min(length(I), length(feature)) + 1e-4);
        w = max(exp(-(d * d) / (pc.h * pc.h)), 1e-6);
    }
    vec3 e = I - vec3(dot(x, beta[0]), dot(x, beta[1]), dot(x, beta[2]));
    float r2 = dot(e, e);
    float lambda = pc.lambda;
    if (ADAPTIVE_LAMBDA) {
        if (noise_level < 0.0) noise_level = r2;
        bool far = r2 > pc.change_ratio * (noise_level + 1e-6);
        streak = far ? streak + 1.0 : 0.0;
        // A change is a residual far above the noise level for 2–4 frames in a row: forget
        // fast while it lasts. A spike is one frame (its weight w handles it); a residual
        // that stays high longer is the new scene's noise level, adopted as such, so a
        // noisier state after the change does not keep the model forgetting.
        if (streak >= 2.0 && streak <= 4.0) lambda = pc.lambda_min;
        if (streak > 4.0) {
            noise_level = r2;
            streak = 0.0;
        }
        // Spikes barely move the noise level; ordinary residuals track it.
        noise_level = mix(noise_level, r2, far ? 0.02 : 0.1);
    }
    vec4 Px = P * x;
    vec4 q = Px / (lambda / w + dot(x, Px));
    for (int c = 0; c < 3; ++c) beta[c] += q * e[c];
    P = (P - outerProduct(q, Px)) / lambda;
    // fp32 hygiene: keep P symmetric with a positive, bounded diagonal (wind-up guard
    // for predictors that stop exciting some direction on long static runs).
    P = 0.5 * (P + transpose(P));
    for (int k = 0; k < 4; ++k) P[k][k] = clamp(P[k][k], 1e-8, P_MAX);
    bool ok = true;
    for (int k = 0; k < 4; ++k) {
        ok = ok && !any(isnan(P[k])) && !any(isinf(P[k]));
    }
    for (int c = 0; c < 3; ++c) ok = ok && !any(isnan(beta[c])) && !any(isinf(beta[c]));
    if (!ok) {
        beta[0] = vec4(I.r, 0, 0, 0);
        beta[1] = vec4(I.g, 0, 0, 0);
        beta[2] = vec4(I.b, 0, 0, 0);
        P = mat4(pc.delta);
    }
    vec4 a, b, c;
    pack_p(P, a, b, c);
    c.z = noise_level;
    c.w = streak;
    imageStore(z_cur, p, vec4(z, age));
    imageStore(beta_r_cur, p, beta[0]);
    imageStore(beta_g_cur, p, beta[1]);
    imageStore(beta_b_cur, p, beta[2]);
    imageStore(p0_cur, p, a);
    imageStore(p1_cur, p, b);
    imageStore(p2_cur, p, c);
}
