#version 460
// Present: tone-maps the denoised HDR frame (include/tonemap.glsl, the project's one tone
// map) into the swapchain image, which is written as a storage image of whatever UNORM
// format the surface offers (hence no format qualifier: shaderStorageImageWriteWithoutFormat).
// The frame lands at `offset`; columns left of `split_x` come from `left_image`, the rest
// from `right_image` (a split view of two denoisers), with a one-pixel divider; pixels
// outside the frame get `background` (sRGB-encoded). The frame fills view_width ×
// view_height target pixels: the source's own size copies pixel for pixel; a larger view
// (the explorer renders fewer pixels while the view moves) upsamples bilinearly in linear
// HDR, before the tone map. The split column is in view pixels.
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
    uint view_width;
    uint view_height;
    int split_x;       // >= view_width: left image only
    float exposure;
    float pad0;
    float pad1;
    vec4 background;   // sRGB-encoded rgb
} pc;

vec3 fetch(bool left, ivec2 p) {
    return left ? imageLoad(left_image, p).rgb : imageLoad(right_image, p).rgb;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.target_width) || p.y >= int(pc.target_height)) return;
    ivec2 s = p - ivec2(pc.offset_x, pc.offset_y);
    vec3 c = pc.background.rgb;
    ivec2 view = ivec2(pc.view_width, pc.view_height);
    ivec2 source = ivec2(pc.source_width, pc.source_height);
    if (all(greaterThanEqual(s, ivec2(0))) && all(lessThan(s, view))) {
        bool split = pc.split_x > 0 && pc.split_x < view.x;
        bool left = s.x < pc.split_x;
        if (split && s.x == pc.split_x) {
            c = vec3(1.0);
        } else if (view == source) {
            c = tonemap_srgb(fetch(left, s), pc.exposure);
        } else {
            vec2 f = (vec2(s) + 0.5) * vec2(source) / vec2(view) - 0.5;
            ivec2 i0 = ivec2(floor(f));
            vec2 w = f - vec2(i0);
            ivec2 hi = source - 1;
            ivec2 a = clamp(i0, ivec2(0), hi);
            ivec2 b = clamp(i0 + 1, ivec2(0), hi);
            vec3 t00 = fetch(left, a);
            vec3 t10 = fetch(left, ivec2(b.x, a.y));
            vec3 t01 = fetch(left, ivec2(a.x, b.y));
            vec3 t11 = fetch(left, b);
            vec3 hdr = mix(mix(t00, t10, w.x), mix(t01, t11, w.x), w.y);
            c = tonemap_srgb(hdr, pc.exposure);
        }
    }
    imageStore(target, p, vec4(c, 1.0));
}
