#version 460
// ours' temporal gradients pooled (wrls_gradient.comp measured them, one pixel per S×S
// stratum): per stratum, the strata around it summed into a luminance ratio (as a log)
// with its standard error and the colour of the change, over 3×3 strata or over 5×5,
// whichever shows the change more clearly (the larger squared ratio of log ratio to
// standard error): a small pool keeps a light's moving edge sharp, a large one finds a
// change that a dark, noisy region hides from nine strata. Once per stratum, so the
// update passes read one texel per pixel.
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

struct Pooled {
    float L;       // log luminance ratio
    float var_l;   // its variance
    vec3 colour;   // each channel's ratio over the luminance's
    bool measured;
};

// The (2 radius + 1)² strata around stratum `s`.
Pooled pool(ivec2 s, ivec2 strata, int radius) {
    Pooled o;
    o.L = 0.0;
    o.var_l = 0.0;
    o.colour = vec3(1.0);
    o.measured = false;
    vec3 sum_new = vec3(0.0), sum_old = vec3(0.0);
    float nn = 0.0, no = 0.0, oo = 0.0;  // sums of products of the luminances
    float n = 0.0;
    for (int dy = -radius; dy <= radius; ++dy) {
        for (int dx = -radius; dx <= radius; ++dx) {
            ivec2 k = clamp(s + ivec2(dx, dy), ivec2(0), strata - 1);
            vec3 a = imageLoad(gradient_new, k).rgb, b = imageLoad(gradient_old, k).rgb;
            sum_new += a;
            sum_old += b;
            float yn = luminance(a), yo = luminance(b);
            nn += yn * yn;
            no += yn * yo;
            oo += yo * yo;
            n += 1.0;
        }
    }
    float y_new = luminance(sum_new), y_old = luminance(sum_old);
    float y_max = max(y_new, y_old);
    if (!(y_max > 1e-6 && y_old > 1e-6)) return o;  // nothing lit to compare
    // The ratio's standard error from the strata's scatter about it (a ratio
    // estimator's sandwich variance), as a log: a steady change is a constant.
    float R = y_new / y_old;
    float scatter = max(nn - 2.0 * R * no + R * R * oo, 0.0);
    float var_r = scatter / (y_old * y_old) * (n / (n - 1.0));
    o.L = log(clamp(R, 0.25, 4.0));
    o.var_l = var_r / (R * R + 1e-12);
    // Channels far darker than the luminance are damped towards no change.
    float eps = 0.01 * y_max;
    vec3 ratio = clamp((sum_new + eps) / (sum_old + eps), vec3(0.25), vec3(4.0));
    o.colour = ratio / exp(o.L);
    o.measured = true;
    return o;
}

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    ivec2 strata = ivec2(pc.width, pc.height);
    if (s.x >= strata.x || s.y >= strata.y) return;
    Pooled p = pool(s, strata, 1);
    Pooled q = pool(s, strata, 2);
    if (q.measured && (!p.measured || q.L * q.L * p.var_l > p.L * p.L * q.var_l)) p = q;
    imageStore(gradient_ratio, s, vec4(p.colour, p.L));
    imageStore(gradient_spread, s, vec4(p.var_l, p.measured ? 1.0 : 0.0, 0.0, 0.0));
}
