//! `none`: the noisy input, unchanged (the baseline every method is compared with).

use super::{Built, DenoiseFrame, Denoiser, DenoiserConfig};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::ImageHandle;

pub struct Passthrough;

impl Passthrough {
    pub fn create(_: &GpuContext, _: &'static str, _: &DenoiserConfig) -> Built {
        Ok(Box::new(Passthrough))
    }
}

impl Denoiser for Passthrough {
    fn add<'f>(&'f self, f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        Ok(f.input.noisy)
    }
}
