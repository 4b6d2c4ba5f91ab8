// The one reprojection step every temporal denoiser uses: where this pixel's surface was
// last frame (motion vectors from a per-pixel world position and last frame's camera),
// whether that place was on screen, and whether it is the same surface (disocclusion test
// on world positions). History data is then fetched bilinearly at that place.
#ifndef DVR_REPROJECT_GLSL
#define DVR_REPROJECT_GLSL

#include "common.glsl"
#include "frame.glsl"

// A clip-space w below this is taken as this (a point at or behind the camera's plane).
const float CLIP_W_MIN = 1e-6;

// Motion in pixels: xy from the closest first real collision, zw from the surface features.
layout(binding = 20, rgba32f) uniform readonly image2D motion;
// This frame's and last frame's world positions (w > 0 where something was hit), from
// the same source as the motion vectors in use.
layout(binding = 21, rgba32f) uniform readonly image2D position_cur;
layout(binding = 22) uniform sampler2D position_prev;

// Which motion source to use: 0 = first real collision (the paper's), 1 = features.
layout(constant_id = 8) const int MOTION_SOURCE = 0;

struct Reprojection {
    vec2 uv;        // last frame's texture coordinate of this pixel's surface
    vec2 motion;    // this pixel's motion to last frame, in pixels
    bool valid;     // on screen, same surface, history exists
    ivec2 tap;      // the first (lower-left) texel of the bilinear footprint at uv
    vec4 weights;   // bilinear weights of taps (0,0) (1,0) (0,1) (1,1), zero for a tap
                    // that is not this pixel's surface, renormalised (see history_fetch)
};

vec2 to_pixel(mat4 view_proj, vec3 world, ivec2 size) {
    vec4 clip = view_proj * vec4(world, 1.0);
    return (clip.xy / max(clip.w, CLIP_W_MIN) * 0.5 + 0.5) * vec2(size);
}

// Whether last frame's texel `tap` showed this pixel's surface: a screen-space round
// trip. What was there last frame must have moved on screen as this pixel's surface did
// (within `tolerance` pixels). Unlike comparing world positions, this tolerates the
// stochastic depth and the jittered sample position of the first real collision in
// semi-transparent media (with a still camera every point's motion is zero; under motion
// a depth error only changes it by its parallax), and it also tests pixels whose ray
// missed this frame: a background pixel where the object was last frame compares the
// object's motion with the background's, so no colour is dragged into the background.
// Where last frame's ray missed but this one hit, only a still pixel of the first real
// collision keeps its history (a semi-transparent pixel whose first collision comes and
// goes), anything moving is a disocclusion.
// `camera_still`: the two frames' cameras are the same, so every point's own motion is
// zero (the round trip below, exactly) and the test needs no projections.
// The features' position is deterministic: under a still camera a pixel whose ray hit
// last frame and misses now, or the other way round, sees a medium that moved in place
// (a cut toggled, a crop shrunk, a series' next time point, a TF that cleared a layer),
// and its history is another surface's.
bool same_surface(ivec2 tap, vec2 delta, bool hit_now, float tolerance, ivec2 size,
                  bool camera_still) {
    vec4 prev = texelFetch(position_prev, tap, 0);
    if (camera_still && MOTION_SOURCE == 1 && (prev.w > 0.0) != hit_now) return false;
    if (prev.w > 0.0) {
        if (camera_still) return length(delta) <= tolerance;
        // Compare displacements, not places: that point's own motion must carry it from
        // where it was last frame to where it is now as this pixel's motion does. The
        // first real collision comes from a jittered sample (the pixel filter reaches
        // beyond the pixel), so comparing places would reject still pixels at random;
        // with a deterministic position the two tests agree.
        vec2 was = to_pixel(frame.prev_view_proj, prev.xyz, size);
        vec2 back = to_pixel(frame.view_proj, prev.xyz, size);
        return length(back - was + delta) <= tolerance;
    }
    return !hit_now || length(delta) <= tolerance;
}

// Where this pixel's surface was last frame and which texels of the bilinear footprint
// there still show it. Each tap is tested on its own, so a footprint straddling a
// silhouette fetches only the texels of this pixel's side (a plain bilinear fetch there
// leaks the other side's history a little every frame: a halo that trails the motion).
Reprojection reproject(ivec2 p, ivec2 size, bool history_valid, vec3 camera, float tolerance) {
    Reprojection r;
    vec4 m = imageLoad(motion, p);
    vec2 delta = MOTION_SOURCE == 0 ? m.xy : m.zw;
    vec2 q = vec2(p) + 0.5 + delta;
    r.uv = q / vec2(size);
    r.motion = delta;
    r.valid = history_valid && all(greaterThanEqual(q, vec2(0.0))) && all(lessThan(q, vec2(size)));
    r.tap = ivec2(floor(q - 0.5));
    r.weights = vec4(0.0);
    if (!r.valid) return r;
    bool hit_now = imageLoad(position_cur, p).w > 0.0;
    vec2 f = q - 0.5 - vec2(r.tap);
    vec4 bilinear = vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
    bool camera_still = frame.view_proj == frame.prev_view_proj;
    const ivec2 offsets[4] = ivec2[](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(1, 1));
    bool same[4] = bool[](false, false, false, false);
    for (int i = 0; i < 4; ++i) {
        ivec2 t = r.tap + offsets[i];
        bool inside = all(greaterThanEqual(t, ivec2(0))) && all(lessThan(t, size));
        // A tap without bilinear weight is not tested (a still camera's pixel has one
        // tap): it adds nothing, and the nearest tap always has weight.
        same[i] = inside && bilinear[i] > 0.0 &&
                  same_surface(t, delta, hit_now, tolerance, size, camera_still);
        if (same[i]) r.weights[i] = bilinear[i];
    }
    float total = dot(r.weights, vec4(1.0));
    // The nearest texel (one of the four taps, always on screen) decides whether there is
    // a history at all (as a nearest-texel test would); the weights then use whichever
    // taps agree.
    ivec2 nearest = ivec2(q) - r.tap;
    r.valid = total > 0.0 && same[nearest.x + 2 * nearest.y];
    r.weights = r.valid ? r.weights / total : vec4(0.0);
    return r;
}

// A history texel blend over the taps of `r` that show this pixel's surface.
vec4 history_fetch(sampler2D history, Reprojection r) {
    const ivec2 offsets[4] = ivec2[](ivec2(0, 0), ivec2(1, 0), ivec2(0, 1), ivec2(1, 1));
    ivec2 hi = textureSize(history, 0) - 1;
    vec4 sum = vec4(0.0);
    for (int i = 0; i < 4; ++i) {
        if (r.weights[i] > 0.0) sum += r.weights[i] * texelFetch(history, clamp(r.tap + offsets[i], ivec2(0), hi), 0);
    }
    return sum;
}

#endif
