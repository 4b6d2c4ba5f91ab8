#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) uniform writeonly image2D out_image;
void main() { imageStore(out_image, ivec2(gl_GlobalInvocationID.xy), vec4(1.0)); }
