// RAE (engine/src/denoise/rae.rs): the network's input and output transforms, matching
// tools/rae/model.py exactly. The including .comp file defines RAE_OUTPUT (0 or 1) and
// TENSOR_FORMAT (rgba32f, or rgba16f in the *_f16 variants); the frame side is rgba32f.
// Input (RAE_OUTPUT 0): HDR colour -> log(1 + max(rgb, 0)) into the padded input tensor
// (width × height, a multiple of 2^levels), edge pixels replicated past the frame
// (`src_width` × `src_height`). Output (RAE_OUTPUT 1): the output tensor's first three
// channels -> exp(max(y, 0)) - 1, cropped to the frame.
#include "common.glsl"

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

#if RAE_OUTPUT
layout(binding = 0, TENSOR_FORMAT) uniform readonly image2D src;
layout(binding = 1, rgba32f) uniform writeonly image2D dst;
#else
layout(binding = 0, rgba32f) uniform readonly image2D src;
layout(binding = 1, TENSOR_FORMAT) uniform writeonly image2D dst;
#endif

layout(push_constant) uniform RaeIoPush {
    uint width;       // size of what is written
    uint height;
    uint src_width;   // size of what is read
    uint src_height;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) {
        return;
    }
    ivec2 s = min(p, ivec2(pc.src_width, pc.src_height) - 1);
    vec3 c = imageLoad(src, s).rgb;
#if RAE_OUTPUT
    imageStore(dst, p, vec4(exp(max(c, vec3(0.0))) - 1.0, 1.0));
#else
    c = all_finite(c) ? log(1.0 + max(c, vec3(0.0))) : vec3(0.0);
    imageStore(dst, p, vec4(c, 0.0));
#endif
}
