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
    ctx.pipeline(
        "variance_atrous",
        &[
            ("SHARED_TILES", SpecValue::Bool(ctx.shared_tiles)),
            ("CARRY", SpecValue::Bool(carry)),
            ("NONNEGATIVE", SpecValue::Bool(nonnegative)),
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
    let push = VarianceAtrousPush {
        width: size.width,
        height: size.height,
        step: level.step,
        kappa: level.kappa,
        last: level.last as u32,
        keep: level.keep,
        pad1: 0,
        pad2: 0,
    };
    frame.add_compute(name, pipeline, push, size, |b| {
        // Without CARRY the shader never reads `prediction`, but the binding exists.
        b.read("color_in", src)
            .write("color_out", dst)
            .read("prediction", prediction.unwrap_or(src));
    });
}
