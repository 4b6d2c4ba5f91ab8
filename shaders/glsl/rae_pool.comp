#version 460
// RAE 2×2 max-pool, fp32 tensors (body: include/rae_pool.glsl).
#define TENSOR_FORMAT rgba32f
#include "rae_pool.glsl"
