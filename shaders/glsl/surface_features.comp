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
#include "common.glsl"
#include "frame.glsl"
#include "volume.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Accumulated opacity below which a ray counts as having met nothing.
const float MIN_VISIBLE_OPACITY = 0.05;

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
    bool cut_entry = any(notEqual(cut_normal, vec3(0.0)));
    float voxel = min(box_size().x / float(frame.dims.x),
                      min(box_size().y / float(frame.dims.y), box_size().z / float(frame.dims.z)));
    float base_step = voxel * pc.step_voxels;
    float alpha = 0.0;
    float threshold = frame.params.z;
    vec4 pos = vec4(0.0);
    vec4 nrm = vec4(0.0, 0.0, 0.0, 0.0);
    vec4 alb = vec4(0.0);
    if (span.x < span.y) {
        // March the bricks the majorant grid says hold anything; skip empty ones whole.
        GridWalk w = grid_walk_begin(o, d, span.x);
        float t = span.x;
        float prev_alpha = 0.0;
        float mean_t = 0.0;  // Σ t · (contribution of the step to the accumulated opacity)
        float step_len = base_step;  // the step of the brick the march is in
        float t_hit = 0.0;           // the last step's position
        for (int guard = 0; guard < 4096 && alpha < threshold; ++guard) {
            float cell_exit = min(grid_walk_exit(w), span.y);
            float m = grid_majorant(w);
            if (m > 0.0) {
                // Steps short enough that one step's opacity stays below ~0.2 in this
                // brick (fine where it is dense, up to 4× longer where it is faint).
                step_len = clamp(0.2 / m, base_step, 4.0 * base_step);
                for (; t < cell_exit && alpha < threshold; t += step_len) {
                    vec3 p = o + d * t;
                    float a = 1.0 - exp(-extinction_at(p) * step_len);
                    prev_alpha = alpha;
                    alpha += (1.0 - alpha) * a;
                    mean_t += t * (alpha - prev_alpha);
                    t_hit = t;
                }
            } else {
                t = cell_exit;
            }
            if (alpha >= threshold || t >= span.y || !grid_walk_advance(w)) break;
        }
        // The crossing's work (the gradient's six fetches, the albedo) runs once, after the
        // march: inside the loop a SIMD CPU device (lavapipe) runs a branch's body for
        // the whole batch at every step, which made the pass four times as slow.
        bool found = alpha >= threshold;
        if (found) {
            // Interpolate the crossing inside the last step, so depth and
            // position do not terrace at the step length.
            float f = (threshold - prev_alpha) / max(alpha - prev_alpha, 1e-6);
            float th = t_hit - step_len * (1.0 - clamp(f, 0.0, 1.0));
            vec3 ph = o + d * th;
            float density = density_at(ph);
            vec3 g = density_gradient(ph);
            vec3 n = length(g) > 1e-6 ? -normalize(g) : -d;
            if (cut_entry && th - span.x < CUT_FACE_STEPS * base_step) n = cut_normal;
            if (dot(n, d) > 0.0) n = -n;
            pos = vec4(ph, 1.0);
            nrm = vec4(n, th);
            alb = vec4(tf_albedo_opacity(density).rgb, 1.0);
        }
        if (!found && alpha >= MIN_VISIBLE_OPACITY) {
            pos = vec4(o + d * (mean_t / alpha), 1.0);
        }
    }
    imageStore(feature_position, ivec2(pixel), pos);
    imageStore(feature_normal, ivec2(pixel), nrm);
    imageStore(feature_albedo, ivec2(pixel), alb);
}
