//! Deterministic surface features (shaders/glsl/surface_features.comp): position, normal,
//! depth and albedo where accumulated opacity crosses a threshold.

use super::SceneBindings;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, History, ImageHandle, RenderGraph};
use crate::passes::path_trace::volume_specialization;
use ash::vk;

gpu_block! {
    /// `FeaturesPush` in surface_features.comp.
    pub struct FeaturesPush {
        pub width: u32,
        pub height: u32,
        /// March step in voxels.
        pub step_voxels: f32,
        pub pad: f32,
    }
}

/// March step in voxels: fine enough that one-voxel vessels are not skipped.
pub const STEP_VOXELS: f32 = 0.5;

pub struct SurfaceFeatures {
    pipeline: Pipeline<FeaturesPush>,
}

#[derive(Clone, Copy, Debug)]
pub struct FeatureImages {
    /// xyz world position, w = 1 where valid; `prev` is last frame's.
    pub position: History,
    /// xyz normal (towards the viewer), w = distance along the ray.
    pub normal: ImageHandle,
    /// rgb TF albedo, w = 1 where valid.
    pub albedo: ImageHandle,
}

impl SurfaceFeatures {
    /// `pooled`: the volume is paged through the brick pool.
    pub fn new(ctx: &GpuContext, pooled: bool) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("surface_features", &[volume_specialization(pooled)])?,
        })
    }

    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
        scene: &SceneBindings,
        size: Extent,
    ) -> Result<FeatureImages> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let out = FeatureImages {
            position: graph.history(ctx, "features.position", desc)?,
            normal: graph.image(ctx, "features.normal", desc)?,
            albedo: graph.image(ctx, "features.albedo", desc)?,
        };
        let push = FeaturesPush {
            width: size.width,
            height: size.height,
            step_voxels: STEP_VOXELS,
            pad: 0.0,
        };
        frame.add_compute("surface_features", &self.pipeline, push, size, |b| {
            scene.bind_volume(b);
            b.write("feature_position", out.position.cur)
                .write("feature_normal", out.normal)
                .write("feature_albedo", out.albedo);
        });
        Ok(out)
    }
}
