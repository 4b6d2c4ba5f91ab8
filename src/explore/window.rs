//! The window and what lives as long as it does: the device, its swapchain, the UI
//! renderer and the live session ([`Gfx`]), and winit's events.

use super::*;

/// GPU state that exists while the window does. Torn down in order: session, UI
/// renderer, swapchain (and surface), then the device when the last handle goes.
pub(super) struct Gfx {
    pub session: Option<Session>,
    pub overlay: Option<EguiOverlay>,
    pub swapchain: Swapchain,
    pub ctx: Arc<GpuContext>,
}

impl Gfx {
    /// Rebuilds the swapchain at the window's size (resized, out of date or
    /// suboptimal); the UI renderer follows its format.
    pub(super) fn recreate_swapchain(&mut self, size: winit::dpi::PhysicalSize<u32>) -> Result<()> {
        let extent = vk::Extent2D {
            width: size.width,
            height: size.height,
        };
        self.swapchain.recreate(&self.ctx, extent)?;
        if let Some(o) = self.overlay.as_mut() {
            o.set_format(self.swapchain.format)?;
        }
        Ok(())
    }
}

impl Drop for Gfx {
    fn drop(&mut self) {
        let _ = self.ctx.wait_idle();
        self.session.take();
        self.overlay.take();
        self.swapchain.destroy(&self.ctx);
    }
}

impl Explorer {
    /// Pixels of the panel at the current scale.
    pub(super) fn panel_pixels(&self) -> u32 {
        if self.ui.show_panel {
            (PANEL_WIDTH * self.egui_ctx.pixels_per_point()).round() as u32
        } else {
            0
        }
    }

    pub(super) fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let ppp = self.egui_ctx.pixels_per_point();
        let (w, h) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title(format!("dvr explore — {}", self.scene.name))
            .with_inner_size(PhysicalSize::new(w + (PANEL_WIDTH * ppp).round() as u32, h));
        let window = Arc::new(
            event_loop
                .create_window(attributes)
                .map_err(|e| anyhow::anyhow!("{NO_DISPLAY} (creating the window: {e})"))?,
        );
        let display = window
            .display_handle()
            .context("the window's display handle")?
            .as_raw();
        let handle = window
            .window_handle()
            .context("the window's handle")?
            .as_raw();
        let instance_extensions = ash_window::enumerate_required_extensions(display)
            .context("Vulkan surface extensions for this display")?
            .to_vec();
        let ctx = Arc::new(GpuContext::new(ContextOptions {
            instance_extensions,
            device_extensions: vec![ash::khr::swapchain::NAME.as_ptr()],
            ..Default::default()
        })?);
        let surface =
            unsafe { ash_window::create_surface(&ctx.entry, &ctx.instance, display, handle, None) }
                .context("creating the window's Vulkan surface")?;
        let size = window.inner_size();
        let swapchain = Swapchain::new(
            &ctx,
            surface,
            vk::Extent2D {
                width: size.width.max(1),
                height: size.height.max(1),
            },
            self.model.vsync,
        )?;
        let overlay = EguiOverlay::new(&ctx, swapchain.format)?;
        let setup = self
            .setup
            .take()
            .context("the window opened twice (the session is made once)")?;
        let denoisers = self.denoiser_list();
        crate::setup::warn_unused_overrides(&denoisers);
        let session = Session::new(setup, Arc::clone(&ctx), &denoisers)?;
        self.ui.max_spp = session.renderer()?.samples_per_dispatch();
        self.ui.stats.device = ctx.info.name.clone();
        self.ui.stats.present_mode = format!("{:?}", swapchain.present_mode);
        let max_texture_side = 4096;
        self.egui_state = Some(egui_winit::State::new(
            self.egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            None,
            Some(max_texture_side),
        ));
        self.gfx = Some(Gfx {
            session: Some(session),
            overlay: Some(overlay),
            swapchain,
            ctx,
        });
        self.window = Some(window);
        Ok(())
    }

    /// The rendered view's size for the current window.
    pub(super) fn view_size(&self) -> (u32, u32) {
        let ext = self
            .gfx
            .as_ref()
            .map(|g| g.swapchain.extent)
            .unwrap_or(vk::Extent2D {
                width: self.args.size.0,
                height: self.args.size.1,
            });
        (
            ext.width.saturating_sub(self.panel_pixels()).max(16),
            ext.height.max(16),
        )
    }
}

impl Explorer {
    /// Runs `step`; an error ends the event loop, and `finish` reports it.
    fn or_exit(
        &mut self,
        event_loop: &ActiveEventLoop,
        step: fn(&mut Self, &ActiveEventLoop) -> Result<()>,
    ) {
        if let Err(e) = step(self, event_loop) {
            self.error = Some(e);
            event_loop.exit();
        }
    }
}

impl ApplicationHandler for Explorer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            self.or_exit(event_loop, Self::open_window);
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(window) = self.window.clone() else {
            return;
        };
        let consumed = self
            .egui_state
            .as_mut()
            .is_some_and(|s| s.on_window_event(&window, &event).consumed);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(_) | WindowEvent::ScaleFactorChanged { .. } => {
                self.resized = true;
            }
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed
                    && !consumed
                    && !self.egui_ctx.egui_wants_keyboard_input() =>
            {
                if event.logical_key == WinitKey::Named(NamedKey::Escape) {
                    event_loop.exit();
                } else if let Some(k) = Key::from_winit(&event.logical_key) {
                    self.command(&Command::Key(k));
                }
            }
            WindowEvent::MouseInput { state, button, .. } => match state {
                ElementState::Pressed if !self.egui_ctx.is_pointer_over_egui() => {
                    self.pointer.pressed(button);
                }
                ElementState::Released => {
                    if let Some(pick) = self.pointer.released() {
                        self.command(&pick);
                    }
                }
                _ => {}
            },
            WindowEvent::CursorMoved { position, .. } => {
                if let Some(c) = self.pointer.moved(position.x, position.y) {
                    self.command(&c);
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !self.egui_ctx.is_pointer_over_egui() => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y as f64,
                    MouseScrollDelta::PixelDelta(p) => p.y / 50.0,
                };
                self.command(&Command::Zoom(steps));
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if self.error.is_none() {
            self.or_exit(event_loop, Self::frame);
        }
    }
}
