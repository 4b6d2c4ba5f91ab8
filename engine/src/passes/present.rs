//! Present (shaders/glsl/present.comp): tone-maps the denoised HDR frame into a display
//! image, usually the acquired swapchain image, with the project's one tone map (the
//! GLSL twin of [`crate::metrics::tonemap_srgb`]). It can show two denoisers side by
//! side (a split view) and places the frame at an offset, filling the rest with a
//! background colour; a frame rendered smaller than its place is upsampled bilinearly.

use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle};
use glam::Vec4;

gpu_block! {
    /// `PresentPush` in present.comp.
    pub struct PresentPush {
        pub target_width: u32,
        pub target_height: u32,
        pub offset_x: i32,
        pub offset_y: i32,
        pub source_width: u32,
        pub source_height: u32,
        pub view_width: u32,
        pub view_height: u32,
        pub split_x: i32,
        pub exposure: f32,
        pub pad0: f32,
        pub pad1: f32,
        pub background: Vec4,
    }
}

/// Where and how the frame lands in the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PresentLayout {
    /// Top-left corner of the frame in the target, in pixels.
    pub offset: [i32; 2],
    /// The frame's size in the target: `None` is the source's size (pixel for pixel); a
    /// larger one upsamples the source bilinearly (the explorer while the view moves).
    pub size: Option<[u32; 2]>,
    /// Columns of the frame (in target pixels) left of this come from `left`, the rest
    /// from `right`; `None` shows `left` only.
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
            size: None,
            split_x: None,
            exposure: 1.0,
            background: [0.0; 3],
        }
    }
}

pub struct Present {
    pipeline: Pipeline<PresentPush>,
}

impl Present {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        Ok(Self {
            pipeline: ctx.pipeline("present", &[])?,
        })
    }

    /// Tone-maps `left` (and `right` right of the split) of size `source` into `target`
    /// of size `target_size`. `target` may have any storage-capable format.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &self,
        frame: &mut Frame<'_>,
        left: ImageHandle,
        right: ImageHandle,
        source: Extent,
        target: ImageHandle,
        target_size: Extent,
        layout: &PresentLayout,
    ) {
        let [view_width, view_height] = layout.size.unwrap_or([source.width, source.height]);
        let push = PresentPush {
            target_width: target_size.width,
            target_height: target_size.height,
            offset_x: layout.offset[0],
            offset_y: layout.offset[1],
            source_width: source.width,
            source_height: source.height,
            view_width,
            view_height,
            split_x: layout
                .split_x
                .map_or(i32::MAX, |x| x.min(i32::MAX as u32) as i32),
            exposure: layout.exposure,
            pad0: 0.0,
            pad1: 0.0,
            background: Vec4::new(
                layout.background[0],
                layout.background[1],
                layout.background[2],
                1.0,
            ),
        };
        frame.add_compute("present", &self.pipeline, push, target_size, |b| {
            b.read("left_image", left)
                .read("right_image", right)
                .write("target", target);
        });
    }
}
