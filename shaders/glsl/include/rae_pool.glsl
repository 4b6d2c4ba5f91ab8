// RAE (engine/src/denoise/rae.rs): 2×2 max-pool of a TENSOR_FORMAT image (defined by the
// including .comp file; 4 channels per texel,
// group g of pixel (x, y) at texel (g·width + x, y)); `width`/`height` are the output's.

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0, TENSOR_FORMAT) uniform readonly image2D src;
layout(binding = 1, TENSOR_FORMAT) uniform writeonly image2D dst;

layout(push_constant) uniform RaePoolPush {
    uint width;
    uint height;
    uint groups;
    uint pad0;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    int g = int(gl_GlobalInvocationID.z);
    int w = int(pc.width);
    if (p.x >= w || p.y >= int(pc.height)) {
        return;
    }
    ivec2 s = ivec2(g * 2 * w + 2 * p.x, 2 * p.y);
    vec4 m = max(max(imageLoad(src, s), imageLoad(src, s + ivec2(1, 0))),
                 max(imageLoad(src, s + ivec2(0, 1)), imageLoad(src, s + ivec2(1, 1))));
    imageStore(dst, ivec2(g * w + p.x, p.y), m);
}
