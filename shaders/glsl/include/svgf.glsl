// SVGF (Schied et al. 2017) maths shared by its passes: albedo demodulation, the packed
// edge-stopping features, the B3-spline à-trous kernel and the edge-stopping weights.
//
// MIRRORED: the functions marked [mirror] are reproduced line for line in Rust in
// engine/src/denoise/svgf.rs (`edge`), whose unit tests check them on step edges.
// Change both together.
#ifndef DVR_SVGF_GLSL
#define DVR_SVGF_GLSL

// The 1D B3-spline kernel [1/16, 1/4, 3/8, 1/4, 1/16], indexed by |offset|. [mirror]
const float SVGF_B3[3] = float[](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);

// What colour is divided by before filtering and multiplied by after, from the
// composited guide albedo (aux_features.comp: rgb the TF albedo weighted by where the
// ray's first scattering event falls, a the share of the ray the volume stops): the
// expected albedo of the first scattering vertex, plus 1 for the share that passes
// through to the background (nothing to demodulate by there), plus `eps` (a black albedo
// channel amplifies at most 1/eps). An opaque surface gives its albedo, as the paper's
// primary-hit albedo; a faint layer or a thin vessel before a brighter medium gives the
// mix its radiance comes from, so its pixel demodulates like its neighbours. The
// threshold features' albedo (rgb, w 1 where valid else 0) reads the same way.
vec3 svgf_demod_factor(vec4 albedo, float eps) {
    return albedo.rgb + (1.0 - albedo.a) + eps;
}

// Edge-stopping features of one pixel, packed by svgf_temporal into one rgba32f texel:
// octahedral normal (xy), linear depth along the ray (z), depth slope (w, see
// svgf_depth_slope) in depth units per pixel. A pixel without a threshold surface
// (features.albedo.w = 0) is stored as z = SVGF_MEDIUM where its ray still meets the
// medium (a semi-transparent layer: features.position.w = 1, its expected collision) and
// as z = SVGF_BACKGROUND where it meets nothing.
const float SVGF_BACKGROUND = -1.0;
const float SVGF_MEDIUM = -2.0;
struct SvgfGeometry {
    bool valid;
    vec3 n;
    float z;
    float dz;
};

vec2 svgf_sign_not_zero(vec2 v) {
    return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0);
}

vec4 svgf_pack_geometry(bool valid, bool medium, vec3 n, float z, float dz) {
    if (!valid) return vec4(0.0, 0.0, medium ? SVGF_MEDIUM : SVGF_BACKGROUND, 0.0);
    n /= max(abs(n.x) + abs(n.y) + abs(n.z), 1e-20);
    vec2 e = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * svgf_sign_not_zero(n.xy);
    return vec4(e, z, dz);
}

SvgfGeometry svgf_unpack_geometry(vec4 g) {
    SvgfGeometry s;
    s.valid = g.z >= 0.0;
    vec3 n = vec3(g.xy, 1.0 - abs(g.x) - abs(g.y));
    if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * svgf_sign_not_zero(n.xy);
    s.n = s.valid ? normalize(n) : vec3(0.0);
    s.z = g.z;
    s.dz = g.w;
    return s;
}

// The depth slope (depth change per pixel) the depth weight is scaled by: the measured
// gradient, floored at the depth quantum of the surface features. They are marched in
// fixed steps, so their depth is terraced: zero gradient inside a terrace, a jump of one
// step at its edge, which must not read as a discontinuity. [mirror]
float svgf_depth_slope(float gradient, float quantum) {
    return max(gradient, quantum);
}

// Depth scale for a tap `dist` pixels away (Schied et al.: σz times the depth gradient
// times the offset, in the length form of the authors' implementation). [mirror]
float svgf_phi_z(float sigma_z, float slope, float dist) {
    return sigma_z * slope * dist;
}

// Luminance scale: σl times the standard deviation of luminance, plus `eps` so a
// noise-free (zero-variance) neighbourhood does not divide by zero. [mirror]
float svgf_phi_l(float sigma_l, float variance, float eps) {
    return sigma_l * sqrt(max(variance, 0.0)) + eps;
}

// Depth and normal part of the weight between centre p and tap q, with the validity
// rule: the background (no medium: z = SVGF_BACKGROUND) mixes only with itself; a pixel
// in the semi-transparent medium (z = SVGF_MEDIUM) has no geometry to differ in and
// mixes with the medium and with surfaces (weight 1, the luminance decides), so a few
// pixels whose rays reach the opacity threshold at a vessel or along a rim are not left
// to filter among themselves. [mirror]
float svgf_geometry_weight(bool valid_p, bool valid_q, float z_p, float z_q, float phi_z,
                           vec3 n_p, vec3 n_q, float sigma_n) {
    if (!valid_p || !valid_q) return (z_p == SVGF_BACKGROUND) == (z_q == SVGF_BACKGROUND) ? 1.0 : 0.0;
    float w_n = pow(max(0.0, dot(n_p, n_q)), sigma_n);
    float e_z = abs(z_p - z_q) / max(phi_z, 1e-20);
    return exp(-e_z) * w_n;
}

// Luminance part of the weight. [mirror]
float svgf_luminance_weight(float l_p, float l_q, float phi_l) {
    return exp(-abs(l_p - l_q) / phi_l);
}

#endif
