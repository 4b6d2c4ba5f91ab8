#version 460
// ours' spatial prior, the fit: a local linear model of the estimates on the guides and
// the position, x_q = βᵀf_q + ε_q with f_q = (1, albedo's luminance, q, normal) (β per
// colour channel), fitted by least squares over the window around each cell of a grid
// PRIOR_STRIDE pixels apart, with the residuals' mean square V. The albedo tells
// materials apart (a vessel, a shell), the normal the shading of a surface across the
// window as the light moves over it, the position the rest of the shading (a shadow's
// edge, light through a semi-transparent layer). The prior (ours_prior.comp)
// interpolates the coefficients between the cells, as the fast guided filter does,
// instead of fitting at every pixel: a window of 144 pixels moved by PRIOR_STRIDE changes
// its fit little.
#include "common.glsl"
#include "ours_prior.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D sums;  // per block (ours_prior_sums.comp)
// The coefficients per channel, with the position's in image coordinates (pixels /
// PRIOR_POSITION_UNIT) so that interpolating them between cells interpolates the cells'
// predictions: `lo` those of the first four features, `hi` the normal's, with V in a.
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
// albedo (one material, or only background) leaves its coefficients undetermined, and the
// fit falls back to a plane.
const float RIDGE = 1e-3;

void main() {
    const int D = PRIOR_FEATURES;
    ivec2 cell = ivec2(gl_GlobalInvocationID.xy);
    if (cell.x >= int(pc.cells_x) || cell.y >= int(pc.cells_y)) return;
    // The window: the 3×3 blocks around the cell, PRIOR_WINDOW pixels a side. A block's
    // sums hold positions relative to its own centre, o_b = o − t with t the offset of the
    // cell's centre from the block's; with f₀ = 1, f' = f + t f₀ on the position's rows:
    // Σ f'_i f'_j = Σ f_i f_j + t_i Σ f_j + t_j Σ f_i + t_i t_j n, Σ f'_i x = Σ f_i x + t_i Σ x.
    vec2 c = cell_centre(cell);
    vec4 T[PRIOR_SUM_TEXELS];
    for (int k = 0; k < PRIOR_SUM_TEXELS; ++k) T[k] = vec4(0.0);
    float shift[2][D];  // Σ_b t_b Σ f_j, for the position's x and y
    for (int j = 0; j < D; ++j) {
        shift[0][j] = 0.0;
        shift[1][j] = 0.0;
    }
    vec3 shift_b[2] = vec3[2](vec3(0.0), vec3(0.0));  // Σ_b t_b Σ x
    vec3 tt = vec3(0.0);                                // Σ_b n_b (t_x², t_x t_y, t_y²)
    for (int by = -1; by <= 1; ++by) {
        for (int bx = -1; bx <= 1; ++bx) {
            ivec2 block = cell + ivec2(bx, by);
            if (any(lessThan(block, ivec2(0))) || block.x >= int(pc.cells_x) || block.y >= int(pc.cells_y)) continue;
            vec4 S[PRIOR_SUM_TEXELS];
            for (int k = 0; k < PRIOR_SUM_TEXELS; ++k) {
                S[k] = imageLoad(sums, ivec2(block.x * PRIOR_SUM_TEXELS + k, block.y));
                T[k] += S[k];
            }
            vec2 t = (cell_centre(block) - c) / PRIOR_POSITION_UNIT;
            [[unroll]] for (int j = 0; j < D; ++j) {
                int k = SUM_A + j * (j + 1) / 2;  // Σ f_j f₀
                float s = S[k >> 2][k & 3];
                shift[0][j] += t.x * s;
                shift[1][j] += t.y * s;
            }
            vec3 b0 = vec3(S[SUM_B >> 2][SUM_B & 3], S[(SUM_B + 1) >> 2][(SUM_B + 1) & 3],
                           S[(SUM_B + 2) >> 2][(SUM_B + 2) & 3]);
            shift_b[0] += t.x * b0;
            shift_b[1] += t.y * b0;
            float nb = S[0].x;
            tt += nb * vec3(t.x * t.x, t.x * t.y, t.y * t.y);
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
    // The shift onto the cell's centre: rows and columns of the position's features.
    const int PX = FEATURE_X, PY = FEATURE_Y;
    for (int j = 0; j < D; ++j) {
        if (j <= PX) A[PX][j] += shift[0][j];
        else A[j][PX] += shift[0][j];
        if (j <= PY) A[PY][j] += shift[1][j];
        else A[j][PY] += shift[1][j];
    }
    A[PX][PX] += shift[0][PX] + tt.x;
    A[PY][PX] += tt.y;
    A[PY][PY] += shift[1][PY] + tt.z;
    B[PX] += shift_b[0];
    B[PY] += shift_b[1];
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
    // β₀ for positions in image coordinates: β₀ + β·(q − c)/u = (β₀ − β·c/u) + β·q/u.
    beta[0] -= (beta[FEATURE_X] * c.x + beta[FEATURE_Y] * c.y) / PRIOR_POSITION_UNIT;
    imageStore(fit_r_lo, cell, vec4(beta[0].r, beta[1].r, beta[2].r, beta[3].r));
    imageStore(fit_r_hi, cell, vec4(beta[4].r, beta[5].r, beta[6].r, V));
    imageStore(fit_g_lo, cell, vec4(beta[0].g, beta[1].g, beta[2].g, beta[3].g));
    imageStore(fit_g_hi, cell, vec4(beta[4].g, beta[5].g, beta[6].g, V));
    imageStore(fit_b_lo, cell, vec4(beta[0].b, beta[1].b, beta[2].b, beta[3].b));
    imageStore(fit_b_hi, cell, vec4(beta[4].b, beta[5].b, beta[6].b, V));
}
