#version 460
// RAE (engine/src/denoise/rae.rs): the network's input and output transforms, matching
// tools/rae/model.py exactly. MODE 0 (input): HDR colour -> log(1 + max(rgb, 0)) into
// the padded input tensor (width × height, a multiple of 2^levels), edge pixels
// replicated past the frame (`src_width` × `src_height`). MODE 1 (output): the output
// tensor's first three channels -> exp(max(y, 0)) - 1, cropped to the frame.
#include "common.glsl"

layout(constant_id = 0) const int MODE = 0;

layout(local_size_x = 8, local_size_y = 8, local_size_z = 1) in;

layout(binding = 0, rgba32f) uniform readonly image2D src;
layout(binding = 1, rgba32f) uniform writeonly image2D dst;

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
    if (MODE == 0) {
        c = all_finite(c) ? log(1.0 + max(c, vec3(0.0))) : vec3(0.0);
        imageStore(dst, p, vec4(c, 0.0));
    } else {
        imageStore(dst, p, vec4(exp(max(c, vec3(0.0))) - 1.0, 1.0));
    }
}
