#version 460
// ours' temporal gradients pooled (wrls_gradient.comp measured them, one pixel per S×S
// stratum): per stratum, the 3×3 strata around it summed into a luminance ratio (as a
// log) with its standard error and the colour of the change. Once per stratum, so the
// update passes read one texel per pixel instead of eighteen (the update is the largest
// pass of ours under a moving light).
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D gradient_new;   // rgb re-traced
layout(binding = 1, rgba32f) uniform readonly image2D gradient_old;   // rgb last frame's
layout(binding = 2, rgba32f) uniform writeonly image2D gradient_ratio;   // rgb colour, a log ratio
layout(binding = 3, rgba32f) uniform writeonly image2D gradient_spread;  // x its variance, y measured

layout(push_constant) uniform WrlsGradientPoolPush {
    uint width;   // strata across
    uint height;  // strata down
    uint pad0;
    uint pad1;
} pc;

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    ivec2 strata = ivec2(pc.width, pc.height);
    if (s.x >= strata.x || s.y >= strata.y) return;
    vec3 sum_new = vec3(0.0), sum_old = vec3(0.0);
    float nn = 0.0, no = 0.0, oo = 0.0;  // sums of products of the luminances
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 k = clamp(s + ivec2(dx, dy), ivec2(0), strata - 1);
            vec3 n = imageLoad(gradient_new, k).rgb, o = imageLoad(gradient_old, k).rgb;
            sum_new += n;
            sum_old += o;
            float yn = luminance(n), yo = luminance(o);
            nn += yn * yn;
            no += yn * yo;
            oo += yo * yo;
        }
    }
    float y_new = luminance(sum_new), y_old = luminance(sum_old);
    float y_max = max(y_new, y_old);
    if (!(y_max > 1e-6 && y_old > 1e-6)) {  // nothing lit to compare (or not finite)
        imageStore(gradient_ratio, s, vec4(1.0, 1.0, 1.0, 0.0));
        imageStore(gradient_spread, s, vec4(0.0));
        return;
    }
    // The luminance ratio and its standard error from the strata's scatter about it (a
    // ratio estimator's sandwich variance), as a log: a steady change is a constant.
    float R = y_new / y_old;
    float scatter = max(nn - 2.0 * R * no + R * R * oo, 0.0);
    float var_r = scatter / (y_old * y_old) * (9.0 / 8.0);
    float L = log(clamp(R, 0.25, 4.0));
    float var_l = var_r / (R * R + 1e-12);
    // Each channel's ratio over the luminance's; channels far darker than the luminance
    // are damped towards no change.
    float eps = 0.01 * y_max;
    vec3 ratio = clamp((sum_new + eps) / (sum_old + eps), vec3(0.25), vec3(4.0));
    imageStore(gradient_ratio, s, vec4(ratio / exp(L), L));
    imageStore(gradient_spread, s, vec4(var_l, 1.0, 0.0, 0.0));
}
