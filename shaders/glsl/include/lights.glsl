// Light sampling for next-event estimation: one light chosen uniformly per vertex.
#ifndef DVR_LIGHTS_GLSL
#define DVR_LIGHTS_GLSL

#include "common.glsl"
#include "frame.glsl"
#include "specialization.glsl"

// Squared distance to a light below which it is taken as this (no division by zero at a
// light's own position).
const float LIGHT_DIST2_MIN = 1e-8;
// The solid angle of the whole sphere (an environment light's directions).
const float SPHERE_SOLID_ANGLE = 4.0 * PI;
// An area light spans ±u and ±v about its centre: its area is four times |u × v|.
const float QUAD_AREA_PER_CROSS = 4.0;

layout(binding = 6) uniform sampler2D environment_map;  // equirectangular, rgb radiance

struct LightSample {
    vec3 dir;        // towards the light
    float dist;      // FLT_BIG for the environment
    vec3 radiance;   // incident radiance / pdf (already divided by the pdf)
};

vec3 uniform_sphere(float u1, float u2) {
    float z = 1.0 - 2.0 * u1;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u2;
    return vec3(r * cos(phi), r * sin(phi), z);
}

vec3 environment_radiance(Light l, vec3 dir) {
    int mode = int(l.radiance.w);
    if (mode == ENV_GRADIENT) {
        return mix(l.u_axis.rgb, l.radiance.rgb, 0.5 * (dir.z + 1.0));  // z up
    }
    if (HAS_ENV_MAP && mode == ENV_MAP) {
        vec2 uv = vec2(atan(dir.y, dir.x) / (2.0 * PI) + 0.5, acos(clamp(dir.z, -1.0, 1.0)) / PI);
        return texture(environment_map, uv).rgb * l.u_axis.w;
    }
    return l.radiance.rgb;
}

// Radiance seen along an escaping ray (camera rays that miss everything).
vec3 escaped_radiance(vec3 dir) {
    vec3 sum = vec3(0.0);
    for (int i = 0; i < frame.counts.x; ++i) {
        if (int(frame.lights[i].position_kind.w) == LIGHT_ENV) {
            sum += environment_radiance(frame.lights[i], dir);
        }
    }
    return sum;
}

LightSample sample_light(vec3 p, inout Rng rng) {
    int count = frame.counts.x;
    int index = min(int(rng_next(rng) * float(count)), count - 1);
    Light l = frame.lights[index];
    int kind = int(l.position_kind.w);
    LightSample s;
    float choice = float(count);
    if (kind == LIGHT_ENV) {
        s.dir = uniform_sphere(rng_next(rng), rng_next(rng));
        s.dist = FLT_BIG;
        s.radiance = environment_radiance(l, s.dir) * SPHERE_SOLID_ANGLE * choice;
    } else if (kind == LIGHT_AREA) {
        vec3 q = l.position_kind.xyz + (2.0 * rng_next(rng) - 1.0) * l.u_axis.xyz
                 + (2.0 * rng_next(rng) - 1.0) * l.v_axis.xyz;
        vec3 to = q - p;
        float d2 = max(dot(to, to), LIGHT_DIST2_MIN);
        s.dist = sqrt(d2);
        s.dir = to / s.dist;
        vec3 n = cross(l.u_axis.xyz, l.v_axis.xyz);
        float area = QUAD_AREA_PER_CROSS * length(n);
        // One-sided: emits from the side its normal (u × v) faces.
        float cos_l = max(dot(normalize(n), -s.dir), 0.0);
        s.radiance = l.radiance.rgb * cos_l * area / d2 * choice;
    } else {
        vec3 to = l.position_kind.xyz - p;
        float d2 = max(dot(to, to), LIGHT_DIST2_MIN);
        s.dist = sqrt(d2);
        s.dir = to / s.dist;
        s.radiance = l.radiance.rgb / d2 * choice;
    }
    return s;
}

#endif
