// One pixel sample of the path tracer: a camera ray through the Gaussian pixel filter and
// the random walk along it. Shared by the path-tracing pass and by ours' temporal-gradient
// pass, which re-traces last frame's samples (same seeds, last frame's camera) in this
// frame's scene; the two must compute the very same path for the same random numbers.
#ifndef DVR_PATH_GLSL
#define DVR_PATH_GLSL

#include "common.glsl"
#include "frame.glsl"
#include "specialization.glsl"
#include "volume.glsl"
#include "lights.glsl"
#include "transport.glsl"
#include "phase.glsl"

// Exposure Render's hybrid scattering: P_brdf = opacity (1 − exp(−|∇| · scale)), with the
// normalised gradient magnitude below the floor taken as no surface.
const float HYBRID_GRADIENT_SCALE = 25.0;
const float HYBRID_GRADIENT_MIN = 1e-5;
// Russian roulette's survival probability is the throughput's largest channel, at most this
// (a path always has some chance to end).
const float RR_SURVIVAL_MAX = 0.95;
// The Gaussian pixel filter's uniform is kept above this (log(0) is -inf).
const float FILTER_U_MIN = 1e-7;

// Direction of the camera ray through `pixel` (continuous pixel coordinates) of an image
// of `size` pixels, for a camera with inverse view-projection `inv_view_proj`.
vec3 camera_ray_dir(vec2 pixel, vec2 size, mat4 inv_view_proj) {
    vec2 ndc = pixel / size * 2.0 - 1.0;
    vec4 near_h = inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 far_h = inv_view_proj * vec4(ndc, 1.0, 1.0);
    return normalize(far_h.xyz / far_h.w - near_h.xyz / near_h.w);
}

// One path; returns radiance and the first real collision distance (negative if none).
vec3 trace_path(vec3 o, vec3 d, inout Rng rng, out float first_t) {
    first_t = -1.0;
    vec3 throughput = vec3(1.0);
    vec3 result = vec3(0.0);
    int max_bounces = frame.counts.w;
    for (int bounce = 0; bounce <= max_bounces; ++bounce) {
        vec2 span = intersect_medium(o, d);
        float t = span.x < span.y ? sample_free_flight(o, d, span.x, span.y, rng) : -1.0;
        if (t < 0.0) {
            if (bounce == 0) result += throughput * escaped_radiance(d);
            break;
        }
        vec3 p = o + d * t;
        if (bounce == 0) first_t = t;
        MediumPoint m = medium_point(p);
        vec4 ao = m.albedo_opacity;
        vec3 albedo = ao.rgb;
        if (USE_EMISSION) result += throughput * medium_emission(m);

        // Scattering model at this vertex.
        bool surface = false;
        vec3 n = vec3(0.0);
        vec4 spec = vec4(0.0);
        if (PHASE == PHASE_HYBRID) {
            vec3 g = medium_gradient(m);
            float gm = length(g);
            // Exposure Render: P_brdf grows with opacity and normalised gradient magnitude
            // (several channels' opacities sum, and may pass 1).
            float opacity = CHANNELS > 1 ? min(ao.a, 1.0) : ao.a;
            float p_brdf = opacity * (1.0 - exp(-gm * HYBRID_GRADIENT_SCALE));
            if (gm > HYBRID_GRADIENT_MIN && rng_next(rng) < p_brdf) {
                surface = true;
                n = -g / gm;
                if (dot(n, d) > 0.0) n = -n;
                spec = medium_specular(m);
            }
        }

        // Next-event estimation to one randomly chosen light.
        if (frame.counts.x > 0) {
            LightSample ls = sample_light(p, rng);
            vec3 f;
            if (surface) {
                f = surface_eval(n, d, ls.dir, albedo, spec.rgb, spec.a);
            } else if (PHASE != PHASE_ISOTROPIC) {
                f = albedo * hg_eval(dot(d, ls.dir), frame.params.y);
            } else {
                f = albedo * INV_4PI;
            }
            if (max(f.r, max(f.g, f.b)) > 0.0) {
                vec2 sspan = intersect_medium(p, ls.dir);
                float t_end = min(sspan.y, ls.dist);
                float tr = sspan.x < t_end ? transmittance(p, ls.dir, 0.0, t_end, rng) : 1.0;
                result += throughput * f * ls.radiance * tr;
            }
        }

        // Continue the walk: sample the phase function / BRDF.
        vec3 wo;
        if (surface) {
            // Cosine-weighted diffuse direction; the lobe mixture weight folds into albedo.
            float u1 = rng_next(rng), u2 = rng_next(rng);
            float r = sqrt(u1), phi = 2.0 * PI * u2;
            wo = orthonormal_dir(n, vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u1))));
            throughput *= albedo;
        } else {
            float g = PHASE == PHASE_ISOTROPIC ? 0.0 : frame.params.y;
            wo = hg_sample(d, g, rng_next(rng), rng_next(rng));
            throughput *= albedo;
        }
        if (bounce >= int(frame.seeds.z)) {
            float q = min(max(throughput.r, max(throughput.g, throughput.b)), RR_SURVIVAL_MAX);
            if (rng_next(rng) >= q) break;
            throughput /= q;
        }
        o = p;
        d = wo;
    }
    return result;
}

// Gaussian pixel filter by importance sampling: offsets drawn from N(0, sigma²).
vec2 gaussian_offset(inout Rng rng) {
    float u1 = max(rng_next(rng), FILTER_U_MIN);
    float u2 = rng_next(rng);
    float r = frame.params.w * sqrt(-2.0 * log(u1));
    return vec2(r * cos(2.0 * PI * u2), r * sin(2.0 * PI * u2));
}

struct PixelSample {
    vec3 radiance;  // finite (a non-finite path counts as 0)
    vec3 origin;
    vec3 dir;
    float first_t;  // first real collision distance, negative if none
};

// Sample `sample_index` of `pixel` in frame `frame_index`, seen by a camera at `origin`
// with inverse view-projection `inv_view_proj`.
PixelSample pixel_sample(uvec2 pixel, uint frame_index, uint sample_index, vec2 size,
                         mat4 inv_view_proj, vec3 origin) {
    Rng rng = rng_init(pixel, frame_index, sample_index, frame.seeds.x);
    vec2 pos = vec2(pixel) + 0.5 + gaussian_offset(rng);
    PixelSample s;
    s.origin = origin;
    s.dir = camera_ray_dir(pos, size, inv_view_proj);
    s.radiance = trace_path(s.origin, s.dir, rng, s.first_t);
    if (!all_finite(s.radiance)) s.radiance = vec3(0.0);
    return s;
}

#endif
