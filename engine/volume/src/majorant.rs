//! The coarse majorant grid: per-brick bounds of the density for delta and ratio tracking.
//!
//! Delta tracking samples free paths against a majorant `μ̄ ≥ μ(x)`; a tight local
//! majorant makes empty and thin regions cheap (few null collisions) and a brick whose
//! max is 0 can be skipped outright. The grid stores, per brick of `brick`³ voxels, the
//! min and max of the *normalised* density; the renderer maps them through the transfer
//! function's opacity (take the max of the LUT over `[min, max]`) and density scale.
//!
//! Bounds hold for trilinear samples, not just voxel values: a sample anywhere in a brick's
//! region `[b·B, (b+1)·B)` (in voxel units, voxel centres at `i + 0.5`, clamp-to-edge
//! addressing) interpolates voxels `b·B - 1 ..= (b+1)·B`, so each brick's range includes a
//! one-voxel apron on every side. Trilinear interpolation is a convex combination, so it
//! never leaves `[min, max]` of those voxels (up to the GPU filter's rounding, which the
//! shader absorbs with a tiny relative epsilon).

use super::procedural::fill_slices;
use super::Volume;

/// Per-brick density bounds, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub struct MajorantGrid {
    /// Bricks along x, y, z: `ceil(volume dims / brick)`.
    pub dims: [u32; 3],
    /// Brick edge in voxels.
    pub brick: u32,
    /// Minimum normalised density a trilinear sample in the brick can take.
    pub min: Vec<f32>,
    /// Maximum normalised density a trilinear sample in the brick can take.
    pub max: Vec<f32>,
}

impl MajorantGrid {
    /// Builds the grid for `v` with bricks of `brick`³ voxels (8 or 16 are the useful
    /// sizes; values are clamped to `1..=4096`).
    pub fn build(v: &Volume, brick: u32) -> MajorantGrid {
        let brick = brick.clamp(1, super::MAX_DIM);
        let dims = v.dims.map(|d| d.div_ceil(brick).max(1));
        let bricks_per_slab = dims[0] as usize * dims[1] as usize;
        // One "slice" of the filler is one z layer of bricks; each entry is (min, max).
        let bounds: Vec<(f32, f32)> = fill_slices([dims[0], dims[1], dims[2]], |bz, layer| {
            for (i, out) in layer.iter_mut().enumerate().take(bricks_per_slab) {
                let bx = i as u32 % dims[0];
                let by = i as u32 / dims[0];
                *out = brick_bounds(v, [bx, by, bz], brick);
            }
        });
        MajorantGrid {
            dims,
            brick,
            min: bounds.iter().map(|b| b.0).collect(),
            max: bounds.iter().map(|b| b.1).collect(),
        }
    }

    /// Linear index of brick (x, y, z).
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        (z as usize * self.dims[1] as usize + y as usize) * self.dims[0] as usize + x as usize
    }

    /// The largest density in the volume (the global majorant).
    pub fn global_max(&self) -> f32 {
        self.max.iter().copied().fold(0.0, f32::max)
    }
}

/// Min and max over the brick's voxels plus a one-voxel apron, clamped to the volume.
fn brick_bounds(v: &Volume, b: [u32; 3], brick: u32) -> (f32, f32) {
    let range = |axis: usize| {
        let lo = (b[axis] * brick).saturating_sub(1);
        let hi = ((b[axis] + 1) * brick).min(v.dims[axis].saturating_sub(1));
        (lo as usize, hi as usize)
    };
    let (x0, x1) = range(0);
    let (y0, y1) = range(1);
    let (z0, z1) = range(2);
    let (nx, ny) = (v.dims[0] as usize, v.dims[1] as usize);
    fn fold<T: Copy>(
        data: &[T],
        rows: impl Iterator<Item = usize>,
        width: usize,
        conv: impl Fn(T) -> f32,
    ) -> (f32, f32) {
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for start in rows {
            // `get`: a hand-built Volume whose data is shorter than its dims yields
            // bounds from what exists instead of a panic.
            for &x in data.get(start..start + width).unwrap_or(&[]) {
                let f = conv(x);
                lo = lo.min(f);
                hi = hi.max(f);
            }
        }
        if lo <= hi {
            (lo, hi)
        } else {
            (0.0, 0.0)
        }
    }
    let rows = (z0..=z1).flat_map(move |z| (y0..=y1).map(move |y| (z * ny + y) * nx + x0));
    let width = x1 - x0 + 1;
    match &v.data {
        // Integer data: fold in the integer domain, convert once.
        super::VolumeData::U8(d) => {
            let (lo, hi) = fold(d, rows, width, f32::from);
            (lo / 255.0, hi / 255.0)
        }
        super::VolumeData::U16(d) => {
            let (lo, hi) = fold(d, rows, width, f32::from);
            (lo / 65535.0, hi / 65535.0)
        }
        super::VolumeData::F32(d) => fold(d, rows, width, |x| x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::VolumeData;

    /// Trilinear sample with clamp-to-edge at continuous voxel position `p` (voxel
    /// centres at i + 0.5), as a GPU sampler computes it (in f64).
    fn trilinear(v: &Volume, p: [f64; 3]) -> f64 {
        let mut acc = 0.0;
        let base = p.map(|c| (c - 0.5).floor());
        let f = [0, 1, 2].map(|i| p[i] - 0.5 - base[i]);
        for corner in 0..8 {
            let mut w = 1.0;
            let mut idx = [0u32; 3];
            for a in 0..3 {
                let hi = (corner >> a) & 1 == 1;
                w *= if hi { f[a] } else { 1.0 - f[a] };
                let i = base[a] as i64 + i64::from(hi);
                idx[a] = i.clamp(0, i64::from(v.dims[a]) - 1) as u32;
            }
            acc += w * f64::from(v.value(idx[0], idx[1], idx[2]).unwrap_or(0.0));
        }
        acc
    }

    fn check_bounds(v: &Volume, brick: u32) {
        let g = MajorantGrid::build(v, brick);
        assert_eq!(g.dims, v.dims.map(|d| d.div_ceil(brick)));
        let mut rng = 0x2545_f491_u64;
        let mut next = move || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64
        };
        for bz in 0..g.dims[2] {
            for by in 0..g.dims[1] {
                for bx in 0..g.dims[0] {
                    let i = g.index(bx, by, bz);
                    let (lo, hi) = (f64::from(g.min[i]), f64::from(g.max[i]));
                    let b = [bx, by, bz];
                    // Corners and edges of the brick region plus random interior points.
                    let mut points = Vec::new();
                    for c in 0..8 {
                        points.push([0, 1, 2].map(|a| {
                            let edge = if (c >> a) & 1 == 1 { b[a] + 1 } else { b[a] };
                            f64::from((edge * brick).min(v.dims[a]))
                        }));
                    }
                    for _ in 0..64 {
                        points.push([0, 1, 2].map(|a| {
                            let start = f64::from(b[a] * brick);
                            let end = f64::from(((b[a] + 1) * brick).min(v.dims[a]));
                            start + (end - start) * next()
                        }));
                    }
                    for p in points {
                        let s = trilinear(v, p);
                        assert!(
                            s <= hi + 1e-6 && s >= lo - 1e-6,
                            "brick {b:?}: sample {s} at {p:?} outside [{lo}, {hi}]"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn bounds_every_trilinear_sample_in_its_brick() {
        let phantom = Volume::builtin("phantom", 40).expect("phantom");
        check_bounds(&phantom, 8);
        check_bounds(&phantom, 16);
        // A single hot voxel on a brick boundary: the neighbour brick must see it through
        // the apron, and a far brick must not.
        let mut d = vec![0u8; 20 * 20 * 20];
        let hot = (5 * 20 + 5) * 20 + 8; // (8, 5, 5): first voxel of brick x = 1
        d[hot] = 255;
        let v = Volume::new("hot", [20; 3], [1.0; 3], VolumeData::U8(d)).expect("valid");
        check_bounds(&v, 8);
        let g = MajorantGrid::build(&v, 8);
        assert_eq!(g.max[g.index(0, 0, 0)], 1.0, "apron reaches into brick 0");
        assert_eq!(g.max[g.index(1, 0, 0)], 1.0);
        assert_eq!(g.max[g.index(2, 0, 0)], 0.0, "far brick stays empty");
        assert_eq!(g.global_max(), 1.0);
        // Odd sizes and float data.
        let f: Vec<f32> = (0..7 * 5 * 3)
            .map(|i| ((i * 37) % 11) as f32 / 10.0)
            .collect();
        let v = Volume::new("f", [7, 5, 3], [1.0; 3], VolumeData::F32(f)).expect("valid");
        check_bounds(&v, 2);
        assert_eq!(MajorantGrid::build(&v, 0).brick, 1);
    }

    #[test]
    fn inconsistent_hand_built_volume_does_not_panic() {
        let v = Volume {
            name: "broken".into(),
            dims: [16, 16, 16],
            spacing: [1.0; 3],
            to_patient: crate::PatientTransform::aligned([1.0; 3]),
            window: [0.0, 1.0],
            sample_kind: crate::SampleKind::U8,
            data: VolumeData::U8(vec![255; 100]),
        };
        let g = MajorantGrid::build(&v, 8);
        assert_eq!(g.max.len(), 8);
        assert_eq!(g.max[g.index(0, 0, 0)], 1.0);
        assert_eq!(g.max[g.index(1, 1, 1)], 0.0);
    }
}
