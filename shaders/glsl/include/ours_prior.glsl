// ours' spatial prior (ours_prior_fit.comp, ours_prior.comp): the grid of fits, the
// model's features and the small solver.
#ifndef DVR_OURS_PRIOR_GLSL
#define DVR_OURS_PRIOR_GLSL
// [[unroll]] where a packed array is read or written: unrolled, its indices are constants
// and it stays in registers (lavapipe otherwise keeps it in memory, at twice the cost).
#extension GL_EXT_control_flow_attributes : require
#include "ours_constants.glsl"

// Pixels between two fits' centres and the edge of the blocks their normal equations are
// summed over (set by the engine, which sizes the grid: its `prior::PRIOR_STRIDE`). A
// fit's window is the 3×3 blocks around its cell: 12×12 pixels hold 144 estimates for the
// 7 coefficients of each channel.
layout(constant_id = 0) const int PRIOR_STRIDE = 4;
// The model's features: 1, the guide albedo's r, g, b and the gradient normal's x, y, z,
// from the guides' footprint (ours_guide.comp).
const int PRIOR_FEATURES = 7;
// The sums of a block (ours_prior_sums.comp), packed: the lower triangle of Σ f fᵀ, then
// Σ f x (rgb per feature), then Σ x² (rgb).
const int SUM_A = 0;
const int SUM_B = PRIOR_FEATURES * (PRIOR_FEATURES + 1) / 2;
const int SUM_XX = SUM_B + 3 * PRIOR_FEATURES;
const int PRIOR_SUM_TEXELS = (SUM_XX + 3 + 3) / 4;

// The features of a pixel with footprint albedo a and normal n: the first four, then the
// normal's three.
vec4 features_lo(vec3 a) { return vec4(1.0, a); }
vec3 features_hi(vec3 n) { return n; }

// Where there is no fit (no finite estimate in the window): V so large that the prior
// leaves the pixels near the cell as they are.
const float NO_FIT = NO_ESTIMATE;

// Solves (A + ridge·diag(0, 1, …, 1)) β = B for three right-hand sides (the colour
// channels) by Cholesky; false if that matrix is not positive definite. A is symmetric
// (only its lower triangle, A[i][j] with j ≤ i, is read).
bool solve_ridge(float A[PRIOR_FEATURES][PRIOR_FEATURES], vec3 B[PRIOR_FEATURES], float ridge,
                 out vec3 beta[PRIOR_FEATURES]) {
    const int D = PRIOR_FEATURES;
    float L[D][D];
    for (int j = 0; j < D; ++j) {
        float d = A[j][j] + (j > 0 ? ridge : 0.0);
        for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
        if (!(d > PIVOT_MIN)) return false;
        L[j][j] = sqrt(d);
        for (int i = j + 1; i < D; ++i) {
            float s = A[i][j];
            for (int k = 0; k < j; ++k) s -= L[i][k] * L[j][k];
            L[i][j] = s / L[j][j];
        }
    }
    vec3 z[D];
    for (int i = 0; i < D; ++i) {
        vec3 s = B[i];
        for (int k = 0; k < i; ++k) s -= L[i][k] * z[k];
        z[i] = s / L[i][i];
    }
    for (int i = D - 1; i >= 0; --i) {
        vec3 s = z[i];
        for (int k = i + 1; k < D; ++k) s -= L[k][i] * beta[k];
        beta[i] = s / L[i][i];
    }
    return true;
}

#endif
