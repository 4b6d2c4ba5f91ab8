#version 460
// RAE 3×3 convolution, fp32 tensors (body: include/rae_conv.glsl).
#define TENSOR_FORMAT rgba32f
#include "rae_conv.glsl"
