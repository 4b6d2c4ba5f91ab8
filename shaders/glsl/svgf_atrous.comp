#version 460
// One SVGF à-trous iteration (Schied et al. 2017, §4.3): a 5×5 B3-spline kernel with taps
// `step` pixels apart, weighted by depth, normal and luminance edge-stopping functions;
// the luminance scale follows the 3×3 Gaussian-prefiltered variance, and the variance is
// filtered with the squared weights for the next iteration. Dispatched five times with
// step 1, 2, 4, 8, 16; the last iteration multiplies the albedo back in (`modulate`).
#include "common.glsl"
#include "svgf.glsl"
#include "atrous_tile.glsl"

layout(local_size_x = TILE, local_size_y = TILE) in;

layout(binding = 0, rgba32f) uniform readonly image2D color_in;    // demodulated rgb, a variance
layout(binding = 1, rgba32f) uniform readonly image2D geometry;
layout(binding = 2, rgba32f) uniform readonly image2D demod_albedo;  // see svgf_demod_factor
layout(binding = 3, rgba32f) uniform writeonly image2D color_out;

layout(push_constant) uniform SvgfAtrousPush {
    uint width;
    uint height;
    int step;             // tap spacing in pixels: 2^iteration
    uint modulate;        // 1 on the last iteration: multiply the albedo back in
    float sigma_z;
    float sigma_n;
    float sigma_l;
    float luminance_eps;  // added to the luminance scale
    float demod_eps;      // as in svgf_temporal
    float pad0;
    float pad1;
    float pad2;
} pc;

shared vec4 color_tile[TILE_TEXELS];
shared vec4 geometry_tile[TILE_TEXELS];

vec4 color_tap(TileWindow w, ivec2 q) {
    return w.on ? color_tile[tile_index(w, q)] : imageLoad(color_in, q);
}

vec4 geometry_tap(TileWindow w, ivec2 q) {
    return w.on ? geometry_tile[tile_index(w, q)] : imageLoad(geometry, q);
}

// The variance at p blurred by a 3×3 Gaussian ([1 2 1]/4 in each direction), which
// steadies the luminance scale against the noise of the variance estimate itself. (Its
// taps, clamped to the image, lie within the window's margin of 2·step ≥ 2.)
float prefiltered_variance(TileWindow win, ivec2 p, ivec2 size) {
    const float k[2] = float[](0.5, 0.25);
    float v = 0.0;
    for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), size - 1);
            v += k[abs(dx)] * k[abs(dy)] * color_tap(win, q).a;
        }
    }
    return v;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    TileWindow win = tile_window(pc.step);
    if (win.on) {
        TILE_LOAD(win, color_tile, color_in, size);
        TILE_LOAD(win, geometry_tile, geometry, size);
        barrier();
    }
    if (p.x >= size.x || p.y >= size.y) return;

    vec4 centre = color_tap(win, p);
    float lp = luminance(centre.rgb);
    SvgfGeometry gp = svgf_unpack_geometry(geometry_tap(win, p));
    float phi_l = svgf_phi_l(pc.sigma_l, prefiltered_variance(win, p, size), pc.luminance_eps);

    // The centre's edge-stopping weight is 1 by definition; only its kernel weight counts.
    float k0 = SVGF_B3[0] * SVGF_B3[0];
    vec3 sum = k0 * centre.rgb;
    float var_sum = k0 * k0 * centre.a;
    float wsum = k0;
    for (int dy = -2; dy <= 2; ++dy) {
        for (int dx = -2; dx <= 2; ++dx) {
            ivec2 q = p + ivec2(dx, dy) * pc.step;
            if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 cq = color_tap(win, q);
            SvgfGeometry gq = svgf_unpack_geometry(geometry_tap(win, q));
            float phi_z = svgf_phi_z(pc.sigma_z, gp.dz, float(pc.step) * length(vec2(dx, dy)));
            float w = SVGF_B3[abs(dx)] * SVGF_B3[abs(dy)]
                * svgf_geometry_weight(gp.valid, gq.valid, gp.z, gq.z, phi_z, gp.n, gq.n, pc.sigma_n)
                * svgf_luminance_weight(lp, luminance(cq.rgb), phi_l);
            sum += w * cq.rgb;
            var_sum += w * w * cq.a;
            wsum += w;
        }
    }
    vec3 color = sum / wsum;
    float variance = var_sum / (wsum * wsum);
    if (!all_finite(color) || isnan(variance) || isinf(variance)) {
        color = centre.rgb;
        variance = centre.a;
    }
    if (pc.modulate != 0u) {
        color *= svgf_demod_factor(imageLoad(demod_albedo, p), pc.demod_eps);
        imageStore(color_out, p, vec4(color, 1.0));
    } else {
        imageStore(color_out, p, vec4(color, variance));
    }
}
