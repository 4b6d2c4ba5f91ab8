#version 460
// SVGF variance estimate (Schied et al. 2017, §4.2): the temporal variance of luminance
// from the accumulated moments where the history is long enough; where it is shorter than
// `min_history` frames (disocclusions, the first frames) a spatial estimate instead, from
// the moments of a 7×7 neighbourhood weighted by depth and normal only. As in the
// authors' implementation the spatial estimate is scaled by min_history / n, so the first
// frames are filtered harder.
#include "common.glsl"
#include "svgf.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(binding = 0, rgba32f) uniform readonly image2D integrated;  // demodulated rgb, a variance
layout(binding = 1, rgba32f) uniform readonly image2D moments;     // m1, m2, history length
layout(binding = 2, rgba32f) uniform readonly image2D geometry;
layout(binding = 3, rgba32f) uniform writeonly image2D estimated;  // demodulated rgb, a variance

layout(push_constant) uniform SvgfVariancePush {
    uint width;
    uint height;
    float min_history;    // frames below which the spatial estimate is used (4)
    float sigma_z;
    float sigma_n;
    float pad0;
    float pad1;
    float pad2;
} pc;

const int RADIUS = 3;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    if (p.x >= size.x || p.y >= size.y) return;

    vec4 centre = imageLoad(integrated, p);
    vec4 mp = imageLoad(moments, p);
    float n = max(mp.z, 1.0);
    if (n >= pc.min_history) {
        imageStore(estimated, p, centre);
        return;
    }
    SvgfGeometry gp = svgf_unpack_geometry(imageLoad(geometry, p));
    vec2 sum = mp.xy;
    float wsum = 1.0;
    for (int dy = -RADIUS; dy <= RADIUS; ++dy) {
        for (int dx = -RADIUS; dx <= RADIUS; ++dx) {
            ivec2 q = p + ivec2(dx, dy);
            if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            SvgfGeometry gq = svgf_unpack_geometry(imageLoad(geometry, q));
            float phi_z = svgf_phi_z(pc.sigma_z, gp.dz, length(vec2(dx, dy)));
            float w = svgf_geometry_weight(gp.valid, gq.valid, gp.z, gq.z, phi_z, gp.n, gq.n, pc.sigma_n);
            sum += w * imageLoad(moments, q).xy;
            wsum += w;
        }
    }
    vec2 m = sum / wsum;
    float variance = max(m.y - m.x * m.x, 0.0) * (pc.min_history / n);
    imageStore(estimated, p, vec4(centre.rgb, variance));
}
