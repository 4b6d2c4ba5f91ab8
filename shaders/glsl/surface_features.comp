#version 460
// Deterministic surface features for reprojection and edge-stopping: march the pixel
// centre's ray front to back, compositing opacity, and stop where accumulated opacity
// crosses a threshold. There: world position, linear depth, gradient normal and TF albedo,
// with a validity flag (0 where the threshold is never reached).
// Where the threshold is not reached but the ray still meets a visible amount of medium
// (a semi-transparent layer), the position is the EXPECTED first real collision: the mean
// of the first-collision depth distribution μ(t)T(t), from the same compositing weights.
// It is what the paper's per-sample first collisions average to, without their noise, so
// reprojection through semi-transparent layers gets a stable depth. Normal and albedo stay
// invalid there (edge-stopping only trusts threshold surfaces). Where the ray enters the
// medium through a cut and meets the threshold at once, the surface is the cut face and
// its normal the cut's.
// This pass runs where no method of the frame reads the guides; where one does,
// aux_features.comp finds the same surface in its own march (include/features_march.glsl).
#include "common.glsl"
#include "frame.glsl"
#include "volume.glsl"
#include "features_march.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 7, rgba32f) uniform writeonly image2D feature_position;  // xyz, w valid
layout(binding = 8, rgba32f) uniform writeonly image2D feature_normal;    // xyz, w depth
layout(binding = 9, rgba32f) uniform writeonly image2D feature_albedo;    // rgb, w valid

layout(push_constant) uniform FeaturesPush {
    uint width;
    uint height;
    float step_voxels;  // march step in voxels
    float pad;
} pc;

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
    vec2 ndc = (vec2(pixel) + 0.5) / vec2(pc.width, pc.height) * 2.0 - 1.0;
    vec4 far_h = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    vec3 o = frame.camera_pos.xyz;
    vec3 d = normalize(far_h.xyz / far_h.w - o);
    vec3 cut_normal;
    vec2 span = intersect_medium(o, d, cut_normal);
    float voxel = min(box_size().x / float(frame.dims.x),
                      min(box_size().y / float(frame.dims.y), box_size().z / float(frame.dims.z)));
    float step_len = voxel * pc.step_voxels;
    float threshold = frame.params.z;
    Crossing c = crossing_begin();
    if (span.x < span.y) {
        GridWalk w = grid_walk_begin(o, d, span.x);
        float t = span.x;
        for (int guard = 0; guard < 4096 && !c.found; ++guard) {
            float cell_exit = min(grid_walk_exit(w), span.y);
            if (grid_majorant(w) > 0.0) {
                for (; t < cell_exit && !c.found; t += step_len) {
                    float a = step_opacity(extinction_at(o + d * t), step_len);
                    crossing_step(c, t, a, threshold);
                }
            } else {
                t = cell_exit;
            }
            if (c.found || t >= span.y || !grid_walk_advance(w)) break;
        }
    }
    vec4 pos, nrm, alb;
    crossing_features(c, o, d, span.x, cut_normal, step_len, threshold, pos, nrm, alb);
    imageStore(feature_position, ivec2(pixel), pos);
    imageStore(feature_normal, ivec2(pixel), nrm);
    imageStore(feature_albedo, ivec2(pixel), alb);
}
