#version 460
// ours' spatial prior, the sums: per block of PRIOR_STRIDE×PRIOR_STRIDE pixels (one per
// fit's cell), the normal equations' sums over its pixels, Σ f fᵀ (lower triangle), Σ f x
// and Σ x². A fit's window is the 3×3 blocks around its cell (ours_prior_fit.comp), so
// each pixel's products are formed once here rather than once for each of the nine
// windows that hold it.
#include "common.glsl"
#include "ours_prior.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D estimate;   // the filter's state: rgb x, a P
layout(binding = 1, rgba16f) uniform readonly image2D footprint;         // rgb albedo (ours_guide.comp)
layout(binding = 3, rgba16f) uniform readonly image2D footprint_normal;  // xyz normal
layout(binding = 2, rgba32f) uniform writeonly image2D sums;      // PRIOR_SUM_TEXELS per block, side by side

layout(push_constant) uniform OursPriorFitPush {
    uint width;   // of the image
    uint height;
    uint cells_x; // of the grid
    uint cells_y;
} pc;

void main() {
    const int D = PRIOR_FEATURES;
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    if (cell.x >= int(pc.cells_x) || cell.y >= int(pc.cells_y)) return;
    ivec2 size = ivec2(pc.width, pc.height);
    float A[D][D];
    vec3 B[D];
    for (int i = 0; i < D; ++i) {
        B[i] = vec3(0.0);
        for (int j = 0; j < D; ++j) A[i][j] = 0.0;
    }
    vec3 xx = vec3(0.0);
    for (int dy = 0; dy < PRIOR_STRIDE; ++dy) {
        for (int dx = 0; dx < PRIOR_STRIDE; ++dx) {
            ivec2 q = cell * PRIOR_STRIDE + ivec2(dx, dy);
            if (q.x >= size.x || q.y >= size.y) continue;
            vec3 x = imageLoad(estimate, q).rgb;
            if (!all_finite(x)) continue;
            x = max(x, vec3(0.0));  // radiance: a shift may leave the state below zero
            vec4 lo = features_lo(imageLoad(footprint, q).rgb);
            vec3 hi = features_hi(imageLoad(footprint_normal, q).xyz);
            float f[D] = float[D](lo.x, lo.y, lo.z, lo.w, hi.x, hi.y, hi.z);
            for (int i = 0; i < D; ++i) {
                B[i] += f[i] * x;
                for (int j = 0; j <= i; ++j) A[i][j] += f[i] * f[j];
            }
            xx += x * x;
        }
    }
    float S[PRIOR_SUM_TEXELS * 4];
    [[unroll]] for (int i = 0; i < D; ++i) {
        [[unroll]] for (int j = 0; j <= i; ++j) S[SUM_A + i * (i + 1) / 2 + j] = A[i][j];
        S[SUM_B + 3 * i] = B[i].r;
        S[SUM_B + 3 * i + 1] = B[i].g;
        S[SUM_B + 3 * i + 2] = B[i].b;
    }
    S[SUM_XX] = xx.r;
    S[SUM_XX + 1] = xx.g;
    S[SUM_XX + 2] = xx.b;
    [[unroll]] for (int k = SUM_XX + 3; k < PRIOR_SUM_TEXELS * 4; ++k) S[k] = 0.0;
    [[unroll]] for (int t = 0; t < PRIOR_SUM_TEXELS; ++t) {
        imageStore(sums, ivec2(cell.x * PRIOR_SUM_TEXELS + t, cell.y),
                   vec4(S[4 * t], S[4 * t + 1], S[4 * t + 2], S[4 * t + 3]));
    }
}
