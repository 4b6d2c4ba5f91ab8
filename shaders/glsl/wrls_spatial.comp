#version 460
// The paper's denoiser, spatial part: pixel i's colour blends the predictions of the 25
// linear models in its 5×5 window, each applied to i's own predictor p_i, with bilateral
// weights: pixel distance, and for the paper's variant the temporal-feature difference.
// `ours` weighs a neighbour by how far its prediction lies from pixel i's own, in units of
// the two predictions' standard errors (residual noise level × P00, what RLS knows of its
// own uncertainty): young models blend widely, converged ones only with neighbours that
// agree, so the filter never blurs what the per-pixel models have resolved.
#include "common.glsl"
#include "wrls.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D z;  // this frame's temporal feature
layout(binding = 1, rgba32f) uniform readonly image2D beta_r;
layout(binding = 2, rgba32f) uniform readonly image2D beta_g;
layout(binding = 3, rgba32f) uniform readonly image2D beta_b;
layout(binding = 4, rgba32f) uniform readonly image2D noisy;
layout(binding = 5, rgba32f) uniform writeonly image2D denoised;
layout(binding = 6, rgba32f) uniform readonly image2D p0;  // x: P00
layout(binding = 7, rgba32f) uniform readonly image2D p2;  // z: residual noise level
layout(binding = 8, rgba32f) uniform readonly image2D constant;  // rgb β of p = [1], a its P
layout(binding = 9, rgba32f) uniform readonly image2D errors;    // a-priori errors (const, feature)

layout(push_constant) uniform WrlsSpatialPush {
    uint width;
    uint height;
    float sigma_spatial;  // pixels
    float sigma_range;    // relative feature difference (paper's variant)
    float kappa;          // standard errors a neighbour's prediction may differ by (ours)
    float pad0;
    float pad1;
    float pad2;
} pc;

// Variance of a model's constant term: residual noise per channel × P00 (or × the
// constant model's scalar P).
float prediction_variance(ivec2 j, float p00) {
    return max(imageLoad(p2, j).z, 0.0) / 3.0 * max(p00, 0.0);
}

// Range term of ours' weights: squared prediction difference in standard errors.
float agreement(vec3 pred, vec3 own, float var_i, float var_j) {
    vec3 dp = pred - own;
    return dot(dp, dp) / 3.0 / (pc.kappa * pc.kappa * (var_i + var_j + 1e-8));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec3 zi = imageLoad(z, p).rgb;
    vec4 xi = predictor(zi);
    vec3 own = vec3(dot(xi, imageLoad(beta_r, p)), dot(xi, imageLoad(beta_g, p)), dot(xi, imageLoad(beta_b, p)));
    float var_i = prediction_variance(p, imageLoad(p0, p).x);
    vec4 ci = imageLoad(constant, p);
    float var_ci = prediction_variance(p, ci.a);
    float share = feature_share(imageLoad(errors, p).xy);
    float norm_i = dot(zi, zi) + 1e-4;
    vec3 sum = vec3(0.0);
    float wsum = 0.0;
    vec3 sum_c = vec3(0.0);
    float wsum_c = 0.0;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            ivec2 j = p + ivec2(dx, dy);
            if (any(lessThan(j, ivec2(0))) || any(greaterThanEqual(j, size))) continue;
            float spatial = -float(dx * dx + dy * dy) / (2.0 * pc.sigma_spatial * pc.sigma_spatial);
            vec3 pred = vec3(dot(xi, imageLoad(beta_r, j)), dot(xi, imageLoad(beta_g, j)),
                             dot(xi, imageLoad(beta_b, j)));
            float range;
            if (PAPER_PREDICTOR) {
                vec3 dz = zi - imageLoad(z, j).rgb;
                range = dot(dz, dz) / (pc.sigma_range * pc.sigma_range * norm_i);
            } else {
                range = agreement(pred, own, var_i, prediction_variance(j, imageLoad(p0, j).x));
            }
            float w = exp(spatial - range);
            sum += w * pred;
            wsum += w;
            if (MODEL_SELECTION && share < 1.0) {
                vec4 cj = imageLoad(constant, j);
                float wc = exp(spatial - agreement(cj.rgb, ci.rgb, var_ci, prediction_variance(j, cj.a)));
                sum_c += wc * cj.rgb;
                wsum_c += wc;
            }
        }
    }
    vec3 result = sum / max(wsum, 1e-8);
    if (MODEL_SELECTION && share < 1.0) result = mix(sum_c / max(wsum_c, 1e-8), result, share);
    if (!all_finite(result)) result = imageLoad(noisy, p).rgb;
    imageStore(denoised, p, vec4(max(result, vec3(0.0)), 1.0));
}
