#version 460
// ours' temporal gradients pooled (ours_gradient.comp measured them, one pixel per S×S
// stratum): per stratum, the strata around it summed into a luminance ratio (as a log)
// with its standard error and the colour of the change, over 3×3, 5×5 and 9×9 strata, and
// shrunk level by level: the 9×9 ratio towards no change, the 5×5 towards the shrunk 9×9,
// the 3×3 towards the shrunk 5×5, each keeping k²/(k² + shrink) of its departure when it
// lies k standard errors away. A small pool keeps a light's moving edge sharp but is
// noisy; shrunk towards no change, its noise was kept out but so was much of a real
// change, and the models lagged where the light moved fastest (mri/point-light). Shrunk
// towards the wider pools instead, a change the neighbourhood shows clearly is kept and
// only the local departure from it must prove itself. Once per stratum, so the update
// passes read one texel per pixel.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D gradient_new;   // rgb re-traced
layout(binding = 1, rgba32f) uniform readonly image2D gradient_old;   // rgb last frame's
layout(binding = 2, rgba32f) uniform writeonly image2D gradient_ratio;  // rgb colour, a log ratio

layout(push_constant) uniform OursGradientPoolPush {
    uint width;    // strata across
    uint height;   // strata down
    float shrink;  // squared standard errors of a departure that halve it
    uint pad0;
} pc;

// A ratio beyond RATIO_MAX per frame is taken as RATIO_MAX: the scaled model then starts
// closer to the new value and the update's jump test takes the rest. Channels darker than
// DARK_CHANNEL of the luminance are damped towards no change (their ratios are noise over
// almost nothing). (ours_constants.glsl)

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

Sums merge(Sums s, Sums t) {
    return Sums(s.new_rgb + t.new_rgb, s.old_rgb + t.old_rgb, s.nn + t.nn, s.no + t.no,
                s.oo + t.oo, s.n + t.n);
}

Pooled pooled(Sums s) {
    Pooled o;
    o.L = 0.0;
    o.var_l = 0.0;
    o.colour = vec3(1.0);
    o.measured = false;
    float y_new = luminance(s.new_rgb), y_old = luminance(s.old_rgb);
    float y_max = max(y_new, y_old);
    if (!(y_max > LIT_MIN && y_old > LIT_MIN)) return o;  // nothing lit to compare
    // The ratio's standard error from the strata's scatter about it (a ratio
    // estimator's sandwich variance), as a log: a steady change is a constant.
    float R = y_new / y_old;
    float scatter = max(s.nn - 2.0 * R * s.no + R * R * s.oo, 0.0);
    float var_r = scatter / (y_old * y_old) * (s.n / (s.n - 1.0));
    o.L = log(clamp(R, 1.0 / RATIO_MAX, RATIO_MAX));
    o.var_l = var_r / (R * R + VARIANCE_FLOOR);
    // Channels far darker than the luminance are damped towards no change.
    float eps = DARK_CHANNEL * y_max;
    vec3 ratio = clamp((s.new_rgb + eps) / (s.old_rgb + eps), vec3(1.0 / RATIO_MAX), vec3(RATIO_MAX));
    o.colour = ratio / exp(o.L);
    o.measured = true;
    return o;
}

// `L`, `var_l`, shrunk towards `prior`; `kept` the share of the departure kept.
float shrunk(float L, float var_l, float prior, out float kept) {
    float d = L - prior;
    kept = d * d / (d * d + pc.shrink * var_l + VARIANCE_FLOOR);
    return prior + kept * d;
}

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    ivec2 strata = ivec2(pc.width, pc.height);
    if (s.x >= strata.x || s.y >= strata.y) return;
    // One pass over the 9×9 strata, each stratum loaded once and added to one ring (the
    // 3×3, the rest of the 5×5, the rest of the 9×9); the squares are the rings' sums.
    // (Adding each stratum to every square it lies in instead cost 3.4× as much on
    // lavapipe: 2.5 against 0.7 ms at 256².)
    Sums rings[3];
    for (int i = 0; i < 3; ++i) rings[i] = Sums(vec3(0.0), vec3(0.0), 0.0, 0.0, 0.0, 0.0);
    for (int dy = -POOL_RADIUS_WIDE; dy <= POOL_RADIUS_WIDE; ++dy) {
        for (int dx = -POOL_RADIUS_WIDE; dx <= POOL_RADIUS_WIDE; ++dx) {
            ivec2 k = clamp(s + ivec2(dx, dy), ivec2(0), strata - 1);
            vec3 a = imageLoad(gradient_new, k).rgb, b = imageLoad(gradient_old, k).rgb;
            int r = max(abs(dx), abs(dy));
            if (r <= POOL_RADIUS_NEAR) {
                rings[0] = add(rings[0], a, b);
            } else if (r <= POOL_RADIUS_MID) {
                rings[1] = add(rings[1], a, b);
            } else {
                rings[2] = add(rings[2], a, b);
            }
        }
    }
    Sums pools[3];
    pools[0] = rings[0];
    pools[1] = merge(pools[0], rings[1]);
    pools[2] = merge(pools[1], rings[2]);
    // From the widest to the nearest; nothing measured: log ratio 0, colour 1 (no change).
    float L = 0.0, kept;
    vec3 colour = vec3(1.0);
    for (int i = 2; i >= 0; --i) {
        Pooled p = pooled(pools[i]);
        if (!p.measured) continue;
        L = shrunk(p.L, p.var_l, L, kept);
        colour = mix(colour, p.colour, kept);
    }
    imageStore(gradient_ratio, s, vec4(colour, L));
}
