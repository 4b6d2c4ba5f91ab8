#version 460
// RAE 2×2 max-pool, fp16 tensors (body: include/rae_pool.glsl).
#define TENSOR_FORMAT rgba16f
#include "rae_pool.glsl"
