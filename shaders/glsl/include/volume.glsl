// The density volume, its transfer-function LUTs and the majorant grid: bindings shared by
// every pass that looks into the volume, and the functions that sample them.
#ifndef DVR_VOLUME_GLSL
#define DVR_VOLUME_GLSL

#include "frame.glsl"
#include "specialization.glsl"

layout(binding = 1) uniform sampler3D volume_density;      // normalised density [0,1]
layout(binding = 2) uniform sampler1D tf_diffuse_opacity;  // rgb albedo, a opacity
layout(binding = 3) uniform sampler1D tf_specular_roughness;
layout(binding = 4) uniform sampler1D tf_emissive;
layout(binding = 5) uniform sampler3D majorant_grid;       // max μt per brick (texelFetch)
// The brick pool (engine/src/renderer/brick_pool.rs), read when the pipeline is
// specialised for it (POOLED_VOLUME); volume_density is then the coarse copy beneath it.
layout(binding = 30) uniform sampler3D brick_pool;         // resident bricks with aprons
layout(binding = 31) uniform sampler3D brick_table;        // per brick: slot, stand-in (texelFetch)
// A label map's look on the volume's grid (engine/volume/src/labels/look.rs), read when
// LABELS is not LABELS_NONE: per voxel its label's tint (rgb) and mask (a: the label's
// opacity where shown, 0 where hidden), and the shape: the shown labels' indicator,
// filtered, whose gradient is a label surface's smooth normal.
layout(binding = 32) uniform sampler3D label_look;
layout(binding = 33) uniform sampler3D label_shape;

#define POOL_BRICK 32
#define POOL_APRON 2
#define POOL_STORED (POOL_BRICK + 2 * POOL_APRON)

vec3 box_size() { return frame.box_max.xyz - frame.box_min.xyz; }

vec3 to_uvw(vec3 p) { return (p - frame.box_min.xyz) / box_size(); }

// Brick of `voxel` (voxel units, centres at i + 0.5).
ivec3 pool_brick(vec3 voxel) {
    return clamp(ivec3(floor(voxel / float(POOL_BRICK))), ivec3(0), textureSize(brick_table, 0) - 1);
}

// Density at `voxel` through brick `b` (its table entry: x the slot or −1, y the stand-in
// density or −1 for the coarse copy): the slot's texels (the apron reaches 2 voxels past
// the brick), the stand-in, or the coarse copy.
float pool_density(vec3 voxel, ivec3 b, vec2 entry) {
    if (entry.x < 0.0) {
        return entry.y >= 0.0 ? entry.y : texture(volume_density, voxel / vec3(frame.dims.xyz)).r;
    }
    ivec3 pool = textureSize(brick_pool, 0);
    int sx = pool.x / POOL_STORED;
    int sy = pool.y / POOL_STORED;
    int s = int(entry.x);
    int z = s / (sx * sy);
    int rest = s - z * sx * sy;
    int y = rest / sx;
    ivec3 origin = ivec3(rest - y * sx, y, z) * POOL_STORED;
    vec3 t = vec3(origin) + (voxel - vec3(b * POOL_BRICK)) + float(POOL_APRON);
    return texture(brick_pool, t / vec3(pool)).r;
}

bool pooled() { return POOLED_VOLUME; }

float density_at(vec3 p) {
    if (pooled()) {
        vec3 voxel = to_uvw(p) * vec3(frame.dims.xyz);
        ivec3 b = pool_brick(voxel);
        return pool_density(voxel, b, texelFetch(brick_table, b, 0).xy);
    }
    return texture(volume_density, to_uvw(p)).r;
}

// LUT coordinate hitting texel centres: entry i is density i/(N-1).
float lut_coord(float d) {
    float n = float(textureSize(tf_diffuse_opacity, 0));
    return (clamp(d, 0.0, 1.0) * (n - 1.0) + 0.5) / n;
}

vec4 tf_albedo_opacity(float d) { return texture(tf_diffuse_opacity, lut_coord(d)); }
vec4 tf_specular(float d) { return texture(tf_specular_roughness, lut_coord(d)); }
vec3 tf_emission(float d) { return texture(tf_emissive, lut_coord(d)).rgb; }

// Every channel's density at p (the volume's components; dense volumes only: a
// multi-channel medium is never paged).
vec4 densities_at(vec3 p) { return texture(volume_density, to_uvw(p)); }

// Channel c's LUTs: the c-th of CHANNELS equal segments, texel centres as lut_coord.
float channel_lut_coord(float d, int c) {
    float n = float(textureSize(tf_diffuse_opacity, 0) / CHANNELS);
    return (float(c) * n + clamp(d, 0.0, 1.0) * (n - 1.0) + 0.5) / (n * float(CHANNELS));
}

// Channel c's opacity at density d, linear between the frame block's entries (what its
// LUT texture gives, read without a sampler).
float channel_opacity(float d, int c) {
    float x = clamp(d, 0.0, 1.0) * float(LUT_SIZE - 1);
    int i = min(int(x), LUT_SIZE - 2);
    return mix(frame.channel_opacity[i][c], frame.channel_opacity[i + 1][c], x - float(i));
}

// The medium's albedo (the channels' albedos weighted by their shares of the extinction)
// and opacity (their sum), with each channel's share.
vec4 medium_albedo_opacity(vec4 dens, out vec4 share) {
    vec3 albedo = vec3(0.0);
    float opacity = 0.0;
    share = vec4(0.0);
    for (int c = 0; c < CHANNELS; ++c) {
        vec4 t = texture(tf_diffuse_opacity, channel_lut_coord(dens[c], c));
        share[c] = t.a;
        albedo += t.a * t.rgb;
        opacity += t.a;
    }
    float inv = opacity > 0.0 ? 1.0 / opacity : 0.0;
    share *= inv;
    return vec4(albedo * inv, opacity);
}

float label_shape_at(vec3 p) { return texture(label_shape, to_uvw(p)).r; }

// The labels' tint and mask at p.
vec4 label_look_at(vec3 p) { return texture(label_look, to_uvw(p)); }

// The gradient of the filtered shape (per voxel; grows into what is shown): the normal
// of a label's surface, smooth because the shape is filtered.
vec3 label_gradient(vec3 p) {
    vec3 h = box_size() / vec3(frame.dims.xyz);
    return 0.5 * vec3(
        label_shape_at(p + vec3(h.x, 0, 0)) - label_shape_at(p - vec3(h.x, 0, 0)),
        label_shape_at(p + vec3(0, h.y, 0)) - label_shape_at(p - vec3(0, h.y, 0)),
        label_shape_at(p + vec3(0, 0, h.z)) - label_shape_at(p - vec3(0, 0, h.z)));
}

// Where the mask changes faster than this per voxel, the medium's surface is a label's
// boundary (a hidden label's face), and its normal is the mask's, as a cut face takes
// the cut's.
const float LABEL_EDGE = 0.05;

// A trilinear read of the mask ramps across a hidden label's face over a whole voxel: a
// soft layer at a fraction of the tissue's extinction, which rays cross in many null
// collisions and into which they scatter. When every shown label has the same opacity a
// (frame.labels.x; 0 when they differ), the read is a times the share of shown voxels
// around p, and that share is sharpened to this window about its half. The window is
// symmetric about 1/2, so across a flat face it moves no medium, and a face still lies
// on the trilinear surface rather than a voxel's facet; the normals come from the
// filtered shape either way.
const float LABEL_FACE_LOW = 0.4;
const float LABEL_FACE_HIGH = 0.6;

// The mask at p from its trilinear read m (tint: the extinction's factor).
float label_mask(float m) {
    float a = frame.labels.x;
    return a > 0.0 ? a * smoothstep(LABEL_FACE_LOW, LABEL_FACE_HIGH, m / a) : m;
}

// With a label map and one channel, the mask rides in the volume texture's second
// component (engine/src/renderer/packing.rs, with_mask): the extinction, evaluated at
// every step of delta tracking, takes one fetch for density and mask.
bool mask_in_volume() { return LABELS != LABELS_NONE && CHANNELS == 1; }

// Extinction coefficient at p (per world unit): with several channels, the sum of theirs;
// with a label map, times its mask (solid: the mask alone).
float extinction_at(vec3 p) {
    if (mask_in_volume()) {
        vec2 dm = texture(volume_density, to_uvw(p)).rg;
        float o = LABELS == LABELS_SOLID ? 1.0 : tf_albedo_opacity(dm.r).a;
        return o * (LABELS == LABELS_SOLID ? dm.g : label_mask(dm.g)) * frame.box_min.w;
    }
    if (LABELS == LABELS_SOLID) return label_look_at(p).a * frame.box_min.w;
    float opacity;
    if (CHANNELS > 1) {
        vec4 dens = densities_at(p);
        opacity = 0.0;
        for (int c = 0; c < CHANNELS; ++c) {
            opacity += channel_opacity(dens[c], c);
        }
    } else {
        opacity = tf_albedo_opacity(density_at(p)).a;
    }
    if (LABELS == LABELS_TINT) opacity *= label_mask(label_look_at(p).a);
    return opacity * frame.box_min.w;
}

// Central-difference gradient of density, in density per voxel.
// Pooled, all six samples read the centre's brick, whose apron holds them.
vec3 density_gradient(vec3 p) {
    vec3 h = box_size() / vec3(frame.dims.xyz);
    if (pooled()) {
        vec3 v = to_uvw(p) * vec3(frame.dims.xyz);
        ivec3 b = pool_brick(v);
        vec2 e = texelFetch(brick_table, b, 0).xy;
        return 0.5 * vec3(
            pool_density(v + vec3(1, 0, 0), b, e) - pool_density(v - vec3(1, 0, 0), b, e),
            pool_density(v + vec3(0, 1, 0), b, e) - pool_density(v - vec3(0, 1, 0), b, e),
            pool_density(v + vec3(0, 0, 1), b, e) - pool_density(v - vec3(0, 0, 1), b, e));
    }
    return 0.5 * vec3(
        density_at(p + vec3(h.x, 0, 0)) - density_at(p - vec3(h.x, 0, 0)),
        density_at(p + vec3(0, h.y, 0)) - density_at(p - vec3(0, h.y, 0)),
        density_at(p + vec3(0, 0, h.z)) - density_at(p - vec3(0, 0, h.z)));
}

// A point of the medium where something happens (a collision, a features crossing): its
// density and TF values, one channel's or the channels' mix (see medium_albedo_opacity).
struct MediumPoint {
    vec3 p;
    float density;        // one channel
    vec4 dens;            // several: each channel's density
    vec4 share;           // several: each channel's share of the extinction
    vec4 albedo_opacity;  // albedo, opacity (several: the sum, which may pass 1)
    vec4 look;            // with a label map: its tint and mask here
};

MediumPoint medium_point(vec3 p) {
    MediumPoint m;
    m.p = p;
    m.density = 0.0;
    m.dens = vec4(0.0);
    m.share = vec4(0.0);
    m.look = vec4(1.0);
    if (CHANNELS > 1) {
        m.dens = densities_at(p);
        m.albedo_opacity = medium_albedo_opacity(m.dens, m.share);
    } else {
        m.density = density_at(p);
        m.albedo_opacity = tf_albedo_opacity(m.density);
    }
    if (LABELS != LABELS_NONE) {
        m.look = label_look_at(p);
        m.albedo_opacity = LABELS == LABELS_SOLID
            ? m.look
            : vec4(m.albedo_opacity.rgb * m.look.rgb, m.albedo_opacity.a * label_mask(m.look.a));
    }
    return m;
}

vec3 medium_emission(MediumPoint m) {
    if (LABELS == LABELS_SOLID) return vec3(0.0);
    if (LABELS == LABELS_TINT) {
        vec3 e = vec3(0.0);
        if (CHANNELS > 1) {
            for (int c = 0; c < CHANNELS; ++c) {
                e += m.share[c] * texture(tf_emissive, channel_lut_coord(m.dens[c], c)).rgb;
            }
        } else {
            e = tf_emission(m.density);
        }
        return e * m.look.rgb;
    }
    if (CHANNELS > 1) {
        vec3 e = vec3(0.0);
        for (int c = 0; c < CHANNELS; ++c) {
            e += m.share[c] * texture(tf_emissive, channel_lut_coord(m.dens[c], c)).rgb;
        }
        return e;
    }
    return tf_emission(m.density);
}

vec4 medium_specular(MediumPoint m) {
    if (LABELS == LABELS_SOLID) return vec4(0.0, 0.0, 0.0, 1.0);  // diffuse tissue
    if (CHANNELS > 1) {
        vec4 s = vec4(0.0);
        for (int c = 0; c < CHANNELS; ++c) {
            s += m.share[c] * texture(tf_specular_roughness, channel_lut_coord(m.dens[c], c));
        }
        return s;
    }
    return tf_specular(m.density);
}

// The density gradient (density per voxel); with several channels, the channels'
// gradients weighted by their shares of the extinction at the point; with a label map,
// the mask's where the point is on a label's boundary (solid: always).
vec3 medium_gradient(MediumPoint m) {
    if (LABELS == LABELS_SOLID) return label_gradient(m.p);
    if (LABELS == LABELS_TINT) {
        vec3 g = label_gradient(m.p);
        if (dot(g, g) > LABEL_EDGE * LABEL_EDGE) return g;
    }
    if (CHANNELS > 1) {
        vec3 h = box_size() / vec3(frame.dims.xyz);
        vec4 gx = densities_at(m.p + vec3(h.x, 0, 0)) - densities_at(m.p - vec3(h.x, 0, 0));
        vec4 gy = densities_at(m.p + vec3(0, h.y, 0)) - densities_at(m.p - vec3(0, h.y, 0));
        vec4 gz = densities_at(m.p + vec3(0, 0, h.z)) - densities_at(m.p - vec3(0, 0, h.z));
        return 0.5 * vec3(dot(m.share, gx), dot(m.share, gy), dot(m.share, gz));
    }
    return density_gradient(m.p);
}

// The interval of the ray o + t d (t >= 0) inside what the cut keeps: the crop box (the
// volume's box without a crop) and the half-space in front of every clip plane. That
// region is convex, so one interval; empty when x >= y. `cut_normal` is the outward
// normal of the cut face where the ray enters, or zero where it enters through the
// volume's own box (so the features passes can give a cut face the cut's normal).
vec2 intersect_medium(vec3 o, vec3 d, out vec3 cut_normal) {
    vec3 inv = 1.0 / d;
    vec3 t0 = (frame.crop_min.xyz - o) * inv;
    vec3 t1 = (frame.crop_max.xyz - o) * inv;
    vec3 tmin = min(t0, t1);
    vec3 tmax = max(t0, t1);
    float enter = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
    float exit = min(min(tmax.x, tmax.y), tmax.z);
    cut_normal = vec3(0.0);
    // A crop face that is not the volume's own face.
    for (int a = 0; a < 3; ++a) {
        if (tmin[a] == enter && enter > 0.0) {
            bool low = d[a] > 0.0;
            float face = low ? frame.crop_min[a] : frame.crop_max[a];
            float box_face = low ? frame.box_min[a] : frame.box_max[a];
            if (face != box_face) {
                cut_normal = vec3(0.0);
                cut_normal[a] = low ? -1.0 : 1.0;
            }
        }
    }
    for (int i = 0; i < frame.counts.z; ++i) {
        vec4 p = frame.clip[i];
        float s = dot(p.xyz, o) + p.w;
        float dn = dot(p.xyz, d);
        if (dn > 0.0) {
            float t = -s / dn;
            if (t > enter) {
                enter = t;
                cut_normal = -p.xyz;
            }
        } else if (dn < 0.0) {
            exit = min(exit, -s / dn);
        } else if (s < 0.0) {
            exit = -1.0;  // parallel and behind the plane: nothing is kept
        }
    }
    return vec2(enter, exit);
}

vec2 intersect_medium(vec3 o, vec3 d) {
    vec3 unused;
    return intersect_medium(o, d, unused);
}

// Where a features pass met the medium within this many march steps of the ray's entry
// through a cut, what it met is the cut face: it takes the cut's normal, not the
// density gradient (which belongs to structures the cut passes through).
const float CUT_FACE_STEPS = 2.0;
// A ray direction's component below this is taken as this (the grid walk divides by it).
const float DIR_MIN = 1e-12;

// Majorant grid traversal (Amanatides–Woo). Cell c is brick c of the volume: bricks are
// a whole number of voxels, so when a dimension is not a multiple of the brick the grid
// reaches past the box (the walk still ends at the box exit).
struct GridWalk {
    ivec3 cell;
    ivec3 step_dir;
    vec3 t_next;
    vec3 t_delta;
    ivec3 grid;
};

GridWalk grid_walk_begin(vec3 o, vec3 d, float t) {
    GridWalk w;
    w.grid = textureSize(majorant_grid, 0);
    vec3 cell_size = box_size() / vec3(frame.dims.xyz) * float(frame.dims.w);
    vec3 p = o + d * t;
    vec3 g = (p - frame.box_min.xyz) / cell_size;
    w.cell = clamp(ivec3(floor(g)), ivec3(0), w.grid - 1);
    w.step_dir = ivec3(sign(d));
    vec3 inv = 1.0 / max(abs(d), vec3(DIR_MIN));
    w.t_delta = cell_size * inv;
    vec3 next_boundary = frame.box_min.xyz + (vec3(w.cell) + step(vec3(0.0), d)) * cell_size;
    w.t_next = t + (next_boundary - p) * sign(d) * inv;
    w.t_next = mix(vec3(FLT_BIG), w.t_next, notEqual(w.step_dir, ivec3(0)));
    return w;
}

float grid_walk_exit(GridWalk w) { return min(w.t_next.x, min(w.t_next.y, w.t_next.z)); }

bool grid_walk_advance(inout GridWalk w) {
    if (w.t_next.x <= w.t_next.y && w.t_next.x <= w.t_next.z) {
        w.cell.x += w.step_dir.x; w.t_next.x += w.t_delta.x;
    } else if (w.t_next.y <= w.t_next.z) {
        w.cell.y += w.step_dir.y; w.t_next.y += w.t_delta.y;
    } else {
        w.cell.z += w.step_dir.z; w.t_next.z += w.t_delta.z;
    }
    return all(greaterThanEqual(w.cell, ivec3(0))) && all(lessThan(w.cell, w.grid));
}

float grid_majorant(GridWalk w) { return texelFetch(majorant_grid, w.cell, 0).r; }

#endif
