#version 460
// Motion vectors to the previous frame, in pixels: where this pixel's surface was last
// frame, from the closest first real collision (xy, the paper's choice) and from the
// deterministic opacity-threshold position (zw; the collision where the threshold is never
// reached). Pixels whose ray hit nothing use a point far along the view ray, so camera
// rotation still moves the background correctly.
#include "common.glsl"
#include "frame.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 7, rgba32f) uniform readonly image2D first_hit;
layout(binding = 8, rgba32f) uniform readonly image2D feature_position;
layout(binding = 9, rgba32f) uniform writeonly image2D motion;

layout(push_constant) uniform MotionPush {
    uint width;
    uint height;
    uint pad0;
    uint pad1;
} pc;

vec2 project(mat4 view_proj, vec3 world) {
    vec4 clip = view_proj * vec4(world, 1.0);
    vec2 ndc = clip.xy / max(clip.w, 1e-6);
    return (ndc * 0.5 + 0.5) * vec2(pc.width, pc.height);
}

// The point's own displacement, measured from where it projects now rather than from the
// pixel centre: the first real collision comes from a jittered sample (the pixel filter
// reaches beyond the pixel), and with a still camera its motion must be exactly zero.
vec2 point_motion(vec3 world) {
    return project(frame.prev_view_proj, world) - project(frame.view_proj, world);
}

vec3 far_point(vec2 pixel) {
    vec2 ndc = pixel / vec2(pc.width, pc.height) * 2.0 - 1.0;
    vec4 far_h = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 d = normalize(far_h.xyz / far_h.w - frame.camera_pos.xyz);
    return frame.camera_pos.xyz + d * 1000.0;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
    vec2 centre = vec2(pixel) + 0.5;
    vec4 hit = imageLoad(first_hit, ivec2(pixel));
    vec4 feat = imageLoad(feature_position, ivec2(pixel));
    vec3 p_hit = hit.w > 0.0 ? hit.xyz : far_point(centre);
    // A ray through a thin semi-transparent fringe collides without ever reaching the
    // features' opacity threshold: its content moves with the volume (the collision),
    // not with the background, or the history drags the fringe out into a halo.
    vec3 p_feat = feat.w > 0.0 ? feat.xyz : p_hit;
    vec2 m_hit = point_motion(p_hit);
    vec2 m_feat = point_motion(p_feat);
    imageStore(motion, ivec2(pixel), vec4(m_hit, m_feat));
}
