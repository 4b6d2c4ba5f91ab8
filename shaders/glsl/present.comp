#version 460
// Present: tone-maps the denoised HDR frame (include/tonemap.glsl, the project's one tone
// map) into the swapchain image, which is written as a storage image of whatever UNORM
// format the surface offers (hence no format qualifier: shaderStorageImageWriteWithoutFormat).
// The frame lands at `offset`; columns left of `split_x` come from `left_image`, the rest
// from `right_image` (a split view of two denoisers), with a one-pixel divider; pixels
// outside the frame get `background` (sRGB-encoded).
layout(local_size_x = 8, local_size_y = 8) in;

#include "tonemap.glsl"

layout(binding = 0, rgba32f) uniform readonly image2D left_image;
layout(binding = 1, rgba32f) uniform readonly image2D right_image;
layout(binding = 2) uniform writeonly image2D target;

layout(push_constant) uniform PresentPush {
    uint target_width;
    uint target_height;
    int offset_x;
    int offset_y;
    uint source_width;
    uint source_height;
    int split_x;       // >= source_width: left image only
    float exposure;
    vec4 background;   // sRGB-encoded rgb
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.target_width) || p.y >= int(pc.target_height)) return;
    ivec2 s = p - ivec2(pc.offset_x, pc.offset_y);
    vec3 c = pc.background.rgb;
    if (all(greaterThanEqual(s, ivec2(0))) && s.x < int(pc.source_width) &&
        s.y < int(pc.source_height)) {
        bool split = pc.split_x > 0 && pc.split_x < int(pc.source_width);
        if (split && s.x == pc.split_x) {
            c = vec3(1.0);
        } else {
            vec3 hdr = s.x < pc.split_x ? imageLoad(left_image, s).rgb
                                        : imageLoad(right_image, s).rgb;
            c = tonemap_srgb(hdr, pc.exposure);
        }
    }
    imageStore(target, p, vec4(c, 1.0));
}
