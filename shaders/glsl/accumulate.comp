#version 460
// Progressive accumulation: adds this frame's radiance (weighted by its sample count) to a
// running sum, and writes the running mean. Used by the `accum` denoiser and to build
// high-sample references.
layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D radiance;
layout(binding = 1, rgba32f) uniform readonly image2D sum_prev;
layout(binding = 2, rgba32f) uniform writeonly image2D sum_cur;
layout(binding = 3, rgba32f) uniform writeonly image2D mean;

layout(push_constant) uniform AccumulatePush {
    uint width;
    uint height;
    uint history_valid;  // 0: start over
    float weight;        // samples in this frame's radiance
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec4 s = pc.history_valid != 0u ? imageLoad(sum_prev, p) : vec4(0.0);
    vec3 c = imageLoad(radiance, p).rgb;
    s += vec4(c * pc.weight, pc.weight);
    imageStore(sum_cur, p, s);
    imageStore(mean, p, vec4(s.rgb / max(s.w, 1e-8), 1.0));
}
