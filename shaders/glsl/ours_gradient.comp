#version 460
// ours' temporal gradients (after A-SVGF, Schied, Peters and Dachsbacher, HPG 2018): in
// each S×S stratum of last frame's image one pixel's samples are traced again, with last
// frame's camera and random numbers, in this frame's scene (lights, transfer function).
// The two estimates share their paths, so their difference measures how much that
// pixel's true radiance changed since last frame with little noise: a light or TF change
// only changes what it touches. (A camera move alone changes nothing, so the pass runs
// only when the scene changed. Tracing through this frame's camera instead, from where
// the pixel's surface moved, was tried for the view-dependent change of semi-transparent
// volumes: the two paths then part, and the noisier gradients cost 1.2 dB on
// phantom/orbit.) Written at stratum resolution, in last frame's image: the re-traced
// radiance and last frame's measurement.
#include "path.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 7, rgba32f) uniform readonly image2D noisy_prev;  // last frame's radiance
layout(binding = 8, rgba32f) uniform writeonly image2D gradient_new;  // rgb re-traced, a 1
layout(binding = 9, rgba32f) uniform writeonly image2D gradient_old;  // rgb last frame's

layout(push_constant) uniform OursGradientPush {
    mat4 prev_inv_view_proj;  // last frame's camera
    vec4 prev_camera;         // xyz its position
    uint width;
    uint height;
    uint spp;
    uint prev_frame;          // last frame's index (its sample stream)
    uint stratum;             // S
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

void main() {
    ivec2 s = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    int S = int(pc.stratum);
    if (any(greaterThanEqual(s * S, size))) return;
    // A different pixel of the stratum each frame, so no pixel is always the one measured.
    uint k = pcg(uint(s.x) + pcg(uint(s.y) + pcg(pc.prev_frame))) % uint(S * S);
    ivec2 j = min(s * S + ivec2(int(k) % S, int(k) / S), size - 1);
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < pc.spp; ++i) {
        sum += pixel_sample(uvec2(j), pc.prev_frame, i, vec2(size), pc.prev_inv_view_proj,
                            pc.prev_camera.xyz).radiance;
    }
    vec3 old = imageLoad(noisy_prev, j).rgb;
    imageStore(gradient_new, s, vec4(sum / float(max(pc.spp, 1u)), 1.0));
    imageStore(gradient_old, s, vec4(all_finite(old) ? old : vec3(0.0), 1.0));
}
