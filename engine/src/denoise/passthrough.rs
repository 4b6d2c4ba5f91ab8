//! `none`: the noisy input, unchanged (the baseline every method is compared with).

use super::{DenoiseInputs, Denoiser};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::{Frame, ImageHandle, RenderGraph};

/// The name comes from its registry row.
pub struct Passthrough(pub &'static str);

impl Denoiser for Passthrough {
    fn name(&self) -> &str {
        self.0
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
