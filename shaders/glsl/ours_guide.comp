#version 460
// ours' guides for its spatial prior, spread over each pixel's footprint by a 3×3 tent:
// the TF albedo composited along the pixel's ray (aux_features.comp) and the gradient
// normal of its surface (surface_features.comp; zero where the ray finds
// none). The path tracer jitters its samples over the pixel, so a silhouette or a vessel
// edge between two pixel centres is a blend in the radiance; the tent makes it one in the
// guides too, and the prior's fit does not draw a staircase.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D guide;       // rgb albedo, a opacity
layout(binding = 1, rgba32f) uniform readonly image2D normal;      // xyz normal, w distance
layout(binding = 2, rgba16f) uniform writeonly image2D footprint;         // rgb albedo
layout(binding = 3, rgba16f) uniform writeonly image2D footprint_normal;  // xyz normal

layout(push_constant) uniform OursGuidePush {
    uint width;
    uint height;
    uint pad0;
    uint pad1;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec3 sa = vec3(0.0), sn = vec3(0.0);
    // The tent's weights: (r + 1 − |dx|)(r + 1 − |dy|), summing to (r + 1)⁴.
    const int t = FOOTPRINT_RADIUS + 1;
    const float total = float(t * t * t * t);
    for (int dy = -FOOTPRINT_RADIUS; dy <= FOOTPRINT_RADIUS; ++dy) {
        for (int dx = -FOOTPRINT_RADIUS; dx <= FOOTPRINT_RADIUS; ++dx) {
            ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), size - 1);
            vec3 a = imageLoad(guide, q).rgb, n = imageLoad(normal, q).xyz;
            float w = float((t - abs(dx)) * (t - abs(dy)));
            sa += w * (all_finite(a) ? a : vec3(0.0));
            sn += w * (all_finite(n) ? n : vec3(0.0));
        }
    }
    imageStore(footprint, p, vec4(sa / total, 1.0));
    imageStore(footprint_normal, p, vec4(sn / total, 0.0));
}
