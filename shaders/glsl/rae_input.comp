#version 460
// RAE input transform, fp32 tensors (body: include/rae_io.glsl).
#define RAE_OUTPUT 0
#define TENSOR_FORMAT rgba32f
#include "rae_io.glsl"
