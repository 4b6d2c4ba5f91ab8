// What ours' update (ours_update.comp) reads of a change before it predicts: the temporal
// gradients around a pixel (a light or TF change measured on re-traced samples).
#ifndef DVR_OURS_CHANGE_GLSL
#define DVR_OURS_CHANGE_GLSL

#include "common.glsl"

// Temporal gradients pooled per S×S stratum of last frame's image (ours_gradient.comp
// re-traced one pixel per stratum, ours_gradient_pool.comp pooled and shrunk 3×3, 5×5 and
// 9×9 strata): the log luminance ratio of this frame's radiance to last frame's, and the
// colour of the change (0 and 1 where nothing was measured).
layout(binding = 23, rgba32f) uniform readonly image2D gradient_ratio;  // rgb colour, a log ratio

// What the temporal gradients say about the scene around last frame's texture coordinate
// `uv`: per channel, the ratio of this frame's radiance to last frame's (the same paths
// traced in both scenes), and the relative change of luminance |R − 1| / max(R, 1). No
// measurement (`measured` false): ratio 1, change 0.
struct SceneChange {
    vec3 ratio;
    float change;
};

SceneChange scene_change(vec2 uv, ivec2 size, bool measured, uint stratum) {
    SceneChange sc;
    sc.ratio = vec3(1.0);
    sc.change = 0.0;
    if (!measured) return sc;
    // Interpolated bilinearly between the strata's centres.
    vec2 t = uv * vec2(size) / float(stratum) - 0.5;
    ivec2 k0 = ivec2(floor(t));
    vec2 f = t - vec2(k0);
    ivec2 hi = imageSize(gradient_ratio) - 1;
    vec4 pooled = mix(mix(imageLoad(gradient_ratio, clamp(k0, ivec2(0), hi)),
                          imageLoad(gradient_ratio, clamp(k0 + ivec2(1, 0), ivec2(0), hi)), f.x),
                      mix(imageLoad(gradient_ratio, clamp(k0 + ivec2(0, 1), ivec2(0), hi)),
                          imageLoad(gradient_ratio, clamp(k0 + ivec2(1, 1), ivec2(0), hi)), f.x), f.y);
    float Ra = exp(pooled.a);
    sc.change = abs(Ra - 1.0) / max(Ra, 1.0);
    sc.ratio = pooled.rgb * Ra;
    return sc;
}

#endif
