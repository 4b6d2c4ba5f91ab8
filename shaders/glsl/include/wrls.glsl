// State of the per-pixel linear models (TVCG §5): predictor p = [1, z] (d = 4), one β
// per colour channel, and one symmetric 4×4 P shared by the channels, stored as its upper
// triangle in three rgba32f texels: (P00 P01 P02 P03) (P11 P12 P13 P22) (P23 P33 − −).
#ifndef DVR_WRLS_GLSL
#define DVR_WRLS_GLSL

// Ablation switches (the paper's Fig. 8): weighted (wRLS) or plain RLS (w = 1), and the
// temporal feature in the predictor or not (p = [1]).
layout(constant_id = 9) const bool WEIGHTED = true;
layout(constant_id = 10) const bool USE_FEATURE = true;
// The paper builds the predictor from z(t), which contains this frame's noisy colour, the
// regression target itself; the fitted coefficient on z then tends to 1 + α and the
// output keeps (amplified) single-frame noise. `ours` fits against the reprojected,
// clamped history Ψ[z_q(t−1), Ĩ(t)] instead (uncorrelated with this frame's noise), so
// static regions converge like a long average. PAPER_PREDICTOR = true restores the
// paper's exact formulation for comparison (`wrls-paper`).
layout(constant_id = 11) const bool PAPER_PREDICTOR = false;
// Per-pixel automatic forgetting (beyond the paper): when the a-priori residual is far
// above its running noise level twice in a row (a light/TF change, not a single spike),
// the model starts over from the current sample, like a model on a new surface.
layout(constant_id = 12) const bool RESTART_ON_CHANGE = true;
// Model selection (beyond the paper; "model no more than a scene needs"): each pixel also
// keeps the constant model p = [1] and tracks both models' a-priori (out-of-sample)
// squared errors; the temporal feature is used only where it predicts measurably better
// (a changing pixel), the constant model where it does not (a static one: fitting three
// more coefficients to noise costs variance, measured 2x the MSE of p = [1] there).
layout(constant_id = 13) const bool MODEL_SELECTION = true;

// Weight of the feature model given both models' running a-priori squared errors
// (x: constant model, y: feature model): 0 until the feature removes a clear share of
// the constant model's error, 1 once it removes a quarter.
float feature_share(vec2 errors) {
    if (!MODEL_SELECTION) return 1.0;
    if (errors.x <= 0.0 || errors.y <= 0.0) return 0.0;
    return smoothstep(0.05, 0.25, 1.0 - errors.y / errors.x);
}

mat4 unpack_p(vec4 a, vec4 b, vec4 c) {
    return mat4(
        a.x, a.y, a.z, a.w,
        a.y, b.x, b.y, b.z,
        a.z, b.y, b.w, c.x,
        a.w, b.z, c.x, c.y);
}

void pack_p(mat4 m, out vec4 a, out vec4 b, out vec4 c) {
    a = vec4(m[0][0], m[0][1], m[0][2], m[0][3]);
    b = vec4(m[1][1], m[1][2], m[1][3], m[2][2]);
    c = vec4(m[2][3], m[3][3], 0.0, 0.0);
}

vec4 predictor(vec3 z) {
    return USE_FEATURE ? vec4(1.0, z) : vec4(1.0, 0.0, 0.0, 0.0);
}

#endif
