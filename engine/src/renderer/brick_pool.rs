//! The brick pool: a volume past the memory budget (or past one allocation or the 3D
//! image limit) is paged into the GPU in bricks. The volume is split into bricks of
//! [`BRICK`]³ voxels; only bricks the current TF can make visible are resident, each in a
//! slot of one pool texture with an apron of [`APRON`] voxels; a brick table maps each
//! brick to its slot, or to a stand-in: the brick's own lowest density where the TF makes
//! its whole range transparent, or a coarse copy of the volume (the volume averaged over
//! 2^level voxels per side, always resident) where a visible brick has no slot. The path
//! tracer's majorant walk is the dense path's: a brick the TF hides has majorant 0.
//!
//! What holds: a sample at p reads the brick that contains p, and the six samples of a
//! central-difference gradient read the brick of the gradient's centre; the apron covers
//! both (trilinear: one voxel; the gradient's ±1 voxel: one more), clamped to the volume's
//! edge as the dense texture's sampler clamps. So a resident brick's samples are the
//! dense texture's, up to the rounding of a different texture coordinate.

use super::uploads::{BrickRanges, VolumeFormat, VolumeUpload};
use crate::bytes::human_bytes;

/// Interior edge of a pool brick in voxels: a multiple of the majorant grid's brick, so a
/// majorant cell never straddles two pool bricks (`POOL_BRICK` in include/volume.glsl).
pub const BRICK: u32 = 32;
/// Voxels stored beyond each face: one for trilinear filtering, one more for the
/// gradient's samples one voxel past the brick (`POOL_APRON` in include/volume.glsl).
pub const APRON: u32 = 2;
/// Stored edge of a brick in the pool.
pub const STORED: u32 = BRICK + 2 * APRON;
/// Most bricks uploaded per frame after the first: a TF edit that makes many bricks
/// visible streams them in over several frames (the coarse level shows until they
/// arrive), so no frame waits for a whole pool's upload.
pub const STREAM_PER_FRAME: usize = 256;
/// Share of the budget the coarse stand-in may take.
const COARSE_SHARE: u64 = 8;

/// How the volume reaches the GPU.
#[derive(Clone, Debug, PartialEq)]
pub enum VolumePath {
    /// One 3D texture: the fast path, for volumes within the budget and the limits.
    Dense,
    /// Bricks paged into a pool, with a coarse copy beneath.
    Pool(PoolLayout),
}

/// The shape of a brick pool.
#[derive(Clone, Debug, PartialEq)]
pub struct PoolLayout {
    /// Bricks along x, y, z.
    pub grid: [u32; 3],
    /// Slots along x, y, z of the pool texture.
    pub slots: [u32; 3],
    /// The coarse stand-in averages 2^level voxels per side.
    pub level: u32,
    pub coarse_dims: [u32; 3],
}

impl PoolLayout {
    pub fn slot_count(&self) -> usize {
        self.slots.iter().map(|&s| s as usize).product()
    }
    pub fn brick_count(&self) -> usize {
        self.grid.iter().map(|&g| g as usize).product()
    }
    /// Texels of the pool texture.
    pub fn pool_extent(&self) -> [u32; 3] {
        self.slots.map(|s| s * STORED)
    }
    /// Texel offset of slot `s` in the pool texture.
    pub fn slot_origin(&self, s: u32) -> [u32; 3] {
        let [sx, sy, _] = self.slots;
        [s % sx, (s / sx) % sy, s / (sx * sy)].map(|c| c * STORED)
    }
    /// Bytes the pool, the coarse copy and the brick table take.
    pub fn bytes(&self, format: VolumeFormat) -> u64 {
        let texels = |d: [u32; 3]| d.iter().map(|&x| x as u64).product::<u64>();
        (texels(self.pool_extent()) + texels(self.coarse_dims)) * format.bytes() as u64
            + self.brick_count() as u64 * 8
    }
}

/// What the device and the budget allow.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Bytes the volume may take on the GPU (`--gpu-memory`).
    pub budget: u64,
    pub max_image_dimension_3d: u32,
    pub max_allocation: u64,
    /// The largest device-local heap: a dense texture and its upload copy must fit it
    /// together, whatever the budget says.
    pub heap: u64,
}

/// Bytes of one stored brick.
pub fn brick_bytes(format: VolumeFormat) -> usize {
    (STORED * STORED * STORED) as usize * format.bytes()
}

/// Chooses the dense path when the volume fits the budget and the device's limits,
/// otherwise a pool: the coarsest copy that is still the finest within an eighth of the
/// budget, and as many slots as the rest holds (never more than there are bricks).
/// `Err` says why no pool fits.
pub fn plan(dims: [u32; 3], format: VolumeFormat, limits: &Limits) -> Result<VolumePath, String> {
    let bpp = format.bytes() as u64;
    let texels = |d: [u32; 3]| d.iter().map(|&x| x as u64).product::<u64>();
    let dense = texels(dims) * bpp;
    let max_dim = limits.max_image_dimension_3d;
    if dims.iter().all(|&d| d <= max_dim)
        && dense <= limits.max_allocation
        && dense <= limits.budget
        && dense.saturating_mul(2) <= limits.heap
    {
        return Ok(VolumePath::Dense);
    }
    let grid = dims.map(|d| d.div_ceil(BRICK));
    let coarse_budget = (limits.budget / COARSE_SHARE).min(limits.max_allocation);
    let mut level = 1;
    let coarse_dims = loop {
        let c = dims.map(|d| d.div_ceil(1 << level));
        if c.iter().all(|&d| d <= max_dim) && texels(c) * bpp <= coarse_budget {
            break c;
        }
        if c.iter().all(|&d| d == 1) {
            return Err(format!(
                "a budget of {} holds not even a 1-voxel coarse copy",
                human_bytes(limits.budget)
            ));
        }
        level += 1;
    };
    let table = texels(grid) * 8;
    let rest = limits
        .budget
        .saturating_sub(texels(coarse_dims) * bpp + table);
    let per_brick = brick_bytes(format) as u64;
    let wanted = (rest / per_brick)
        .min(texels(grid))
        .min(limits.max_allocation / per_brick);
    if wanted == 0 {
        return Err(format!(
            "a budget of {} leaves no room for one {STORED}³ brick ({}) beside the coarse copy and the brick table",
            human_bytes(limits.budget),
            human_bytes(per_brick)
        ));
    }
    // Whole rows and layers of slots: of a near-cube and of full rows first, the
    // arrangement that keeps more of the `wanted` slots.
    let per_axis = (max_dim / STORED).max(1) as u64;
    let arrange = |sx: u64| {
        let sx = sx.clamp(1, per_axis.min(wanted));
        let sy = (wanted / sx).clamp(1, per_axis.min(sx));
        let sz = (wanted / (sx * sy)).clamp(1, per_axis);
        [sx, sy, sz]
    };
    let cube = arrange((wanted as f64).cbrt().floor() as u64);
    let rows = arrange(per_axis);
    let count = |s: [u64; 3]| s[0] * s[1] * s[2];
    let [sx, sy, sz] = if count(rows) > count(cube) {
        rows
    } else {
        cube
    };
    Ok(VolumePath::Pool(PoolLayout {
        grid,
        slots: [sx as u32, sy as u32, sz as u32],
        level,
        coarse_dims,
    }))
}

/// Writes brick `b`'s stored texels (interior and apron, clamped to the volume's edge)
/// into `out`, x fastest.
pub fn write_brick(v: &VolumeUpload, b: [u32; 3], out: &mut [u8]) {
    v.fill(
        b.map(|c| (c * BRICK) as i64 - APRON as i64),
        [STORED; 3],
        out,
    );
}

/// Density ranges per pool brick from the majorant grid's (whose bricks tile a pool
/// brick exactly): the union of the cells' ranges, which include their one-voxel aprons.
pub fn pool_ranges(cells: &BrickRanges) -> BrickRanges {
    let per = (BRICK / cells.brick).max(1);
    let grid = cells.grid.map(|g| g.div_ceil(per));
    let n = grid.iter().map(|&g| g as usize).product();
    let (mut min, mut max) = (vec![f32::INFINITY; n], vec![f32::NEG_INFINITY; n]);
    let [gx, gy, gz] = cells.grid;
    for z in 0..gz {
        for y in 0..gy {
            for x in 0..gx {
                let c = ((z * gy + y) * gx + x) as usize;
                let b = (((z / per) * grid[1] + y / per) * grid[0] + x / per) as usize;
                min[b] = min[b].min(cells.min[c]);
                max[b] = max[b].max(cells.max[c]);
            }
        }
    }
    BrickRanges {
        brick: BRICK,
        grid,
        min,
        max,
    }
}

/// Which brick is in which slot, and what the TF wants resident.
#[derive(Clone, Debug)]
pub struct Residency {
    pub layout: PoolLayout,
    ranges: BrickRanges,
    /// Per brick: its slot.
    slot_of: Vec<Option<u32>>,
    /// Per slot: its brick.
    brick_in: Vec<Option<u32>>,
    /// Per brick: whether the current TF can make it visible (empty before the first TF).
    visible: Vec<bool>,
    /// Visible bricks without a slot yet, most opaque last (taken from the end).
    pending: Vec<u32>,
    /// Bricks the current TF makes visible, and how many of them have a slot.
    pub visible_count: usize,
    /// Bricks uploaded into slots since the pool was made.
    uploaded: u64,
}

impl Residency {
    pub fn new(layout: PoolLayout, ranges: BrickRanges) -> Self {
        let n = layout.brick_count();
        assert_eq!(ranges.min.len(), n, "one range per brick");
        Self {
            slot_of: vec![None; n],
            brick_in: vec![None; layout.slot_count()],
            visible: Vec::new(),
            pending: Vec::new(),
            visible_count: 0,
            uploaded: 0,
            layout,
            ranges,
        }
    }

    pub fn ranges(&self) -> &BrickRanges {
        &self.ranges
    }

    /// The TF changed: `majorants` (per brick, from [`Self::ranges`]) says which bricks
    /// it can make visible. The most opaque visible bricks, as many as there are slots,
    /// are wanted; the rest of the visible ones show at the coarse level. Returns whether
    /// the brick table changed (a TF edit that moves no brick's visibility does not).
    pub fn set_transfer_function(&mut self, majorants: &[f32]) -> bool {
        let visible: Vec<bool> = majorants.iter().map(|&m| m > 0.0).collect();
        if visible == self.visible {
            return false;
        }
        self.visible = visible;
        let mut want: Vec<u32> = (0..majorants.len() as u32)
            .filter(|&b| self.visible[b as usize])
            .collect();
        self.visible_count = want.len();
        want.sort_by(|&a, &b| majorants[b as usize].total_cmp(&majorants[a as usize]));
        want.truncate(self.layout.slot_count());
        let mut wanted = vec![false; majorants.len()];
        for &b in &want {
            wanted[b as usize] = true;
        }
        // A resident brick no longer wanted gives its slot up (its table entry changes in
        // the same upload as the slot's new brick).
        for s in 0..self.brick_in.len() {
            if let Some(b) = self.brick_in[s] {
                if !wanted[b as usize] {
                    self.brick_in[s] = None;
                    self.slot_of[b as usize] = None;
                }
            }
        }
        self.pending = want
            .into_iter()
            .rev()
            .filter(|&b| self.slot_of[b as usize].is_none())
            .collect();
        true
    }

    /// Up to `n` bricks to upload now, each with the slot it goes to; the table (see
    /// [`Self::table`]) counts them resident from now on.
    pub fn take_uploads(&mut self, n: usize) -> Vec<(u32, u32)> {
        let mut free =
            (0..self.brick_in.len() as u32).filter(|&s| self.brick_in[s as usize].is_none());
        let mut out = Vec::new();
        while out.len() < n {
            let Some(&b) = self.pending.last() else {
                break;
            };
            let Some(s) = free.next() else { break };
            self.pending.pop();
            out.push((b, s));
        }
        for &(b, s) in &out {
            self.brick_in[s as usize] = Some(b);
            self.slot_of[b as usize] = Some(s);
        }
        self.uploaded += out.len() as u64;
        out
    }

    /// Bricks uploaded into slots since the pool was made (a brick uploaded again after
    /// losing its slot counts again).
    pub fn uploaded(&self) -> u64 {
        self.uploaded
    }

    /// Visible bricks still waiting for a slot's upload.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    /// Visible bricks with a slot.
    pub fn resident_visible(&self) -> usize {
        self.slot_of
            .iter()
            .zip(&self.visible)
            .filter(|(s, &v)| v && s.is_some())
            .count()
    }

    /// The brick table (rg32f per brick, x fastest): r the slot, or −1; g where r is −1,
    /// the stand-in density (the brick's lowest: the TF makes its whole range
    /// transparent), or −1 where the coarse copy stands in (a visible brick without a
    /// slot).
    pub fn table(&self) -> Vec<[f32; 2]> {
        (0..self.slot_of.len())
            .map(|b| match self.slot_of[b] {
                Some(s) => [s as f32, 0.0],
                None if self.visible.get(b) == Some(&true) => [-1.0, -1.0],
                None => [-1.0, self.ranges.min[b].max(0.0)],
            })
            .collect()
    }
}

/// How a renderer holds its volume: dense, or in a brick pool (this module).
#[derive(Clone, Debug, PartialEq)]
pub enum VolumeResidency {
    /// One dense 3D texture.
    Dense,
    /// A brick pool: of the bricks the current TF can make visible, `resident` have a
    /// slot, `pending` wait for their upload, and the rest (past the pool's slots) show at
    /// the coarse level.
    Pool {
        layout: PoolLayout,
        visible: usize,
        resident: usize,
        pending: usize,
        /// Bricks uploaded into slots since the renderer was made.
        uploaded: u64,
    },
}

impl std::fmt::Display for VolumeResidency {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            VolumeResidency::Dense => write!(f, "dense volume"),
            VolumeResidency::Pool {
                layout,
                visible,
                resident,
                ..
            } => {
                write!(
                    f,
                    "brick pool: {resident} of {visible} visible bricks resident ({} slots of {}³), coarse level {} ({}×{}×{})",
                    layout.slot_count(),
                    BRICK,
                    layout.level,
                    layout.coarse_dims[0],
                    layout.coarse_dims[1],
                    layout.coarse_dims[2]
                )
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: Limits = Limits {
        budget: 1 << 30,
        max_image_dimension_3d: 4096,
        max_allocation: 2 << 30,
        heap: 2 << 30,
    };

    #[test]
    fn dense_when_it_fits_pool_when_not() {
        assert_eq!(
            plan([256; 3], VolumeFormat::R16, &LIMITS),
            Ok(VolumePath::Dense)
        );
        let Ok(VolumePath::Pool(p)) = plan([1024; 3], VolumeFormat::R16, &LIMITS) else {
            panic!("a 2 GiB volume over a 1 GiB budget is pooled");
        };
        assert_eq!(p.grid, [32; 3]);
        // The coarse copy within an eighth of the budget: 1024/4 = 256³ × 2 B = 32 MiB.
        assert_eq!((p.level, p.coarse_dims), (2, [256; 3]));
        assert!(p.bytes(VolumeFormat::R16) <= LIMITS.budget, "{:?}", p);
        // Most of the budget is slots: (1 GiB − 32 MiB − 256 KiB) / 93312 B = 11142, of
        // which 22×22×23 fit in whole layers.
        assert_eq!(p.slot_count(), 11132, "{p:?}");
        // A few slots go in one row, none lost to a cube's layers.
        let small = Limits {
            budget: 1 << 20,
            ..LIMITS
        };
        let Ok(VolumePath::Pool(p)) = plan([128, 128, 64], VolumeFormat::R16, &small) else {
            panic!("2 MiB over 1 MiB is pooled");
        };
        assert_eq!((p.slots, p.slot_count()), ([10, 1, 1], 10));
        assert!(p.pool_extent().iter().all(|&e| e <= 4096));
        // A budget past the heap does not make a texture and its upload copy fit.
        let generous = Limits {
            budget: 4 << 30,
            ..LIMITS
        };
        assert!(matches!(
            plan([1024; 3], VolumeFormat::R16, &generous),
            Ok(VolumePath::Pool(_))
        ));
        assert_eq!(
            plan([1024; 3], VolumeFormat::R8, &generous),
            Ok(VolumePath::Dense)
        );
        // Past the 3D image limit even within the budget.
        let big = Limits {
            budget: u64::MAX,
            heap: u64::MAX,
            ..LIMITS
        };
        assert!(matches!(
            plan([8192, 8, 8], VolumeFormat::R8, &big),
            Ok(VolumePath::Pool(_))
        ));
        // No room for a brick.
        let tiny = Limits {
            budget: 20_000,
            ..LIMITS
        };
        let e = plan([512; 3], VolumeFormat::R8, &tiny).unwrap_err();
        assert!(e.contains("no room for one"), "{e}");
    }

    #[test]
    fn bricks_carry_clamped_aprons() {
        let dims = [40, 3, 2];
        let bytes: Vec<u8> = (0..dims.iter().product::<u32>())
            .map(|i| (i % 251) as u8)
            .collect();
        let v = VolumeUpload {
            name: "t".into(),
            dims,
            format: VolumeFormat::R8,
            bytes: bytes.clone(),
            blocks: None,
            extra_channels: Vec::new(),
            world_size: [1.0; 3],
            window: [0.0, 1.0],
            mm_per_unit: 1.0,
            bricks: BrickRanges {
                brick: 8,
                grid: [5, 1, 1],
                min: vec![0.0; 5],
                max: vec![1.0; 5],
            },
        };
        let mut out = vec![0u8; brick_bytes(VolumeFormat::R8)];
        write_brick(&v, [1, 0, 0], &mut out);
        let at =
            |x: usize, y: usize, z: usize| out[(z * STORED as usize + y) * STORED as usize + x];
        let src = |x: usize, y: usize, z: usize| bytes[(z * 3 + y) * 40 + x];
        // Stored x = 0 is voxel 32 − 2 = 30; past the volume's edge the last voxel repeats.
        assert_eq!(at(0, 2, 2), src(30, 0, 0));
        assert_eq!(at(9, 2, 2), src(39, 0, 0));
        assert_eq!(at(20, 2, 2), src(39, 0, 0));
        assert_eq!(at(5, 4, 3), src(35, 2, 1));
        // Before the volume's first voxel (brick 0 starts at voxel −2) the first repeats,
        // on every axis.
        write_brick(&v, [0, 0, 0], &mut out);
        let at =
            |x: usize, y: usize, z: usize| out[(z * STORED as usize + y) * STORED as usize + x];
        assert_eq!(
            (at(0, 0, 0), at(1, 1, 1), at(2, 2, 2)),
            (src(0, 0, 0), src(0, 0, 0), src(0, 0, 0))
        );
        assert_eq!(at(7, 3, 3), src(5, 1, 1));
        assert_eq!(at(35, 35, 35), src(33, 2, 1));
    }

    #[test]
    fn residency_follows_the_transfer_function() {
        let layout = PoolLayout {
            grid: [4, 1, 1],
            slots: [2, 1, 1],
            level: 1,
            coarse_dims: [64, 16, 16],
        };
        let ranges = BrickRanges {
            brick: BRICK,
            grid: [4, 1, 1],
            min: vec![0.1, 0.2, 0.3, 0.4],
            max: vec![0.5; 4],
        };
        let mut r = Residency::new(layout, ranges);
        assert!(r.set_transfer_function(&[0.0, 1.0, 3.0, 2.0]));
        assert_eq!(r.visible_count, 3);
        // The two most opaque get the two slots; brick 1 waits at the coarse level.
        assert_eq!(r.take_uploads(10), vec![(2, 0), (3, 1)]);
        let t = r.table();
        assert_eq!(t, vec![[-1.0, 0.1], [-1.0, -1.0], [0.0, 0.0], [1.0, 0.0]]);
        // A new TF hides brick 2: its slot goes to brick 1, and brick 3 stays put.
        assert!(r.set_transfer_function(&[0.0, 1.0, 0.0, 2.0]));
        assert_eq!(r.take_uploads(1), vec![(1, 0)]);
        // Other opacities, the same bricks visible: nothing to upload, the table stands.
        assert!(!r.set_transfer_function(&[0.0, 5.0, 0.0, 0.5]));
        assert_eq!(r.table()[2], [-1.0, 0.3]);
        assert_eq!(r.resident_visible(), 2);
        assert_eq!(r.pending(), 0);
    }

    #[test]
    fn pool_ranges_fold_the_majorant_cells() {
        let cells = BrickRanges {
            brick: 8,
            grid: [5, 1, 1],
            min: vec![0.5, 0.4, 0.3, 0.2, 0.9],
            max: vec![0.6, 0.7, 0.5, 0.3, 1.0],
        };
        let p = pool_ranges(&cells);
        assert_eq!(p.grid, [2, 1, 1]);
        assert_eq!((p.min, p.max), (vec![0.2, 0.9], vec![0.7, 1.0]));
    }

    #[test]
    fn shader_constants_match() {
        let glsl = include_str!("../../../shaders/glsl/include/volume.glsl");
        assert!(glsl.contains(&format!("#define POOL_BRICK {BRICK}")));
        assert!(glsl.contains(&format!("#define POOL_APRON {APRON}")));
    }
}
