#version 460
// ours' pooled lag test: the mean a-posteriori residual of the linear models over a 5×5
// neighbourhood, with the variance of that mean. One pixel's residual at 1–2 spp is
// mostly noise, so a model that lags a slow change (or a view-dependent one) is invisible
// to a per-pixel test for many frames; averaged over 25 pixels the noise falls five-fold
// and the lag shows. Next frame's update adds a significant mean to the models.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D residual;  // rgb residual, a variance (< 0: none)
layout(binding = 1, rgba32f) uniform writeonly image2D drift;    // rgb mean, a its variance

layout(push_constant) uniform WrlsDriftPush {
    uint width;
    uint height;
    uint pad0;
    uint pad1;
} pc;

// The window's radius (5×5 at 2), a specialisation constant so the loops unroll.
layout(constant_id = 15) const int DRIFT_RADIUS = 2;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec3 sum = vec3(0.0);
    float var_sum = 0.0;
    float n = 0.0;
    for (int dy = -DRIFT_RADIUS; dy <= DRIFT_RADIUS; ++dy) {
        for (int dx = -DRIFT_RADIUS; dx <= DRIFT_RADIUS; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 r = imageLoad(residual, q);
            if (r.a < 0.0) continue;  // none (wrls_change.glsl's lag_residual)
            sum += r.rgb;
            var_sum += r.a;
            n += 1.0;
        }
    }
    // Fewer than half the neighbours with a history: no estimate (variance infinite).
    float min_n = 0.5 * float((2 * DRIFT_RADIUS + 1) * (2 * DRIFT_RADIUS + 1));
    imageStore(drift, p, n >= min_n ? vec4(sum / n, var_sum / (n * n)) : vec4(0.0, 0.0, 0.0, 1e30));
}
