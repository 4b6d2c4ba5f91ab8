//! Progressive accumulation (shaders/glsl/accumulate.comp): a running sum in a history
//! pair and its mean. The `accum` denoiser and reference rendering both use it.

use super::Extent;
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc};
use crate::graph::{Bind, Frame, ImageHandle, RenderGraph};
use crate::renderer::uniforms::AccumulatePush;
use ash::vk;

pub struct Accumulate {
    pipeline: ComputePipeline,
}

impl Accumulate {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(ctx, "accumulate", &[])?,
        })
    }

    /// Adds `radiance` (carrying `weight` samples) to the running sum `name`; returns the
    /// running mean. The sum restarts when its history is invalid (reset or first frame).
    #[allow(clippy::too_many_arguments)]
    pub fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        name: &str,
        radiance: ImageHandle,
        weight: f32,
        size: Extent,
    ) -> Result<ImageHandle> {
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let sum = graph.history(ctx, &format!("{name}.sum"), desc)?;
        let mean = graph.image(ctx, &format!("{name}.out"), desc)?;
        let push = AccumulatePush {
            width: size.width,
            height: size.height,
            history_valid: sum.valid as u32,
            weight,
        };
        frame.add_pass(
            name,
            |b| {
                b.read(radiance).read(sum.prev).write(sum.cur).write(mean);
            },
            move |pc| {
                let binds = [
                    ("radiance", Bind::Image(radiance)),
                    ("sum_prev", Bind::Image(sum.prev)),
                    ("sum_cur", Bind::Image(sum.cur)),
                    ("mean", Bind::Image(mean)),
                ];
                let groups = self.pipeline.groups_2d(size.width, size.height);
                pc.dispatch(&self.pipeline, &binds, &push, groups)
            },
        );
        Ok(mean)
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        self.pipeline.destroy(ctx);
    }
}
