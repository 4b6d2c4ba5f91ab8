//! The scene's GPU-side data: the density volume as a 3D texture, the transfer function
//! as 1D LUTs, the majorant grid and the environment map. Uploads go through the render
//! graph as transfer passes, like everything else.

use crate::error::{EngineError, Result};
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::{Frame, ImageHandle, RenderGraph};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// Texel format of an uploaded volume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VolumeFormat {
    R8,
    R16,
    R32F,
}

impl VolumeFormat {
    pub fn vk(self) -> vk::Format {
        match self {
            VolumeFormat::R8 => vk::Format::R8_UNORM,
            VolumeFormat::R16 => vk::Format::R16_UNORM,
            VolumeFormat::R32F => vk::Format::R32_SFLOAT,
        }
    }
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

/// A volume ready for upload.
#[derive(Clone, Debug)]
pub struct VolumeUpload {
    pub name: String,
    pub dims: [u32; 3],
    pub format: VolumeFormat,
    /// Texel bytes, x fastest.
    pub bytes: Vec<u8>,
    /// World-space size of the box (the volume is centred at the origin).
    pub world_size: [f32; 3],
    pub bricks: BrickRanges,
}

impl VolumeUpload {
    /// Brick edge of the majorant grid, in voxels.
    pub const BRICK: u32 = 8;

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
            world_size: extent.map(|e| e / longest),
            bricks: BrickRanges {
                brick: grid.brick,
                grid: grid.dims,
                min: grid.min,
                max: grid.max,
            },
        }
    }
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

pub struct SceneImages {
    pub volume: ImageHandle,
    pub tf: [ImageHandle; 3],
    pub majorant: ImageHandle,
    pub environment: ImageHandle,
}

/// Adds a pass that copies `bytes` into `image` through a staging buffer of its own
/// (`<name>.staging`): for set-up work that waits for its submission.
pub fn add_upload(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'_>,
    name: &str,
    image: ImageHandle,
    bytes: &[u8],
) -> Result<()> {
    add_upload_via(
        ctx,
        graph,
        frame,
        name,
        &format!("{name}.staging"),
        image,
        bytes,
    )
}

/// [`add_upload`] for a frame in flight in slot `slot`: the staging buffer is the slot's
/// own, since the host writes it while recording, and the other slot's frame may not
/// have copied from its buffer yet.
pub fn add_frame_upload(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'_>,
    name: &str,
    slot: usize,
    image: ImageHandle,
    bytes: &[u8],
) -> Result<()> {
    let staging = format!("{name}.staging.{slot}");
    add_upload_via(ctx, graph, frame, name, &staging, image, bytes)
}

fn add_upload_via(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'_>,
    name: &str,
    staging: &str,
    image: ImageHandle,
    bytes: &[u8],
) -> Result<()> {
    let staging = graph.buffer(ctx, staging, bytes.len() as u64, MemoryLocation::CpuToGpu)?;
    graph.buffer_mut(staging).write(bytes)?;
    frame.add_pass(
        name.to_string(),
        |b| {
            b.transfer_src(staging).transfer_dst(image);
        },
        move |pc| pc.copy_buffer_to_image(staging, image),
    );
    Ok(())
}

/// Checks a volume against the device's limits before anything is allocated: each
/// dimension within the 3D image limit, the texture within one allocation, and the
/// texture plus its staging copy within the device-local heap (lavapipe: a 1024³ 8-bit
/// volume fits its 2 GiB, a 1024³ 16-bit one does not).
pub fn check_volume_fits(ctx: &GpuContext, v: &VolumeUpload) -> Result<()> {
    let texels: u64 = v.dims.iter().map(|&d| d as u64).product();
    let needed = texels * v.format.bytes() as u64;
    if let Some(&d) = v
        .dims
        .iter()
        .find(|&&d| d > ctx.info.max_image_dimension_3d)
    {
        return Err(EngineError::TooLarge {
            what: format!("volume {:?}: dimension {d}", v.name),
            needed: d as u64,
            limit: ctx.info.max_image_dimension_3d as u64,
            device: ctx.info.name.clone(),
        });
    }
    let heap = if ctx.info.device_local_heap > 0 {
        ctx.info.device_local_heap
    } else {
        u64::MAX
    };
    if needed > ctx.info.max_memory_allocation_size || needed.saturating_mul(2) > heap {
        return Err(EngineError::TooLarge {
            what: format!(
                "volume {:?} ({:?} voxels, {:?}; the texture and its upload copy)",
                v.name, v.dims, v.format
            ),
            needed: needed.saturating_mul(2),
            limit: heap.min(ctx.info.max_memory_allocation_size.saturating_mul(2)),
            device: ctx.info.name.clone(),
        });
    }
    if needed != v.bytes.len() as u64 {
        return Err(EngineError::Resource {
            resource: v.name.clone(),
            problem: format!(
                "{} bytes for {:?} voxels of {:?}",
                v.bytes.len(),
                v.dims,
                v.format
            ),
        });
    }
    Ok(())
}

/// Creates the scene images and adds their uploads to `frame`.
pub fn create<'f>(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'f>,
    volume: &VolumeUpload,
    environment: Option<&EnvironmentUpload>,
    lut_size: u32,
) -> Result<SceneImages> {
    check_volume_fits(ctx, volume)?;
    let vol = graph.image(
        ctx,
        "scene.volume",
        ImageDesc::d3(volume.dims, volume.format.vk()),
    )?;
    add_upload(ctx, graph, frame, "upload_volume", vol, &volume.bytes)?;
    let lut_desc = ImageDesc::d1(lut_size, vk::Format::R32G32B32A32_SFLOAT);
    let tf = [
        graph.image(ctx, "scene.tf_diffuse_opacity", lut_desc)?,
        graph.image(ctx, "scene.tf_specular_roughness", lut_desc)?,
        graph.image(ctx, "scene.tf_emissive", lut_desc)?,
    ];
    let majorant = graph.image(
        ctx,
        "scene.majorant",
        ImageDesc::d3(volume.bricks.grid, vk::Format::R32_SFLOAT),
    )?;
    // Without a map, a black 1×1 stands in (the binding exists in every variant).
    let black = [[0f32; 4]];
    let (width, height, rgba) = match environment {
        Some(e) => (e.width, e.height, &e.rgba[..]),
        None => (1, 1, &black[..]),
    };
    let env = graph.image(
        ctx,
        "scene.environment",
        ImageDesc::d2(width, height, vk::Format::R32G32B32A32_SFLOAT),
    )?;
    add_upload(
        ctx,
        graph,
        frame,
        "upload_environment",
        env,
        bytemuck::cast_slice(rgba),
    )?;
    // Later frames' shaders sample what this frame uploads.
    frame.add_ready_for_sampling("scene_ready", &[vol, tf[0], tf[1], tf[2], majorant, env]);
    Ok(SceneImages {
        volume: vol,
        tf,
        majorant,
        environment: env,
    })
}

/// Max extinction per brick for the current TF: the largest LUT opacity over the
/// brick's density range (LUT entries bracketing the range, since linear interpolation
/// never exceeds its neighbours), times the density scale.
pub fn majorants(bricks: &BrickRanges, opacity: &[f32], density_scale: f32) -> Vec<f32> {
    let n = opacity.len();
    if n == 0 {
        return vec![0.0; bricks.min.len()];
    }
    // Sparse table for O(1) range maxima over the LUT.
    let mut table = vec![opacity.to_vec()];
    let mut span = 1;
    while span * 2 <= n {
        let prev = &table[table.len() - 1];
        let next: Vec<f32> = (0..=n - span * 2)
            .map(|i| prev[i].max(prev[i + span]))
            .collect();
        table.push(next);
        span *= 2;
    }
    let range_max = |lo: usize, hi: usize| {
        let len = hi - lo + 1;
        let k = usize::BITS as usize - 1 - len.leading_zeros() as usize;
        table[k][lo].max(table[k][hi + 1 - (1 << k)])
    };
    let scale = (n - 1) as f32;
    bricks
        .min
        .iter()
        .zip(&bricks.max)
        .map(|(&lo, &hi)| {
            let a = ((lo.clamp(0.0, 1.0) * scale).floor() as usize).min(n - 1);
            let b = ((hi.clamp(0.0, 1.0) * scale).ceil() as usize).min(n - 1);
            range_max(a.min(b), b.max(a)) * density_scale
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn majorant_bounds_every_interpolated_opacity_in_range() {
        let opacity: Vec<f32> = (0..256).map(|i| ((i as f32) * 0.37).sin().abs()).collect();
        let bricks = BrickRanges {
            brick: 8,
            grid: [3, 1, 1],
            min: vec![0.0, 0.2, 0.9],
            max: vec![0.1, 0.55, 1.0],
        };
        let m = majorants(&bricks, &opacity, 2.0);
        for (k, (&lo, &hi)) in bricks.min.iter().zip(&bricks.max).enumerate() {
            for s in 0..=1000 {
                let d = lo + (hi - lo) * s as f32 / 1000.0;
                let x = d * 255.0;
                let i = x.floor() as usize;
                let f = x - i as f32;
                let v = opacity[i] * (1.0 - f) + opacity[(i + 1).min(255)] * f;
                assert!(
                    v * 2.0 <= m[k] + 1e-6,
                    "brick {k} density {d}: {v} > {}",
                    m[k]
                );
            }
        }
        // Tight for a constant range.
        let flat = BrickRanges {
            brick: 8,
            grid: [1, 1, 1],
            min: vec![0.5],
            max: vec![0.5],
        };
        let c = majorants(&flat, &vec![0.25; 256], 4.0);
        assert!((c[0] - 1.0).abs() < 1e-6);
    }
}
