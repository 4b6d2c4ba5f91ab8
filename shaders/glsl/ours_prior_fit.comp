#version 460
// ours' spatial prior, the fit: a local linear model of the estimates on the guide
// albedo and the position, x_q = β₀ + β₁ a_q + β₂ q + ε_q (β per colour channel), fitted
// by least squares over the window around each cell of a grid PRIOR_STRIDE pixels apart,
// with the residuals' mean square V. The position lets the fit follow the shading across
// the window (a shadow's edge, a lit side), which the albedo does not know. The prior
// (ours_prior.comp) interpolates the coefficients between the cells, as the fast guided
// filter does, instead of fitting at every pixel: the fit is the costly part, and a
// window of 144 pixels moved by PRIOR_STRIDE changes its fit little.
#include "common.glsl"
#include "ours_prior.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D estimate;   // rgb x, a P
layout(binding = 1, rgba32f) uniform readonly image2D footprint;  // rgb albedo (ours_guide.comp)
// The coefficients, with the position's in image coordinates (pixels / PRIOR_POSITION_UNIT)
// so that interpolating them between cells interpolates the cells' predictions.
layout(binding = 2, rgba32f) uniform writeonly image2D fit0;      // rgb β₀, a V
layout(binding = 3, rgba32f) uniform writeonly image2D fit_r;     // rgb: the albedo's r
layout(binding = 4, rgba32f) uniform writeonly image2D fit_g;
layout(binding = 5, rgba32f) uniform writeonly image2D fit_b;
layout(binding = 6, rgba32f) uniform writeonly image2D fit_x;     // rgb: the position's x
layout(binding = 7, rgba32f) uniform writeonly image2D fit_y;

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
    ivec2 size = ivec2(pc.width, pc.height);
    // The window: PRIOR_WINDOW pixels a side around the cell's centre c.
    ivec2 first = cell * PRIOR_STRIDE + PRIOR_STRIDE / 2 - PRIOR_WINDOW / 2;
    vec2 c = vec2(cell * PRIOR_STRIDE) + 0.5 * float(PRIOR_STRIDE - 1);
    float A[D][D];
    vec3 B[D];
    for (int i = 0; i < D; ++i) {
        B[i] = vec3(0.0);
        for (int j = 0; j < D; ++j) A[i][j] = 0.0;
    }
    vec3 xx = vec3(0.0);
    float n = 0.0;
    for (int dy = 0; dy < PRIOR_WINDOW; ++dy) {
        for (int dx = 0; dx < PRIOR_WINDOW; ++dx) {
            ivec2 q = first + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec3 x = imageLoad(estimate, q).rgb;
            if (!all_finite(x)) continue;
            vec3 a = imageLoad(footprint, q).rgb;
            vec2 o = (vec2(q) - c) / PRIOR_POSITION_UNIT;
            float f[D] = float[D](1.0, a.r, a.g, a.b, o.x, o.y);
            for (int i = 0; i < D; ++i) {
                B[i] += f[i] * x;
                for (int j = 0; j <= i; ++j) A[i][j] += f[i] * f[j];
            }
            xx += x * x;
            n += 1.0;
        }
    }
    vec3 beta[D];
    float V = NO_FIT;
    if (n > 0.0 && solve_ridge(A, B, RIDGE * n, beta)) {
        // The residuals' sum of squares, Σ(x − βᵀf)² = Σx² − 2βᵀB + βᵀAβ.
        vec3 rss = xx;
        for (int i = 0; i < D; ++i) {
            rss -= 2.0 * beta[i] * B[i];
            for (int j = 0; j < D; ++j) rss += beta[i] * (j <= i ? A[i][j] : A[j][i]) * beta[j];
        }
        V = dot(max(rss, vec3(0.0)), vec3(1.0 / 3.0)) / n;
    }
    if (!(V < NO_FIT)) {
        V = NO_FIT;
        for (int i = 0; i < D; ++i) beta[i] = vec3(0.0);
    }
    // β₀ for positions in image coordinates: β₀ + β·(q − c)/u = (β₀ − β·c/u) + β·q/u.
    vec3 b0 = beta[0] - (beta[4] * c.x + beta[5] * c.y) / PRIOR_POSITION_UNIT;
    imageStore(fit0, cell, vec4(b0, V));
    imageStore(fit_r, cell, vec4(beta[1], 0.0));
    imageStore(fit_g, cell, vec4(beta[2], 0.0));
    imageStore(fit_b, cell, vec4(beta[3], 0.0));
    imageStore(fit_x, cell, vec4(beta[4], 0.0));
    imageStore(fit_y, cell, vec4(beta[5], 0.0));
}
