//! `none`: the noisy input, unchanged (the baseline every method is compared with).

use super::{DenoiseInputs, Denoiser};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::{Frame, ImageHandle, RenderGraph};

pub struct Passthrough;

impl Denoiser for Passthrough {
    fn name(&self) -> &str {
        "none"
    }

    fn add<'f>(
        &'f self,
        _ctx: &GpuContext,
        _graph: &mut RenderGraph,
        _frame: &mut Frame<'f>,
        input: &DenoiseInputs,
    ) -> Result<ImageHandle> {
        Ok(input.noisy)
    }
}
