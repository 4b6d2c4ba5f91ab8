#version 460
// ours' young-pixel network, its input (engine/src/denoise/ours/young.rs): the twelve
// features of each pixel, log(1 + noisy), the guide albedo, the surface normal and
// log(1 + ours' estimate), averaged over 2×2 pixels (the trunk runs at half resolution;
// a window past an odd edge averages the pixels it holds, as torch's ceil-mode pooling).
#include "common.glsl"
#include "ours_young.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D noisy;
layout(binding = 1, rgba32f) uniform readonly image2D albedo;  // rgb, a opacity
layout(binding = 2, rgba32f) uniform readonly image2D normal;  // xyz, w distance
layout(binding = 3, rgba32f) uniform readonly image2D ours;
layout(binding = 4, rgba32f) uniform writeonly image2D dst;

layout(push_constant) uniform OursYoungInputPush {
    uint width;   // the full frame's
    uint height;
    uint columns;  // the tensors' groups per row
    uint pad0;
} pc;

// A radiance as the network reads it; a non-finite one counts as black.
vec3 log_radiance(vec3 c) {
    return all_finite(c) ? log(1.0 + max(c, vec3(0.0))) : vec3(0.0);
}

vec3 finite_or_zero(vec3 v) { return all_finite(v) ? v : vec3(0.0); }

void main() {
    ivec2 h = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    ivec2 half_size = (size + 1) / 2;
    if (h.x >= half_size.x || h.y >= half_size.y) return;
    vec3 n = vec3(0.0), a = vec3(0.0), m = vec3(0.0), o = vec3(0.0);
    float count = 0.0;
    for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 p = 2 * h + ivec2(dx, dy);
            if (p.x >= size.x || p.y >= size.y) continue;
            n += log_radiance(imageLoad(noisy, p).rgb);
            a += clamp(finite_or_zero(imageLoad(albedo, p).rgb), 0.0, 1.0);
            m += clamp(finite_or_zero(imageLoad(normal, p).xyz), -1.0, 1.0);
            o += log_radiance(imageLoad(ours, p).rgb);
            count += 1.0;
        }
    }
    n /= count;
    a /= count;
    m /= count;
    o /= count;
    imageStore(dst, young_texel(0u, h, half_size, pc.columns), vec4(n, a.r));
    imageStore(dst, young_texel(1u, h, half_size, pc.columns), vec4(a.gb, m.xy));
    imageStore(dst, young_texel(2u, h, half_size, pc.columns), vec4(m.z, o));
}
