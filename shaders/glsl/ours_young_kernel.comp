#version 460
// ours' young-pixel network, one level of its kernel cascade
// (engine/src/denoise/ours/young.rs): the head's nine logits of this level, upsampled
// bilinearly from half resolution (torch's align_corners=False), are a softmax's weights
// over the 3×3 taps `dilation` apart (edges clamped) of the level's input: the noisy
// radiance at the first level, the previous level's output after it. The output is a
// convex combination of the frame's own pixels. At the last level one more logit's
// sigmoid weighs that estimate against ours'.
#include "common.glsl"
#include "ours_young.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// The network's kernels' taps on either side (3×3): the architecture it was trained with.
const int YOUNG_TAP_RADIUS = 1;
const int YOUNG_TAP_SIDE = 2 * YOUNG_TAP_RADIUS + 1;

layout(binding = 0, rgba32f) uniform readonly image2D src;
layout(binding = 1, rgba32f) uniform readonly image2D logits;  // the head's tensor
layout(binding = 2, rgba32f) uniform readonly image2D ours;
layout(binding = 3, rgba32f) uniform writeonly image2D dst;

layout(push_constant) uniform OursYoungKernelPush {
    uint width;         // the full frame's
    uint height;
    uint first_logit;   // this level's nine logits start here
    int dilation;
    uint blend_logit;   // the sigmoid's logit, read at the last level
    uint last;
    uint columns;       // the logits' groups per row
    uint pad0;
} pc;

ivec2 half_size;
ivec2 i0, i1;
vec2 l1;

// Channel c of the head's output, bilinearly upsampled to this pixel.
float logit(uint c) {
    uint g = c / 4u;
    int k = int(c % 4u);
    float v00 = imageLoad(logits, young_texel(g, i0, half_size, pc.columns))[k];
    float v01 = imageLoad(logits, young_texel(g, ivec2(i1.x, i0.y), half_size, pc.columns))[k];
    float v10 = imageLoad(logits, young_texel(g, ivec2(i0.x, i1.y), half_size, pc.columns))[k];
    float v11 = imageLoad(logits, young_texel(g, i1, half_size, pc.columns))[k];
    vec2 l0 = 1.0 - l1;
    return l0.y * (l0.x * v00 + l1.x * v01) + l1.y * (l0.x * v10 + l1.x * v11);
}

vec3 radiance(ivec2 q) {
    vec3 c = imageLoad(src, q).rgb;
    return all_finite(c) ? max(c, vec3(0.0)) : vec3(0.0);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    half_size = (size + 1) / 2;
    // torch's source index: scale · (x + ½) − ½, at least 0.
    vec2 scale = vec2(half_size) / vec2(size);
    vec2 s = max(scale * (vec2(p) + 0.5) - 0.5, vec2(0.0));
    i0 = ivec2(s);
    i1 = min(i0 + 1, half_size - 1);
    l1 = s - vec2(i0);
    float l[YOUNG_TAP_SIDE * YOUNG_TAP_SIDE];
    float top = -FLT_BIG;
    for (int k = 0; k < l.length(); ++k) {
        l[k] = logit(pc.first_logit + uint(k));
        top = max(top, l[k]);
    }
    vec3 sum = vec3(0.0);
    float total = 0.0;
    for (int dy = -YOUNG_TAP_RADIUS; dy <= YOUNG_TAP_RADIUS; ++dy) {
        for (int dx = -YOUNG_TAP_RADIUS; dx <= YOUNG_TAP_RADIUS; ++dx) {
            float e = exp(l[(dy + YOUNG_TAP_RADIUS) * YOUNG_TAP_SIDE + dx + YOUNG_TAP_RADIUS] - top);
            ivec2 q = clamp(p + pc.dilation * ivec2(dx, dy), ivec2(0), size - 1);
            sum += e * radiance(q);
            total += e;
        }
    }
    vec3 y = sum / total;
    if (pc.last != 0u) {
        float c = 1.0 / (1.0 + exp(-logit(pc.blend_logit)));
        vec3 o = imageLoad(ours, p).rgb;
        o = all_finite(o) ? max(o, vec3(0.0)) : y;
        y = c * y + (1.0 - c) * o;
    }
    imageStore(dst, p, vec4(y, 1.0));
}
