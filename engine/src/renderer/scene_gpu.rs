//! The scene's GPU-side data: the density volume as a 3D texture, the transfer function
//! as 1D LUTs, the majorant grid and the environment map. Uploads go through the render
//! graph as transfer passes, like everything else.

use super::brick_pool::{self, Limits, PoolLayout, VolumePath, STORED};
use super::uploads::{BrickRanges, EnvironmentUpload, VolumeUpload};
use crate::error::{EngineError, Result};
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::{BufferHandle, Frame, ImageHandle, RenderGraph};
use ash::vk;
use std::borrow::Cow;

pub struct SceneImages {
    pub volume: ImageHandle,
    pub tf: [ImageHandle; 3],
    pub majorant: ImageHandle,
    pub environment: ImageHandle,
    pub pool: ImageHandle,
    pub brick_table: ImageHandle,
    /// The label map's look (RGBA8: tint, opacity) and shape (R8: the shown labels'
    /// filtered indicator; include/volume.glsl), uploaded by the frames whose look
    /// changed; 1×1×1 stand-ins without a label map.
    pub labels: ImageHandle,
    pub label_shape: ImageHandle,
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
    let staging = graph.staging(ctx, staging, bytes.len() as u64)?;
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

/// The memory budget a renderer assumes without `--gpu-memory`: half the largest
/// device-local heap, so a dense texture and its upload copy fit together (lavapipe: a
/// 1024³ 8-bit volume is dense, a 1024³ 16-bit one is pooled).
pub fn default_budget(ctx: &GpuContext) -> u64 {
    match ctx.info.device_local_heap {
        0 => ctx.info.max_memory_allocation_size,
        heap => heap / 2,
    }
}

/// Decides, before anything is allocated, how `v` reaches the device within `budget`
/// bytes (`None`: [`default_budget`]): one dense texture where it fits the budget and the
/// device's limits, else a brick pool; an error names the volume and the device where
/// not even a pool fits, or where the bytes do not match the header.
pub fn plan_volume(ctx: &GpuContext, v: &VolumeUpload, budget: Option<u64>) -> Result<VolumePath> {
    let texels: u64 = v.dims.iter().map(|&d| d as u64).product();
    let needed = texels * v.texel_bytes() as u64;
    if v.blocks.is_none() && needed != v.bytes.len() as u64 {
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
    let limits = Limits {
        budget: budget.unwrap_or_else(|| default_budget(ctx)),
        max_image_dimension_3d: ctx.info.max_image_dimension_3d,
        max_allocation: ctx.info.max_memory_allocation_size,
        heap: match ctx.info.device_local_heap {
            0 => u64::MAX,
            heap => heap,
        },
    };
    if v.channels() > 1 {
        return plan_channels(ctx, v, needed, &limits);
    }
    brick_pool::plan(v.dims, v.format, &limits).map_err(|why| EngineError::TooLarge {
        what: format!(
            "volume {:?} ({:?} voxels, {:?}): {why}",
            v.name, v.dims, v.format
        ),
        needed,
        limit: limits.budget,
        device: ctx.info.name.clone(),
    })
}

/// A multi-channel medium is held dense (the brick pool pages one field): it must fit
/// the budget and the device's 3D image size.
fn plan_channels(
    ctx: &GpuContext,
    v: &VolumeUpload,
    needed: u64,
    limits: &Limits,
) -> Result<VolumePath> {
    let largest = v.dims.iter().copied().max().unwrap_or(0);
    let why = if largest > limits.max_image_dimension_3d {
        format!(
            "{largest} voxels along an axis; the device's 3D images reach {}",
            limits.max_image_dimension_3d
        )
    } else if needed > limits.budget.min(limits.max_allocation) {
        "a medium of several channels is held as one dense texture and does not fit \
         (raise --gpu-memory, or pick fewer channels)"
            .to_string()
    } else {
        return Ok(VolumePath::Dense);
    };
    Err(EngineError::TooLarge {
        what: format!(
            "volume {:?} ({:?} voxels, {} channels of {:?}): {why}",
            v.name,
            v.dims,
            v.channels(),
            v.format
        ),
        needed,
        limit: limits.budget,
        device: ctx.info.name.clone(),
    })
}

/// What [`create`] makes the scene images for.
pub struct SceneDesc<'a> {
    pub volume: &'a VolumeUpload,
    pub path: &'a VolumePath,
    pub environment: Option<&'a EnvironmentUpload>,
    pub lut_size: u32,
    /// Whether a label map's look is read beside the volume.
    pub labels: bool,
}

/// Creates the scene images and adds their uploads to `frame`: the volume (dense, or the
/// coarse copy beneath a brick pool), the pool and its brick table (1×1×1 stand-ins on
/// the dense path, whose shaders never read them), the LUTs, majorant grid and
/// environment map, and the label look (a 1×1×1 stand-in without a label map).
pub fn create<'f>(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'f>,
    desc: &SceneDesc<'_>,
) -> Result<SceneImages> {
    let SceneDesc {
        volume,
        path,
        environment,
        lut_size,
        labels,
    } = *desc;
    let mask = super::packing::mask_in_volume(volume, labels);
    let format = if mask {
        volume.format.vk_components(2)
    } else {
        volume.vk_format()
    };
    // Dense: the volume itself (with the label mask beside each density, all shown until
    // the first frame's look), and 1×1×1 pool and table no shader reads. Pooled: the
    // coarse copy, the pool (slots are written as the TF makes their bricks visible, and
    // read only through the table, which starts with no slot) and the table.
    let (volume_dims, volume_bytes, pool_extent, grid, no_slot) = match path {
        VolumePath::Dense if mask => (
            volume.dims,
            Cow::Owned(super::packing::with_mask(volume, None)),
            [1; 3],
            [1; 3],
            0.0,
        ),
        VolumePath::Dense => (volume.dims, volume.dense_bytes(), [1; 3], [1; 3], 0.0),
        VolumePath::Pool(layout) => (
            layout.coarse_dims,
            Cow::Owned(volume.coarse(layout.level, layout.coarse_dims)),
            layout.pool_extent(),
            layout.grid,
            -1.0,
        ),
    };
    let vol = graph.image(ctx, "scene.volume", ImageDesc::d3(volume_dims, format))?;
    add_upload(ctx, graph, frame, "upload_volume", vol, &volume_bytes)?;
    let pool = graph.image(ctx, "scene.brick_pool", ImageDesc::d3(pool_extent, format))?;
    let table_desc = ImageDesc::d3(grid, vk::Format::R32G32_SFLOAT);
    let table = graph.image(ctx, "scene.brick_table", table_desc)?;
    let entries = vec![[-1f32, no_slot]; table_desc.texel_count() as usize];
    let entries = bytemuck::cast_slice(&entries);
    add_upload(ctx, graph, frame, "upload_brick_table", table, entries)?;
    // One LUT segment per channel (include/volume.glsl, channel_lut_coord).
    let lut_desc = ImageDesc::d1(
        lut_size * volume.channels(),
        vk::Format::R32G32B32A32_SFLOAT,
    );
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
    let label_dims = if labels { volume.dims } else { [1; 3] };
    let label_desc = ImageDesc::d3(label_dims, vk::Format::R8G8B8A8_UNORM);
    let label_look = graph.image(ctx, "scene.labels", label_desc)?;
    let shape_desc = ImageDesc::d3(label_dims, vk::Format::R8_UNORM);
    let label_shape = graph.image(ctx, "scene.label_shape", shape_desc)?;
    if !labels {
        add_upload(ctx, graph, frame, "upload_labels", label_look, &[255; 4])?;
        add_upload(ctx, graph, frame, "upload_label_shape", label_shape, &[255])?;
    }
    // Later frames' shaders sample what this frame uploads.
    frame.add_ready_for_sampling(
        "scene_ready",
        &[
            vol,
            tf[0],
            tf[1],
            tf[2],
            majorant,
            env,
            pool,
            table,
            label_look,
            label_shape,
        ],
    );
    Ok(SceneImages {
        volume: vol,
        tf,
        majorant,
        environment: env,
        pool,
        brick_table: table,
        labels: label_look,
        label_shape,
    })
}

/// Adds a pass that copies bricks of `volume` into their pool slots through the staging
/// buffer `staging` (at least `uploads.len()` bricks long).
pub fn add_brick_uploads(
    graph: &mut RenderGraph,
    frame: &mut Frame<'_>,
    staging: BufferHandle,
    pool: ImageHandle,
    volume: &VolumeUpload,
    layout: &PoolLayout,
    uploads: &[(u32, u32)],
) -> Result<()> {
    let size = brick_pool::brick_bytes(volume.format);
    let mut bytes = vec![0u8; size * uploads.len()];
    let [gx, gy, _] = layout.grid;
    let mut regions = Vec::with_capacity(uploads.len());
    for (i, (&(b, s), out)) in uploads.iter().zip(bytes.chunks_mut(size)).enumerate() {
        let brick = [b % gx, (b / gx) % gy, b / (gx * gy)];
        brick_pool::write_brick(volume, brick, out);
        let [x, y, z] = layout.slot_origin(s);
        regions.push(
            vk::BufferImageCopy::default()
                .buffer_offset((i * size) as u64)
                .image_subresource(
                    vk::ImageSubresourceLayers::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .layer_count(1),
                )
                .image_offset(vk::Offset3D {
                    x: x as i32,
                    y: y as i32,
                    z: z as i32,
                })
                .image_extent(vk::Extent3D {
                    width: STORED,
                    height: STORED,
                    depth: STORED,
                }),
        );
    }
    graph.buffer_mut(staging).write(&bytes)?;
    frame.add_pass(
        "upload_bricks".to_string(),
        |b| {
            b.transfer_src(staging).transfer_dst(pool);
        },
        move |pc| pc.copy_buffer_to_image_regions(staging, pool, &regions),
    );
    Ok(())
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

/// Zeroes the majorant of every brick that one cut removes whole (see
/// [`Cut::removes`](crate::scene::Cut::removes)), for a volume of `dims` voxels spanning `world` units: the majorant
/// grid then skips it, and the brick pool does not make it resident.
pub fn mask_cut(
    majorants: &mut [f32],
    bricks: &BrickRanges,
    dims: [u32; 3],
    world: [f32; 3],
    cut: &crate::scene::Cut,
) {
    if !cut.active() {
        return;
    }
    let world = glam::Vec3::from(world).as_dvec3();
    let voxel = world / glam::DVec3::from(dims.map(f64::from));
    let [gx, gy, _] = bricks.grid;
    let edge = f64::from(bricks.brick);
    for (i, m) in majorants.iter_mut().enumerate() {
        let i = i as u32;
        let cell = glam::DVec3::new(
            f64::from(i % gx),
            f64::from((i / gx) % gy),
            f64::from(i / (gx * gy)),
        );
        // The brick's voxels, widened by one for trilinear reads across its faces.
        let lo = (cell * edge - 1.0) * voxel - world * 0.5;
        let hi = ((cell + 1.0) * edge + 1.0) * voxel - world * 0.5;
        if cut.removes(lo, hi, world, dims) {
            *m = 0.0;
        }
    }
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
