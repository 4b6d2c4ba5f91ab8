// The project's one tone map, in GLSL: the same function as engine/src/metrics/tonemap.rs
// (Narkowicz's ACES fit, clamp to 1, sRGB OETF), which documents it. tests/present.rs
// checks that the two agree on a ramp of values.
#ifndef DVR_TONEMAP_GLSL
#define DVR_TONEMAP_GLSL

// x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14), NaN and negatives as 0, clamped to 1.
float aces_narkowicz(float x) {
    x = isnan(x) ? 0.0 : clamp(x, 0.0, 65504.0);  // +inf -> large -> 1 after the clamp
    return min((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 1.0);
}

// The sRGB OETF (IEC 61966-2-1) on [0, 1]; exactly 1 at 1.
float linear_to_srgb(float y) {
    y = clamp(y, 0.0, 1.0);
    if (y >= 1.0) return 1.0;
    if (y <= 0.0031308) return 12.92 * y;
    return 1.055 * pow(y, 1.0 / 2.4) - 0.055;
}

// Linear HDR radiance -> sRGB-encoded display value in [0, 1], per channel.
vec3 tonemap_srgb(vec3 c, float exposure) {
    return vec3(linear_to_srgb(aces_narkowicz(exposure * c.r)),
                linear_to_srgb(aces_narkowicz(exposure * c.g)),
                linear_to_srgb(aces_narkowicz(exposure * c.b)));
}

#endif
