#version 460
// ours' spatial prior, the fit: a local linear model of the estimates on the guides,
// x_q = βᵀf_q + ε_q with f_q = (1, albedo r, g, b, normal x, y, z) (β per colour
// channel), fitted by least squares over the window around each cell of a grid
// PRIOR_STRIDE pixels apart, with the residuals' mean square V. The albedo tells
// materials apart (a vessel's hue against the shell), the normal the shading of a
// surface across the window as the light or the view moves. The prior (ours_prior.comp)
// interpolates the coefficients between the cells, as the fast guided filter does,
// instead of fitting at every pixel: a window of 144 pixels moved by PRIOR_STRIDE changes
// its fit little. The window's normal equations are the sums of its 3×3 blocks'
// (ours_prior_sums.comp).
#include "common.glsl"
#include "ours_prior.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D sums;  // per block (ours_prior_sums.comp)
// The coefficients per channel: `lo` those of the first four features, `hi` the normal's,
// with V in a.
layout(binding = 1, rgba32f) uniform writeonly image2D fit_r_lo;
layout(binding = 2, rgba32f) uniform writeonly image2D fit_r_hi;
layout(binding = 3, rgba32f) uniform writeonly image2D fit_g_lo;
layout(binding = 4, rgba32f) uniform writeonly image2D fit_g_hi;
layout(binding = 5, rgba32f) uniform writeonly image2D fit_b_lo;
layout(binding = 6, rgba32f) uniform writeonly image2D fit_b_hi;

layout(push_constant) uniform OursPriorFitPush {
    uint width;   // of the image
    uint height;
    uint cells_x; // of the grid
    uint cells_y;
} pc;

// Ridge on the coefficients other than β₀, relative to the window's count: a uniform
// albedo (one material, or only background) or normal (a flat face, no surface) leaves
// its coefficients undetermined, and the fit falls back on the other features or a
// constant.

void main() {
    const int D = PRIOR_FEATURES;
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    if (cell.x >= int(pc.cells_x) || cell.y >= int(pc.cells_y)) return;
    // The window's sums: the 3×3 blocks around the cell.
    vec4 T[PRIOR_SUM_TEXELS];
    for (int k = 0; k < PRIOR_SUM_TEXELS; ++k) T[k] = vec4(0.0);
    for (int by = -FIT_RADIUS; by <= FIT_RADIUS; ++by) {
        for (int bx = -FIT_RADIUS; bx <= FIT_RADIUS; ++bx) {
            ivec2 block = cell + ivec2(bx, by);
            if (any(lessThan(block, ivec2(0))) || block.x >= int(pc.cells_x) || block.y >= int(pc.cells_y)) continue;
            [[unroll]] for (int k = 0; k < PRIOR_SUM_TEXELS; ++k) {
                T[k] += imageLoad(sums, ivec2(block.x * PRIOR_SUM_TEXELS + k, block.y));
            }
        }
    }
    float A[D][D];
    vec3 B[D];
    [[unroll]] for (int i = 0; i < D; ++i) {
        [[unroll]] for (int j = 0; j <= i; ++j) {
            int k = SUM_A + i * (i + 1) / 2 + j;
            A[i][j] = T[k >> 2][k & 3];
        }
        int k = SUM_B + 3 * i;
        B[i] = vec3(T[k >> 2][k & 3], T[(k + 1) >> 2][(k + 1) & 3], T[(k + 2) >> 2][(k + 2) & 3]);
    }
    vec3 xx = vec3(T[SUM_XX >> 2][SUM_XX & 3], T[(SUM_XX + 1) >> 2][(SUM_XX + 1) & 3],
                   T[(SUM_XX + 2) >> 2][(SUM_XX + 2) & 3]);
    float n = A[0][0];
    vec3 beta[D];
    float V = NO_FIT;
    if (n > 0.0 && solve_ridge(A, B, RIDGE * n, beta)) {
        // The residuals' sum of squares, Σ(x − βᵀf)² = Σx² − 2βᵀB + βᵀAβ, where the solve
        // made Aβ = B − ridge·β (off β₀): Σx² − βᵀB − ridge·Σ β_i².
        vec3 rss = xx - beta[0] * B[0];
        [[unroll]] for (int i = 1; i < D; ++i) rss -= beta[i] * B[i] + RIDGE * n * beta[i] * beta[i];
        V = dot(max(rss, vec3(0.0)), vec3(1.0 / 3.0)) / n;
    }
    if (!(V < NO_FIT)) {
        V = NO_FIT;
        for (int i = 0; i < D; ++i) beta[i] = vec3(0.0);
    }
    imageStore(fit_r_lo, cell, vec4(beta[0].r, beta[1].r, beta[2].r, beta[3].r));
    imageStore(fit_r_hi, cell, vec4(beta[4].r, beta[5].r, beta[6].r, V));
    imageStore(fit_g_lo, cell, vec4(beta[0].g, beta[1].g, beta[2].g, beta[3].g));
    imageStore(fit_g_hi, cell, vec4(beta[4].g, beta[5].g, beta[6].g, V));
    imageStore(fit_b_lo, cell, vec4(beta[0].b, beta[1].b, beta[2].b, beta[3].b));
    imageStore(fit_b_hi, cell, vec4(beta[4].b, beta[5].b, beta[6].b, V));
}
