//! The UI as the renderer's [`Overlay`]: egui's tessellated meshes drawn by
//! `egui-ash-renderer` into the swapchain image with dynamic rendering, inside a pass the
//! render graph declared (so the graph, not egui, transitions the image). Texture
//! uploads (the font atlas) go through the crate's own one-off submissions, outside the
//! frame, onto images the graph never sees.

use anyhow::{Context, Result};
use ash::vk;
use dvr_engine::gpu::GpuContext;
use dvr_engine::graph::{ImageHandle, PassContext};
use dvr_engine::renderer::Overlay;
use dvr_engine::EngineError;
use egui_ash_renderer::allocator::DefaultAllocator;
use egui_ash_renderer::{DynamicRendering, Options, RenderMode, Renderer};
use std::cell::{Cell, RefCell};

pub struct EguiOverlay {
    renderer: RefCell<Renderer<DefaultAllocator>>,
    primitives: RefCell<Vec<egui::ClippedPrimitive>>,
    pixels_per_point: Cell<f32>,
    format: vk::Format,
    upload_pool: vk::CommandPool,
    device: ash::Device,
}

impl EguiOverlay {
    pub fn new(ctx: &GpuContext, format: vk::Format) -> Result<Self> {
        let renderer = Renderer::with_default_allocator(
            &ctx.instance,
            ctx.physical,
            ctx.device.clone(),
            render_mode(format),
            Options {
                // The renderer keeps two frames in flight; one more set of vertex
                // buffers leaves margin.
                in_flight_frames: 3,
                enable_depth_test: false,
                enable_depth_write: false,
                // UNORM swapchain: the fragment shader encodes sRGB itself.
                srgb_framebuffer: false,
            },
        )
        .context("creating the egui renderer")?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let upload_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .context("vkCreateCommandPool for UI textures")?;
        Ok(Self {
            renderer: RefCell::new(renderer),
            primitives: RefCell::new(Vec::new()),
            pixels_per_point: Cell::new(1.0),
            format,
            upload_pool,
            device: ctx.device.clone(),
        })
    }

    /// Rebuilds the pipeline when a recreated swapchain changed format.
    pub fn set_format(&mut self, format: vk::Format) -> Result<()> {
        if format != self.format {
            self.renderer
                .get_mut()
                .set_render_mode(render_mode(format))
                .context("rebuilding the egui pipeline")?;
            self.format = format;
        }
        Ok(())
    }

    /// Uploads this frame's texture changes (before the frame that draws with them).
    pub fn set_textures(&mut self, ctx: &GpuContext, delta: &egui::TexturesDelta) -> Result<()> {
        let r = self.renderer.get_mut();
        for (id, deltas) in &delta.set {
            for image in deltas {
                r.set_texture(ctx.queue, self.upload_pool, *id, image)
                    .context("uploading a UI texture")?;
            }
        }
        Ok(())
    }

    /// Frees textures egui no longer uses; the caller has waited for the frames that
    /// drew with them.
    pub fn free_textures<'a>(
        &mut self,
        ids: impl IntoIterator<Item = &'a egui::TextureId>,
    ) -> Result<()> {
        let r = self.renderer.get_mut();
        for id in ids {
            r.free_texture(*id).context("freeing a UI texture")?;
        }
        Ok(())
    }

    /// The meshes the next frame draws.
    pub fn set_primitives(&mut self, primitives: Vec<egui::ClippedPrimitive>, ppp: f32) {
        *self.primitives.get_mut() = primitives;
        self.pixels_per_point.set(ppp);
    }
}

fn render_mode(format: vk::Format) -> RenderMode {
    RenderMode::DynamicRendering(DynamicRendering {
        color_attachment_format: format,
        depth_attachment_format: None,
        stencil_attachment_format: None,
    })
}

impl Overlay for EguiOverlay {
    fn record(&self, pc: &mut PassContext, target: ImageHandle) -> dvr_engine::Result<()> {
        let view = pc.image_view(target)?;
        let desc = pc.image_desc(target)?;
        let extent = vk::Extent2D {
            width: desc.extent[0],
            height: desc.extent[1],
        };
        let attachment = [vk::RenderingAttachmentInfo::default()
            .image_view(view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::LOAD)
            .store_op(vk::AttachmentStoreOp::STORE)];
        let info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D { x: 0, y: 0 },
                extent,
            })
            .layer_count(1)
            .color_attachments(&attachment);
        let device = &pc.ctx.device;
        unsafe { device.cmd_begin_rendering(pc.cmd, &info) };
        let drawn = self.renderer.borrow_mut().cmd_draw(
            pc.cmd,
            extent,
            self.pixels_per_point.get(),
            &self.primitives.borrow(),
        );
        unsafe { device.cmd_end_rendering(pc.cmd) };
        drawn.map_err(|e| EngineError::Pass {
            pass: "ui_overlay".into(),
            problem: format!("egui-ash-renderer: {e}"),
        })
    }
}

impl Drop for EguiOverlay {
    fn drop(&mut self) {
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.upload_pool, None);
        }
    }
}
