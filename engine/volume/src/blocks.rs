//! Volumes whose voxels are made block by block, on demand: the dense array never exists
//! in memory. The brick pool asks for each brick it makes resident, the renderer for the
//! per-cell density bounds of the majorant grid and for the coarse copy beneath the pool.

/// A volume that writes any block of its voxels when asked (16-bit: normalised density
/// × 65535, little-endian).
pub trait VoxelBlocks: Send + Sync + std::fmt::Debug {
    /// Voxels along x, y, z.
    fn dims(&self) -> [u32; 3];

    /// Writes the `size` block of voxels starting at `origin` into `out` (x fastest,
    /// 2 bytes each). Coordinates outside the volume read its nearest edge voxel, as a
    /// clamp-to-edge sampler does.
    fn fill(&self, origin: [i64; 3], size: [u32; 3], out: &mut [u8]);

    /// Bounds of the normalised density per cell of `cell`³ voxels (cells x fastest,
    /// `ceil(dims / cell)` of them), each covering every trilinear sample in the cell:
    /// its voxels and a one-voxel apron. They may be loose (a larger max, a smaller min),
    /// never tight where the volume is not.
    fn cell_bounds(&self, cell: u32) -> (Vec<f32>, Vec<f32>);

    /// The volume at `dims` (its own dims divided by 2^level, rounded up), each voxel the
    /// density at the centre of the 2^level block it stands for.
    fn coarse(&self, level: u32, dims: [u32; 3]) -> Vec<u8>;
}
