//! Motion vectors (shaders/glsl/motion.comp): per-pixel offset to last frame's position,
//! from the first real collision (xy) and from the opacity-threshold features (zw).

use super::Extent;
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc};
use crate::graph::{Bind, BufferHandle, Frame, ImageHandle, RenderGraph};
use crate::renderer::uniforms::MotionPush;
use ash::vk;

pub struct Motion {
    pipeline: ComputePipeline,
}

impl Motion {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(ctx, "motion", &[])?,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        uniforms: BufferHandle,
        first_hit: ImageHandle,
        feature_position: Option<ImageHandle>,
        size: Extent,
    ) -> Result<ImageHandle> {
        // Without surface features this frame, zw repeats the first-collision motion.
        let feature_position = feature_position.unwrap_or(first_hit);
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let motion = graph.image(ctx, "motion", desc)?;
        let push = MotionPush {
            width: size.width,
            height: size.height,
            ..Default::default()
        };
        frame.add_pass(
            "motion",
            |b| {
                b.uniform(uniforms)
                    .read(first_hit)
                    .read(feature_position)
                    .write(motion);
            },
            move |pc| {
                let binds = [
                    ("frame", Bind::Buffer(uniforms)),
                    ("first_hit", Bind::Image(first_hit)),
                    ("feature_position", Bind::Image(feature_position)),
                    ("motion", Bind::Image(motion)),
                ];
                let groups = self.pipeline.groups_2d(size.width, size.height);
                pc.dispatch(&self.pipeline, &binds, &push, groups)
            },
        );
        Ok(motion)
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        self.pipeline.destroy(ctx);
    }
}
