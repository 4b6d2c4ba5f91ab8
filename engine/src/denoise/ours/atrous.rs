//! `<name>.atrous0..k` (ours_atrous.comp): the à-trous spatial filter over the filters'
//! estimates, edge-stopped by their variances: steps 1, 2, 4, … ping-ponging between the
//! estimate and a scratch image, the last level into the denoiser's output.

use super::Ours;
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};

gpu_block! {
    /// `OursAtrousPush` in ours_atrous.comp.
    pub struct OursAtrousPush {
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

impl Ours {
    pub(super) fn add_atrous<'f>(
        &'f self,
        pipeline: &'f Pipeline<OursAtrousPush>,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        size: Extent,
        estimate: ImageHandle,
    ) -> Result<ImageHandle> {
        let n = &self.name;
        let desc = graph.image_desc(estimate);
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        let ping = graph.image(ctx, &format!("{n}.atrous"), desc)?;
        let levels = super::ATROUS_LEVELS;
        let mut src = estimate;
        for i in 0..levels {
            let last = i + 1 == levels;
            let dst = match (last, src == ping) {
                (true, _) => out,
                (false, true) => estimate,
                (false, false) => ping,
            };
            let push = OursAtrousPush {
                width: size.width,
                height: size.height,
                step: 1 << i,
                kappa: self.params.kappa,
                last: last as u32,
                keep: self.params.keep,
                pad1: 0,
                pad2: 0,
            };
            frame.add_compute(format!("{n}.atrous{i}"), pipeline, push, size, |b| {
                b.read("color_in", src).write("color_out", dst);
            });
            src = dst;
        }
        Ok(out)
    }
}
