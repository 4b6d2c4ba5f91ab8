//! Progressive accumulation (shaders/glsl/accumulate.comp): a running sum in a history
//! pair and its mean. The `accum` denoiser and reference rendering both use it.

use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};
use ash::vk;

gpu_block! {
    /// `AccumulatePush` in accumulate.comp.
    pub struct AccumulatePush {
        pub width: u32,
        pub height: u32,
        /// 0: start over.
        pub history_valid: u32,
        /// Samples in this frame's radiance.
        pub weight: f32,
    }
}

pub struct Accumulate {
    pipeline: Pipeline<AccumulatePush>,
}

impl Accumulate {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("accumulate", &[])?,
        })
    }

    /// Adds `radiance` (carrying `weight` samples) to the running sum `name`; returns the
    /// running mean. The sum restarts when its history is invalid (reset or first frame).
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
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
        frame.add_compute(name, &self.pipeline, push, size, |b| {
            b.read("radiance", radiance)
                .read("sum_prev", sum.prev)
                .write("sum_cur", sum.cur)
                .write("mean", mean);
        });
        Ok(mean)
    }
}
