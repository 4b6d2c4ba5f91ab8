#version 460
// ours' noise measurement, first half: per pixel, the sums over the 5 pixels of its row
// (clamped at the image's edge) of what R is measured from, and of the noisy colour. ours'
// variances are in one unit throughout, the mean over the colour channels of each
// channel's variance (the unit of the innovation's |e|²/3, the à-trous' range term and
// the prior's residuals): at 2 spp or more, x sums the variance of each pixel's mean from
// its samples' luminance moments, which the update (ours_update.comp) turns into that unit
// by the neighbourhood's colour; at 1 spp, which has no moments, x sums |y|²/3, and R is
// the spread of the neighbourhood's colours. yzw sum the colour, the neighbourhood's mean
// (its chromaticity, and the level of a change). The update sums 5 rows of these: the 5×5
// neighbourhood in 10 loads instead of 25.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D moments;  // x mean, y 2nd moment of luminance
layout(binding = 3, rgba32f) uniform readonly image2D noisy;    // rgb this frame's pixel means
layout(binding = 2, rgba32f) uniform writeonly image2D rows;    // x Σ noise (or Σ |y|²/3), yzw Σ y

layout(push_constant) uniform OursNoisePush {
    uint width;
    uint height;
    float spp;
    float pad;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 s = vec4(0.0);
    for (int dx = -NOISE_RADIUS; dx <= NOISE_RADIUS; ++dx) {
        ivec2 q = ivec2(clamp(p.x + dx, 0, size.x - 1), p.y);
        vec3 y = imageLoad(noisy, q).rgb;
        if (!all_finite(y)) y = vec3(0.0);
        if (pc.spp >= 2.0) {
            vec2 m = imageLoad(moments, q).xy;
            if (!all_finite(vec3(m, 0.0))) m = vec2(0.0);
            s.x += max(m.y - m.x * m.x, 0.0) / max(pc.spp - 1.0, 1.0);
        } else {
            s.x += dot(y, y) / 3.0;
        }
        s.yzw += y;
    }
    imageStore(rows, p, s);
}
