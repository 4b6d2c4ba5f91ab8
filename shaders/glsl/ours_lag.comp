#version 460
// ours' pooled lag test: the mean a-posteriori residual of the per-pixel filters over a
// square neighbourhood (5×5 at radius 2), with the variance of that mean from the
// residuals' scatter. One pixel's
// residual at 1–2 spp is mostly noise, so a filter that lags a change the gradients did
// not measure (a view-dependent change, a drift with nothing to re-trace) is invisible to
// a per-pixel test for many frames; averaged over 25 pixels the noise falls five-fold and
// the lag shows. Next frame's update (ours_update.comp) takes a significant mean as a
// shift of the state: it corrects the estimate and adds the correction's uncertainty to
// the process noise.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D residual;  // rgb residual, a variance (< 0: none)
layout(binding = 1, rgba32f) uniform writeonly image2D lag;      // rgb mean, a its variance

layout(push_constant) uniform OursLagPush {
    uint width;
    uint height;
    uint pad0;
    uint pad1;
} pc;

// The window's radius (5×5 at 2), a specialisation constant so the loops unroll.
layout(constant_id = 15) const int LAG_RADIUS = 2;
// LAG_MIN_SHARE of the window must hold a residual for the mean to count (next to a
// disocclusion, a few old pixels say little about a region); where there is no estimate
// the variance written is NO_ESTIMATE, so large that no mean is significant.

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec3 sum = vec3(0.0);
    float sq = 0.0;
    float n = 0.0;
    for (int dy = -LAG_RADIUS; dy <= LAG_RADIUS; ++dy) {
        for (int dx = -LAG_RADIUS; dx <= LAG_RADIUS; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 r = imageLoad(residual, q);
            if (r.a < 0.0) continue;  // none (ours_update.comp)
            sum += r.rgb;
            sq += dot(r.rgb, r.rgb) / 3.0;
            n += 1.0;
        }
    }
    // Fewer than half the neighbours with a residual: no estimate (variance infinite).
    float min_n = LAG_MIN_SHARE * float((2 * LAG_RADIUS + 1) * (2 * LAG_RADIUS + 1));
    if (n < min_n) {
        imageStore(lag, p, vec4(0.0, 0.0, 0.0, NO_ESTIMATE));
        return;
    }
    // The variance of the mean from the residuals' own scatter (a t-test): Monte Carlo
    // noise is heavier-tailed than the filters' variances say, and the scatter knows it.
    vec3 mean = sum / n;
    float scatter = max(sq - n * dot(mean, mean) / 3.0, 0.0) / (n - 1.0);
    imageStore(lag, p, vec4(mean, scatter / n));
}
