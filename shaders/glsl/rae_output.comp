#version 460
// RAE output transform, fp32 tensors (body: include/rae_io.glsl).
#define RAE_OUTPUT 1
#define TENSOR_FORMAT rgba32f
#include "rae_io.glsl"
