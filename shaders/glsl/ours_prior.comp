#version 460
// ours' spatial prior: where an estimate is young (its relative standard error above
// `keep`), a local linear model of its neighbours' estimates on the guides
// (ours_prior_fit.comp) predicts it, and the prediction is combined with the estimate by
// their variances before the à-trous filter.
//
// Model. Around p, x_q = βᵀf_q + ε_q, f_q = (1, a_q, n_q), with a_q the TF albedo
// composited along q's ray and n_q its surface's gradient normal, both over its footprint
// (deterministic: ours_guide.comp). The fit's prediction x̂_p = βᵀf_p is given the error variance V, the
// residuals' mean square over the window: its average error there, with the neighbours'
// own noise counted in full (which the fit averages down), so the prior is trusted less
// than it could be where the model holds; where it does not hold at p alone (a fold the
// window's fit misses) V understates the error. With the estimate's variance P, the two are
// combined as two measurements of one value:
//     x' = (V x_p + P x̂_p) / (V + P),   P' = V P / (V + P).
// A young estimate (the first frames, a disocclusion, a change the gradients measured)
// leans on the albedo's structure (a silhouette, a coloured vessel, a shell's rim) where
// the à-trous' range term, comparing two noisy estimates, tells them apart only by
// chance; a converged one (P ≪ V) keeps its own value; where the albedo explains little
// (an MRI's shading), V is large and the prior weighs little.
// Every pixel's prediction x̂ is also written out, converged or not: the à-trous carries
// each neighbour's estimate to the pixel by it (variance_atrous.comp, CARRY).
#include "common.glsl"
#include "ours_prior.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D estimate;   // rgb x, a P
layout(binding = 1, rgba16f) uniform readonly image2D footprint;          // rgb albedo (ours_guide.comp)
layout(binding = 10, rgba16f) uniform readonly image2D footprint_normal;  // xyz normal
layout(binding = 2) uniform sampler2D fit_r_lo;                   // ours_prior_fit.comp
layout(binding = 3) uniform sampler2D fit_r_hi;                   // a V
layout(binding = 4) uniform sampler2D fit_g_lo;
layout(binding = 5) uniform sampler2D fit_g_hi;
layout(binding = 6) uniform sampler2D fit_b_lo;
layout(binding = 7) uniform sampler2D fit_b_hi;
layout(binding = 8, rgba32f) uniform writeonly image2D combined;    // rgb x', a P'
layout(binding = 9, rgba32f) uniform writeonly image2D prediction;  // rgb x̂, a 1 where there is one

layout(push_constant) uniform OursPriorPush {
    uint width;
    uint height;
    float keep;  // relative standard error below which an estimate is kept as it is
    uint combine;  // 1: young estimates are combined with the prediction (0: ours-no-prior)
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    // The fits interpolated bilinearly between the cells' centres (cell i's centre is
    // pixel PRIOR_STRIDE·i + (PRIOR_STRIDE − 1)/2).
    vec2 uv = (vec2(p) + 0.5) / (float(PRIOR_STRIDE) * vec2(textureSize(fit_r_lo, 0)));
    vec4 lo = features_lo(imageLoad(footprint, p).rgb);
    vec3 hi = features_hi(imageLoad(footprint_normal, p).xyz);
    vec4 r_hi = texture(fit_r_hi, uv);
    vec3 pred = vec3(dot(texture(fit_r_lo, uv), lo) + dot(r_hi.xyz, hi),
                     dot(texture(fit_g_lo, uv), lo) + dot(texture(fit_g_hi, uv).xyz, hi),
                     dot(texture(fit_b_lo, uv), lo) + dot(texture(fit_b_hi, uv).xyz, hi));
    float V = r_hi.a;
    bool fitted = V > 0.0 && V < NO_FIT && all_finite(pred);
    // Every pixel's prediction, for the à-trous to carry neighbours by (a 0: none).
    imageStore(prediction, p, fitted ? vec4(pred, 1.0) : vec4(0.0));
    vec4 centre = imageLoad(estimate, p);  // the filter's state
    centre.rgb = max(centre.rgb, vec3(0.0));  // radiance: a shift may leave it below zero
    float P = centre.a;
    // A converged estimate is kept (as the à-trous keeps it).
    if (pc.combine == 0u || !fitted || !all_finite(centre.rgb) || !(P >= pc.keep * pc.keep * dot(centre.rgb, centre.rgb) / 3.0) || isinf(P)) {
        imageStore(combined, p, centre);
        return;
    }
    pred = max(pred, vec3(0.0));
    vec3 x = (V * centre.rgb + P * pred) / (V + P);
    imageStore(combined, p, vec4(x, V * P / (V + P)));
}
