//! Denoisers. Each is a few render-graph passes plus the history resources it owns,
//! behind one trait; all read the same noisy frame and the same features and motion, so
//! differences between methods are the denoisers' alone.

mod accum;
mod entry;
pub mod ours;
mod overrides;
mod passthrough;
pub mod rae;
pub mod registry;
pub mod svgf;
pub mod taa;
pub mod variance_atrous;
pub mod wrls_paper;

pub use accum::Accum;
pub use ours::{Ours, OursVariant};
#[cfg(test)]
pub(crate) use overrides::assert_overrides_refused;
pub use overrides::{check_env_overrides, override_variables, unused_overrides, with_overrides};
pub use overrides::{Overridable, Overrides, Tunables};
pub use passthrough::Passthrough;
pub use rae::{Rae, RaeWeights};
pub use registry::{Build, Built, DenoiserConfig, DenoiserInfo, FeatureUse, Registry, DENOISERS};
pub use svgf::Svgf;
pub use taa::Taa;
pub use wrls_paper::{Wrls, WrlsVariant};

use crate::error::{EngineError, Result};
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::{Bindings, BufferHandle, Extent, Frame, History, ImageHandle, RenderGraph};
use crate::passes::surface_features::FeatureImages;
use crate::passes::SceneBindings;
use ash::vk;

/// Disocclusion tolerance of the shared reprojection (include/reproject.glsl): how far,
/// in pixels, last frame's surface may land from this pixel when projected back.
pub const REPROJECTION_TOLERANCE_PX: f32 = 1.5;

/// Which per-pixel world position drives motion vectors and the disocclusion test.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MotionSource {
    /// The closest first real collision among the frame's samples (the paper's choice).
    #[default]
    FirstHit,
    /// The deterministic surface features: the opacity-threshold position, or the expected
    /// first collision through semi-transparent layers.
    Features,
}

impl MotionSource {
    pub const ALL: [MotionSource; 2] = [MotionSource::FirstHit, MotionSource::Features];

    /// The name on the command line, in scene sessions and in reports.
    pub fn name(self) -> &'static str {
        match self {
            MotionSource::FirstHit => "first-hit",
            MotionSource::Features => "features",
        }
    }

    /// The value of the shaders' MOTION_SOURCE specialisation constant.
    pub fn spec(self) -> i32 {
        match self {
            MotionSource::FirstHit => 0,
            MotionSource::Features => 1,
        }
    }
}

impl std::fmt::Display for MotionSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for MotionSource {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown motion source {s:?}; use first-hit or features"))
    }
}

/// What changed since the previous frame (drives resets of history-based methods).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Changes {
    pub camera: bool,
    pub lights: bool,
    pub transfer_function: bool,
    /// The clip planes or the crop box.
    pub cut: bool,
}

impl Changes {
    pub fn any(&self) -> bool {
        self.camera || self.lights || self.transfer_function || self.cut
    }
}

/// Everything a denoiser may read this frame.
#[derive(Clone, Copy, Debug)]
pub struct DenoiseInputs {
    pub uniforms: BufferHandle,
    /// This frame's noisy HDR radiance (rgba32f).
    pub noisy: ImageHandle,
    /// Luminance moments (x mean, y second moment).
    pub moments: ImageHandle,
    /// Deterministic surface features; rendered only when a denoiser of this frame
    /// reads them (its registry entry's [`DenoiserInfo::features`]).
    pub features: Option<FeatureImages>,
    /// The guide albedo composited along each ray (aux_features.comp: rgb, a opacity);
    /// rendered only when a denoiser of this frame reads it ([`DenoiserInfo::guides`]).
    pub guides: Option<ImageHandle>,
    /// Closest first real collision per pixel, this frame's and last frame's.
    pub first_hit: History,
    /// Motion to the previous frame in pixels: xy from the first collision, zw from features.
    pub motion: ImageHandle,
    pub size: Extent,
    /// Camera position this frame (disocclusion tolerances scale with distance).
    pub camera: glam::Vec3,
    pub spp: u32,
    pub changes: Changes,
    /// Last frame's samples as this frame's scene can re-trace them; `None` on the first
    /// frame, after a reset, and where there is no scene (synthetic inputs).
    pub retrace: Option<Retrace>,
}

/// What re-tracing last frame's samples in this frame's scene needs (ours' temporal
/// gradients): the scene, last frame's camera and sample stream, and what it measured.
#[derive(Clone, Copy, Debug)]
pub struct Retrace {
    pub scene: SceneBindings,
    /// Last frame's noisy radiance.
    pub radiance_prev: ImageHandle,
    pub inv_view_proj_prev: glam::Mat4,
    pub camera_prev: glam::Vec3,
    /// Last frame's index (its random numbers).
    pub frame_prev: u32,
}

impl DenoiseInputs {
    /// An RGBA32F image of the frame's size: what every denoiser's output is, and most of
    /// its histories and intermediate images.
    pub fn rgba32f(&self) -> ImageDesc {
        ImageDesc::d2(
            self.size.width,
            self.size.height,
            vk::Format::R32G32B32A32_SFLOAT,
        )
    }

    /// The surface features, or an error naming the denoiser that forgot to ask for them.
    pub fn features(&self, denoiser: &str) -> Result<FeatureImages> {
        self.features.ok_or_else(|| EngineError::Pass {
            pass: denoiser.to_string(),
            problem: "surface features were not rendered: its registry entry \
                      (denoise/registry.rs) must say it reads them"
                .into(),
        })
    }

    /// The resources of the shared reprojection (include/reproject.glsl) for a motion
    /// source: the frame uniforms, the motion vectors, and this and last frame's world
    /// positions from that source.
    pub fn reprojection(&self, denoiser: &str, motion: MotionSource) -> Result<Reprojection> {
        let positions = match motion {
            MotionSource::FirstHit => self.first_hit,
            MotionSource::Features => self.features(denoiser)?.position,
        };
        Ok(Reprojection {
            uniforms: self.uniforms,
            motion: self.motion,
            position_cur: positions.cur,
            position_prev: positions.prev,
            valid: positions.valid,
        })
    }
}

/// What every temporal denoiser's reprojecting pass declares and binds, in one place.
#[derive(Clone, Copy, Debug)]
pub struct Reprojection {
    uniforms: BufferHandle,
    motion: ImageHandle,
    position_cur: ImageHandle,
    position_prev: ImageHandle,
    /// Last frame's positions exist (false on the first frame and after resets).
    pub valid: bool,
}

impl Reprojection {
    /// Binds the frame block, motion and positions to the variables include/frame.glsl
    /// and include/reproject.glsl declare.
    pub fn bind(&self, b: &mut Bindings) {
        b.uniform("frame", self.uniforms)
            .read("motion", self.motion)
            .read("position_cur", self.position_cur)
            .sampled_nearest("position_prev", self.position_prev);
    }
}

/// What a denoiser adds its passes with: the device, the graph, the frame being
/// recorded (whose passes the renderer counts as the denoiser's own) and the frame's
/// inputs.
pub struct DenoiseFrame<'a, 'f> {
    pub ctx: &'a GpuContext,
    pub graph: &'a mut RenderGraph,
    pub frame: &'a mut Frame<'f>,
    pub input: &'a DenoiseInputs,
}

impl<'a, 'f> DenoiseFrame<'a, 'f> {
    /// The device, graph, frame and inputs, for a body that hands them to its passes
    /// (and then this frame to its next stage).
    pub fn parts(
        &mut self,
    ) -> (
        &'a GpuContext,
        &mut RenderGraph,
        &mut Frame<'f>,
        &'a DenoiseInputs,
    ) {
        (self.ctx, &mut *self.graph, &mut *self.frame, self.input)
    }
}

/// A denoiser: its registry row names it ([`DenoiserInfo::name`]), and it names its own
/// passes and images after that name.
pub trait Denoiser {
    /// Adds the denoiser's passes; returns its HDR output image.
    fn add<'f>(&'f self, f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle>;
}
