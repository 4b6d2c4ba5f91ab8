//! The guide images of single-frame denoisers (shaders/glsl/aux_features.comp): per pixel
//! the TF albedo and gradient normal composited along the ray with the weights of its
//! first scattering event, the "albedo" and "normal" auxiliary images Intel Open Image
//! Denoise takes. Rendered only when a frame asks for them (`dvr eval --aux`); no
//! denoiser of dvr reads them.

use super::surface_features::STEP_VOXELS;
use super::SceneBindings;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};
use ash::vk;

gpu_block! {
    /// `AuxFeaturesPush` in aux_features.comp.
    pub struct AuxFeaturesPush {
        pub width: u32,
        pub height: u32,
        /// March step in voxels.
        pub step_voxels: f32,
        pub pad: f32,
    }
}

/// The names under which a frame's guide images are read back (beside the methods').
pub const ALBEDO: &str = "aux.albedo";
pub const NORMAL: &str = "aux.normal";

pub struct AuxFeatures {
    pipeline: Pipeline<AuxFeaturesPush>,
}

impl AuxFeatures {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("aux_features", &[])?,
        })
    }

    /// Adds the pass; returns (albedo: rgb, a opacity; normal: xyz world, w opacity).
    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
        scene: &SceneBindings,
        size: Extent,
    ) -> Result<(ImageHandle, ImageHandle)> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let albedo = graph.image(ctx, ALBEDO, desc)?;
        let normal = graph.image(ctx, NORMAL, desc)?;
        let push = AuxFeaturesPush {
            width: size.width,
            height: size.height,
            step_voxels: STEP_VOXELS,
            pad: 0.0,
        };
        frame.add_compute("aux_features", &self.pipeline, push, size, |b| {
            scene.bind_volume(b);
            b.write("aux_albedo", albedo).write("aux_normal", normal);
        });
        Ok((albedo, normal))
    }
}
