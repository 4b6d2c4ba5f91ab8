#version 460
// The volumetric path tracer (TVCG §3/§6, Exposure Render extended): camera rays through
// a Gaussian pixel filter, free flights by delta tracking (or ray marching), a random walk
// with next-event estimation to one light per vertex, Russian roulette, emission from the
// emissive TF. Writes this frame's mean radiance, the luminance moments, and the world
// position of the closest first real collision among the pixel's samples.
#include "common.glsl"
#include "frame.glsl"
#include "specialization.glsl"
#include "volume.glsl"
#include "lights.glsl"
#include "transport.glsl"
#include "phase.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 7, rgba32f) uniform writeonly image2D radiance;
layout(binding = 8, rgba32f) uniform writeonly image2D moments;
layout(binding = 9, rgba32f) uniform writeonly image2D first_hit;

layout(push_constant) uniform PathTracePush {
    uint sample_offset;  // index of the first sample (progressive references)
    uint spp;            // samples this dispatch
    uint width;
    uint height;
} pc;

vec3 camera_ray_dir(vec2 pixel, out vec3 origin) {
    vec2 ndc = pixel / vec2(pc.width, pc.height) * 2.0 - 1.0;
    vec4 near_h = frame.inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec4 far_h = frame.inv_view_proj * vec4(ndc, 1.0, 1.0);
    origin = frame.camera_pos.xyz;
    return normalize(far_h.xyz / far_h.w - near_h.xyz / near_h.w);
}

// One path; returns radiance and the first real collision distance (negative if none).
vec3 trace_path(vec3 o, vec3 d, inout Rng rng, out float first_t) {
    first_t = -1.0;
    vec3 throughput = vec3(1.0);
    vec3 result = vec3(0.0);
    int max_bounces = frame.counts.w;
    for (int bounce = 0; bounce <= max_bounces; ++bounce) {
        vec2 span = intersect_box(o, d);
        float t = span.x < span.y ? sample_free_flight(o, d, span.x, span.y, rng) : -1.0;
        if (t < 0.0) {
            if (bounce == 0) result += throughput * escaped_radiance(d);
            break;
        }
        vec3 p = o + d * t;
        if (bounce == 0) first_t = t;
        float density = density_at(p);
        vec4 ao = tf_albedo_opacity(density);
        vec3 albedo = ao.rgb;
        if (USE_EMISSION) result += throughput * tf_emission(density);

        // Scattering model at this vertex.
        bool surface = false;
        vec3 n = vec3(0.0);
        vec4 spec = vec4(0.0);
        if (PHASE == PHASE_HYBRID) {
            vec3 g = density_gradient(p);
            float gm = length(g);
            // Exposure Render: P_brdf grows with opacity and normalised gradient magnitude.
            float p_brdf = ao.a * (1.0 - exp(-gm * 25.0));
            if (gm > 1e-5 && rng_next(rng) < p_brdf) {
                surface = true;
                n = -g / gm;
                if (dot(n, d) > 0.0) n = -n;
                spec = tf_specular(density);
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
                vec2 sspan = intersect_box(p, ls.dir);
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
            float q = min(max(throughput.r, max(throughput.g, throughput.b)), 0.95);
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
    float u1 = max(rng_next(rng), 1e-7);
    float u2 = rng_next(rng);
    float r = frame.params.w * sqrt(-2.0 * log(u1));
    return vec2(r * cos(2.0 * PI * u2), r * sin(2.0 * PI * u2));
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
    vec3 sum = vec3(0.0);
    float lum_sum = 0.0, lum2_sum = 0.0;
    float closest = FLT_BIG;
    vec3 closest_p = vec3(0.0);
    for (uint s = 0u; s < pc.spp; ++s) {
        Rng rng = rng_init(pixel, uint(frame.counts.y), pc.sample_offset + s, frame.seeds.x);
        vec2 pos = vec2(pixel) + 0.5 + gaussian_offset(rng);
        vec3 o;
        vec3 d = camera_ray_dir(pos, o);
        float first_t;
        vec3 l = trace_path(o, d, rng, first_t);
        if (!all_finite(l)) l = vec3(0.0);
        sum += l;
        float y = luminance(l);
        lum_sum += y;
        lum2_sum += y * y;
        if (first_t >= 0.0 && first_t < closest) {
            closest = first_t;
            closest_p = o + d * first_t;
        }
    }
    float inv = 1.0 / float(max(pc.spp, 1u));
    imageStore(radiance, ivec2(pixel), vec4(sum * inv, 1.0));
    imageStore(moments, ivec2(pixel), vec4(lum_sum * inv, lum2_sum * inv, 0.0, 0.0));
    imageStore(first_hit, ivec2(pixel), vec4(closest_p, closest < FLT_BIG ? 1.0 : 0.0));
}
