// RAE (engine/src/denoise/rae.rs): one 3×3 convolution with bias and leaky ReLU fused,
// over the concatenation of two inputs. Tensors are TENSOR_FORMAT images (rgba32f, or
// rgba16f in the *_f16 variants: the including .comp file defines it) holding 4 channels
// per texel, channel group g of pixel (x, y) at texel (g·width + x, y). Input A is at
// this level's resolution, or at half of it with `a_upsample` (the decoder's
// nearest-neighbour upsampling fused into the fetch); input B (skip connection or the
// previous frame's recurrent state) is at this level's resolution and reads as zero when
// `b_enabled` is 0. Zero padding outside the level's image, as torch's Conv2d(padding=1).
// One invocation per output pixel and output group: loops are at most
// (groups_a + groups_b) × 9 steps, far below lavapipe's loop limiter.
// Weights (tools/rae/model.py export_floats): for output group go, input group gi and tap
// t = ky·3 + kx, four vec4 columns (one per input channel of the group) over the group's
// four output channels; biases are one vec4 per output group.

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0, TENSOR_FORMAT) uniform readonly image2D in_a;
layout(binding = 1, TENSOR_FORMAT) uniform readonly image2D in_b;
layout(binding = 2, TENSOR_FORMAT) uniform writeonly image2D dst;
layout(binding = 3, std430) readonly buffer RaeWeights { vec4 w[]; } weights;

layout(push_constant) uniform RaeConvPush {
    uint width;           // this level's (output) size
    uint height;
    uint groups_a;        // channel groups of A
    uint groups_b;        // channel groups of B (0: no B)
    uint a_upsample;      // 1: A is at half resolution (nearest upsample)
    uint b_enabled;       // 0: B reads as zero (invalid recurrent state)
    uint weights_offset;  // in vec4
    uint bias_offset;     // in vec4
    float slope;          // leaky ReLU slope; 1 = linear
    uint pad0;
    uint pad1;
    uint pad2;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    uint go = gl_GlobalInvocationID.z;
    int w = int(pc.width);
    int h = int(pc.height);
    if (p.x >= w || p.y >= h) {
        return;
    }
    uint gin = pc.groups_a + pc.groups_b;
    uint base = pc.weights_offset + go * gin * 36u;
    vec4 acc = weights.w[pc.bias_offset + go];
    int wa = pc.a_upsample != 0u ? w / 2 : w;
    for (uint gi = 0u; gi < pc.groups_a; ++gi) {
        for (int t = 0; t < 9; ++t) {
            ivec2 q = p + ivec2(t % 3 - 1, t / 3 - 1);
            if (q.x < 0 || q.y < 0 || q.x >= w || q.y >= h) {
                continue;
            }
            ivec2 s = pc.a_upsample != 0u ? q / 2 : q;
            vec4 v = imageLoad(in_a, ivec2(int(gi) * wa + s.x, s.y));
            uint k = base + (gi * 9u + uint(t)) * 4u;
            acc += weights.w[k] * v.x + weights.w[k + 1u] * v.y + weights.w[k + 2u] * v.z
                + weights.w[k + 3u] * v.w;
        }
    }
    if (pc.b_enabled != 0u) {
        for (uint gb = 0u; gb < pc.groups_b; ++gb) {
            uint gi = pc.groups_a + gb;
            for (int t = 0; t < 9; ++t) {
                ivec2 q = p + ivec2(t % 3 - 1, t / 3 - 1);
                if (q.x < 0 || q.y < 0 || q.x >= w || q.y >= h) {
                    continue;
                }
                vec4 v = imageLoad(in_b, ivec2(int(gb) * w + q.x, q.y));
                uint k = base + (gi * 9u + uint(t)) * 4u;
                acc += weights.w[k] * v.x + weights.w[k + 1u] * v.y + weights.w[k + 2u] * v.z
                    + weights.w[k + 3u] * v.w;
            }
        }
    }
    vec4 outv = max(acc, acc * pc.slope);
    imageStore(dst, ivec2(int(go) * w + p.x, p.y), outv);
}
