// The per-frame uniform block: camera, volume placement, lights, render settings.
// Mirrored by `FrameUniforms` in engine/src/renderer/uniforms.rs (a test checks offsets).
#ifndef DVR_FRAME_GLSL
#define DVR_FRAME_GLSL

#define MAX_LIGHTS 4
#define MAX_CLIP_PLANES 6
#define LUT_SIZE 256
#define LIGHT_POINT 0
#define LIGHT_AREA 1
#define LIGHT_ENV 2
#define ENV_CONSTANT 0
#define ENV_GRADIENT 1
#define ENV_MAP 2

struct Light {
    vec4 position_kind;  // xyz position (area: centre), w kind
    vec4 radiance;       // rgb colour × intensity (env: top colour), w env mode
    vec4 u_axis;         // area: half-extent vector along u; env: bottom colour
    vec4 v_axis;         // area: half-extent vector along v
};

layout(binding = 0, std140) uniform FrameBlock {
    mat4 view_proj;
    mat4 inv_view_proj;
    mat4 prev_view_proj;
    vec4 camera_pos;     // xyz, w unused
    vec4 box_min;        // volume bounds in world space, w = density scale (μt per opacity)
    vec4 box_max;        // w = majorant over the whole volume
    ivec4 dims;          // volume voxels xyz, w = majorant grid brick edge in voxels
    ivec4 counts;        // x lights, y frame index, z clip planes, w max bounces
    vec4 params;         // x ray-march step (world), y HG g, z feature opacity threshold, w filter sigma (pixels)
    uvec4 seeds;         // x seed, y sample offset (progressive accumulation), z rr depth, w width
    Light lights[MAX_LIGHTS];
    // What the cut keeps (scene/cut.rs): the crop box in world space, already within the
    // volume's box (the box itself without a crop), and counts.z planes (xyz unit normal,
    // w offset): x is kept where dot(xyz, x) + w >= 0.
    vec4 crop_min;
    vec4 crop_max;
    vec4 clip[MAX_CLIP_PLANES];
    // With a label map: x the one opacity every shown label has, 0 when they differ
    // (volume.glsl, label_mask); yzw unused.
    vec4 labels;
    // Several channels: entry i, lane c is channel c's opacity at density i/(LUT_SIZE-1)
    // (its LUT's alpha, 0 where hidden). The extinction reads it rather than the LUT
    // textures: on lavapipe a sampler call per channel at every delta-tracking step costs
    // more than two uniform reads (volume.glsl, channel_opacity).
    vec4 channel_opacity[LUT_SIZE];
} frame;

#endif
