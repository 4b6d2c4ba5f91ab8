//! Motion vectors (shaders/glsl/motion.comp): per-pixel offset to last frame's position,
//! from the first real collision (xy) and from the opacity-threshold features (zw).

use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{BufferHandle, Extent, Frame, ImageHandle, RenderGraph};
use ash::vk;

gpu_block! {
    /// `MotionPush` in motion.comp.
    pub struct MotionPush {
        pub width: u32,
        pub height: u32,
        pub pad0: u32,
        pub pad1: u32,
    }
}

pub struct Motion {
    pipeline: Pipeline<MotionPush>,
}

impl Motion {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("motion", &[])?,
        })
    }

    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'_>,
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
        frame.add_compute("motion", &self.pipeline, push, size, |b| {
            b.uniform("frame", uniforms)
                .read("first_hit", first_hit)
                .read("feature_position", feature_position)
                .write("motion", motion);
        });
        Ok(motion)
    }
}
