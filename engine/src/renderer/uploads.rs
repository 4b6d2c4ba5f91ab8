//! What the CPU hands the device: a volume (its bytes held, or made block by block on
//! demand) with its majorant grid's brick ranges, a transfer function's LUTs and an
//! environment map. Blocks of a volume read clamped at its edge, and its coarse copy,
//! are made here for the brick pool.

use crate::volume::blocks::VoxelBlocks;
use ash::vk;
use std::borrow::Cow;
use std::sync::Arc;

/// Texel format of an uploaded volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeFormat {
    R8,
    R16,
    R32F,
}

impl VolumeFormat {
    /// The one-channel texel format.
    pub fn vk(self) -> vk::Format {
        self.vk_components(1)
    }

    /// The texel format of `components` (1, 2 or 4) of this type.
    pub fn vk_components(self, components: u32) -> vk::Format {
        use vk::Format as F;
        match (self, components) {
            (VolumeFormat::R8, 1) => F::R8_UNORM,
            (VolumeFormat::R8, 2) => F::R8G8_UNORM,
            (VolumeFormat::R8, _) => F::R8G8B8A8_UNORM,
            (VolumeFormat::R16, 1) => F::R16_UNORM,
            (VolumeFormat::R16, 2) => F::R16G16_UNORM,
            (VolumeFormat::R16, _) => F::R16G16B16A16_UNORM,
            (VolumeFormat::R32F, 1) => F::R32_SFLOAT,
            (VolumeFormat::R32F, 2) => F::R32G32_SFLOAT,
            (VolumeFormat::R32F, _) => F::R32G32B32A32_SFLOAT,
        }
    }
    /// Bytes of one component.
    pub fn bytes(self) -> usize {
        match self {
            VolumeFormat::R8 => 1,
            VolumeFormat::R16 => 2,
            VolumeFormat::R32F => 4,
        }
    }
}

/// Min/max normalised density per brick (a coarse grid over the volume).
#[derive(Clone, Debug, PartialEq)]
pub struct BrickRanges {
    /// Brick edge in voxels; brick (i, j, k) covers voxels [i·brick, (i+1)·brick) etc.,
    /// so the last brick along an axis may reach past the volume.
    pub brick: u32,
    pub grid: [u32; 3],
    pub min: Vec<f32>,
    pub max: Vec<f32>,
}

/// A channel of a multi-channel volume past the first (see `packing.rs`).
#[derive(Clone, Debug)]
pub struct ChannelUpload {
    pub name: String,
    /// The physical values at density 0 and 1 of this channel.
    pub window: [f32; 2],
    pub bricks: BrickRanges,
}

/// A volume ready for upload.
#[derive(Clone, Debug)]
pub struct VolumeUpload {
    pub name: String,
    pub dims: [u32; 3],
    /// The type of each texel component.
    pub format: VolumeFormat,
    /// Texel bytes, x fastest, every channel's component of a texel together; empty when
    /// `blocks` makes them.
    pub bytes: Vec<u8>,
    /// A volume made block by block on demand (R16), whose dense bytes never exist.
    pub blocks: Option<Arc<dyn VoxelBlocks>>,
    /// World-space size of the box (the volume is centred at the origin).
    pub world_size: [f32; 3],
    /// The physical values at density 0 and 1: what a data-unit TF is mapped through.
    pub window: [f32; 2],
    /// Millimetres per world unit: the volume's longest physical side (the scale bar).
    pub mm_per_unit: f32,
    /// Channel 0's brick ranges.
    pub bricks: BrickRanges,
    /// Channels 1.. of a multi-channel medium, packed into the same texels (empty for
    /// one field).
    pub extra_channels: Vec<ChannelUpload>,
}

impl VolumeUpload {
    /// Brick edge of the majorant grid, in voxels.
    pub const BRICK: u32 = 8;

    /// The fields in the medium (1–4).
    pub fn channels(&self) -> u32 {
        1 + self.extra_channels.len() as u32
    }

    /// The texture's texel format (see [`super::packing::components`]).
    pub fn vk_format(&self) -> vk::Format {
        self.format
            .vk_components(super::packing::components(self.channels()))
    }

    /// The value at `voxel` in data units (the first channel's with several); `None`
    /// outside, or for a volume made on demand (no bytes on the host).
    pub fn data_value(&self, voxel: [u32; 3]) -> Option<f32> {
        let [nx, ny, nz] = self.dims.map(|d| d as usize);
        let [x, y, z] = voxel.map(|c| c as usize);
        if self.blocks.is_some() || x >= nx || y >= ny || z >= nz {
            return None;
        }
        let at = ((z * ny + y) * nx + x) * self.texel_bytes();
        let b = self.bytes.get(at..at + self.format.bytes())?;
        let d = match self.format {
            VolumeFormat::R8 => f32::from(b[0]) / 255.0,
            VolumeFormat::R16 => f32::from(u16::from_le_bytes([b[0], b[1]])) / 65535.0,
            VolumeFormat::R32F => f32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        };
        let [lo, hi] = self.window;
        Some(lo + d * (hi - lo))
    }

    /// Per voxel, whether every field is 0 there (`None` for a volume made on demand):
    /// where a TF transparent at 0 puts no medium.
    pub fn zero_voxels(&self) -> Option<Vec<bool>> {
        if self.blocks.is_some() {
            return None;
        }
        let texel = self.texel_bytes();
        Some(
            self.bytes
                .chunks_exact(texel)
                .map(|t| t.iter().all(|&b| b == 0))
                .collect(),
        )
    }

    /// Bytes of one texel.
    pub fn texel_bytes(&self) -> usize {
        self.format.bytes() * super::packing::components(self.channels()) as usize
    }

    /// A loaded volume as a texture upload: world space is the volume centred at the
    /// origin with its longest side 1 unit; bricks of [`Self::BRICK`] voxels.
    pub fn from_volume(v: &crate::volume::Volume) -> Self {
        use crate::volume::{MajorantGrid, VolumeData};
        let grid = MajorantGrid::build(v, Self::BRICK);
        let format = match v.data {
            VolumeData::U8(_) => VolumeFormat::R8,
            VolumeData::U16(_) => VolumeFormat::R16,
            VolumeData::F32(_) => VolumeFormat::R32F,
        };
        let extent = v.extent();
        let longest = extent.iter().copied().fold(f32::MIN, f32::max).max(1e-6);
        Self {
            name: v.name.clone(),
            dims: v.dims,
            format,
            bytes: v.data.as_bytes().to_vec(),
            blocks: None,
            world_size: extent.map(|e| e / longest),
            window: v.window,
            mm_per_unit: longest,
            bricks: BrickRanges {
                brick: grid.brick,
                grid: grid.dims,
                min: grid.min,
                max: grid.max,
            },
            extra_channels: Vec::new(),
        }
    }
}

impl VolumeUpload {
    /// A volume made on demand: 1-voxel spacing, world space as [`Self::from_volume`],
    /// the majorant grid's bounds from the blocks' own.
    pub fn on_demand(name: &str, blocks: Arc<dyn VoxelBlocks>) -> Self {
        let dims = blocks.dims();
        let longest = dims.iter().copied().max().unwrap_or(1).max(1) as f32;
        let (min, max) = blocks.cell_bounds(Self::BRICK);
        Self {
            name: name.to_string(),
            dims,
            format: VolumeFormat::R16,
            bytes: Vec::new(),
            world_size: dims.map(|d| d as f32 / longest),
            window: [0.0, 1.0],
            // Made on demand at 1 mm voxels.
            mm_per_unit: longest,
            bricks: BrickRanges {
                brick: Self::BRICK,
                grid: dims.map(|d| d.div_ceil(Self::BRICK)),
                min,
                max,
            },
            blocks: Some(blocks),
            extra_channels: Vec::new(),
        }
    }

    /// Writes the `size` block of voxels at `origin` into `out` (x fastest), outside the
    /// volume its nearest edge voxel: from the held bytes, or made by the blocks.
    pub fn fill(&self, origin: [i64; 3], size: [u32; 3], out: &mut [u8]) {
        match &self.blocks {
            Some(b) => b.fill(origin, size, out),
            None => {
                let bpp = self.format.bytes();
                fill_clamped(&self.bytes, self.dims, bpp, origin, size, out)
            }
        }
    }

    /// The volume at 2^level coarser (`dims`): the held bytes box-filtered, or the
    /// blocks' own coarse copy.
    pub fn coarse(&self, level: u32, dims: [u32; 3]) -> Vec<u8> {
        match &self.blocks {
            Some(b) => b.coarse(level, dims),
            None => coarse_copy(self, level, dims),
        }
    }

    /// The dense bytes: held, or made from the blocks (the dense path of a volume made on
    /// demand, where the budget holds it).
    pub fn dense_bytes(&self) -> Cow<'_, [u8]> {
        if self.blocks.is_none() {
            return Cow::Borrowed(&self.bytes);
        }
        let texels: usize = self.dims.iter().map(|&d| d as usize).product();
        let mut out = vec![0u8; texels * self.format.bytes()];
        self.fill([0; 3], self.dims, &mut out);
        Cow::Owned(out)
    }
}

/// Writes the `size` block of `bytes` (a dense `dims` volume of `bpp`-byte voxels, x
/// fastest) starting at `origin` into `out`, reading the nearest edge voxel outside the
/// volume as a clamp-to-edge sampler does. Rows are copied whole where they lie inside.
pub fn fill_clamped(
    bytes: &[u8],
    dims: [u32; 3],
    bpp: usize,
    origin: [i64; 3],
    size: [u32; 3],
    out: &mut [u8],
) {
    let [nx, ny, nz] = dims.map(|d| d as i64);
    let w = size[0] as usize;
    // The run of x inside the volume: [x0, x1) in the block, starting at voxel origin.x + x0.
    let x0 = (-origin[0]).clamp(0, w as i64) as usize;
    let x1 = (nx - origin[0]).clamp(x0 as i64, w as i64) as usize;
    let mut o = 0;
    for z in 0..size[2] as i64 {
        let sz = (origin[2] + z).clamp(0, nz - 1);
        for y in 0..size[1] as i64 {
            let sy = (origin[1] + y).clamp(0, ny - 1);
            let row = &bytes[((sz * ny + sy) * nx) as usize * bpp..][..nx as usize * bpp];
            let dst = &mut out[o..o + w * bpp];
            let first = &row[..bpp];
            let last = &row[row.len() - bpp..];
            for px in dst[..x0 * bpp].chunks_exact_mut(bpp) {
                px.copy_from_slice(first);
            }
            if x1 > x0 {
                let start = (origin[0] + x0 as i64) as usize * bpp;
                dst[x0 * bpp..x1 * bpp].copy_from_slice(&row[start..start + (x1 - x0) * bpp]);
            }
            for px in dst[x1 * bpp..].chunks_exact_mut(bpp) {
                px.copy_from_slice(last);
            }
            o += w * bpp;
        }
    }
}

/// The volume averaged over 2^level voxels per side (a box filter; partial blocks at the
/// far edges average what they hold), in the volume's own format: the coarse copy of a
/// volume held dense (see [`VolumeUpload::coarse`]).
pub fn coarse_copy(v: &VolumeUpload, level: u32, dims: [u32; 3]) -> Vec<u8> {
    let f = 1usize << level;
    let [nx, ny, nz] = v.dims.map(|d| d as usize);
    let read = |i: usize| -> f64 {
        match v.format {
            VolumeFormat::R8 => v.bytes[i] as f64,
            VolumeFormat::R16 => u16::from_le_bytes([v.bytes[2 * i], v.bytes[2 * i + 1]]) as f64,
            VolumeFormat::R32F => {
                f32::from_le_bytes(v.bytes[4 * i..4 * i + 4].try_into().expect("four bytes")) as f64
            }
        }
    };
    let mut out =
        Vec::with_capacity(dims.iter().map(|&d| d as usize).product::<usize>() * v.format.bytes());
    for cz in 0..dims[2] as usize {
        for cy in 0..dims[1] as usize {
            for cx in 0..dims[0] as usize {
                let (mut sum, mut n) = (0.0, 0usize);
                for z in cz * f..((cz + 1) * f).min(nz) {
                    for y in cy * f..((cy + 1) * f).min(ny) {
                        let row = (z * ny + y) * nx;
                        for x in cx * f..((cx + 1) * f).min(nx) {
                            sum += read(row + x);
                            n += 1;
                        }
                    }
                }
                let mean = sum / n.max(1) as f64;
                match v.format {
                    VolumeFormat::R8 => out.push(mean.round() as u8),
                    VolumeFormat::R16 => {
                        out.extend_from_slice(&(mean.round() as u16).to_le_bytes())
                    }
                    VolumeFormat::R32F => out.extend_from_slice(&(mean as f32).to_le_bytes()),
                }
            }
        }
    }
    out
}

/// One transfer function sampled into LUTs (rgba each, same length).
#[derive(Clone, Debug, PartialEq)]
pub struct LutUpload {
    pub diffuse_opacity: Vec<[f32; 4]>,
    pub specular_roughness: Vec<[f32; 4]>,
    pub emissive: Vec<[f32; 4]>,
}

impl From<&crate::transfer::TfLut> for LutUpload {
    fn from(l: &crate::transfer::TfLut) -> Self {
        Self {
            diffuse_opacity: l.diffuse_opacity.clone(),
            specular_roughness: l.specular_roughness.clone(),
            emissive: l.emissive.clone(),
        }
    }
}

/// An equirectangular RGB environment map.
#[derive(Clone, Debug)]
pub struct EnvironmentUpload {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<[f32; 4]>,
}
