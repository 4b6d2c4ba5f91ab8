//! The path-tracing pass (shaders/glsl/path_trace.comp): this frame's noisy radiance, its
//! luminance moments and the closest first real collision per pixel.

use super::SceneBindings;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::{Extent, Frame, History, ImageHandle, RenderGraph};
use crate::scene::{Estimator, LabelMode, Phase, PipelineKey};
use crate::shaders::frame::{
    ESTIMATOR_DELTA, ESTIMATOR_RAY_MARCH, LABELS_NONE, LABELS_SOLID, LABELS_TINT, PHASE_HG,
    PHASE_HYBRID, PHASE_ISOTROPIC,
};
use ash::vk;

gpu_block! {
    /// `PathTracePush` in path_trace.comp.
    pub struct PathTracePush {
        /// Index of this dispatch's first sample (references accumulate batches).
        pub sample_offset: u32,
        pub spp: u32,
        pub width: u32,
        pub height: u32,
    }
}

/// How the volume is held, which every pipeline that reads it is specialised for
/// (include/volume.glsl): dense or paged through the brick pool, how many channels its
/// texels pack (1–4), and whether a label map's look is read beside it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VolumeLayout {
    pub pooled: bool,
    pub channels: u32,
    pub labels: Option<LabelMode>,
}

impl Default for VolumeLayout {
    fn default() -> Self {
        Self {
            pooled: false,
            channels: 1,
            labels: None,
        }
    }
}

/// What the pipeline is specialised for (what the scene uses): the render settings'
/// [`PipelineKey`], whether an environment map is bound and how the volume is held.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct PathTraceFeatures {
    pub estimator: Estimator,
    pub phase: Phase,
    pub emission: bool,
    pub environment_map: bool,
    pub volume: VolumeLayout,
}

impl PathTraceFeatures {
    pub fn new(key: PipelineKey, environment_map: bool, volume: VolumeLayout) -> Self {
        Self {
            estimator: key.estimator,
            phase: key.phase,
            emission: key.emission,
            environment_map,
            volume,
        }
    }
}

/// The specialisation of a pipeline that reads the volume (include/volume.glsl).
pub fn volume_specialization(volume: VolumeLayout) -> [(&'static str, SpecValue); 3] {
    let labels = match volume.labels {
        None => LABELS_NONE,
        Some(LabelMode::Tint) => LABELS_TINT,
        Some(LabelMode::Solid) => LABELS_SOLID,
    };
    [
        ("POOLED_VOLUME", SpecValue::Bool(volume.pooled)),
        ("CHANNELS", SpecValue::I32(volume.channels as i32)),
        ("LABELS", SpecValue::I32(labels)),
    ]
}

/// The specialisation constants of a pipeline that traces paths (include/path.glsl):
/// the path tracer's, and ours' temporal-gradient pass, which must trace the same paths.
pub fn specialization(features: PathTraceFeatures) -> [(&'static str, SpecValue); 7] {
    let estimator = match features.estimator {
        Estimator::Delta => ESTIMATOR_DELTA,
        Estimator::RayMarch => ESTIMATOR_RAY_MARCH,
    };
    let phase = match features.phase {
        Phase::Isotropic => PHASE_ISOTROPIC,
        Phase::Hg => PHASE_HG,
        Phase::Hybrid => PHASE_HYBRID,
    };
    let [pooled, channels, labels] = volume_specialization(features.volume);
    [
        ("ESTIMATOR", SpecValue::I32(estimator)),
        ("PHASE", SpecValue::I32(phase)),
        ("USE_EMISSION", SpecValue::Bool(features.emission)),
        ("HAS_ENV_MAP", SpecValue::Bool(features.environment_map)),
        pooled,
        channels,
        labels,
    ]
}

pub struct PathTrace {
    pipeline: Pipeline<PathTracePush>,
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
        Ok(Self {
            pipeline: ctx.pipeline("path_trace", &specialization(features))?,
        })
    }

    /// Adds the pass as `name`, writing images `<name>.radiance` etc.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
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
        let push = PathTracePush {
            sample_offset,
            spp,
            width: size.width,
            height: size.height,
        };
        frame.add_compute(name, &self.pipeline, push, size, |b| {
            scene.bind_volume(b);
            b.sampled("environment_map", scene.environment)
                .write("radiance", out.radiance)
                .write("moments", out.moments)
                .write("first_hit", out.first_hit.cur);
        });
        Ok(out)
    }
}
