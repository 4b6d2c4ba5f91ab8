//! `sparse`: a large, mostly empty procedural volume made on demand, for the brick pool.
//! N×N×N/2 voxels (16-bit) holding blobs and the tubes between them, about 2% of the
//! box: at N = 2048 (8 GiB dense) a few thousand 32³ bricks hold anything. Every voxel is
//! the sum of the shapes around its centre, so any block can be made alone
//! ([`VoxelBlocks`]), and so can the per-cell bounds (from the shapes' boxes) and a coarse
//! copy (the shapes evaluated at the coarse voxels' centres).

use super::blocks::VoxelBlocks;
use super::procedural::fill_slices;

/// One shape: a blob (`a == b`) or a tube from `a` to `b`, in voxel units; density
/// `peak · (1 − (d/r)²)²` at distance `d < r` from it.
#[derive(Clone, Copy, Debug)]
struct Shape {
    a: [f32; 3],
    b: [f32; 3],
    r: f32,
    peak: f32,
}

impl Shape {
    /// Distance from `p` to the blob's centre or the tube's axis.
    fn distance(&self, p: [f32; 3]) -> f32 {
        let ab = [0, 1, 2].map(|i| self.b[i] - self.a[i]);
        let ap = [0, 1, 2].map(|i| p[i] - self.a[i]);
        let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
        let t = if len2 > 0.0 {
            ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (0..3)
            .map(|i| (ap[i] - t * ab[i]).powi(2))
            .sum::<f32>()
            .sqrt()
    }

    /// The profile at distance `d` (it falls with distance).
    fn profile(&self, d: f32) -> f32 {
        let q = (d / self.r).powi(2);
        if q < 1.0 {
            self.peak * (1.0 - q) * (1.0 - q)
        } else {
            0.0
        }
    }

    fn density(&self, p: [f32; 3]) -> f32 {
        self.profile(self.distance(p))
    }

    /// Voxels whose centre (i + 0.5) can be within reach, inclusive.
    fn voxel_box(&self) -> ([i64; 3], [i64; 3]) {
        let lo = [0, 1, 2].map(|i| (self.a[i].min(self.b[i]) - self.r - 0.5).floor() as i64);
        let hi = [0, 1, 2].map(|i| (self.a[i].max(self.b[i]) + self.r - 0.5).ceil() as i64);
        (lo, hi)
    }
}

/// The `sparse` dataset at edge `n`.
#[derive(Debug)]
pub struct Sparse {
    dims: [u32; 3],
    shapes: Vec<Shape>,
}

/// Blobs, and tubes joining consecutive pairs of them.
const BLOBS: usize = 40;
const TUBES: usize = 24;

impl Sparse {
    /// Dims `[n, n, n/2]` (n ≥ 8); the same shapes, scaled, at every size.
    pub fn new(n: u32) -> Self {
        let dims = [n, n, (n / 2).max(1)];
        // A fixed linear congruential stream: the dataset is the same on every machine.
        let mut state: u64 = 0x05ee_d0f5_aa5e;
        let mut next = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let size = dims.map(|d| d as f32);
        let n = n as f32;
        let mut centres = Vec::new();
        let mut shapes = Vec::new();
        for _ in 0..BLOBS {
            let c = [0, 1, 2].map(|i| size[i] * (0.1 + 0.8 * next()));
            centres.push(c);
            shapes.push(Shape {
                a: c,
                b: c,
                r: n * (0.015 + 0.025 * next()),
                peak: 0.5 + 0.5 * next(),
            });
        }
        for k in 0..TUBES {
            shapes.push(Shape {
                a: centres[2 * k % BLOBS],
                b: centres[(2 * k + 1) % BLOBS],
                r: (n * (0.003 + 0.006 * next())).max(0.75),
                peak: 0.6 + 0.4 * next(),
            });
        }
        Self { dims, shapes }
    }

    /// The shapes whose boxes meet the voxel box `lo..=hi`.
    fn shapes_in(&self, lo: [i64; 3], hi: [i64; 3]) -> Vec<Shape> {
        self.shapes
            .iter()
            .filter(|s| {
                let (a, b) = s.voxel_box();
                (0..3).all(|i| a[i] <= hi[i] && b[i] >= lo[i])
            })
            .copied()
            .collect()
    }

    /// The whole volume as 16-bit voxels (for sizes where the dense path holds it).
    pub fn dense(&self) -> Vec<u16> {
        let [nx, ny, _] = self.dims;
        fill_slices(self.dims, |z, slice: &mut [u16]| {
            let mut bytes = vec![0u8; slice.len() * 2];
            self.fill([0, 0, z as i64], [nx, ny, 1], &mut bytes);
            for (v, b) in slice.iter_mut().zip(bytes.chunks_exact(2)) {
                *v = u16::from_le_bytes([b[0], b[1]]);
            }
        })
    }
}

fn to_u16(d: f32) -> u16 {
    (d.clamp(0.0, 1.0) * 65535.0).round() as u16
}

impl VoxelBlocks for Sparse {
    fn dims(&self) -> [u32; 3] {
        self.dims
    }

    fn fill(&self, origin: [i64; 3], size: [u32; 3], out: &mut [u8]) {
        let max = self.dims.map(|d| d as i64 - 1);
        let clamp = |i: usize, c: i64| c.clamp(0, max[i]);
        let lo = [0, 1, 2].map(|i| clamp(i, origin[i]));
        let hi = [0, 1, 2].map(|i| clamp(i, origin[i] + size[i] as i64 - 1));
        let shapes = self.shapes_in(lo, hi);
        let mut o = 0;
        for z in 0..size[2] as i64 {
            let pz = clamp(2, origin[2] + z) as f32 + 0.5;
            for y in 0..size[1] as i64 {
                let py = clamp(1, origin[1] + y) as f32 + 0.5;
                for x in 0..size[0] as i64 {
                    let p = [clamp(0, origin[0] + x) as f32 + 0.5, py, pz];
                    let d: f32 = shapes.iter().map(|s| s.density(p)).sum();
                    out[o..o + 2].copy_from_slice(&to_u16(d).to_le_bytes());
                    o += 2;
                }
            }
        }
    }

    fn cell_bounds(&self, cell: u32) -> (Vec<f32>, Vec<f32>) {
        let grid = self.dims.map(|d| d.div_ceil(cell) as i64);
        let n = grid.iter().product::<i64>() as usize;
        let mut max = vec![0f32; n];
        for s in &self.shapes {
            // A cell's samples read its voxels and a one-voxel apron.
            let (lo, hi) = s.voxel_box();
            let c0 = [0, 1, 2].map(|i| ((lo[i] - 1).max(0) / cell as i64).min(grid[i] - 1));
            let c1 = [0, 1, 2].map(|i| ((hi[i] + 1).max(0) / cell as i64).min(grid[i] - 1));
            // The cell's voxel centres, apron included, lie within `reach` of its
            // centre, so no sample is closer to the shape than the centre's distance
            // less `reach` (a tube's box is mostly far from the tube).
            let reach = 0.5 * 3f32.sqrt() * (cell + 1) as f32;
            for z in c0[2]..=c1[2] {
                for y in c0[1]..=c1[1] {
                    for x in c0[0]..=c1[0] {
                        let centre = [x, y, z].map(|c| (c as f32 + 0.5) * cell as f32);
                        let bound = s.profile((s.distance(centre) - reach).max(0.0));
                        let k = ((z * grid[1] + y) * grid[0] + x) as usize;
                        max[k] = (max[k] + bound).min(1.0);
                    }
                }
            }
        }
        (vec![0.0; n], max)
    }

    fn coarse(&self, level: u32, dims: [u32; 3]) -> Vec<u8> {
        let f = (1u64 << level) as f32;
        let mut sum = vec![0f32; dims.iter().map(|&d| d as usize).product()];
        for s in &self.shapes {
            let (lo, hi) = s.voxel_box();
            let range = |i: usize| {
                let a = (lo[i].max(0) as f32 / f).floor() as i64;
                let b = ((hi[i] as f32 / f).ceil() as i64).min(dims[i] as i64 - 1);
                a..=b
            };
            for z in range(2) {
                for y in range(1) {
                    for x in range(0) {
                        let p = [x, y, z].map(|c| (c as f32 + 0.5) * f);
                        let k = ((z * dims[1] as i64 + y) * dims[0] as i64 + x) as usize;
                        sum[k] += s.density(p);
                    }
                }
            }
        }
        sum.iter().flat_map(|&d| to_u16(d).to_le_bytes()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_match_the_dense_volume_and_clamp_at_the_edges() {
        let v = Sparse::new(64);
        let dense = v.dense();
        let [nx, ny, nz] = v.dims.map(|d| d as i64);
        assert!(dense.iter().any(|&d| d > 30000), "the shapes are there");
        let empty = dense.iter().filter(|&&d| d == 0).count() as f64 / dense.len() as f64;
        assert!(empty > 0.8, "mostly empty: {empty}");
        let mut out = vec![0u8; 10 * 10 * 10 * 2];
        for origin in [[-3, -3, -3], [20, 30, 10], [nx - 5, ny - 5, nz - 5]] {
            v.fill(origin, [10; 3], &mut out);
            for (k, b) in out.chunks_exact(2).enumerate() {
                let (x, y, z) = (k as i64 % 10, k as i64 / 10 % 10, k as i64 / 100);
                let at = |o: i64, c: i64, n: i64| (o + c).clamp(0, n - 1);
                let i =
                    (at(origin[2], z, nz) * ny + at(origin[1], y, ny)) * nx + at(origin[0], x, nx);
                assert_eq!(
                    u16::from_le_bytes([b[0], b[1]]),
                    dense[i as usize],
                    "{origin:?} + {k}"
                );
            }
        }
    }

    #[test]
    fn cell_bounds_hold_every_voxel_and_its_apron() {
        let v = Sparse::new(64);
        let dense = v.dense();
        let (min, max) = v.cell_bounds(8);
        let grid = v.dims.map(|d| d.div_ceil(8) as i64);
        let [nx, ny, nz] = v.dims.map(|d| d as i64);
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let d = dense[((z * ny + y) * nx + x) as usize] as f32 / 65535.0;
                    // Every cell whose region or apron holds the voxel.
                    for cz in ((z - 1).max(0) / 8)..=((z + 1).min(nz - 1) / 8) {
                        for cy in ((y - 1).max(0) / 8)..=((y + 1).min(ny - 1) / 8) {
                            for cx in ((x - 1).max(0) / 8)..=((x + 1).min(nx - 1) / 8) {
                                let k = ((cz * grid[1] + cy) * grid[0] + cx) as usize;
                                assert!(
                                    min[k] <= d && d <= max[k] + 1e-4,
                                    "voxel {x},{y},{z}: {d} vs {}",
                                    max[k]
                                );
                            }
                        }
                    }
                }
            }
        }
        let empty = max.iter().filter(|&&m| m == 0.0).count();
        println!("{empty} of {} cells empty", max.len());
        assert!(
            empty > max.len() / 5,
            "{empty} of {} cells empty",
            max.len()
        );
    }

    #[test]
    fn the_coarse_copy_samples_block_centres() {
        let v = Sparse::new(64);
        let dims = v.dims.map(|d| d.div_ceil(4));
        let coarse = v.coarse(2, dims);
        assert_eq!(coarse.len(), dims.iter().product::<u32>() as usize * 2);
        let at = |x: u32, y: u32, z: u32| {
            let k = 2 * ((z * dims[1] + y) * dims[0] + x) as usize;
            u16::from_le_bytes([coarse[k], coarse[k + 1]])
        };
        for (x, y, z) in [(3, 5, 2), (8, 8, 4), (10, 2, 6)] {
            let p = [x, y, z].map(|c| (c as f32 + 0.5) * 4.0);
            let want: f32 = v.shapes.iter().map(|s| s.density(p)).sum();
            assert_eq!(at(x, y, z), to_u16(want));
        }
    }
}
