//! Deterministic surface features (shaders/glsl/surface_features.comp): position, normal,
//! depth and albedo where accumulated opacity crosses a threshold.

use super::{Extent, SceneBindings};
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc};
use crate::graph::{Bind, Frame, History, ImageHandle, RenderGraph};
use crate::renderer::uniforms::FeaturesPush;
use ash::vk;

/// March step in voxels: fine enough that one-voxel vessels are not skipped.
pub const STEP_VOXELS: f32 = 0.5;

pub struct SurfaceFeatures {
    pipeline: ComputePipeline,
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
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(ctx, "surface_features", &[])?,
        })
    }

    pub fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        scene: &SceneBindings,
        size: Extent,
    ) -> Result<FeatureImages> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let out = FeatureImages {
            position: graph.history(ctx, "features.position", desc)?,
            normal: graph.image(ctx, "features.normal", desc)?,
            albedo: graph.image(ctx, "features.albedo", desc)?,
        };
        let scene = *scene;
        let push = FeaturesPush {
            width: size.width,
            height: size.height,
            step_voxels: STEP_VOXELS,
            pad: 0.0,
        };
        frame.add_pass(
            "surface_features",
            |b| {
                scene.declare_volume(b);
                b.write(out.position.cur)
                    .write(out.normal)
                    .write(out.albedo);
            },
            move |pc| {
                let mut binds = scene.volume_binds();
                binds.extend([
                    ("feature_position", Bind::Image(out.position.cur)),
                    ("feature_normal", Bind::Image(out.normal)),
                    ("feature_albedo", Bind::Image(out.albedo)),
                ]);
                let groups = self.pipeline.groups_2d(size.width, size.height);
                pc.dispatch(&self.pipeline, &binds, &push, groups)
            },
        );
        Ok(out)
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        self.pipeline.destroy(ctx);
    }
}
