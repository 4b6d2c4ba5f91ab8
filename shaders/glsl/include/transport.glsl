// Free-flight sampling and transmittance: delta tracking with ratio-tracked shadow rays
// over the majorant grid (unbiased, the default), or jittered Riemann-sum ray marching
// (Exposure Render's estimator). For a homogeneous medium each brick's majorant equals
// its extinction, so delta tracking reduces to closed-form exponential sampling with no
// null collisions inside the medium.
#ifndef DVR_TRANSPORT_GLSL
#define DVR_TRANSPORT_GLSL

#include "common.glsl"
#include "specialization.glsl"
#include "volume.glsl"

// Guards that end a walk that cannot end (a NaN distance): the majorant cells one ray
// crosses, and the collisions in one cell.
const int WALK_CELLS_MAX = 4096;
const int CELL_COLLISIONS_MAX = 1024;
// The ray marcher's step's optical depth floor (no division by zero in empty space).
const float DTAU_MIN = 1e-12;
// Ratio tracking's Russian roulette: below this transmittance a shadow ray survives with
// probability tr / threshold and goes on at the threshold.
const float SHADOW_RR_THRESHOLD = 0.1;
const float SHADOW_RR_SCALE = 1.0 / SHADOW_RR_THRESHOLD;

// Samples a real collision along o + t d for t in [t0, t1]. Returns the distance, or a
// negative value when the ray leaves the range unscattered.
float sample_free_flight(vec3 o, vec3 d, float t0, float t1, inout Rng rng) {
    if (ESTIMATOR == ESTIMATOR_RAY_MARCH) {
        float step_len = frame.params.x;
        float target = -log(1.0 - rng_next(rng));
        float tau = 0.0;
        float t = t0 + step_len * rng_next(rng);
        while (t < t1) {
            float mu = extinction_at(o + d * t);
            float dtau = mu * step_len;
            if (tau + dtau >= target) {
                return t - step_len * (1.0 - (target - tau) / max(dtau, DTAU_MIN));
            }
            tau += dtau;
            t += step_len;
        }
        return -1.0;
    }
    GridWalk w = grid_walk_begin(o, d, t0);
    float t = t0;
    for (int guard = 0; guard < WALK_CELLS_MAX; ++guard) {
        float cell_exit = min(grid_walk_exit(w), t1);
        float m = grid_majorant(w);
        if (m > 0.0) {
            for (int k = 0; k < CELL_COLLISIONS_MAX; ++k) {
                t -= log(1.0 - rng_next(rng)) / m;
                if (t >= cell_exit) break;
                if (rng_next(rng) * m < extinction_at(o + d * t)) return t;
            }
        }
        t = cell_exit;
        if (t >= t1 || !grid_walk_advance(w)) return -1.0;
    }
    return -1.0;
}

// Transmittance along o + t d for t in [t0, t1].
float transmittance(vec3 o, vec3 d, float t0, float t1, inout Rng rng) {
    if (ESTIMATOR == ESTIMATOR_RAY_MARCH) {
        float step_len = frame.params.x;
        float tau = 0.0;
        float t = t0 + step_len * rng_next(rng);
        while (t < t1) {
            tau += extinction_at(o + d * t) * min(step_len, t1 - t + step_len * 0.5);
            t += step_len;
        }
        return exp(-tau);
    }
    GridWalk w = grid_walk_begin(o, d, t0);
    float t = t0;
    float tr = 1.0;
    for (int guard = 0; guard < WALK_CELLS_MAX; ++guard) {
        float cell_exit = min(grid_walk_exit(w), t1);
        float m = grid_majorant(w);
        if (m > 0.0) {
            for (int k = 0; k < CELL_COLLISIONS_MAX; ++k) {
                t -= log(1.0 - rng_next(rng)) / m;
                if (t >= cell_exit) break;
                tr *= 1.0 - extinction_at(o + d * t) / m;
            }
            // Russian roulette keeps long shadow rays cheap without bias.
            if (tr < SHADOW_RR_THRESHOLD) {
                if (rng_next(rng) >= tr * SHADOW_RR_SCALE) return 0.0;
                tr = SHADOW_RR_THRESHOLD;
            }
        }
        t = cell_exit;
        if (t >= t1 || !grid_walk_advance(w)) break;
    }
    return tr;
}

#endif
