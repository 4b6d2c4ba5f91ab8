//! Shared pieces of the procedural datasets: a parallel slice filler, signed distance
//! helpers and a cheap smooth texture.
//!
//! Both datasets are analytic (signed distance functions evaluated at voxel centres), so
//! they are deterministic, resolution independent and need no files. Generation runs one
//! contiguous block of z slices per thread with `std::thread::scope`.

/// Fills a `dims` volume slice by slice: `fill(z, slice)` writes the `dims[0] * dims[1]`
/// values of slice `z` (x fastest). Slices are shared out over the available cores.
pub(crate) fn fill_slices<T, F>(dims: [u32; 3], fill: F) -> Vec<T>
where
    T: Copy + Default + Send,
    F: Fn(u32, &mut [T]) + Sync,
{
    let slice_len = dims[0] as usize * dims[1] as usize;
    let mut out = vec![T::default(); slice_len * dims[2] as usize];
    if slice_len == 0 {
        return out;
    }
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .clamp(1, dims[2].max(1) as usize);
    let per_thread = (dims[2] as usize).div_ceil(threads);
    std::thread::scope(|scope| {
        for (block, chunk) in out.chunks_mut(per_thread * slice_len).enumerate() {
            let fill = &fill;
            scope.spawn(move || {
                for (i, slice) in chunk.chunks_mut(slice_len).enumerate() {
                    fill((block * per_thread + i) as u32, slice);
                }
            });
        }
    });
    out
}

/// Voxel-centre coordinate of index `i` along an axis of `n` voxels, in `[-1, 1]`.
pub(crate) fn centre(i: u32, n: u32) -> f32 {
    (i as f32 + 0.5) / n as f32 * 2.0 - 1.0
}

pub(crate) fn length(v: [f32; 3]) -> f32 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

/// Approximate signed distance to an axis-aligned ellipsoid with radii `r` centred at `c`
/// (Quilez's bound: exact on the surface, good within a few voxels of it).
pub(crate) fn ellipsoid(p: [f32; 3], c: [f32; 3], r: [f32; 3]) -> f32 {
    let q = [0, 1, 2].map(|i| p[i] - c[i]);
    let k0 = length([0, 1, 2].map(|i| q[i] / r[i]));
    let k1 = length([0, 1, 2].map(|i| q[i] / (r[i] * r[i])));
    if k1 > 0.0 {
        k0 * (k0 - 1.0) / k1
    } else {
        -r[0].min(r[1]).min(r[2])
    }
}

/// Signed distance to a sphere.
pub(crate) fn sphere(p: [f32; 3], c: [f32; 3], r: f32) -> f32 {
    length([0, 1, 2].map(|i| p[i] - c[i])) - r
}

/// Polynomial smooth minimum (smooth union) with blend radius `k`.
pub(crate) fn smin(a: f32, b: f32, k: f32) -> f32 {
    let h = (0.5 + 0.5 * (b - a) / k).clamp(0.0, 1.0);
    b + (a - b) * h - k * h * (1.0 - h)
}

/// Coverage of a surface at signed distance `d_vox` (in voxels): 1 inside, 0 outside,
/// linear over one voxel (a box-filtered edge, so surfaces are not aliased).
pub(crate) fn coverage(d_vox: f32) -> f32 {
    (0.5 - d_vox).clamp(0.0, 1.0)
}

/// A smooth deterministic texture: a sum of plane waves `a cos(k . p + phi)`, evaluated
/// separably (per-axis complex exponentials multiplied together), so a voxel costs a few
/// multiplications rather than trigonometry.
pub(crate) struct Waves {
    waves: Vec<Wave>,
}

/// One plane wave: amplitude and the per-axis tables `e^{i k_a p_a}` as (re, im).
struct Wave {
    amp: f32,
    tables: [Vec<(f32, f32)>; 3],
}

impl Waves {
    /// `spec`: (amplitude, wave vector in units of `[-1, 1]` coordinates, phase).
    pub(crate) fn new(dims: [u32; 3], spec: &[(f32, [f32; 3], f32)]) -> Waves {
        let waves = spec
            .iter()
            .map(|&(amp, k, phase)| {
                let tables = [0, 1, 2].map(|a| {
                    (0..dims[a])
                        .map(|i| {
                            // Fold the phase into the x table.
                            let ph = if a == 0 { phase } else { 0.0 };
                            let t = k[a] * centre(i, dims[a]) + ph;
                            (t.cos(), t.sin())
                        })
                        .collect()
                });
                Wave { amp, tables }
            })
            .collect();
        Waves { waves }
    }

    /// Per-wave complex factors for row (y, z); combine with [`Waves::at`].
    pub(crate) fn row(&self, y: u32, z: u32) -> Vec<(f32, f32)> {
        self.waves
            .iter()
            .map(|w| {
                let (a, b) = w.tables[1][y as usize];
                let (c, d) = w.tables[2][z as usize];
                (w.amp * (a * c - b * d), w.amp * (a * d + b * c))
            })
            .collect()
    }

    /// The texture value at x within a row from [`Waves::row`].
    pub(crate) fn at(&self, row: &[(f32, f32)], x: u32) -> f32 {
        self.waves
            .iter()
            .zip(row)
            .map(|(w, &(re, im))| {
                let (c, s) = w.tables[0][x as usize];
                c * re - s * im
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fill_visits_every_slice_once() {
        let v: Vec<u32> = fill_slices([3, 2, 7], |z, s| s.iter_mut().for_each(|x| *x += z + 1));
        for z in 0..7u32 {
            assert!(v[z as usize * 6..(z as usize + 1) * 6]
                .iter()
                .all(|&x| x == z + 1));
        }
    }

    #[test]
    fn waves_match_direct_evaluation() {
        let dims = [5, 6, 7];
        let spec = [(0.5, [3.0, -2.0, 1.5], 0.3), (0.25, [7.0, 1.0, -4.0], 1.1)];
        let w = Waves::new(dims, &spec);
        let row = w.row(4, 2);
        for x in 0..5 {
            let p = [centre(x, 5), centre(4, 6), centre(2, 7)];
            let direct: f32 = spec
                .iter()
                .map(|(a, k, ph)| a * (k[0] * p[0] + k[1] * p[1] + k[2] * p[2] + ph).cos())
                .sum();
            assert!((w.at(&row, x) - direct).abs() < 1e-5);
        }
    }

    #[test]
    fn sdf_signs() {
        assert!(ellipsoid([0.0; 3], [0.0; 3], [0.5, 0.4, 0.3]) < 0.0);
        assert!((ellipsoid([0.5, 0.0, 0.0], [0.0; 3], [0.5, 0.4, 0.3])).abs() < 1e-6);
        assert!(ellipsoid([0.9, 0.0, 0.0], [0.0; 3], [0.5, 0.4, 0.3]) > 0.0);
        assert!(smin(1.0, 1.0, 0.1) < 1.0);
        assert_eq!(coverage(-1.0), 1.0);
        assert_eq!(coverage(1.0), 0.0);
    }
}
