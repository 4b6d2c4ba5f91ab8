#version 460
// Temporal anti-aliasing as a denoiser: an exponential moving average of the reprojected,
// bilinearly fetched history and this frame (weight `alpha` on the new frame), with the
// history first clipped towards the mean of this frame's 3×3 neighbourhood, inside the
// box mean ± gamma·σ in YCoCg (Salvi's variance clipping with Karis's clip towards the
// centre). Where reprojection fails the output restarts from this frame.
#include "common.glsl"
#include "reproject.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 1, rgba32f) uniform readonly image2D noisy;
layout(binding = 2) uniform sampler2D history_prev;
layout(binding = 3, rgba32f) uniform writeonly image2D history_cur;

layout(push_constant) uniform TaaPush {
    vec4 camera;       // xyz camera position
    uint width;
    uint height;
    uint history_valid;
    float alpha;       // weight of the new frame (0.1)
    float gamma;       // clip box half-size in standard deviations (1)
    float tolerance;   // disocclusion tolerance, relative to camera distance
    float pad0;
    float pad1;
} pc;

vec3 rgb_to_ycocg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b,
                -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}

vec3 ycocg_to_rgb(vec3 c) {
    return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z);
}

vec3 load(ivec2 q) {
    vec3 c = imageLoad(noisy, q).rgb;
    return all_finite(c) ? c : vec3(0.0);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;

    vec3 current = load(p);
    Reprojection r = reproject(p, size, pc.history_valid != 0u, pc.camera.xyz, pc.tolerance);
    vec3 result = current;
    if (r.valid) {
        vec3 m1 = vec3(0.0), m2 = vec3(0.0);
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                vec3 y = rgb_to_ycocg(load(clamp(p + ivec2(dx, dy), ivec2(0), size - 1)));
                m1 += y;
                m2 += y * y;
            }
        }
        vec3 mean = m1 / 9.0;
        vec3 sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3(0.0)));
        vec3 history = history_fetch(history_prev, r).rgb;
        if (all_finite(history)) {
            // Clip the segment mean → history to the box mean ± gamma·σ.
            vec3 h = rgb_to_ycocg(history);
            vec3 extent = pc.gamma * sigma + 1e-7;
            vec3 v = h - mean;
            vec3 u = abs(v / extent);
            float t = max(u.x, max(u.y, u.z));
            if (t > 1.0) h = mean + v / t;
            result = mix(max(ycocg_to_rgb(h), vec3(0.0)), current, pc.alpha);
        }
    }
    imageStore(history_cur, p, vec4(result, 1.0));
}
