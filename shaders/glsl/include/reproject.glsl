// The one reprojection step every temporal denoiser uses: where this pixel's surface was
// last frame (motion vectors from a per-pixel world position and last frame's camera),
// whether that place was on screen, and whether it is the same surface (disocclusion test
// on world positions). History data is then fetched bilinearly at that place.
#ifndef DVR_REPROJECT_GLSL
#define DVR_REPROJECT_GLSL

#include "common.glsl"
#include "frame.glsl"

// Motion in pixels: xy from the closest first real collision, zw from the surface features.
layout(binding = 20, rgba32f) uniform readonly image2D motion;
// This frame's and last frame's world positions (w > 0 where something was hit), from
// the same source as the motion vectors in use.
layout(binding = 21, rgba32f) uniform readonly image2D position_cur;
layout(binding = 22) uniform sampler2D position_prev;

// Which motion source to use: 0 = first real collision (the paper's), 1 = features.
layout(constant_id = 8) const int MOTION_SOURCE = 0;

struct Reprojection {
    vec2 uv;     // last frame's texture coordinate of this pixel's surface
    bool valid;  // on screen, same surface, history exists
};

vec2 to_pixel(mat4 view_proj, vec3 world, ivec2 size) {
    vec4 clip = view_proj * vec4(world, 1.0);
    return (clip.xy / max(clip.w, 1e-6) * 0.5 + 0.5) * vec2(size);
}

// Disocclusion by a screen-space round trip: what was at the reprojected place last
// frame must have moved on screen as this pixel's surface did (within `tolerance`
// pixels). Unlike comparing world positions, this tolerates the stochastic depth and the
// jittered sample position of the first real collision in semi-transparent media (with a
// still camera every point's motion is zero; under motion a depth error only changes it
// by its parallax), and it also tests pixels whose ray missed this frame: a background
// pixel where the object was last frame compares the object's motion with the
// background's, so no colour is dragged into the background. Where last frame's ray
// missed but this one hit, only a still pixel keeps its history (a semi-transparent
// pixel whose first collision comes and goes), anything moving is a disocclusion.
Reprojection reproject(ivec2 p, ivec2 size, bool history_valid, vec3 camera, float tolerance) {
    Reprojection r;
    vec4 m = imageLoad(motion, p);
    vec2 delta = MOTION_SOURCE == 0 ? m.xy : m.zw;
    vec2 q = vec2(p) + 0.5 + delta;
    r.uv = q / vec2(size);
    r.valid = history_valid && all(greaterThanEqual(q, vec2(0.0))) && all(lessThan(q, vec2(size)));
    if (r.valid) {
        vec4 cur = imageLoad(position_cur, p);
        vec4 prev = texelFetch(position_prev, ivec2(q), 0);
        if (prev.w > 0.0) {
            // Compare displacements, not places: that point's own motion must carry it
            // from where it was last frame to where it is now as this pixel's motion
            // does. The first real collision comes from a jittered sample (the pixel
            // filter reaches beyond the pixel), so comparing places would reject still
            // pixels at random; with a deterministic position the two tests agree.
            vec2 was = to_pixel(frame.prev_view_proj, prev.xyz, size);
            vec2 back = to_pixel(frame.view_proj, prev.xyz, size);
            r.valid = length(back - was + delta) <= tolerance;
        } else if (cur.w > 0.0) {
            r.valid = length(delta) <= tolerance;
        }
    }
    return r;
}

#endif
