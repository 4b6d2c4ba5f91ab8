//! `accum`: progressive accumulation while nothing changes; any camera, light or TF
//! change starts over. Converges to the reference on static scenes, lags on animated ones.

use super::{Built, DenoiseFrame, Denoiser, DenoiserConfig};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::ImageHandle;
use crate::passes::accumulate::Accumulate;

pub struct Accum {
    /// Its registry name, which also names its pass and running sum.
    name: &'static str,
    pass: Accumulate,
}

impl Accum {
    pub fn create(ctx: &GpuContext, name: &'static str, _: &DenoiserConfig) -> Built {
        Ok(Box::new(Self {
            name,
            pass: Accumulate::new(ctx)?,
        }))
    }
}

impl Denoiser for Accum {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
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
