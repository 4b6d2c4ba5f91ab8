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
layout(binding = 3, rgba32f) uniform writeonly image2D gradient_spread;  // x variance, y measured

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

// Sums over a square of strata: radiance re-traced and last frame's, products of their
// luminances, and the count.
struct Sums {
    vec3 new_rgb;
    vec3 old_rgb;
    float nn, no, oo;
    float n;
};

Sums add(Sums s, vec3 a, vec3 b) {
    s.new_rgb += a;
    s.old_rgb += b;
    float yn = luminance(a), yo = luminance(b);
    s.nn += yn * yn;
    s.no += yn * yo;
    s.oo += yo * yo;
    s.n += 1.0;
    return s;
}

Pooled pooled(Sums s) {
    Pooled o;
    o.L = 0.0;
    o.var_l = 0.0;
    o.colour = vec3(1.0);
    o.measured = false;
    float y_new = luminance(s.new_rgb), y_old = luminance(s.old_rgb);
    float y_max = max(y_new, y_old);
    if (!(y_max > 1e-6 && y_old > 1e-6)) return o;  // nothing lit to compare
    // The ratio's standard error from the strata's scatter about it (a ratio
    // estimator's sandwich variance), as a log: a steady change is a constant.
    float R = y_new / y_old;
    float scatter = max(s.nn - 2.0 * R * s.no + R * R * s.oo, 0.0);
    float var_r = scatter / (y_old * y_old) * (s.n / (s.n - 1.0));
    o.L = log(clamp(R, 0.25, 4.0));
    o.var_l = var_r / (R * R + 1e-12);
    // Channels far darker than the luminance are damped towards no change.
    float eps = 0.01 * y_max;
    vec3 ratio = clamp((s.new_rgb + eps) / (s.old_rgb + eps), vec3(0.25), vec3(4.0));
    o.colour = ratio / exp(o.L);
    o.measured = true;
    return o;
}

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    ivec2 strata = ivec2(pc.width, pc.height);
    if (s.x >= strata.x || s.y >= strata.y) return;
    // One pass over the 5×5 strata sums both squares (each stratum loaded once).
    Sums near = Sums(vec3(0.0), vec3(0.0), 0.0, 0.0, 0.0, 0.0), wide = near;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            ivec2 k = clamp(s + ivec2(dx, dy), ivec2(0), strata - 1);
            vec3 a = imageLoad(gradient_new, k).rgb, b = imageLoad(gradient_old, k).rgb;
            wide = add(wide, a, b);
            if (max(abs(dx), abs(dy)) <= 1) near = add(near, a, b);
        }
    }
    Pooled p = pooled(near), q = pooled(wide);
    if (q.measured && (!p.measured || q.L * q.L * p.var_l > p.L * p.L * q.var_l)) p = q;
    imageStore(gradient_ratio, s, vec4(p.colour, p.L));
    imageStore(gradient_spread, s, vec4(p.var_l, p.measured ? 1.0 : 0.0, 0.0, 0.0));
}
