// The shared-memory window of an à-trous level (variance_atrous.comp and SVGF's
// svgf_atrous.comp). The 8×8 outputs of a workgroup read a (8 + 4·step)² window of their
// inputs; for steps up to TILE_MAX_STEP the group loads it into shared memory once, each
// texel once instead of up to 25 times from memory, and the taps read it there. Wider
// steps read memory directly (the window would outgrow shared memory, and their taps are
// too far apart to share many texels).
//
// SHARED_TILES is set per device (GpuContext::shared_tiles): on a GPU this is the
// difference between a pass bound by its texel loads and one bound by DRAM; on lavapipe a
// CPU's caches already hold the window and llvmpipe's barriers make tiles 3.3× slower,
// so it reads memory directly. Both paths do the same arithmetic in the same order: the
// output does not depend on the choice (tests/tiles.rs compares them bit for bit).
#ifndef DVR_ATROUS_TILE_GLSL
#define DVR_ATROUS_TILE_GLSL

layout(constant_id = 14) const bool SHARED_TILES = false;

const int TILE = 8;  // the workgroup's edge: local_size_x = local_size_y = TILE
const int TILE_MAX_STEP = 4;
const int TILE_EDGE = TILE + 4 * TILE_MAX_STEP;
const int TILE_TEXELS = TILE_EDGE * TILE_EDGE;

// Where this workgroup's window lies, and whether it is used (uniform over the dispatch,
// so every invocation of a group reaches the barrier).
struct TileWindow {
    bool on;
    ivec2 origin;  // image coordinates of the window's first texel
    int edge;      // its edge in texels: TILE + 4·step
};

TileWindow tile_window(int step) {
    TileWindow w;
    w.on = SHARED_TILES && step <= TILE_MAX_STEP;
    w.edge = TILE + 4 * step;
    w.origin = ivec2(gl_WorkGroupID.xy) * TILE - 2 * step;
    return w;
}

// Index into the window of image texel q (which must lie in it).
int tile_index(TileWindow w, ivec2 q) {
    ivec2 t = q - w.origin;
    return t.y * w.edge + t.x;
}

// Loads IMAGE's part of the window into the shared array ARRAY (vec4[TILE_TEXELS]), the
// whole group cooperating; texels outside the image are never read (the passes skip taps
// there) and are stored as 0. The caller ends its loads with barrier().
#define TILE_LOAD(w, ARRAY, IMAGE, size)                                              \
    for (int i_ = int(gl_LocalInvocationIndex); i_ < (w).edge * (w).edge;             \
         i_ += TILE * TILE) {                                                         \
        ivec2 q_ = (w).origin + ivec2(i_ % (w).edge, i_ / (w).edge);                  \
        ARRAY[i_] = all(greaterThanEqual(q_, ivec2(0))) && all(lessThan(q_, (size)))  \
            ? imageLoad(IMAGE, q_) : vec4(0.0);                                       \
    }

#endif
