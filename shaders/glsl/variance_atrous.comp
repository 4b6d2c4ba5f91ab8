#version 460
// One à-trous iteration (a 5×5 B3-spline kernel with taps `step` pixels apart) over
// per-pixel estimates that carry their own variance, dispatched with step 1, 2, 4, …: ours'
// spatial filter over its Kalman estimates (ATROUS_LEVELS) and the one 5×5 level of the
// paper's p = [1] models (`wrls-nf`, `rls-nf`, keep 0). A neighbour is weighted by how far
// its estimate lies from this pixel's in units of their standard errors, so converged
// estimates keep the detail they resolved while young ones (after a change or a
// disocclusion) are averaged over an ever wider footprint; each iteration passes on the
// variance of its output.
// With CARRY (ours), each neighbour's estimate is first carried to this pixel by ours'
// spatial prior (ours_prior.comp): x_q + x̂_p − x̂_q, the difference the local linear model
// on the guide albedo and the position predicts between the two pixels (a vessel's colour
// against the shell, a silhouette's edge, a lit side), clamped between x_q and x_p so a
// model that overstates a difference cannot overshoot. The range term still compares
// the estimates as they are, so the carry changes what a blended neighbour contributes,
// not which neighbours are blended: the kernel averages noise while the model keeps the
// structure it explains.
#include "common.glsl"
#include "atrous_tile.glsl"

layout(local_size_x = TILE, local_size_y = TILE) in;

layout(binding = 0, rgba32f) uniform readonly image2D color_in;   // rgb prediction, a variance
layout(binding = 1, rgba32f) uniform writeonly image2D color_out; // the same, filtered
layout(binding = 2, rgba32f) uniform readonly image2D prediction;  // rgb x̂ (CARRY), a 0 where none

layout(constant_id = 16) const bool CARRY = false;
// The input is a filter's state, radiance clamped at zero as it is read (ours: the update
// writes no clamped copy).
layout(constant_id = 17) const bool NONNEGATIVE = false;

layout(push_constant) uniform VarianceAtrousPush {
    uint width;
    uint height;
    int step;     // tap spacing in pixels
    float kappa;  // standard errors two predictions may differ by and still be blended
    uint last;    // the last iteration writes the denoiser's output (alpha 1)
    float keep;   // relative standard error below which a pixel is kept as it is
    uint pad1;
    uint pad2;
} pc;

const float B3[3] = float[](3.0 / 8.0, 1.0 / 4.0, 1.0 / 16.0);
// The kernel's radius in taps: B3 spans 5.
const int KERNEL_RADIUS = 2;
// A floor under the range term's variance, in radiance² (a guard against dividing by
// zero where two estimates are exact).
const float RANGE_FLOOR = 1e-10;

shared vec4 tile[TILE_TEXELS];
// The prediction's window, read by every tap of a carrying level as the estimates' is;
// one texel where nothing is carried (the paper's models), so that use keeps its shared
// memory.
const int PREDICTION_TEXELS = CARRY ? TILE_TEXELS : 1;
shared vec4 prediction_tile[PREDICTION_TEXELS];

vec4 tap(TileWindow w, ivec2 q) {
    vec4 v = w.on ? tile[tile_index(w, q)] : imageLoad(color_in, q);
    if (NONNEGATIVE) v.rgb = max(v.rgb, vec3(0.0));
    return v;
}

vec4 prediction_tap(TileWindow w, ivec2 q) {
    return w.on ? prediction_tile[tile_index(w, q)] : imageLoad(prediction, q);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = ivec2(pc.width, pc.height);
    TileWindow win = tile_window(pc.step);
    if (win.on) {
        TILE_LOAD(win, tile, color_in, size);
        if (CARRY) TILE_LOAD(win, prediction_tile, prediction, size);
        barrier();
    }
    if (p.x >= size.x || p.y >= size.y) return;
    vec4 centre = tap(win, p);
    // A pixel whose prediction is already precise (standard error below `keep` of its
    // value: a converged model) is kept as it is. Blending could only pull it towards
    // neighbours whose larger variances let their values in (the range term sums both),
    // which softened the MRI's folds (FLIP) for no gain in PSNR; and it costs a load and
    // a store instead of 25 taps.
    if (centre.a < pc.keep * pc.keep * dot(centre.rgb, centre.rgb) / 3.0) {
        imageStore(color_out, p, vec4(max(centre.rgb, vec3(0.0)), pc.last != 0u ? 1.0 : centre.a));
        return;
    }
    vec4 model = CARRY ? prediction_tap(win, p) : vec4(0.0);
    float k0 = B3[0] * B3[0];
    vec3 sum = k0 * centre.rgb;
    float var_sum = k0 * k0 * centre.a;
    float wsum = k0;
    for (int dy = -KERNEL_RADIUS; dy <= KERNEL_RADIUS; ++dy) {
        for (int dx = -KERNEL_RADIUS; dx <= KERNEL_RADIUS; ++dx) {
            ivec2 q = p + ivec2(dx, dy) * pc.step;
            if ((dx == 0 && dy == 0) || any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec4 cq = tap(win, q);
            vec3 d = cq.rgb - centre.rgb;
            if (CARRY) {
                vec4 mq = prediction_tap(win, q);
                if (model.a > 0.0 && mq.a > 0.0) {
                    cq.rgb = clamp(cq.rgb + model.rgb - mq.rgb, min(cq.rgb, centre.rgb),
                                   max(cq.rgb, centre.rgb));
                }
            }
            float range = dot(d, d) / 3.0 / (pc.kappa * pc.kappa * (centre.a + cq.a) + RANGE_FLOOR);
            float w = B3[abs(dx)] * B3[abs(dy)] * exp(-range);
            sum += w * cq.rgb;
            var_sum += w * w * cq.a;
            wsum += w;
        }
    }
    vec3 colour = sum / wsum;
    float variance = var_sum / (wsum * wsum);
    if (!all_finite(colour) || isnan(variance) || isinf(variance)) {
        colour = centre.rgb;
        variance = centre.a;
    }
    imageStore(color_out, p, vec4(max(colour, vec3(0.0)), pc.last != 0u ? 1.0 : variance));
}
