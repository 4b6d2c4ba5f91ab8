#version 460
// SVGF temporal accumulation (Schied et al. 2017, §4.1), with the shared reprojection in
// place of the paper's (as the TVCG paper did): demodulate this frame's colour by the
// composited guide albedo (svgf_demod_factor), blend it with the reprojected, bilinearly fetched colour history (the output of
// last frame's first à-trous iteration) and blend the luminance moments with theirs.
// Young pixels (history length n) blend with 1/n, so the first frames are plain means.
// Also packs the edge-stopping features (normal, depth, depth gradient) for the spatial
// passes.
#include "common.glsl"
#include "frame.glsl"
#include "reproject.glsl"
#include "svgf.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2, rgba32f) uniform readonly image2D feature_albedo;   // rgb, w valid
layout(binding = 3, rgba32f) uniform readonly image2D feature_normal;   // xyz, w depth
layout(binding = 4) uniform sampler2D color_prev;    // demodulated rgb, a variance
layout(binding = 5) uniform sampler2D moments_prev;  // m1, m2, history length
layout(binding = 6, rgba32f) uniform writeonly image2D integrated;  // demodulated rgb, a variance
layout(binding = 7, rgba32f) uniform writeonly image2D moments_cur;
layout(binding = 8, rgba32f) uniform writeonly image2D geometry;    // see svgf.glsl
// The surface features' position (w = 1 where the ray meets the medium), whatever the
// motion source: the medium/background class must not follow a noisy first collision.
layout(binding = 9, rgba32f) uniform readonly image2D feature_position;
layout(binding = 10, rgba32f) uniform readonly image2D demod_albedo;  // see svgf_demod_factor

layout(push_constant) uniform SvgfTemporalPush {
    vec4 camera;          // xyz camera position
    uint width;
    uint height;
    uint history_valid;
    float tolerance;      // disocclusion tolerance, relative to camera distance
    float color_alpha;    // weight of the new frame in the colour average (0.2)
    float moments_alpha;  // weight of the new frame in the moments average (0.2)
    float demod_eps;      // added to the albedo before dividing by it
    float feature_step;   // march step of the surface features, in voxels
} pc;

// Longest history counted (only 1/n < alpha matters; this keeps n finite).
const float MAX_HISTORY = 1024.0;

bool valid_at(ivec2 q) { return imageLoad(feature_albedo, q).w > 0.0; }

// Depth change per pixel along one axis: the smaller one-sided difference to a valid
// neighbour, so a silhouette on one side does not inflate it.
float axis_gradient(ivec2 p, ivec2 axis, ivec2 size, float z) {
    float g = FLT_BIG;
    for (int s = -1; s <= 1; s += 2) {
        ivec2 q = p + s * axis;
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size)) || !valid_at(q)) continue;
        g = min(g, abs(imageLoad(feature_normal, q).w - z));
    }
    return g == FLT_BIG ? 0.0 : g;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;

    vec4 albedo = imageLoad(feature_albedo, p);
    bool valid = albedo.w > 0.0;
    vec4 nz = imageLoad(feature_normal, p);
    float dz = 0.0;
    if (valid) {
        // The features' depth quantum: their march step, as surface_features.comp takes it.
        vec3 voxel = (frame.box_max.xyz - frame.box_min.xyz) / vec3(frame.dims.xyz);
        float quantum = min(voxel.x, min(voxel.y, voxel.z)) * pc.feature_step;
        if (!(quantum > 0.0) || isinf(quantum)) quantum = 0.0;  // no volume bound
        float gradient = max(axis_gradient(p, ivec2(1, 0), size, nz.w),
                             axis_gradient(p, ivec2(0, 1), size, nz.w));
        dz = svgf_depth_slope(gradient, quantum);
    }
    bool medium = imageLoad(feature_position, p).w > 0.0;
    imageStore(geometry, p, svgf_pack_geometry(valid, medium, nz.xyz, nz.w, dz));

    vec3 c = imageLoad(noisy, p).rgb;
    if (!all_finite(c)) c = vec3(0.0);
    vec3 d = c / svgf_demod_factor(imageLoad(demod_albedo, p), pc.demod_eps);
    float l = luminance(d);
    vec2 m = vec2(l, l * l);

    Reprojection r = reproject(p, size, pc.history_valid != 0u, pc.camera.xyz, pc.tolerance);
    vec3 color = d;
    vec2 moments = m;
    float n = 1.0;
    if (r.valid) {
        vec4 hc = history_fetch(color_prev, r);
        vec4 hm = history_fetch(moments_prev, r);
        if (all_finite(hc.rgb) && all_finite(hm.xyz) && hm.z >= 1.0) {
            n = min(hm.z, MAX_HISTORY) + 1.0;
            float ac = max(pc.color_alpha, 1.0 / n);
            float am = max(pc.moments_alpha, 1.0 / n);
            color = mix(hc.rgb, d, ac);
            moments = mix(hm.xy, m, am);
        }
    }
    float variance = max(moments.y - moments.x * moments.x, 0.0);
    imageStore(integrated, p, vec4(color, variance));
    imageStore(moments_cur, p, vec4(moments, n, 0.0));
}
