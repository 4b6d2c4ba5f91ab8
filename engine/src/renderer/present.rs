//! How a frame ends on screen: the acquired swapchain image is imported into the render
//! graph (which therefore owns its barriers, UNDEFINED → … → PRESENT_SRC_KHR), the
//! present pass tone-maps the denoised frame into it, an optional [`Overlay`] (the
//! explorer's UI) draws on top, an optional copy reads it back (screenshots), and the
//! graph hands it to presentation. The frame's submission waits on the image's acquire
//! semaphore and signals the one presentation waits on.

use crate::error::{EngineError, Result};
use crate::gpu::swapchain::{AcquiredImage, ACQUIRE_WAIT_STAGE};
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::Extent;
use crate::graph::{BufferHandle, Frame, ImageHandle, PassContext, RenderGraph};
use crate::passes::present::{Present, PresentLayout};
use ash::vk;

/// Something drawn over the presented frame by a graphics pipeline (the explorer's UI).
/// It lives in the application; the renderer only schedules it.
pub trait Overlay {
    /// Records draw commands into `target`, declared as a colour attachment and in
    /// `COLOR_ATTACHMENT_OPTIMAL` when this runs: begin dynamic rendering with
    /// `LOAD`/`STORE` on [`PassContext::image_view`], draw, end rendering. Issue no
    /// barriers: the graph places them.
    fn record(&self, pc: &mut PassContext, target: ImageHandle) -> Result<()>;
}

/// Where a frame is presented (see the module docs).
#[derive(Clone, Copy)]
pub struct PresentTarget<'a> {
    pub image: AcquiredImage,
    /// Index (in the renderer's denoiser list) of the denoiser shown, or shown left of
    /// the split.
    pub left: usize,
    /// The denoiser shown right of `layout.split_x`, if split.
    pub right: Option<usize>,
    pub layout: PresentLayout,
    /// Copy the presented image (UI included) back: [`super::FrameResult::screenshot`].
    pub readback: bool,
    pub overlay: Option<&'a dyn Overlay>,
}

impl std::fmt::Debug for PresentTarget<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PresentTarget")
            .field("image", &self.image)
            .field("left", &self.left)
            .field("right", &self.right)
            .field("layout", &self.layout)
            .field("readback", &self.readback)
            .field("overlay", &self.overlay.is_some())
            .finish()
    }
}

/// A presented image read back: sRGB-encoded RGBA8, rows top to bottom.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Screenshot {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
}

/// A screenshot copy waiting for its frame's fence.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PendingScreenshot {
    buffer: BufferHandle,
    width: u32,
    height: u32,
    format: vk::Format,
}

/// Adds present → overlay → (readback) → hand-over to presentation for `target`;
/// `outputs` are the denoisers' HDR images of size `size`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_present_passes<'f>(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'f>,
    present: &'f Present,
    slot: usize,
    target: &PresentTarget<'f>,
    outputs: &[(String, ImageHandle)],
    size: Extent,
) -> Result<Option<PendingScreenshot>> {
    let output = |i: usize| {
        outputs
            .get(i)
            .map(|o| o.1)
            .ok_or_else(|| EngineError::Pass {
                pass: "present".into(),
                problem: format!(
                    "denoiser index {i} out of range ({} denoisers)",
                    outputs.len()
                ),
            })
    };
    let left = output(target.left)?;
    let right = match target.right {
        Some(i) => output(i)?,
        None => left,
    };
    let img = &target.image;
    let extent = Extent {
        width: img.extent.width,
        height: img.extent.height,
    };
    let desc = ImageDesc::d2(extent.width, extent.height, img.format);
    let swapchain_image = graph.import_image(
        &format!("swapchain.{}", img.index),
        img.image,
        img.view,
        desc,
        ACQUIRE_WAIT_STAGE,
    )?;
    let mut layout = target.layout;
    if target.right.is_none() {
        layout.split_x = None;
    }
    present.add(frame, left, right, size, swapchain_image, extent, &layout);
    if let Some(overlay) = target.overlay {
        frame.add_pass(
            "ui_overlay",
            |b| {
                b.color_attachment(swapchain_image);
            },
            move |pc| overlay.record(pc, swapchain_image),
        );
    }
    let pending = if target.readback {
        let bytes = extent.width as u64 * extent.height as u64 * 4;
        let buffer = graph.readback(ctx, &format!("readback.present.{slot}"), bytes)?;
        frame.add_readback("present", swapchain_image, buffer);
        Some(PendingScreenshot {
            buffer,
            width: extent.width,
            height: extent.height,
            format: img.format,
        })
    } else {
        None
    };
    frame.add_present("to_present", swapchain_image);
    Ok(pending)
}

/// Reads a finished screenshot copy as RGBA8.
pub(crate) fn read_screenshot(graph: &RenderGraph, p: PendingScreenshot) -> Result<Screenshot> {
    let bytes = graph
        .buffer_ref(p.buffer)
        .mapped()
        .ok_or_else(|| EngineError::Resource {
            resource: "readback.present".into(),
            problem: "buffer is not host visible".into(),
        })?;
    Ok(Screenshot {
        width: p.width,
        height: p.height,
        rgba: to_rgba8(p.format, bytes)?,
    })
}

/// Converts texels of the swapchain formats the engine picks to RGBA8.
pub fn to_rgba8(format: vk::Format, bytes: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::with_capacity(bytes.len());
    match format {
        vk::Format::R8G8B8A8_UNORM => out.extend_from_slice(bytes),
        vk::Format::B8G8R8A8_UNORM => {
            for p in bytes.chunks_exact(4) {
                out.extend_from_slice(&[p[2], p[1], p[0], p[3]]);
            }
        }
        vk::Format::A2B10G10R10_UNORM_PACK32 => {
            for p in bytes.chunks_exact(4) {
                let v = u32::from_le_bytes([p[0], p[1], p[2], p[3]]);
                let c = |shift: u32| (((v >> shift) & 1023) as f32 * 255.0 / 1023.0).round() as u8;
                out.extend_from_slice(&[c(0), c(10), c(20), 255]);
            }
        }
        other => {
            return Err(EngineError::Resource {
                resource: "readback.present".into(),
                problem: format!("cannot convert {other:?} texels to RGBA8"),
            })
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bgra_and_a2b10g10r10_convert_to_rgba() {
        let bgra = [10u8, 20, 30, 255];
        assert_eq!(
            to_rgba8(vk::Format::B8G8R8A8_UNORM, &bgra).expect("bgra"),
            vec![30, 20, 10, 255]
        );
        let v: u32 = 1023 | (512 << 10) | (3 << 30);
        let out = to_rgba8(vk::Format::A2B10G10R10_UNORM_PACK32, &v.to_le_bytes()).expect("a2");
        assert_eq!(out, vec![255, 128, 0, 255]);
        assert!(to_rgba8(vk::Format::R32_SFLOAT, &[0; 4]).is_err());
    }
}
