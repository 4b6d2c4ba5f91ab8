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
// The constant model (MODEL_SELECTION): rgb β, a its scalar P; and the two models'
// running a-priori squared errors (x constant, y feature).
layout(binding = 16) uniform sampler2D constant_prev;
layout(binding = 17) uniform sampler2D errors_prev;
layout(binding = 18, rgba32f) uniform writeonly image2D constant_cur;
layout(binding = 19, rgba32f) uniform writeonly image2D errors_cur;
// This pixel's prediction after the update (rgb) and its variance per channel (a), what
// the à-trous spatial filter (variance_atrous.comp) starts from.
layout(binding = 25, rgba32f) uniform writeonly image2D prediction;

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
    float change_ratio;   // residual / noise-level ratio that counts as a change
    float outlier_sigmas; // residual weights: k in exp(-r²/(k²·noise level))
    float pad0;
    float pad1;
} pc;

const float P_MAX = 1e6;

// P of a model that has seen nothing: δ·I over the predictor's dimensions.
mat4 initial_p() {
    return USE_FEATURE ? mat4(pc.delta) : mat4(pc.delta, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0);
}

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
    vec4 constant = vec4(0.0, 0.0, 0.0, pc.delta);
    vec3 errors = vec3(-1.0, -1.0, 0.0);  // a-priori errors (const, feature), const streak
    float lambda = pc.lambda;
    if (r.valid) {
        vec4 zq = history_fetch(z_prev, r);
        z_hist = clamp(zq.rgb, lo, hi);
        z = pc.alpha * z_hist + (1.0 - pc.alpha) * I;
        age = zq.w + 1.0;
        beta[0] = history_fetch(beta_r_prev, r);
        beta[1] = history_fetch(beta_g_prev, r);
        beta[2] = history_fetch(beta_b_prev, r);
        vec4 p2 = history_fetch(p2_prev, r);
        P = unpack_p(history_fetch(p0_prev, r), history_fetch(p1_prev, r), p2);
        noise_level = p2.z;
        streak = p2.w;
        if (MODEL_SELECTION) {
            constant = history_fetch(constant_prev, r);
            errors = history_fetch(errors_prev, r).xyz;
        }
    } else {
        // A new surface: start the models over.
        z = I;
        z_hist = I;
        age = 1.0;
        beta[0] = vec4(0.0);
        beta[1] = vec4(0.0);
        beta[2] = vec4(0.0);
        P = initial_p();
    }

    vec3 feature = PAPER_PREDICTOR ? z : z_hist;
    // A new model's first sample has no history: its "feature" would be the sample
    // itself, the regression target, so it only informs the constant term (frame 0 is
    // then a bilateral filter of the noisy frame in the spatial pass).
    vec4 x = r.valid || PAPER_PREDICTOR ? predictor(feature) : vec4(1.0, 0.0, 0.0, 0.0);
    vec3 e = I - vec3(dot(x, beta[0]), dot(x, beta[1]), dot(x, beta[2]));
    float r2 = dot(e, e);
    bool fresh = noise_level < 0.0;
    if (fresh) noise_level = r2;
    // The change threshold, fixed before this frame's restart may raise the noise level.
    float cap = pc.change_ratio * (noise_level + 1e-6);
    bool far = r2 > cap;
    streak = far ? streak + 1.0 : 0.0;
    float w = 1.0;
    if (WEIGHTED && PAPER_PREDICTOR) {
        // The paper's weights: relative colour distance to the temporal feature. With
        // 2-spp volume noise most ordinary samples lie far from it in relative terms, and
        // dark ones more so than bright ones, so they bias the fit (measured +5.5% on a
        // static mri view) and waste most samples.
        float d = length(I - feature) / (min(length(I), length(feature)) + 1e-4);
        w = max(exp(-(d * d) / (pc.h * pc.h)), 1e-6);
    } else if (WEIGHTED && !fresh && streak < 2.0) {
        // Ours: the a-priori residual in units of the model's own running noise level, so
        // only samples many standard deviations out (spikes) lose weight and ordinary
        // noise is averaged in full. A residual that stays high (a change, streak ≥ 2)
        // is not an outlier: it is learned at full weight.
        w = max(exp(-r2 / (pc.outlier_sigmas * pc.outlier_sigmas * (noise_level + 1e-6))), 1e-6);
    }
    if (RESTART_ON_CHANGE && streak >= 2.0) {
        // A confirmed change: the residual far above the noise level twice in a row (a
        // spike is once, and its weight handles it). Start the model over from this
        // sample, as for a new surface, and take the residual as the noise level until
        // the new state's own is measured, so a noisier state after the change does not
        // read as further changes.
        beta[0] = vec4(0.0);
        beta[1] = vec4(0.0);
        beta[2] = vec4(0.0);
        P = initial_p();
        x = vec4(1.0, 0.0, 0.0, 0.0);
        e = I;
        noise_level = max(noise_level, r2);
        streak = 0.0;
    }
    // Without automatic forgetting, a residual that stays high is adopted as the new
    // noise level after a few frames.
    if (streak > 4.0) {
        noise_level = r2;
        streak = 0.0;
    }
    // Spikes barely move the noise level; ordinary residuals track it.
    noise_level = mix(noise_level, r2, far ? 0.02 : 0.1);
    if (MODEL_SELECTION) {
        // Both models' a-priori errors, winsorised at the change threshold so that one
        // spike does not decide; they rise fast (a model that stopped predicting loses at
        // once) and fall slowly (the choice does not flicker on a static pixel).
        vec3 ec = I - constant.rgb;
        float rc2 = dot(ec, ec);
        vec2 sq = min(vec2(rc2, r2), vec2(pc.change_ratio * (noise_level + 1e-6)));
        errors.xy = errors.x < 0.0 ? sq : mix(errors.xy, sq, mix(vec2(0.05), vec2(0.3), greaterThan(sq, errors.xy)));
        // The same weighted RLS with p = [1] (P is a scalar), with its own change test:
        // it cannot follow a change through a feature, so it starts over when its
        // residual is far above the noise level twice in a row.
        float streak_c = rc2 > cap ? errors.z + 1.0 : 0.0;
        float wc = WEIGHTED && streak_c < 2.0
                 ? max(exp(-rc2 / (pc.outlier_sigmas * pc.outlier_sigmas * (noise_level + 1e-6))), 1e-6)
                 : 1.0;
        if (RESTART_ON_CHANGE && streak_c >= 2.0) {
            constant = vec4(0.0, 0.0, 0.0, pc.delta);
            ec = I;
            streak_c = 0.0;
        }
        errors.z = streak_c;
        float qc = constant.a / (lambda / wc + constant.a);
        constant.rgb += qc * ec;
        constant.a = clamp((constant.a - qc * constant.a) / lambda, 1e-8, P_MAX);
        if (!all_finite(constant.rgb) || isnan(constant.a)) constant = vec4(I, pc.delta);
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
    // The prediction of this frame's radiance by the updated models, and its variance:
    // the residual noise per channel times xᵀPx (P00 for the constant model).
    vec3 pred = vec3(dot(x, beta[0]), dot(x, beta[1]), dot(x, beta[2]));
    float var = max(noise_level, 0.0) / 3.0 * max(dot(x, P * x), 0.0);
    if (MODEL_SELECTION) {
        float share = feature_share(errors.xy);
        pred = mix(constant.rgb, pred, share);
        var = mix(max(noise_level, 0.0) / 3.0 * constant.a, var, share);
    }
    if (!all_finite(pred) || isnan(var) || isinf(var)) {
        pred = I;
        var = max(noise_level, 0.0) / 3.0;
    }
    imageStore(prediction, p, vec4(max(pred, vec3(0.0)), var));

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
    if (MODEL_SELECTION) {
        imageStore(constant_cur, p, constant);
        imageStore(errors_cur, p, vec4(errors, 0.0));
    }
}
