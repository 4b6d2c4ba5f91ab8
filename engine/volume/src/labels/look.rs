//! How a label map looks to the renderer: per voxel its label's tint and mask (the
//! label's opacity where shown, 0 where hidden), read with trilinear filtering, and the
//! map's *shape*: the indicator of the shown labels filtered by a Gaussian of
//! [`SMOOTHING_SIGMA`] voxels, whose gradient is the normal of a label's surface.
//!
//! Interpolating label values would make labels that are not there, so the mask is
//! interpolated instead: a hidden label's voxels are empty at their centres, with the
//! half-voxel ramp a trilinear read of the density has too, and a label one voxel thin
//! still shows or hides. Across a flat boundary the ramp is symmetric, so it moves no
//! medium: a ray through a hidden slab loses exactly the slab's optical depth. When every
//! shown label has one opacity ([`LabelLook::shown_opacity`]), the renderer narrows the
//! ramp symmetrically, so a hidden label's face is no soft layer that rays wander in. The
//! normals come from the filtered shape because the raw indicator's gradient is a voxel
//! facet's (a sphere's normals stray by tens of degrees); filtering the mask itself
//! would smooth the normals too, but leaves a ghost of a hidden label's outer layer and
//! erases structures under two voxels across.
//!
//! Where the medium is empty (the volume 0 under a TF transparent there), a voxel's mask
//! matters only through the cells it shares with tissue, so it takes the lowest mask of
//! its non-empty neighbours (0 when it has none): a hidden label next to air leaves no
//! skin (the product of two ramps, density falling and mask rising, would), a shown
//! label's outer half-voxel keeps its own opacity, and the bricks of air around hidden
//! tissue hold no mask, so the majorant skips them.

use super::LabelMap;
use rayon::prelude::*;
use std::sync::Arc;

/// Standard deviation of the shape's filter, in voxels: enough for normals within 10°
/// on a voxelised sphere of radius 20 (the labels test).
pub const SMOOTHING_SIGMA: f32 = 1.0;
const RADIUS: usize = 3;

/// What one label value looks like.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Look {
    pub colour: [f32; 3],
    /// Scales the medium's extinction inside the label.
    pub opacity: f32,
    pub visible: bool,
}

/// The look on the map's grid, and per brick the largest mask a trilinear read inside
/// the brick can see (the majorant grid multiplies by it: hidden space is skipped).
#[derive(Clone, Debug, PartialEq)]
pub struct LabelLook {
    pub dims: [u32; 3],
    /// RGBA8 per voxel, x fastest: the label's tint and mask (opacity where shown).
    pub rgba: Vec<[u8; 4]>,
    /// R8 per voxel: the shown labels' indicator, filtered (shared by the looks that
    /// show the same labels: only visibility changes it).
    pub shape: Arc<Vec<u8>>,
    pub brick: u32,
    pub grid: [u32; 3],
    pub brick_max: Vec<f32>,
    /// The one opacity every shown label in the map has, 0 when they differ or none is
    /// shown. Then a trilinear read of the mask is that opacity times the share of shown
    /// voxels around it, and the renderer sharpens that share (volume.glsl, `label_mask`).
    pub shown_opacity: f32,
}

fn kernel(sigma: f32) -> [f32; 2 * RADIUS + 1] {
    let mut k = [0f32; 2 * RADIUS + 1];
    for (i, w) in k.iter_mut().enumerate() {
        let x = i as f32 - RADIUS as f32;
        *w = (-0.5 * x * x / (sigma * sigma)).exp();
    }
    let sum: f32 = k.iter().sum();
    k.map(|w| w / sum)
}

/// One pass of the filter along axis `axis` (stride `stride` between neighbours,
/// `len` voxels along it), clamping at the edges (the outermost voxels extend outward,
/// so the volume's own faces are not boundaries).
fn filter_axis(src: &[f32], dims: [usize; 3], axis: usize, sigma: f32) -> Vec<f32> {
    let k = kernel(sigma);
    let [nx, ny, _] = dims;
    let stride = [1, nx, nx * ny][axis];
    let len = dims[axis];
    let slice = nx * ny;
    let mut out = vec![0f32; src.len()];
    out.par_chunks_mut(slice)
        .enumerate()
        .for_each(|(z, plane)| {
            for (o, cell) in plane.iter_mut().enumerate() {
                let i = z * slice + o;
                let pos = [o % nx, o / nx, z][axis];
                let mut acc = 0f32;
                for (t, w) in k.iter().enumerate() {
                    let q = (pos + t).saturating_sub(RADIUS).min(len - 1);
                    acc += w * src[i + q * stride - pos * stride];
                }
                *cell = acc;
            }
        });
    out
}

impl LabelLook {
    /// The look of `map` with each label value's [`Look`] from `look`, and the brick
    /// maxima for bricks of `brick` voxels on a grid of `grid` bricks.
    pub fn new(map: &LabelMap, look: impl Fn(u16) -> Look, brick: u32, grid: [u32; 3]) -> Self {
        Self::filtered(map, look, brick, grid, SMOOTHING_SIGMA)
    }

    /// [`LabelLook::new`] with a filter of `sigma` voxels (0: none, the raw indicator,
    /// which trilinear reads leave faceted; for comparisons).
    pub fn filtered(
        map: &LabelMap,
        look: impl Fn(u16) -> Look,
        brick: u32,
        grid: [u32; 3],
        sigma: f32,
    ) -> Self {
        let shape = Arc::new(shape(map, &look, sigma));
        Self::with_shape(map, look, brick, grid, shape, None)
    }

    /// The shape [`LabelLook::new`] makes: the shown labels' indicator filtered.
    pub fn shape_of(map: &LabelMap, look: impl Fn(u16) -> Look) -> Arc<Vec<u8>> {
        Arc::new(shape(map, look, SMOOTHING_SIGMA))
    }

    /// [`LabelLook::new`] that takes `shape` as it is: the shape of a look that shows the
    /// same labels (a colour or opacity edit leaves it, and filtering is most of the
    /// work). `empty`: the voxels that hold no medium (see the module's notes).
    pub fn with_shape(
        map: &LabelMap,
        look: impl Fn(u16) -> Look,
        brick: u32,
        grid: [u32; 3],
        shape: Arc<Vec<u8>>,
        empty: Option<&EmptySpace>,
    ) -> Self {
        let mut table = vec![None; super::MAX_LABEL as usize + 1];
        let rgba: Vec<[u8; 4]> = map
            .values
            .iter()
            .map(|&v| {
                let l: Look = *table[usize::from(v)].get_or_insert_with(|| look(v));
                let [r, g, b] = l.colour;
                [unorm(r), unorm(g), unorm(b), mask_of(&l)]
            })
            .collect();
        let rgba = match empty {
            Some(space) if space.empty.len() == rgba.len() => {
                // Every label in a border list is in the map, so its look is in the table.
                let mask = |l: u16| table[usize::from(l)].map_or(0, |l: Look| mask_of(&l));
                fit_to_medium(rgba, space, mask)
            }
            _ => rgba,
        };
        let brick_max = brick_maxima(&rgba, map.dims, brick, grid);
        // The table holds the labels the map has.
        let mut shown = table.iter().flatten().map(mask_of).filter(|&m| m > 0);
        let shown_opacity = match shown.next() {
            Some(m) if shown.all(|n| n == m) => f32::from(m) / 255.0,
            _ => 0.0,
        };
        Self {
            dims: map.dims,
            rgba,
            shape,
            brick,
            grid,
            brick_max,
            shown_opacity,
        }
    }
}

/// The voxels that hold no medium (see the module's notes), and of those the ones beside
/// tissue, each with the labels of its non-empty 26 neighbours: what a look's empty
/// voxels take their mask from. Found once per map and volume, so a look made again
/// (every frame of a label's fade) reads a list instead of every empty voxel's
/// neighbours.
#[derive(Clone, Debug, PartialEq)]
pub struct EmptySpace {
    empty: Vec<bool>,
    /// Empty voxels with a non-empty neighbour; `border[k]`'s neighbours' labels are
    /// `labels[offsets[k]..offsets[k + 1]]`, each once.
    border: Vec<u32>,
    offsets: Vec<u32>,
    labels: Vec<u16>,
}

impl EmptySpace {
    /// `empty`: per voxel of `map`, whether it holds no medium. `None` when the lengths
    /// differ.
    pub fn new(map: &LabelMap, empty: Vec<bool>) -> Option<Self> {
        if empty.len() != map.values.len() {
            return None;
        }
        let [nx, ny, nz] = map.dims.map(|d| d as usize);
        let slice = nx * ny;
        // Per z plane: (voxel, its neighbours' labels) of the plane's border voxels.
        let planes: Vec<Vec<(u32, Vec<u16>)>> = (0..nz)
            .into_par_iter()
            .map(|z| {
                let mut out = Vec::new();
                for o in 0..slice {
                    let i = z * slice + o;
                    if !empty[i] {
                        continue;
                    }
                    let (x, y) = (o % nx, o / nx);
                    let mut labels: Vec<u16> = Vec::new();
                    for zz in z.saturating_sub(1)..(z + 2).min(nz) {
                        for yy in y.saturating_sub(1)..(y + 2).min(ny) {
                            for xx in x.saturating_sub(1)..(x + 2).min(nx) {
                                let j = zz * slice + yy * nx + xx;
                                if !empty[j] && !labels.contains(&map.values[j]) {
                                    labels.push(map.values[j]);
                                }
                            }
                        }
                    }
                    if !labels.is_empty() {
                        out.push((i as u32, labels));
                    }
                }
                out
            })
            .collect();
        let mut space = Self {
            empty,
            border: Vec::new(),
            offsets: vec![0],
            labels: Vec::new(),
        };
        for (voxel, labels) in planes.into_iter().flatten() {
            space.border.push(voxel);
            space.labels.extend(labels);
            space.offsets.push(space.labels.len() as u32);
        }
        Some(space)
    }
}

/// Each empty voxel's mask becomes the lowest of its non-empty 26 neighbours' (0 with
/// none): the only cells it shares are with them. `mask` is a label's mask.
fn fit_to_medium(
    mut rgba: Vec<[u8; 4]>,
    space: &EmptySpace,
    mask: impl Fn(u16) -> u8,
) -> Vec<[u8; 4]> {
    rgba.par_iter_mut()
        .zip(space.empty.par_iter())
        .filter(|(_, &e)| e)
        .for_each(|(texel, _)| texel[3] = 0);
    for (k, &voxel) in space.border.iter().enumerate() {
        let labels = &space.labels[space.offsets[k] as usize..space.offsets[k + 1] as usize];
        rgba[voxel as usize][3] = labels.iter().map(|&l| mask(l)).min().unwrap_or(0);
    }
    rgba
}

/// A label's mask: its opacity where shown, 0 where hidden.
fn mask_of(l: &Look) -> u8 {
    unorm(if l.visible { l.opacity } else { 0.0 })
}

fn unorm(x: f32) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// The shown labels' indicator filtered by a Gaussian of `sigma` voxels, R8.
fn shape(map: &LabelMap, look: impl Fn(u16) -> Look, sigma: f32) -> Vec<u8> {
    let mut table = vec![None; super::MAX_LABEL as usize + 1];
    let mut field: Vec<f32> = map
        .values
        .iter()
        .map(|&v| {
            let shown = *table[usize::from(v)].get_or_insert_with(|| look(v).visible);
            f32::from(u8::from(shown))
        })
        .collect();
    let dims = map.dims.map(|d| d as usize);
    let uniform = field.windows(2).all(|w| w[0] == w[1]);
    if !uniform && sigma > 0.0 {
        for axis in 0..3 {
            field = filter_axis(&field, dims, axis, sigma);
        }
    }
    field.iter().map(|&x| unorm(x)).collect()
}

/// The largest mask over each brick widened by one voxel (a trilinear read inside the
/// brick reaches its neighbours' nearest voxels).
fn brick_maxima(rgba: &[[u8; 4]], dims: [u32; 3], brick: u32, grid: [u32; 3]) -> Vec<f32> {
    let [nx, ny, nz] = dims.map(|d| d as usize);
    let b = brick as usize;
    let [gx, gy, gz] = grid.map(|g| g as usize);
    let mut out = vec![0f32; gx * gy * gz];
    for (i, m) in out.iter_mut().enumerate() {
        let cell = [i % gx, (i / gx) % gy, i / (gx * gy)];
        let range =
            |a: usize, n: usize| (cell[a] * b).saturating_sub(1)..((cell[a] + 1) * b + 1).min(n);
        let mut best = 0u8;
        for z in range(2, nz) {
            for y in range(1, ny) {
                let row = (z * ny + y) * nx;
                for x in range(0, nx) {
                    best = best.max(rgba[row + x][3]);
                }
            }
        }
        *m = f32::from(best) / 255.0;
    }
    out
}
