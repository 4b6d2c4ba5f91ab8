#version 460
// The volumetric path tracer (TVCG §3/§6, Exposure Render extended): camera rays through
// a Gaussian pixel filter, free flights by delta tracking (or ray marching), a random walk
// with next-event estimation to one light per vertex, Russian roulette, emission from the
// emissive TF; one pixel sample is include/path.glsl. Writes this frame's mean radiance,
// the luminance moments, and the world position of the closest first real collision among
// the pixel's samples.
#include "path.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 7, rgba32f) uniform writeonly image2D radiance;
layout(binding = 8, rgba32f) uniform writeonly image2D moments;
layout(binding = 9, rgba32f) uniform writeonly image2D first_hit;

layout(push_constant) uniform PathTracePush {
    uint sample_offset;  // index of the first sample (progressive references)
    uint spp;            // samples this dispatch
    uint width;
    uint height;
} pc;

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
    vec3 sum = vec3(0.0);
    float lum_sum = 0.0, lum2_sum = 0.0;
    float closest = FLT_BIG;
    vec3 closest_p = vec3(0.0);
    for (uint s = 0u; s < pc.spp; ++s) {
        PixelSample ps = pixel_sample(pixel, uint(frame.counts.y), pc.sample_offset + s,
                                      vec2(pc.width, pc.height), frame.inv_view_proj,
                                      frame.camera_pos.xyz);
        vec3 l = ps.radiance;
        sum += l;
        float y = luminance(l);
        lum_sum += y;
        lum2_sum += y * y;
        if (ps.first_t >= 0.0 && ps.first_t < closest) {
            closest = ps.first_t;
            closest_p = ps.origin + ps.dir * ps.first_t;
        }
    }
    float inv = 1.0 / float(max(pc.spp, 1u));
    imageStore(radiance, ivec2(pixel), vec4(sum * inv, 1.0));
    imageStore(moments, ivec2(pixel), vec4(lum_sum * inv, lum2_sum * inv, 0.0, 0.0));
    imageStore(first_hit, ivec2(pixel), vec4(closest_p, closest < FLT_BIG ? 1.0 : 0.0));
}
