// Constants and the random number generator every pass shares.
#ifndef DVR_COMMON_GLSL
#define DVR_COMMON_GLSL

const float PI = 3.14159265358979;
const float INV_4PI = 0.0795774715459;
const float FLT_BIG = 1e30;

// PCG hash (Jarzynski & Olano 2020): a deterministic stream per pixel, frame and sample,
// so identical seeds give identical images.
uint pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

struct Rng { uint state; };

Rng rng_init(uvec2 pixel, uint frame, uint sample_index, uint seed) {
    Rng r;
    r.state = pcg(pixel.x + pcg(pixel.y + pcg(frame + pcg(sample_index + pcg(seed)))));
    return r;
}

// Uniform in [0, 1).
float rng_next(inout Rng r) {
    r.state = r.state * 747796405u + 2891336453u;
    uint word = ((r.state >> ((r.state >> 28u) + 4u)) ^ r.state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8) * (1.0 / 16777216.0);
}

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

bool all_finite(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }

#endif
