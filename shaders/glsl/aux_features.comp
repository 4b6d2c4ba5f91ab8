#version 460
// The guide images a single-frame denoiser takes beside the colour (Intel Open Image
// Denoise's "albedo" and "normal" auxiliary images), for a volume: march the pixel
// centre's ray front to back and composite, with the weights of the first scattering
// event along it (the medium's opacity over what is still transmitted), the TF albedo and
// the gradient normal of every step, until almost nothing is transmitted. An opaque
// surface gives its own albedo and normal; a semi-transparent layer gives its albedo and
// normal scaled by how much of the ray it stops; a ray that meets nothing gives zero (no
// surface). Deterministic and noise-free, so a denoiser may take them as clean.
// The same march finds the threshold surface (include/features_march.glsl) and writes the
// surface features as surface_features.comp does, so a frame whose methods read both
// marches once.
#include "common.glsl"
#include "frame.glsl"
#include "volume.glsl"
#include "features_march.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// The normal guide costs six density fetches a step; SVGF's demodulation needs only the
// albedo, so its pipeline leaves the normal out (written as zero with the opacity).
layout(constant_id = 16) const bool GUIDE_NORMALS = true;

layout(binding = 7, rgba32f) uniform writeonly image2D aux_albedo;  // rgb albedo, a opacity
layout(binding = 8, rgba32f) uniform writeonly image2D aux_normal;  // xyz world normal, w opacity
// The surface features (surface_features.comp).
layout(binding = 9, rgba32f) uniform writeonly image2D feature_position;  // xyz, w valid
layout(binding = 10, rgba32f) uniform writeonly image2D feature_normal;   // xyz, w depth
layout(binding = 11, rgba32f) uniform writeonly image2D feature_albedo;   // rgb, w valid

layout(push_constant) uniform AuxFeaturesPush {
    uint width;
    uint height;
    float step_voxels;  // march step in voxels
    float pad;
} pc;

// Accumulated opacity at which the ray counts as stopped (what is left cannot change the
// composite by more than 1%).
const float OPAQUE = 0.99;

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
    float threshold = frame.params.z;
    // The march goes on until the composite is done and, past it, until the surface
    // is found (a threshold above OPAQUE).
    float stop = max(OPAQUE, threshold);
    Crossing c = crossing_begin();
    float voxel = min(box_size().x / float(frame.dims.x),
                      min(box_size().y / float(frame.dims.y), box_size().z / float(frame.dims.z)));
    float base_step = voxel * pc.step_voxels;
    float alpha = 0.0;
    vec3 albedo = vec3(0.0);
    vec3 normal = vec3(0.0);
    if (span.x < span.y) {
        // The bricks the majorant grid says hold anything; empty ones are skipped whole.
        GridWalk w = grid_walk_begin(o, d, span.x);
        float t = span.x;
        for (int guard = 0; guard < 4096 && alpha < stop; ++guard) {
            float cell_exit = min(grid_walk_exit(w), span.y);
            float m = grid_majorant(w);
            if (m > 0.0) {
                // One step length everywhere, the one surface_features.comp takes (the
                // surface found here must be its surface); longer steps in faint bricks
                // blur thin vessels (the experiments page has the measurement).
                float step_len = base_step;
                for (; t < cell_exit && alpha < stop; t += step_len) {
                    vec3 p = o + d * t;
                    MediumPoint m = medium_point(p);
                    vec4 tf = m.albedo_opacity;
                    float a = step_opacity(tf.a * frame.box_min.w, step_len);
                    crossing_step(c, t, a, threshold);
                    if (a <= 0.0) continue;
                    float weight = (1.0 - alpha) * a;
                    if (GUIDE_NORMALS) {
                        vec3 g = medium_gradient(m);
                        vec3 n = length(g) > 1e-6 ? -normalize(g) : -d;
                        if (cut_entry && t - span.x < CUT_FACE_STEPS * base_step) n = cut_normal;
                        if (dot(n, d) > 0.0) n = -n;
                        normal += weight * n;
                    }
                    albedo += weight * tf.rgb;
                    alpha += weight;
                }
            } else {
                t = cell_exit;
            }
            if (t >= span.y || !grid_walk_advance(w)) break;
        }
    }
    imageStore(aux_albedo, ivec2(pixel), vec4(clamp(albedo, 0.0, 1.0), alpha));
    imageStore(aux_normal, ivec2(pixel), vec4(clamp(normal, -1.0, 1.0), alpha));
    vec4 pos, nrm, alb;
    crossing_features(c, o, d, span.x, cut_normal, base_step, threshold, pos, nrm, alb);
    imageStore(feature_position, ivec2(pixel), pos);
    imageStore(feature_normal, ivec2(pixel), nrm);
    imageStore(feature_albedo, ivec2(pixel), alb);
}
