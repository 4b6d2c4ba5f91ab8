#version 460
// RAE 3×3 convolution, fp16 tensors (body: include/rae_conv.glsl).
#define TENSOR_FORMAT rgba16f
#include "rae_conv.glsl"
