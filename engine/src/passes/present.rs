//! Present (shaders/glsl/present.comp): tone-maps the denoised HDR frame into a display
//! image, usually the acquired swapchain image, with the project's one tone map (the
//! GLSL twin of [`crate::metrics::tonemap_srgb`]). It can show two denoisers side by
//! side (a split view) and places the frame at an offset, filling the rest with a
//! background colour.

use super::Extent;
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext};
use crate::graph::{Bind, Frame, ImageHandle};
use crate::renderer::uniforms::PresentPush;
use glam::Vec4;

/// Where and how the frame lands in the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresentLayout {
    /// Top-left corner of the frame in the target, in pixels.
    pub offset: [i32; 2],
    /// Columns of the frame left of this come from `left`, the rest from `right`;
    /// `None` shows `left` only.
    pub split_x: Option<u32>,
    /// Linear scale before the tone map (1 = as rendered).
    pub exposure: f32,
    /// sRGB-encoded colour of target pixels outside the frame.
    pub background: [f32; 3],
}

impl Default for PresentLayout {
    fn default() -> Self {
        Self {
            offset: [0, 0],
            split_x: None,
            exposure: 1.0,
            background: [0.0; 3],
        }
    }
}

pub struct Present {
    pipeline: ComputePipeline,
}

impl Present {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ComputePipeline::new(ctx, "present", &[])?,
        })
    }

    /// Tone-maps `left` (and `right` right of the split) of size `source` into `target`
    /// of size `target_size`. `target` may have any storage-capable format.
    #[allow(clippy::too_many_arguments)]
    pub fn add<'f>(
        &'f self,
        frame: &mut Frame<'f>,
        left: ImageHandle,
        right: ImageHandle,
        source: Extent,
        target: ImageHandle,
        target_size: Extent,
        layout: &PresentLayout,
    ) {
        let push = PresentPush {
            target_width: target_size.width,
            target_height: target_size.height,
            offset_x: layout.offset[0],
            offset_y: layout.offset[1],
            source_width: source.width,
            source_height: source.height,
            split_x: layout
                .split_x
                .map_or(i32::MAX, |x| x.min(i32::MAX as u32) as i32),
            exposure: layout.exposure,
            background: Vec4::new(
                layout.background[0],
                layout.background[1],
                layout.background[2],
                1.0,
            ),
        };
        frame.add_pass(
            "present",
            |b| {
                b.read(left).read(right).write(target);
            },
            move |pc| {
                let binds = [
                    ("left_image", Bind::Image(left)),
                    ("right_image", Bind::Image(right)),
                    ("target", Bind::Image(target)),
                ];
                let groups = self
                    .pipeline
                    .groups_2d(target_size.width, target_size.height);
                pc.dispatch(&self.pipeline, &binds, &push, groups)
            },
        );
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        self.pipeline.destroy(ctx);
    }
}
