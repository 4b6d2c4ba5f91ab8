//! A live session: one volume on one device, the view state that is edited between
//! frames, and the renderer that turns it into frames.
//!
//! Everything that changes what is shown is an [`Edit`] on a [`Session`]: a mouse drag in
//! the explorer, a command of its `--script`, a keyframe of a scripted animation
//! ([`Session::play`] applies the scene's view at a frame as edits), an assignment in
//! Python, a message from the notebook viewer. The session checks each edit as a scene
//! file's field is checked (an edit that fails leaves the state as it was), keeps the
//! current [`View`] (camera, lights, TF state), the render settings and the denoisers,
//! and [`Session::frame`] makes the next frame's inputs from them through the one path
//! scripted frames take too ([`SceneSetup::inputs`]). The renderer derives the change flags
//! and motion from consecutive inputs, so an edit is reprojected by the temporal
//! denoisers like a scripted change, never restarted, unless [`Edit::Restart`] says so.
//!
//! What an edit costs: camera, lights and TF edits only change the next frame's inputs;
//! settings restart every history (the renderer's rule), a setting that specialises the
//! pipelines (estimator, phase, emission) or a new environment map builds a new renderer
//! on the same device; denoisers are rebuilt with fresh histories.

mod labels;
pub mod orbit;

pub use labels::{LabelEdit, Pick};
pub use orbit::{Anatomical, OrbitCamera};

use crate::denoise::Registry;
use crate::error::EngineError;
use crate::gpu::GpuContext;
use crate::graph::Extent;
use crate::renderer::scene_setup::{load_environment, SceneSetup, SetupError};
use crate::renderer::{
    FrameInputs, FrameRequest, FrameResult, PresentTarget, Renderer, SettingsChange,
};
use crate::scene::view::{check_camera_spec, check_cut, check_light_list, check_render};
use crate::scene::{
    CameraSpec, Cut, EnvSource, Light, RenderSettings, Scene, SceneError, TfState, View,
};
use crate::transfer::{TfLut, TransferFunction};
use std::path::PathBuf;
use std::sync::Arc;
use thiserror::Error;

/// How edits are named in error messages (`edit: camera.position: …`).
pub const EDIT_ORIGIN: &str = "edit";

/// What can go wrong applying an edit or rendering a frame.
#[derive(Debug, Error)]
pub enum SessionError {
    /// The edit's value is refused (the message names the field); nothing changed.
    #[error(transparent)]
    Invalid(#[from] SceneError),
    #[error(transparent)]
    Engine(#[from] EngineError),
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// A new renderer was needed and could not be built, not even with the settings
    /// that worked before.
    #[error("no renderer: building one for the new settings failed ({0})")]
    NoRenderer(String),
}

pub type Result<T, E = SessionError> = std::result::Result<T, E>;

/// One change of what is shown.
#[derive(Clone, Debug, PartialEq)]
pub enum Edit {
    /// The camera, set outright.
    Camera(CameraSpec),
    /// A left-drag of (dx, dy) pixels ([`OrbitCamera::orbit`]).
    Orbit { dx: f64, dy: f64 },
    /// A right-drag of (dx, dy) pixels ([`OrbitCamera::pan`], in the shown view's pixels).
    Pan { dx: f64, dy: f64 },
    /// Wheel steps, positive zooms in ([`OrbitCamera::zoom`]).
    Zoom { steps: f64 },
    /// Back to the camera the session started with.
    ResetCamera,
    /// Fly to fit the volume, keeping the viewing direction.
    FitCamera,
    /// Look from one side of the patient ([`OrbitCamera::view_from`]).
    ViewFrom(Anatomical),
    /// The lights, in order.
    Lights(Vec<Light>),
    /// The transfer function (a single one: [`TfState::single`]).
    Tf(TfState),
    /// The clip planes and crop box (the renderer re-traces ours' gradients under the
    /// change, as for a TF edit).
    Cut(Cut),
    /// Render settings (checked; every history restarts).
    Settings(RenderSettings),
    /// The denoisers, by registry name (fresh histories).
    Denoisers(Vec<String>),
    /// Restart every history on the next frame (a cut).
    Restart,
    /// The time point of a series (fractional: the two around it interpolated).
    Time(f64),
    /// One channel of a multi-channel medium: what is given changes (the renderer
    /// re-traces ours' gradients under it, as for a TF edit).
    Channel(ChannelEdit),
    /// A label of the label map (or every label): its colour, opacity or visibility
    /// (the renderer re-traces ours' gradients under it, as for a TF edit).
    Label(LabelEdit),
}

/// A change to channel `index`: its TF (over its window, or in data units), its window,
/// colour or visibility.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ChannelEdit {
    pub index: usize,
    pub tf: Option<TransferFunction>,
    pub window: Option<[f32; 2]>,
    pub colour: Option<[f32; 3]>,
    pub visible: Option<bool>,
}

/// A view of one volume, edited between frames; see the module docs.
pub struct Session {
    setup: SceneSetup,
    view: View,
    /// The LUT of `view.tf`, made when the TF changes.
    lut: TfLut,
    orbit: OrbitCamera,
    denoisers: Vec<String>,
    /// The size the view is shown at (its aspect, and the pixels a pan is measured in);
    /// the renderer may render fewer pixels while the view moves.
    view_size: Extent,
    restart: bool,
    frames: u64,
    /// `None` only after a rebuild failed (see [`SessionError::NoRenderer`]).
    renderer: Option<Renderer>,
    ctx: Arc<GpuContext>,
}

impl Session {
    /// A session over `setup` (its scene's view at frame 0, its settings, at its size)
    /// running `denoisers` on `ctx`: a context of its own, or one the caller shares (the
    /// explorer's, which also owns the window's swapchain).
    pub fn new(
        setup: SceneSetup,
        ctx: impl Into<Arc<GpuContext>>,
        denoisers: &[&str],
    ) -> Result<Self> {
        let ctx = ctx.into();
        let denoisers = registry_names(&setup.config.registry, denoisers)?;
        let names: Vec<&str> = denoisers.iter().map(String::as_str).collect();
        let renderer = setup.renderer(Arc::clone(&ctx), &names)?;
        let view = setup.scene.view_at(0);
        Ok(Self {
            lut: view.lut(),
            orbit: OrbitCamera::from_spec(&view.camera),
            view_size: setup.config.size,
            view,
            setup,
            denoisers,
            restart: false,
            frames: 0,
            renderer: Some(renderer),
            ctx,
        })
    }

    /// The scene the session was opened with (its animation is what [`Session::play`]
    /// plays).
    pub fn scene(&self) -> &Scene {
        &self.setup.scene
    }

    pub fn setup(&self) -> &SceneSetup {
        &self.setup
    }

    /// The current view.
    pub fn view(&self) -> &View {
        &self.view
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.setup.settings
    }

    /// The denoisers, by registry name, in the order their outputs come back.
    pub fn denoisers(&self) -> &[String] {
        &self.denoisers
    }

    /// The size the view is shown at.
    pub fn view_size(&self) -> Extent {
        self.view_size
    }

    /// Frames submitted in this session.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    pub fn ctx(&self) -> &Arc<GpuContext> {
        &self.ctx
    }

    pub fn renderer(&self) -> Result<&Renderer> {
        self.renderer.as_ref().ok_or_else(no_renderer)
    }

    fn renderer_mut(&mut self) -> Result<&mut Renderer> {
        self.renderer.as_mut().ok_or_else(no_renderer)
    }

    /// Applies one edit; returns the results of frames in flight that it had to wait
    /// for (a new renderer or new denoisers), in order. An edit that fails changes
    /// nothing.
    pub fn edit(&mut self, edit: Edit) -> Result<Vec<FrameResult>> {
        match edit {
            Edit::Camera(spec) => {
                check_camera_spec(&spec, EDIT_ORIGIN)?;
                self.orbit.set_spec(&spec);
                self.view.camera = spec;
            }
            Edit::Orbit { dx, dy } => self.move_camera(|c, _| c.orbit(dx, dy))?,
            Edit::Pan { dx, dy } => self.move_camera(|c, h| c.pan(dx, dy, h))?,
            Edit::Zoom { steps } => self.move_camera(|c, _| c.zoom(steps))?,
            Edit::ResetCamera => self.move_camera(|c, _| c.reset())?,
            Edit::ViewFrom(side) => self.move_camera(|c, _| c.view_from(side))?,
            Edit::FitCamera => {
                let half = glam::Vec3::from(self.setup.volume.world_size).as_dvec3() * 0.5;
                let aspect = f64::from(self.view_size.aspect());
                self.move_camera(|c, _| c.fit(half, aspect))?
            }
            Edit::Lights(lights) => {
                check_light_list(&lights, self.settings().emission(), EDIT_ORIGIN)?;
                return self.set_lights(lights);
            }
            Edit::Tf(mut tf) => {
                tf.a.validate().map_err(|e| tf_error("transfer.a", e))?;
                if let Some(b) = &tf.b {
                    b.validate().map_err(|e| tf_error("transfer.b", e))?;
                }
                let window = self.setup.volume.window;
                tf.a = tf.a.in_density(window);
                tf.b = tf.b.map(|b| b.in_density(window));
                self.set_tf(tf);
            }
            Edit::Cut(cut) => {
                check_cut(&cut, EDIT_ORIGIN)?;
                self.view.cut = cut;
            }
            Edit::Settings(settings) => return self.set_settings(settings),
            Edit::Denoisers(names) => {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                let names = registry_names(&self.setup.config.registry, &names)?;
                if names == self.denoisers {
                    return Ok(Vec::new());
                }
                let list: Vec<&str> = names.iter().map(String::as_str).collect();
                let done = self.renderer_mut()?.set_denoisers(&list)?;
                self.denoisers = names;
                return Ok(done);
            }
            Edit::Restart => self.restart = true,
            Edit::Time(time) => {
                let times = self.setup.timeline.as_ref().map_or(1, |t| t.times());
                if !(time.is_finite() && time >= 0.0 && time <= (times - 1) as f64) {
                    return Err(invalid_edit(
                        "time",
                        format!(
                            "{time} is outside the time points 0 to {} ({times} in all)",
                            times - 1
                        ),
                    ));
                }
                self.view.time = time;
            }
            Edit::Channel(edit) => self.edit_channel(edit)?,
            Edit::Label(edit) => self.edit_label(edit)?,
        }
        Ok(Vec::new())
    }

    /// Sets the view the scene's animation has at `frame` (camera, lights, TF blend and
    /// shift, time point, channels): a scripted animation is these edits, one frame
    /// after another.
    pub fn play(&mut self, frame: u32) -> Result<Vec<FrameResult>> {
        let view = self.setup.scene.view_at(frame);
        self.orbit.set_spec(&view.camera);
        self.view.camera = view.camera;
        self.view.cut = view.cut;
        self.view.time = view.time;
        self.view.labels = view.labels;
        let channels = view.channels != self.view.channels;
        self.view.channels = view.channels;
        self.set_tf(view.tf);
        if channels {
            self.lut = self.view.lut();
        }
        // The scene's lights were checked with the scene, every frame's values too.
        self.set_lights(view.lights)
    }

    /// Shows the view at `view` pixels, rendered at `rendered` (fewer while the view
    /// moves, in the explorer). Waits for frames in flight when the rendered size
    /// changes and returns their results.
    pub fn resize(&mut self, view: Extent, rendered: Extent) -> Result<Vec<FrameResult>> {
        let done = self.renderer_mut()?.resize(rendered)?;
        self.view_size = view;
        self.setup.config.size = rendered;
        Ok(done)
    }

    /// Renders the current view: see [`Renderer::frame_presented`]. Returns the results
    /// of the frame that last used this frame's slot, if any.
    pub fn frame(
        &mut self,
        request: &FrameRequest,
        present: Option<&PresentTarget<'_>>,
    ) -> Result<Option<FrameResult>> {
        let inputs = self.inputs();
        let mut request = request.clone();
        request.reset |= std::mem::take(&mut self.restart);
        let done = self
            .renderer_mut()?
            .frame_presented(&inputs, &request, present)?;
        self.frames += 1;
        Ok(done)
    }

    /// Waits for every frame in flight; returns their results in order.
    pub fn flush(&mut self) -> Result<Vec<FrameResult>> {
        Ok(self.renderer_mut()?.flush()?)
    }

    /// A high-sample reference of the current view (see [`Renderer::reference`]).
    pub fn reference(&mut self, spp: u32, batch: u32) -> Result<Vec<[f32; 4]>> {
        let inputs = self.inputs();
        Ok(self.renderer_mut()?.reference(&inputs, spp, batch)?)
    }

    /// A high-sample reference of the view the scene's animation has at `frame`,
    /// leaving the current view as it is.
    pub fn reference_at(&mut self, frame: u32, spp: u32, batch: u32) -> Result<Vec<[f32; 4]>> {
        let view = self.setup.scene.view_at(frame);
        let inputs = self
            .setup
            .inputs(&view, self.view_size.aspect(), &view.lut());
        Ok(self.renderer_mut()?.reference(&inputs, spp, batch)?)
    }

    /// The renderer's inputs for the current view.
    fn inputs(&self) -> FrameInputs {
        self.setup
            .inputs(&self.view, self.view_size.aspect(), &self.lut)
    }

    /// A camera move through the orbit camera; refused (and undone) when it would put
    /// the camera where no scene file may (too far from the volume).
    fn move_camera(&mut self, op: impl FnOnce(&mut OrbitCamera, f64)) -> Result<()> {
        let mut moved = self.orbit;
        op(&mut moved, f64::from(self.view_size.height));
        let spec = moved.spec();
        check_camera_spec(&spec, EDIT_ORIGIN)?;
        self.orbit = moved;
        self.view.camera = spec;
        Ok(())
    }

    fn edit_channel(&mut self, edit: ChannelEdit) -> Result<()> {
        let count = self.view.channels.len();
        let Some(mut c) = self.view.channels.get(edit.index).cloned() else {
            return Err(invalid_edit(
                "channel",
                format!(
                    "channel {} does not exist; the volume has {} channel(s) (0 to {})",
                    edit.index,
                    count.max(1),
                    count.max(1) - 1
                ),
            ));
        };
        let field = |f: &str| format!("channel[{}].{f}", edit.index);
        if let Some(tf) = edit.tf {
            tf.validate().map_err(|e| tf_error(&field("tf"), e))?;
            c.tf = tf;
        }
        if let Some([lo, hi]) = edit.window {
            if !(lo.is_finite() && hi.is_finite() && hi > lo) {
                return Err(invalid_edit(
                    &field("window"),
                    format!("[{lo}, {hi}] must be finite, low < high"),
                ));
            }
            c.window = [lo, hi];
        }
        if let Some(colour) = edit.colour {
            if !colour
                .iter()
                .all(|x| x.is_finite() && (0.0..=1.0).contains(x))
            {
                return Err(invalid_edit(
                    &field("colour"),
                    format!("{colour:?} must be in [0, 1]"),
                ));
            }
            c.colour = colour;
        }
        if let Some(v) = edit.visible {
            c.visible = v;
        }
        let tf0 = (edit.index == 0).then(|| c.density_tf());
        self.view.channels[edit.index] = c;
        match tf0 {
            // Channel 0's TF is the view's TF.
            Some(tf) => {
                self.view.tf = TfState::single(tf);
                self.lut = self.view.lut();
            }
            None => self.lut = self.view.lut(),
        }
        Ok(())
    }

    fn set_tf(&mut self, tf: TfState) {
        if tf != self.view.tf {
            self.view.tf = tf;
            self.lut = self.view.lut();
        }
    }

    /// New lights; a new environment map is a new renderer (the map is uploaded once
    /// and its presence specialises the path tracer).
    fn set_lights(&mut self, lights: Vec<Light>) -> Result<Vec<FrameResult>> {
        if environment_map(&lights) == environment_map(&self.view.lights) {
            self.view.lights = lights;
            return Ok(Vec::new());
        }
        let environment = load_environment(&lights)
            .map_err(SetupError::from)?
            .map(Arc::new);
        let before = std::mem::replace(&mut self.setup.environment, environment);
        match self.rebuild(self.setup.settings) {
            Ok(done) => {
                self.view.lights = lights;
                Ok(done)
            }
            Err(e) => {
                self.setup.environment = before;
                self.restore(e)
            }
        }
    }

    fn set_settings(&mut self, settings: RenderSettings) -> Result<Vec<FrameResult>> {
        check_render(&settings, EDIT_ORIGIN)?;
        check_light_list(&self.view.lights, settings.emission(), EDIT_ORIGIN)?;
        if settings.gpu_memory() != self.setup.settings.gpu_memory() {
            return Err(EngineError::InvalidSetting {
                name: "gpu_memory",
                value: format!("{:?}", settings.gpu_memory()),
                allowed: "the volume's budget is fixed when the renderer is made (make a new one)"
                    .into(),
            }
            .into());
        }
        match self.renderer_mut()?.set_settings(&settings)? {
            SettingsChange::Unchanged => Ok(Vec::new()),
            SettingsChange::Applied => {
                self.setup.settings = settings;
                Ok(Vec::new())
            }
            SettingsChange::NeedsNewRenderer => match self.rebuild(settings) {
                Ok(done) => Ok(done),
                Err(e) => self.restore(e),
            },
        }
    }

    /// A new renderer with `settings` on the same device, after the old one's frames
    /// in flight (returned) and its memory are gone.
    fn rebuild(&mut self, settings: RenderSettings) -> Result<Vec<FrameResult>> {
        let done = self.flush()?;
        self.renderer = None;
        let before = std::mem::replace(&mut self.setup.settings, settings);
        let names: Vec<&str> = self.denoisers.iter().map(String::as_str).collect();
        match self.setup.renderer(Arc::clone(&self.ctx), &names) {
            Ok(r) => {
                self.renderer = Some(r);
                Ok(done)
            }
            Err(e) => {
                self.setup.settings = before;
                Err(e.into())
            }
        }
    }

    /// After a failed rebuild: the renderer as it was (same settings and environment),
    /// and the error that refused the edit.
    fn restore(&mut self, refused: SessionError) -> Result<Vec<FrameResult>> {
        if self.renderer.is_none() {
            let names: Vec<&str> = self.denoisers.iter().map(String::as_str).collect();
            match self.setup.renderer(Arc::clone(&self.ctx), &names) {
                Ok(r) => self.renderer = Some(r),
                Err(e) => return Err(SessionError::NoRenderer(format!("{refused}; then {e}"))),
            }
        }
        Err(refused)
    }
}

/// The registry's names for `names` (each checked, duplicates dropped, order kept).
fn registry_names(registry: &Registry, names: &[&str]) -> Result<Vec<String>> {
    let mut out: Vec<String> = Vec::new();
    for n in names {
        let name = registry.find(n)?.name.to_string();
        if !out.contains(&name) {
            out.push(name);
        }
    }
    Ok(out)
}

/// The environment map the lights use, if any.
fn environment_map(lights: &[Light]) -> Option<&PathBuf> {
    lights.iter().find_map(|l| match l {
        Light::Environment(e) => match &e.source {
            EnvSource::Map { path } => Some(path),
            _ => None,
        },
        _ => None,
    })
}

fn tf_error(field: &str, source: crate::transfer::TransferError) -> SessionError {
    SessionError::Invalid(SceneError::Transfer {
        origin: EDIT_ORIGIN.into(),
        field: field.into(),
        source: Box::new(source),
    })
}

fn no_renderer() -> SessionError {
    SessionError::NoRenderer("an earlier settings change left none".into())
}

fn invalid_edit(field: &str, message: String) -> SessionError {
    SessionError::Invalid(SceneError::Invalid {
        origin: EDIT_ORIGIN.into(),
        field: field.into(),
        message,
    })
}
