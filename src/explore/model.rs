//! Model application: what the UI and the script edit reaches the renderer (denoisers,
//! render settings, a new renderer when the specialisation changes) and the swapchain.

use super::*;

impl Explorer {
    /// The renderer's denoisers: the shown one, and the right-hand one when split.
    pub(super) fn denoiser_list(&self) -> Vec<&str> {
        let mut v = vec![self.model.left.as_str()];
        if let Some(r) = self
            .model
            .right
            .as_deref()
            .filter(|r| *r != self.model.left)
        {
            v.push(r);
        }
        v
    }

    /// Brings the renderer and swapchain in line with the model.
    pub(super) fn apply_model(&mut self) -> Result<Vec<FrameResult>> {
        let mut done = Vec::new();
        if self.model == self.applied {
            return Ok(done);
        }
        let denoisers: Vec<String> = self.denoiser_list().iter().map(|s| s.to_string()).collect();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(done);
        };
        let Some(renderer) = gfx.renderer.as_mut() else {
            return Ok(done);
        };
        // The renderer checks the settings and restarts every history when they change.
        match renderer.set_settings(&self.model.render) {
            Ok(SettingsChange::NeedsNewRenderer) => {
                // Specialisation constants change: a new renderer (same device and window).
                done.extend(renderer.flush()?);
                gfx.renderer = None;
                self.setup.settings = self.model.render;
                let names: Vec<&str> = denoisers.iter().map(String::as_str).collect();
                let renderer = self.setup.renderer(Arc::clone(&gfx.ctx), &names)?;
                self.ui.max_spp = renderer.samples_per_dispatch();
                gfx.renderer = Some(renderer);
            }
            Ok(SettingsChange::Applied | SettingsChange::Unchanged) => {
                if renderer.denoiser_names() != denoisers {
                    let names: Vec<&str> = denoisers.iter().map(String::as_str).collect();
                    done.extend(renderer.set_denoisers(&names)?);
                }
            }
            Err(e) => {
                self.ui.set_status(e.to_string());
                self.model.render = *renderer.settings();
            }
        }
        if self.model.vsync != self.applied.vsync {
            let ctx = Arc::clone(&gfx.ctx);
            gfx.swapchain.set_vsync(&ctx, self.model.vsync)?;
            self.ui.stats.present_mode = format!("{:?}", gfx.swapchain.present_mode);
        }
        self.applied = self.model.clone();
        Ok(done)
    }

    /// A key or a UI-independent command (from the keyboard or the script).
    pub(super) fn command(&mut self, c: &Command) {
        let (w, h) = self.view_size();
        let aspect = w as f64 / h.max(1) as f64;
        let half = glam::Vec3::from(self.setup.volume.world_size).as_dvec3() * 0.5;
        if apply_to_camera(&mut self.camera, c, h as f64, |cam| cam.fit(half, aspect)) {
            return;
        }
        match c {
            Command::Key(Key::Help) => self.ui.show_help = !self.ui.show_help,
            Command::Key(Key::ToggleUi) => self.ui.show_panel = !self.ui.show_panel,
            Command::Key(Key::Screenshot) => self.shots.push(self.frame),
            Command::Denoiser(name) => match registry::find(name) {
                Ok(d) => self.model.left = d.name.to_string(),
                Err(e) => self.ui.set_status(e.to_string()),
            },
            Command::Split(right) => self.model.right = right.clone(),
            Command::Tf(tf) => {
                self.model.tf = (**tf).clone();
                self.ui.tf_editor.selected = None;
                self.ui.tf_editor.dragging = None;
            }
            _ => {}
        }
    }
}
