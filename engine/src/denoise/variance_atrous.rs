//! One level of the à-trous filter over estimates that carry their variance
//! (shaders/glsl/variance_atrous.comp), shared by ours' spatial filter and the paper's
//! p = \[1\] models: the push block, the pipeline and how a level is added.

use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle};

gpu_block! {
    /// `VarianceAtrousPush` in variance_atrous.comp.
    pub struct VarianceAtrousPush {
        pub width: u32,
        pub height: u32,
        pub step: i32,
        pub kappa: f32,
        pub last: u32,
        pub keep: f32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

/// The pass's pipeline (shared-memory tiles where the device gains from them); `carry`:
/// neighbours are carried to the pixel by a prediction image first (ours' prior).
pub fn pipeline(
    ctx: &GpuContext,
    carry: bool,
    nonnegative: bool,
) -> Result<Pipeline<VarianceAtrousPush>> {
    guided_pipeline(ctx, carry, nonnegative, false)
}

/// As [`pipeline`], with the range term on a guide image when `guided`.
pub fn guided_pipeline(
    ctx: &GpuContext,
    carry: bool,
    nonnegative: bool,
    guided: bool,
) -> Result<Pipeline<VarianceAtrousPush>> {
    ctx.pipeline(
        "variance_atrous",
        &[
            ("SHARED_TILES", SpecValue::Bool(ctx.shared_tiles)),
            ("CARRY", SpecValue::Bool(carry)),
            ("NONNEGATIVE", SpecValue::Bool(nonnegative)),
            ("GUIDED", SpecValue::Bool(guided)),
        ],
    )
}

/// What one level does.
#[derive(Clone, Copy, Debug)]
pub struct Level {
    /// Tap spacing in pixels (1, 2, 4, …).
    pub step: i32,
    /// Standard errors two estimates may differ by and still be blended.
    pub kappa: f32,
    /// Relative standard error below which a pixel is kept as it is (0: none).
    pub keep: f32,
    /// The last level writes the denoiser's output (alpha 1).
    pub last: bool,
    /// Experiment: a guided level's range in the estimates' variances, not the guide's.
    pub own_variance: bool,
    /// Experiment: a guided last level keeps the guide where the state restarted.
    pub select_fresh: bool,
    /// Experiment: the guide's variance scaled by this in the range term.
    pub guide_scale: f32,
}

/// Adds one level `name` from `src` into `dst` (with `prediction` for a `carry` pipeline).
#[allow(clippy::too_many_arguments)]
pub fn add_level<'f>(
    frame: &mut Frame<'f>,
    pipeline: &'f Pipeline<VarianceAtrousPush>,
    name: String,
    size: Extent,
    level: Level,
    src: ImageHandle,
    dst: ImageHandle,
    prediction: Option<ImageHandle>,
) {
    add_guided_level(
        frame, pipeline, name, size, level, src, dst, prediction, None,
    );
}

/// As [`add_level`], with a guide image for a guided pipeline.
#[allow(clippy::too_many_arguments)]
pub fn add_guided_level<'f>(
    frame: &mut Frame<'f>,
    pipeline: &'f Pipeline<VarianceAtrousPush>,
    name: String,
    size: Extent,
    level: Level,
    src: ImageHandle,
    dst: ImageHandle,
    prediction: Option<ImageHandle>,
    guide: Option<ImageHandle>,
) {
    add_guided_level_state(
        frame, pipeline, name, size, level, src, dst, prediction, guide, None,
    );
}

/// As [`add_guided_level`], with the filter's state (model, noise).
#[allow(clippy::too_many_arguments)]
pub fn add_guided_level_state<'f>(
    frame: &mut Frame<'f>,
    pipeline: &'f Pipeline<VarianceAtrousPush>,
    name: String,
    size: Extent,
    level: Level,
    src: ImageHandle,
    dst: ImageHandle,
    prediction: Option<ImageHandle>,
    guide: Option<ImageHandle>,
    state: Option<(ImageHandle, ImageHandle)>,
) {
    let push = VarianceAtrousPush {
        width: size.width,
        height: size.height,
        step: level.step,
        kappa: level.kappa,
        last: level.last as u32,
        keep: level.keep,
        pad1: level.own_variance as u32 | (level.select_fresh as u32) << 1,
        pad2: level.guide_scale.to_bits(),
    };
    frame.add_compute(name, pipeline, push, size, |b| {
        // Without CARRY the shader never reads `prediction`, but the binding exists.
        b.read("color_in", src)
            .write("color_out", dst)
            .read("prediction", prediction.unwrap_or(src))
            .read("guide", guide.unwrap_or(src))
            .read("state_model", state.map_or(src, |s| s.0))
            .read("state_noise", state.map_or(src, |s| s.1));
    });
}
