#version 460
// ours' noise measurement, first half: per pixel, the sums over the 5 pixels of its row
// (clamped at the image's edge) of what R is measured from: the variance of each pixel's
// mean from its samples' luminance moments, and the mean luminance and its square (at 1
// spp, which has no variance, R comes from their spread; the luminance is also the
// neighbourhood's level of a change). All from the moments image: the noisy frame's
// luminance is its first moment. The update (ours_update.comp) sums 5 rows of these:
// the 5×5 neighbourhood in 10 loads instead of 25.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D moments;  // x mean, y 2nd moment of luminance
layout(binding = 2, rgba32f) uniform writeonly image2D rows;    // x Σ noise, y Σ L, z Σ L²

layout(push_constant) uniform OursNoisePush {
    uint width;
    uint height;
    float spp;
    float pad;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec3 s = vec3(0.0);
    for (int dx = -NOISE_RADIUS; dx <= NOISE_RADIUS; ++dx) {
        ivec2 q = ivec2(clamp(p.x + dx, 0, size.x - 1), p.y);
        vec2 m = imageLoad(moments, q).xy;
        if (!all_finite(vec3(m, 0.0))) m = vec2(0.0);
        if (pc.spp >= 2.0) s.x += max(m.y - m.x * m.x, 0.0) / max(pc.spp - 1.0, 1.0);
        s.y += m.x;
        s.z += m.x * m.x;
    }
    imageStore(rows, p, vec4(s, 0.0));
}
