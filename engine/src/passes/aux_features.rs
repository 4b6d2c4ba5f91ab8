//! The guide images of single-frame denoisers (shaders/glsl/aux_features.comp): per pixel
//! the TF albedo and gradient normal composited along the ray with the weights of its
//! first scattering event, the "albedo" and "normal" auxiliary images Intel Open Image
//! Denoise takes. Rendered when a frame asks for them (`dvr eval --aux`) and, albedo
//! only (a pipeline without the normal's six extra fetches a step), when SVGF reads them
//! to demodulate (`include/svgf.glsl`, `svgf_demod_factor`). Its march also finds the
//! threshold surface and writes the surface features, so a frame that needs both marches
//! once.

use super::path_trace::{volume_specialization, VolumeLayout};
use super::surface_features::{FeatureImages, STEP_VOXELS};
use super::SceneBindings;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
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
    /// The same pass without the normal guide (its image holds zero and the opacity).
    albedo_only: Pipeline<AuxFeaturesPush>,
}

impl AuxFeatures {
    pub fn new(ctx: &GpuContext, volume: VolumeLayout) -> Result<Self> {
        let [pooled, channels, labels] = volume_specialization(volume);
        Ok(Self {
            pipeline: ctx.pipeline("aux_features", &[pooled, channels, labels])?,
            albedo_only: ctx.pipeline(
                "aux_features",
                &[
                    ("GUIDE_NORMALS", SpecValue::Bool(false)),
                    pooled,
                    channels,
                    labels,
                ],
            )?,
        })
    }

    /// The guide images the pass writes: (albedo, normal).
    pub fn images(
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        size: Extent,
    ) -> Result<(ImageHandle, ImageHandle)> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        Ok((
            graph.image(ctx, ALBEDO, desc)?,
            graph.image(ctx, NORMAL, desc)?,
        ))
    }

    /// Adds the pass; returns (albedo: rgb, a opacity; normal: xyz world, w opacity).
    /// Without `normals` the normal image holds zero and the opacity. The same march
    /// writes the surface features into `features`.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
        scene: &SceneBindings,
        size: Extent,
        normals: bool,
        features: FeatureImages,
    ) -> Result<(ImageHandle, ImageHandle)> {
        let (albedo, normal) = Self::images(ctx, graph, size)?;
        let push = AuxFeaturesPush {
            width: size.width,
            height: size.height,
            step_voxels: STEP_VOXELS,
            pad: 0.0,
        };
        let pipeline = if normals {
            &self.pipeline
        } else {
            &self.albedo_only
        };
        frame.add_compute("aux_features", pipeline, push, size, |b| {
            scene.bind_volume(b);
            b.write("aux_albedo", albedo).write("aux_normal", normal);
            features.bind_written(b);
        });
        Ok((albedo, normal))
    }
}
