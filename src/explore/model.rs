//! Model application: what the UI and the script edit reaches the session as edits
//! (denoisers, render settings, TF, lights) and the swapchain.

use super::input::{ChannelCommand, LabelCommand};
use super::*;
use dvr_engine::session::{ChannelEdit, LabelEdit};

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

    /// Brings the session and swapchain in line with the model: each difference is an
    /// edit (settings the session refuses are reported and taken back in the panel).
    pub(super) fn apply_model(&mut self) -> Result<Vec<FrameResult>> {
        let mut done = Vec::new();
        if self.model == self.applied {
            return Ok(done);
        }
        let denoisers: Vec<String> = self.denoiser_list().iter().map(|s| s.to_string()).collect();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(done);
        };
        let Some(session) = gfx.session.as_mut() else {
            return Ok(done);
        };
        if self.model.render != *session.settings() {
            match session.edit(Edit::Settings(self.model.render)) {
                Ok(finished) => done.extend(finished),
                Err(e) => {
                    self.ui.set_status(e.to_string());
                    self.model.render = *session.settings();
                }
            }
            self.ui.max_spp = session.renderer()?.samples_per_dispatch();
        }
        if session.denoisers() != denoisers.as_slice() {
            done.extend(session.edit(Edit::Denoisers(denoisers))?);
        }
        if self.model.tf != self.applied.tf {
            let tf = TfState::single(self.model.tf.clone());
            if let Err(e) = session.edit(Edit::Tf(tf)) {
                self.ui.set_status(e.to_string());
                self.model.tf = session.view().tf.a.clone();
            }
        }
        for i in 0..self.model.channels.len().min(self.applied.channels.len()) {
            let (c, was) = (&self.model.channels[i], &self.applied.channels[i]);
            if c == was {
                continue;
            }
            let edit = ChannelEdit {
                index: i,
                tf: (c.tf != was.tf).then(|| c.tf.clone()),
                window: (c.window != was.window).then_some(c.window),
                colour: (c.colour != was.colour).then_some(c.colour),
                visible: (c.visible != was.visible).then_some(c.visible),
            };
            if let Err(e) = session.edit(Edit::Channel(edit)) {
                self.ui.set_status(e.to_string());
                self.model.channels[i] = session.view().channels[i].clone();
            }
        }
        if self.model.labels != self.applied.labels {
            for (l, was) in self.model.labels.iter().zip(&self.applied.labels) {
                if l == was {
                    continue;
                }
                let edit = LabelEdit {
                    value: Some(l.value),
                    colour: (l.colour != was.colour).then_some(l.colour),
                    opacity: (l.opacity != was.opacity).then_some(l.opacity),
                    visible: (l.visible != was.visible).then_some(l.visible),
                };
                if let Err(e) = session.edit(Edit::Label(edit)) {
                    self.ui.set_status(e.to_string());
                }
            }
            self.model.labels = session.view().labels.clone();
        }
        if self.model.time != self.applied.time {
            if let Err(e) = session.edit(Edit::Time(self.model.time)) {
                self.ui.set_status(e.to_string());
                self.model.time = session.view().time;
            }
        }
        if self.model.cut != self.applied.cut {
            if let Err(e) = session.edit(Edit::Cut(self.model.cut.clone())) {
                self.ui.set_status(e.to_string());
                self.model.cut = session.view().cut.clone();
            }
        }
        if self.model.lights != session.view().lights {
            match session.edit(Edit::Lights(self.model.lights.clone())) {
                Ok(finished) => done.extend(finished),
                Err(e) => {
                    self.ui.set_status(e.to_string());
                    self.model.lights = session.view().lights.clone();
                }
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

    /// Picks what lies under view pixel (x, y): the panel shows it, stdout says it (so a
    /// script's picks can be read).
    fn pick(&mut self, x: f64, y: f64) {
        let (vw, vh) = self.view_size();
        let (rw, rh) = self.ui.stats.render_size;
        if x >= f64::from(vw) || y >= f64::from(vh) || rw == 0 || rh == 0 {
            return;
        }
        let px = ((x * f64::from(rw) / f64::from(vw)) as u32).min(rw - 1);
        let py = ((y * f64::from(rh) / f64::from(vh)) as u32).min(rh - 1);
        let Some(session) = self.gfx.as_mut().and_then(|g| g.session.as_mut()) else {
            return;
        };
        let text = match session.pick(px, py) {
            Ok(Some(p)) => format!(
                "pick ({x:.0}, {y:.0}): label {}{} · intensity {} · voxel {:?}",
                p.label,
                p.label_name.map_or(String::new(), |n| format!(" \"{n}\"")),
                p.intensity,
                p.voxel
            ),
            Ok(None) => format!("pick ({x:.0}, {y:.0}): nothing"),
            Err(e) => format!("pick ({x:.0}, {y:.0}): {e}"),
        };
        println!("{text}");
        self.ui.pick = Some(text);
    }

    /// C: every cut off, or back on (the ones that were on, all when none was).
    fn toggle_cuts(&mut self) {
        let cut = &mut self.model.cut;
        if cut.active() {
            self.cuts_off = cut.planes.iter().map(|p| p.enabled).collect();
            self.crop_off = cut.crop.is_some_and(|c| c.enabled);
            cut.planes.iter_mut().for_each(|p| p.enabled = false);
            if let Some(c) = &mut cut.crop {
                c.enabled = false;
            }
        } else {
            let saved = std::mem::take(&mut self.cuts_off);
            let any = saved.iter().any(|&e| e) || self.crop_off;
            for (i, p) in cut.planes.iter_mut().enumerate() {
                p.enabled = !any || saved.get(i).copied().unwrap_or(true);
            }
            if let Some(c) = &mut cut.crop {
                c.enabled = !any || self.crop_off;
            }
        }
    }

    /// A key or a UI-independent command (from the keyboard, the mouse or the script):
    /// camera commands are session edits, the rest edit the model or the UI.
    pub(super) fn command(&mut self, c: &Command) {
        if let Some(edit) = camera_edit(c) {
            let session = self.gfx.as_mut().and_then(|g| g.session.as_mut());
            if let Some(Err(e)) = session.map(|s| s.edit(edit)) {
                self.ui.set_status(e.to_string());
            }
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
                // With channels, the TF editor's channel takes it.
                let i = self.ui.channel;
                match self.model.channels.get_mut(i) {
                    Some(c) => c.tf = (**tf).clone(),
                    None => self.model.tf = (**tf).clone(),
                }
                self.ui.tf_editor.selected = None;
                self.ui.tf_editor.dragging = None;
            }
            Command::Channel(i, change) => match self.model.channels.get_mut(*i) {
                Some(c) => match change {
                    ChannelCommand::Visible(v) => c.visible = *v,
                    ChannelCommand::Select => self.ui.channel = *i,
                    ChannelCommand::Colour(rgb) => c.colour = *rgb,
                },
                None => self.ui.set_status(format!(
                    "channel {i} does not exist: the volume has {} channel(s)",
                    self.model.channels.len().max(1)
                )),
            },
            Command::Time(t) => self.model.time = *t,
            Command::Label(value, change) => {
                let mut any = false;
                for l in self.model.labels.iter_mut() {
                    if value.is_some_and(|v| v != l.value) {
                        continue;
                    }
                    any = true;
                    match change {
                        LabelCommand::Visible(v) => l.visible = *v,
                        LabelCommand::Colour(c) => l.colour = *c,
                        LabelCommand::Opacity(o) => l.opacity = *o,
                    }
                }
                if !any {
                    self.ui.set_status(match value {
                        Some(v) => format!("label {v} is not in the label map"),
                        None => "the scene has no label map".into(),
                    });
                }
            }
            Command::Pick(x, y) => self.pick(*x, *y),
            Command::Play(on) => self.ui.playback.playing = *on,
            Command::Key(Key::Cut) => self.toggle_cuts(),
            Command::Resize(w, h) => {
                if let Some(window) = &self.window {
                    let panel = self.panel_pixels();
                    let _ = window.request_inner_size(PhysicalSize::new(w + panel, *h));
                }
            }
            Command::Clip(c) => {
                let forward = self.ui.view.map_or(glam::DVec3::Z, |v| v.forward);
                c.apply(&mut self.model.cut, forward);
            }
            _ => {}
        }
    }
}
