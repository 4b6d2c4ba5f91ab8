#version 460
// ours' young-pixel network, one convolution of its trunk or its head
// (engine/src/denoise/ours/young.rs): 3×3 taps `dilation` apart (edges clamped, as
// torch's replicate padding) or a single tap, bias, and a leaky ReLU (slope 1: none).
// One invocation computes every output group of its pixel, so each input texel is read
// once per tap rather than once per output group. Tensors as include/ours_young.glsl;
// weights as tools/young/export.py packs them: for output group go, input group gi, tap
// t and input channel c, a vec4 over the group's four output channels; then the biases.
#include "ours_young.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Output channel groups: the trunk's width, or the head's outputs, over four.
layout(constant_id = 0) const int GROUPS_OUT = 3;

layout(binding = 0, rgba32f) uniform readonly image2D src;
layout(binding = 1, rgba32f) uniform writeonly image2D dst;
layout(binding = 2, std430) readonly buffer YoungWeights { vec4 w[]; } weights;

layout(push_constant) uniform OursYoungConvPush {
    uint width;           // the half-resolution tensor's pixels
    uint height;
    uint groups_in;
    int radius;           // 1: 3×3 taps; 0: one
    int dilation;
    uint weights_offset;  // in vec4
    uint bias_offset;     // in vec4
    float slope;
    uint columns;         // the tensors' groups per row
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 acc[GROUPS_OUT];
    for (int go = 0; go < GROUPS_OUT; ++go) {
        acc[go] = weights.w[pc.bias_offset + uint(go)];
    }
    int side = 2 * pc.radius + 1;
    uint taps = uint(side * side);
    for (int dy = -pc.radius; dy <= pc.radius; ++dy) {
        for (int dx = -pc.radius; dx <= pc.radius; ++dx) {
            ivec2 q = clamp(p + pc.dilation * ivec2(dx, dy), ivec2(0), size - 1);
            uint t = uint((dy + pc.radius) * side + dx + pc.radius);
            for (uint gi = 0u; gi < pc.groups_in; ++gi) {
                vec4 v = imageLoad(src, young_texel(gi, q, size, pc.columns));
                for (int go = 0; go < GROUPS_OUT; ++go) {
                    uint k = pc.weights_offset + ((uint(go) * pc.groups_in + gi) * taps + t) * 4u;
                    acc[go] += weights.w[k] * v.x + weights.w[k + 1u] * v.y
                        + weights.w[k + 2u] * v.z + weights.w[k + 3u] * v.w;
                }
            }
        }
    }
    for (int go = 0; go < GROUPS_OUT; ++go) {
        imageStore(dst, young_texel(uint(go), p, size, pc.columns), max(acc[go], acc[go] * pc.slope));
    }
}
