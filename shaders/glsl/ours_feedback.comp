#version 460
// ours' feedback: where the filter restarted this frame (a change, a disocclusion, the
// first frame), the first à-trous level's estimate replaces the state's, so next frame's
// update starts from a denoised value rather than one frame's noisy mean. Restarted is an
// effective history R / P under FEEDBACK_HISTORY frames. The state keeps its variance P,
// so the spatial estimate is trusted no more than the value it replaces, and the frames
// that follow outweigh it as they would have; older states are left alone, because a
// spatial estimate fed back into them each frame would stay in their memory as blur.
#include "common.glsl"
#include "ours_constants.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D filtered;  // rgb, a variance
layout(binding = 1, rg32f) uniform readonly image2D noise;       // the state's R, D
layout(binding = 2, rgba32f) uniform image2D model;              // the state: rgb, a P

layout(push_constant) uniform OursFeedbackPush {
    uint width;
    uint height;
    uint pad0;
    uint pad1;
} pc;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (p.x >= int(pc.width) || p.y >= int(pc.height)) return;
    vec4 state = imageLoad(model, p);
    float r = imageLoad(noise, p).r;
    // R / P < FEEDBACK_HISTORY, written so that a missing measurement (R 0) or a NaN
    // counts as old.
    if (!(state.a * FEEDBACK_HISTORY > r && r > 0.0)) return;
    vec4 f = imageLoad(filtered, p);
    if (!all_finite(f.rgb)) return;
    imageStore(model, p, vec4(f.rgb, state.a));
}
