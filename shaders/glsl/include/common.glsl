// Constants and the random number generator every pass shares.
#ifndef DVR_COMMON_GLSL
#define DVR_COMMON_GLSL

const float PI = 3.14159265358979;
const float INV_4PI = 0.0795774715459;
const float FLT_BIG = 1e30;

// PCG's constants (Jarzynski & Olano 2020): the LCG step's multiplier and increment, the
// output permutation's multiplier and its shifts.
const uint PCG_MUL = 747796405u;
const uint PCG_INC = 2891336453u;
const uint PCG_OUT_MUL = 277803737u;
const uint PCG_SELECT_SHIFT = 28u;
const uint PCG_OUT_SHIFT = 22u;
// A uniform float from a 32-bit word: its top 24 bits (a float's mantissa holds 24), over
// 2^24.
const int RNG_DROP_BITS = 8;
const float RNG_UNIT = 1.0 / 16777216.0;
// Rec. 709 luminance weights.
const vec3 LUMA_REC709 = vec3(0.2126, 0.7152, 0.0722);

// PCG hash (Jarzynski & Olano 2020): a deterministic stream per pixel, frame and sample,
// so identical seeds give identical images.
uint pcg(uint v) {
    uint state = v * PCG_MUL + PCG_INC;
    uint word = ((state >> ((state >> PCG_SELECT_SHIFT) + 4u)) ^ state) * PCG_OUT_MUL;
    return (word >> PCG_OUT_SHIFT) ^ word;
}

struct Rng { uint state; };

Rng rng_init(uvec2 pixel, uint frame, uint sample_index, uint seed) {
    Rng r;
    r.state = pcg(pixel.x + pcg(pixel.y + pcg(frame + pcg(sample_index + pcg(seed)))));
    return r;
}

// Uniform in [0, 1).
float rng_next(inout Rng r) {
    r.state = r.state * PCG_MUL + PCG_INC;
    uint word = ((r.state >> ((r.state >> PCG_SELECT_SHIFT) + 4u)) ^ r.state) * PCG_OUT_MUL;
    word = (word >> PCG_OUT_SHIFT) ^ word;
    return float(word >> RNG_DROP_BITS) * RNG_UNIT;
}

float luminance(vec3 c) { return dot(c, LUMA_REC709); }

bool all_finite(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

#endif
