#version 460
// RAE output transform, fp16 tensors (body: include/rae_io.glsl).
#define RAE_OUTPUT 1
#define TENSOR_FORMAT rgba16f
#include "rae_io.glsl"
