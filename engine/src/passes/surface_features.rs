//! Deterministic surface features (shaders/glsl/surface_features.comp): position, normal,
//! depth and albedo where accumulated opacity crosses a threshold.

use super::SceneBindings;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{Bindings, Extent, Frame, History, ImageHandle, RenderGraph};
use crate::passes::path_trace::{volume_specialization, VolumeLayout};
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

impl FeatureImages {
    /// The frame's feature images, for whichever pass writes them (this one, or
    /// [`super::aux_features::AuxFeatures`], whose march finds the same surface).
    pub fn new(ctx: &GpuContext, graph: &mut RenderGraph, size: Extent) -> Result<Self> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        Ok(Self {
            position: graph.history(ctx, "features.position", desc)?,
            normal: graph.image(ctx, "features.normal", desc)?,
            albedo: graph.image(ctx, "features.albedo", desc)?,
        })
    }

    /// Binds the images as a features pass writes them.
    pub fn bind_written(&self, b: &mut Bindings) {
        b.write("feature_position", self.position.cur)
            .write("feature_normal", self.normal)
            .write("feature_albedo", self.albedo);
    }
}

impl SurfaceFeatures {
    pub fn new(ctx: &GpuContext, volume: VolumeLayout) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("surface_features", &volume_specialization(volume))?,
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
        let out = FeatureImages::new(ctx, graph, size)?;
        let push = FeaturesPush {
            width: size.width,
            height: size.height,
            step_voxels: STEP_VOXELS,
            pad: 0.0,
        };
        frame.add_compute("surface_features", &self.pipeline, push, size, |b| {
            scene.bind_volume(b);
            out.bind_written(b);
        });
        Ok(out)
    }
}
