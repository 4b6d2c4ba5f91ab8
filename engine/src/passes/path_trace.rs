//! The path-tracing pass (shaders/glsl/path_trace.comp): this frame's noisy radiance, its
//! luminance moments and the closest first real collision per pixel.

use super::{Extent, SceneBindings};
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc, SpecValue};
use crate::graph::{Bind, Frame, History, ImageHandle, RenderGraph};
use crate::renderer::uniforms::PathTracePush;
use ash::vk;

// The estimator and phase function are scene settings; one definition, in `scene`.
pub use crate::scene::{Estimator, Phase};

/// What the pipeline is specialised for (what the scene uses).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PathTraceFeatures {
    pub estimator: Estimator,
    pub phase: Phase,
    pub emission: bool,
    pub environment_map: bool,
}

/// The specialisation constants of a pipeline that traces paths (include/path.glsl):
/// the path tracer's, and ours' temporal-gradient pass, which must trace the same paths.
pub fn specialization(features: PathTraceFeatures) -> [(&'static str, SpecValue); 4] {
    let estimator = match features.estimator {
        Estimator::Delta => 0,
        Estimator::RayMarch => 1,
    };
    let phase = match features.phase {
        Phase::Isotropic => 0,
        Phase::Hg => 1,
        Phase::Hybrid => 2,
    };
    [
        ("ESTIMATOR", SpecValue::I32(estimator)),
        ("PHASE", SpecValue::I32(phase)),
        ("USE_EMISSION", SpecValue::Bool(features.emission)),
        ("HAS_ENV_MAP", SpecValue::Bool(features.environment_map)),
    ]
}

pub struct PathTrace {
    pipeline: ComputePipeline,
}

#[derive(Clone, Copy, Debug)]
pub struct PathTraceOutputs {
    /// This frame's radiance (`radiance_history.cur`).
    pub radiance: ImageHandle,
    /// This and last frame's radiance (ours' temporal gradients re-trace last frame's
    /// samples and compare).
    pub radiance_history: History,
    pub moments: ImageHandle,
    /// World position of the closest first real collision (w = 1 where hit); `prev`
    /// holds last frame's, for disocclusion tests.
    pub first_hit: History,
}

impl PathTrace {
    pub fn new(ctx: &GpuContext, features: PathTraceFeatures) -> Result<Self> {
        let pipeline = ComputePipeline::new(ctx, "path_trace", &specialization(features))?;
        Ok(Self { pipeline })
    }

    /// Adds the pass as `name`, writing images `<name>.radiance` etc.
    #[allow(clippy::too_many_arguments)]
    pub fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        name: &str,
        scene: &SceneBindings,
        size: Extent,
        sample_offset: u32,
        spp: u32,
    ) -> Result<PathTraceOutputs> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let radiance_history = graph.history(ctx, &format!("{name}.radiance"), desc)?;
        let out = PathTraceOutputs {
            radiance: radiance_history.cur,
            radiance_history,
            moments: graph.image(ctx, &format!("{name}.moments"), desc)?,
            first_hit: graph.history(ctx, &format!("{name}.first_hit"), desc)?,
        };
        let scene = *scene;
        let push = PathTracePush {
            sample_offset,
            spp,
            width: size.width,
            height: size.height,
        };
        frame.add_pass(
            name,
            |b| {
                scene.declare_volume(b);
                b.sampled(scene.environment)
                    .write(out.radiance)
                    .write(out.moments)
                    .write(out.first_hit.cur);
            },
            move |pc| {
                let mut binds = scene.volume_binds();
                binds.extend([
                    ("environment_map", Bind::Image(scene.environment)),
                    ("radiance", Bind::Image(out.radiance)),
                    ("moments", Bind::Image(out.moments)),
                    ("first_hit", Bind::Image(out.first_hit.cur)),
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
