// The threshold surface of a features march, shared by the two passes that march for it:
// surface_features.comp, which stops there, and aux_features.comp, which composites the
// guides along the same steps and so finds the same surface in the same march. Both step
// one base step at a time through the bricks the majorant grid says hold anything, and
// feed every step's opacity to `crossing_step`, so the surface is the same whichever
// pass found it.
#ifndef DVR_FEATURES_MARCH_GLSL
#define DVR_FEATURES_MARCH_GLSL

#include "common.glsl"
#include "frame.glsl"
#include "volume.glsl"

// Accumulated opacity below which a ray counts as having met nothing.
const float MIN_VISIBLE_OPACITY = 0.05;

// The march's state up to the crossing (where accumulated opacity reaches the feature
// threshold), frozen there.
struct Crossing {
    float alpha;       // accumulated opacity
    float prev_alpha;  // before the last step
    float mean_t;      // Σ t · (the step's contribution to the accumulated opacity)
    float t_hit;       // the last step's position
    bool found;
};

// The opacity of one step of length step_len through extinction mu: both passes take
// it from here, so their steps' opacities are the same to the bit.
float step_opacity(float mu, float step_len) { return 1.0 - exp(-mu * step_len); }

Crossing crossing_begin() { return Crossing(0.0, 0.0, 0.0, 0.0, false); }

// One step at t whose own opacity is a. Only assignments: this runs inside the march
// loop, where a SIMD CPU device (lavapipe) runs a branch's body for the whole batch.
void crossing_step(inout Crossing c, float t, float a, float threshold) {
    float alpha = c.alpha + (1.0 - c.alpha) * a;
    c.prev_alpha = c.found ? c.prev_alpha : c.alpha;
    c.mean_t = c.found ? c.mean_t : c.mean_t + t * (alpha - c.alpha);
    c.t_hit = c.found ? c.t_hit : t;
    c.alpha = c.found ? c.alpha : alpha;
    c.found = c.found || alpha >= threshold;
}

// The surface features of a finished march: at the crossing (interpolated inside its
// step, so depth and position do not terrace at the step length) the position, the
// gradient normal (the cut's where the ray entered through a cut and met the threshold at
// once) with the distance along the ray, and the TF albedo; where the threshold was not
// reached but the ray met a visible amount of medium, the expected first collision
// (mean_t / alpha) with normal and albedo invalid; elsewhere nothing.
void crossing_features(Crossing c, vec3 o, vec3 d, float entry, vec3 cut_normal,
                       float step_len, float threshold, out vec4 pos, out vec4 nrm,
                       out vec4 alb) {
    pos = vec4(0.0);
    nrm = vec4(0.0);
    alb = vec4(0.0);
    if (c.found) {
        float f = (threshold - c.prev_alpha) / max(c.alpha - c.prev_alpha, 1e-6);
        float th = c.t_hit - step_len * (1.0 - clamp(f, 0.0, 1.0));
        vec3 ph = o + d * th;
        MediumPoint m = medium_point(ph);
        vec3 g = medium_gradient(m);
        vec3 n = length(g) > 1e-6 ? -normalize(g) : -d;
        bool cut_entry = any(notEqual(cut_normal, vec3(0.0)));
        if (cut_entry && th - entry < CUT_FACE_STEPS * step_len) n = cut_normal;
        if (dot(n, d) > 0.0) n = -n;
        pos = vec4(ph, 1.0);
        nrm = vec4(n, th);
        alb = vec4(m.albedo_opacity.rgb, 1.0);
    } else if (c.alpha >= MIN_VISIBLE_OPACITY) {
        pos = vec4(o + d * (c.mean_t / c.alpha), 1.0);
    }
}

#endif
