//! `accum`: progressive accumulation while nothing changes; any camera, light or TF
//! change starts over. Converges to the reference on static scenes, lags on animated ones.

use super::{DenoiseInputs, Denoiser};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::{Frame, ImageHandle, RenderGraph};
use crate::passes::accumulate::Accumulate;

pub struct Accum {
    /// Its registry name, which also names its pass and running sum.
    name: &'static str,
    pass: Accumulate,
}

impl Accum {
    pub fn new(ctx: &GpuContext, name: &'static str) -> Result<Self> {
        Ok(Self {
            name,
            pass: Accumulate::new(ctx)?,
        })
    }
}

impl Denoiser for Accum {
    fn name(&self) -> &str {
        self.name
    }

    fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
    ) -> Result<ImageHandle> {
        if input.changes.any() {
            graph.reset_history(&format!("{}.", self.name));
        }
        self.pass.add(
            ctx,
            graph,
            frame,
            self.name,
            input.noisy,
            input.spp as f32,
            input.size,
        )
    }
}
