// Phase functions: isotropic (the paper's), Henyey–Greenstein, and Exposure Render's
// gradient-based hybrid, which scatters from a surface BRDF (Lambert + a Blinn-Phong lobe)
// with probability growing with opacity and normalised gradient magnitude.
#ifndef DVR_PHASE_GLSL
#define DVR_PHASE_GLSL

#include "common.glsl"
#include "specialization.glsl"

// Henyey–Greenstein: the denominator's floor (g → ±1 at cos θ = ±1), and |g| below which
// it samples as isotropic (its closed form divides by g).
const float HG_DENOM_MIN = 1e-12;
const float HG_ISOTROPIC_G = 1e-3;
// |n.x| above which the frame around n is built from the y axis, not the x axis.
const float FRAME_AXIS_SWITCH = 0.9;
// Roughness below this is taken as this (the Blinn-Phong exponent grows as 1 / r⁴).
const float ROUGHNESS_MIN = 0.02;

float hg_eval(float cos_theta, float g) {
    float denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return INV_4PI * (1.0 - g * g) / (denom * sqrt(max(denom, HG_DENOM_MIN)));
}

vec3 orthonormal_dir(vec3 n, vec3 local) {
    vec3 t = abs(n.x) > FRAME_AXIS_SWITCH ? vec3(0, 1, 0) : vec3(1, 0, 0);
    vec3 b = normalize(cross(n, t));
    t = cross(b, n);
    return local.x * t + local.y * b + local.z * n;
}

// Samples a new direction given the incoming travel direction wi (pointing along the
// ray); HG's g > 0 scatters forward. The phase/pdf ratio is 1 for these samplers.
vec3 hg_sample(vec3 wi, float g, float u1, float u2) {
    float cos_theta;
    if (abs(g) < HG_ISOTROPIC_G) {
        cos_theta = 1.0 - 2.0 * u1;
    } else {
        float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u1);
        cos_theta = (1.0 + g * g - s * s) / (2.0 * g);
    }
    float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
    float phi = 2.0 * PI * u2;
    return orthonormal_dir(wi, vec3(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta));
}

// Blinn-Phong exponent from roughness (0 = mirror-like, 1 = very rough).
float phong_exponent(float roughness) {
    float r = clamp(roughness, ROUGHNESS_MIN, 1.0);
    return 2.0 / (r * r * r * r) - 2.0;
}

// Surface BRDF × cosine for the hybrid model; n faces the viewer (against wi).
vec3 surface_eval(vec3 n, vec3 wi, vec3 wo, vec3 diffuse, vec3 specular, float roughness) {
    float cos_o = dot(n, wo);
    if (cos_o <= 0.0) return vec3(0.0);
    vec3 h = normalize(wo - wi);
    float e = phong_exponent(roughness);
    float spec = (e + 2.0) / (2.0 * PI) * pow(max(dot(n, h), 0.0), e);
    return (diffuse / PI + specular * spec) * cos_o;
}

#endif
