// ours' young-pixel network's tensors (engine/src/denoise/ours/young.rs): images of four
// channels per texel, the channel groups of a half-resolution tensor tiled `columns` to a
// row, so a frame of any size keeps them within the device's image limit.
#ifndef DVR_OURS_YOUNG_GLSL
#define DVR_OURS_YOUNG_GLSL

// The texel of channel group g of pixel p in a tensor of `size` pixels per group.
ivec2 young_texel(uint g, ivec2 p, ivec2 size, uint columns) {
    return ivec2(int(g % columns) * size.x + p.x, int(g / columns) * size.y + p.y);
}

#endif
