//! `dvr explore`: the desktop volume explorer. A window (winit) whose swapchain the
//! renderer presents to every frame: path trace → denoise → tone map into the swapchain
//! image → the egui panel on top, all in the renderer's one render graph.
//!
//! The loop, once per frame ([`Explorer::frame`]): scripted commands due → the UI (egui)
//! edits the [`ui::Model`] → model changes go to the renderer (denoisers, settings; a
//! pipeline-specialising change rebuilds it) → acquire a swapchain image → the frame's
//! inputs from the camera, lights and TF through `scene_setup::inputs_for` (the same path
//! `dvr capture` takes) → `Renderer::frame_presented` → present → handle
//! the results of the frame that finished (timings, screenshots, recorded frames).
//!
//! Mouse and keys: see [`input::SHORTCUTS`]; `--script` plays the same commands at given
//! frames (see [`input`]).

mod camera;
mod input;
mod overlay;
mod record;
mod tf_editor;
mod ui;

use crate::setup;
use anyhow::{bail, Context, Result};
use ash::vk;
use camera::OrbitCamera;
use dvr_engine::denoise::MotionSource;
use dvr_engine::gpu::{ContextOptions, GpuContext, Swapchain};
use dvr_engine::image_io::{to_rgb, write_exr, write_png, PNG_EXPOSURE};
use dvr_engine::passes::present::PresentLayout;
use dvr_engine::passes::Extent;
use dvr_engine::renderer::scene_setup::{self, inputs_for, load_volume, SceneSetup};
use dvr_engine::renderer::{
    FrameRequest, FrameResult, PresentTarget, RenderSettings, Renderer, Screenshot,
};
use dvr_engine::scene::{Scene, VolumeSource};
use input::{apply_to_camera, Command, DragKind, Key, Pointer, Script};
use overlay::EguiOverlay;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use record::Recorder;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use ui::{Model, UiState, PANEL_WIDTH};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key as WinitKey, NamedKey};
use winit::window::{Window, WindowId};

/// What `dvr explore` says when there is no display to open a window on.
pub const NO_DISPLAY: &str =
    "dvr explore needs a display; run under Xvfb: Xvfb :99 & DISPLAY=:99 dvr explore …";

/// Frames left out of the frame-rate summary (pipeline compilation on first use).
const WARMUP_FRAMES: usize = 5;
/// Bins of the density histogram behind the transfer-function editor.
const HISTOGRAM_BINS: usize = 128;

#[derive(clap::Args, Clone, Debug)]
pub struct ExploreArgs {
    /// Built-in scene (`dvr scenes` lists them) or a scene TOML file; its camera,
    /// lights, TF and render settings at frame 0 are the starting point.
    #[arg(long, default_value = setup::DEFAULT_SCENE)]
    pub scene: String,
    /// A volume file (NRRD, NIfTI, DICOM folder, raw with sidecar) to explore instead of
    /// the scene's.
    #[arg(long)]
    pub volume: Option<PathBuf>,
    /// Size of the rendered view, WIDTHxHEIGHT (the window adds the panel's width).
    #[arg(long, default_value = "512x512", value_parser = setup::parse_size)]
    pub size: (u32, u32),
    /// Denoiser shown; `A,B` starts in a split view of A (left) and B (right).
    #[arg(long, default_value = "ours")]
    pub denoiser: String,
    /// Exit after this many frames.
    #[arg(long)]
    pub frames: Option<u64>,
    /// Write the last presented frame (window contents, UI included) to this PNG.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Record the session into this folder: frames, per-frame state and a replayable
    /// scene (DIR/session.toml, for `dvr capture --scene`).
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Present without vsync (MAILBOX, else IMMEDIATE).
    #[arg(long)]
    pub no_vsync: bool,
    /// Scripted input, e.g. "orbit:30,0@10;zoom:2@20" (see README, Explorer).
    #[arg(long)]
    pub script: Option<String>,
    /// Samples per pixel per frame (default: the scene's).
    #[arg(long, value_parser = crate::setup::parse_spp)]
    pub spp: Option<u32>,
    /// Edge length of procedural volumes (phantom, cloud), 8 to 4096.
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub volume_size: u32,
    /// Where motion vectors come from: `features` (opacity-threshold surface) or
    /// `first-hit` (closest first real collision), as for the other commands.
    #[arg(long, default_value = setup::DEFAULT_MOTION, value_parser = setup::parse_motion)]
    pub motion: MotionSource,
}

/// True when the environment names an X11 or Wayland display.
fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

pub fn run(args: ExploreArgs) -> Result<()> {
    let names: Vec<String> = args
        .denoiser
        .split(',')
        .map(|s| s.trim().to_string())
        .collect();
    if names.is_empty() || names.len() > 2 {
        bail!("--denoiser takes one denoiser or two for a split view (A,B)");
    }
    for n in &names {
        if !dvr_engine::denoise::NAMES.contains(&n.as_str()) {
            bail!(
                "unknown denoiser {n:?}; available: {}",
                dvr_engine::denoise::NAMES.join(", ")
            );
        }
    }
    let script = match &args.script {
        Some(s) => Script::parse(s).context("--script")?,
        None => Script::default(),
    };
    if !has_display() {
        bail!("{NO_DISPLAY} (neither DISPLAY nor WAYLAND_DISPLAY is set)");
    }
    let mut scene = crate::setup::open_scene(&args.scene)?;
    if let Some(path) = &args.volume {
        scene.volume.source = VolumeSource::File {
            path: path.clone(),
            raw: None,
        };
    }
    let volume = load_volume(&scene, args.volume_size)?;
    let histogram = volume.histogram(HISTOGRAM_BINS);
    let size = Extent {
        width: args.size.0,
        height: args.size.1,
    };
    let mut setup = SceneSetup::with_volume(scene, &volume, size, args.spp)?;
    setup.settings.motion_source = args.motion;
    drop(volume);
    let event_loop = EventLoop::new().map_err(|e| anyhow::anyhow!("{NO_DISPLAY} ({e})"))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = Explorer::new(args, setup, &histogram, script, &names)?;
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    app.finish()
}

/// GPU state that exists while the window does. Torn down in order: renderer, UI
/// renderer, swapchain (and surface), then the device when the last handle goes.
struct Gfx {
    renderer: Option<Renderer>,
    overlay: Option<EguiOverlay>,
    swapchain: Swapchain,
    ctx: Arc<GpuContext>,
}

impl Gfx {
    /// Rebuilds the swapchain at the window's size (resized, out of date or
    /// suboptimal); the UI renderer follows its format.
    fn recreate_swapchain(&mut self, size: winit::dpi::PhysicalSize<u32>) -> Result<()> {
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
        self.renderer.take();
        self.overlay.take();
        self.swapchain.destroy(&self.ctx);
    }
}

struct Explorer {
    args: ExploreArgs,
    setup: SceneSetup,
    script: Script,
    model: Model,
    /// The model the renderer currently reflects.
    applied: Model,
    camera: OrbitCamera,
    ui: UiState,
    pointer: Pointer,
    egui_ctx: egui::Context,
    egui_state: Option<egui_winit::State>,
    // Before `window`: the surface must go before the window it was made for.
    gfx: Option<Gfx>,
    window: Option<Arc<Window>>,
    recorder: Option<Recorder>,
    /// Frames submitted so far.
    frame: u64,
    /// Restart denoiser histories on the next frame (settings changed).
    reset: bool,
    resized: bool,
    /// Frame indices whose results should be saved as F12 screenshots.
    shots: Vec<u64>,
    shot_count: u32,
    last_screenshot: Option<Screenshot>,
    frame_started: Option<Instant>,
    frame_ms: Vec<f32>,
    /// UI textures egui released, freed after the frames in flight.
    free_textures: Vec<egui::TextureId>,
    /// (pass, total GPU ms, frames) after the warm-up, for the summary.
    pass_totals: Vec<(String, f64, u32)>,
    /// GPU frame spans after the warm-up, ms.
    gpu_spans: Vec<f64>,
    started: Instant,
    error: Option<anyhow::Error>,
}

impl Explorer {
    fn new(
        args: ExploreArgs,
        setup: SceneSetup,
        histogram: &[u32],
        script: Script,
        names: &[String],
    ) -> Result<Self> {
        let state = setup.scene.frame_state(0);
        let camera = OrbitCamera::from_spec(&setup.scene.camera_at(0));
        let model = Model {
            tf: setup.scene.tf_a.clone(),
            lights: state.lights,
            render: {
                let mut r = setup.scene.render;
                r.spp = setup.settings.spp;
                r
            },
            exposure: PNG_EXPOSURE,
            vsync: !args.no_vsync,
            left: names[0].clone(),
            right: names.get(1).cloned(),
            split: 0.5,
        };
        let mut ui = UiState::new(histogram);
        let recorder = match &args.record {
            Some(dir) => {
                ui.recording = true;
                Some(Recorder::new(dir)?)
            }
            None => None,
        };
        let egui_ctx = egui::Context::default();
        ui::style(&egui_ctx);
        Ok(Self {
            args,
            setup,
            script,
            applied: model.clone(),
            model,
            camera,
            ui,
            pointer: Pointer::default(),
            egui_ctx,
            egui_state: None,
            gfx: None,
            window: None,
            recorder,
            frame: 0,
            reset: false,
            resized: false,
            shots: Vec::new(),
            shot_count: 0,
            last_screenshot: None,
            frame_started: None,
            frame_ms: Vec::new(),
            free_textures: Vec::new(),
            pass_totals: Vec::new(),
            gpu_spans: Vec::new(),
            started: Instant::now(),
            error: None,
        })
    }

    /// Pixels of the panel at the current scale.
    fn panel_pixels(&self) -> u32 {
        if self.ui.show_panel {
            (PANEL_WIDTH * self.egui_ctx.pixels_per_point()).round() as u32
        } else {
            0
        }
    }

    fn open_window(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let ppp = self.egui_ctx.pixels_per_point();
        let (w, h) = self.args.size;
        let attributes = Window::default_attributes()
            .with_title(format!("dvr explore — {}", self.setup.scene.name))
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
        let renderer = self
            .setup
            .renderer_shared(Arc::clone(&ctx), &self.denoiser_list())?;
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
            renderer: Some(renderer),
            overlay: Some(overlay),
            swapchain,
            ctx,
        });
        self.window = Some(window);
        Ok(())
    }

    /// The renderer's denoisers: the shown one, and the right-hand one when split.
    fn denoiser_list(&self) -> Vec<&str> {
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

    /// The renderer settings for the model: what a scene with the model's render
    /// settings and lights asks for (`scene_setup::render_settings`, the one mapping),
    /// over the current size, seed and motion source.
    fn render_settings(&self, current: &RenderSettings) -> RenderSettings {
        let scene = Scene {
            render: self.model.render,
            lights: self.model.lights.clone(),
            ..self.setup.scene.clone()
        };
        let s = scene_setup::render_settings(&scene, current.size, self.model.render.spp);
        RenderSettings {
            spp: s.spp,
            max_bounces: s.max_bounces,
            rr_depth: s.rr_depth,
            features: s.features,
            hg_g: s.hg_g,
            step_voxels: s.step_voxels,
            ..current.clone()
        }
    }

    /// Brings the renderer and swapchain in line with the model.
    fn apply_model(&mut self) -> Result<Vec<FrameResult>> {
        let mut done = Vec::new();
        if self.model == self.applied {
            return Ok(done);
        }
        let denoisers: Vec<String> = self.denoiser_list().iter().map(|s| s.to_string()).collect();
        let Some(current) = self
            .gfx
            .as_ref()
            .and_then(|g| g.renderer.as_ref())
            .map(|r| r.settings.clone())
        else {
            return Ok(done);
        };
        let settings = self.render_settings(&current);
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(done);
        };
        let Some(renderer) = gfx.renderer.as_mut() else {
            return Ok(done);
        };
        if settings.features != renderer.settings.features {
            // Specialisation constants change: a new renderer (same device and window).
            done.extend(renderer.flush()?);
            gfx.renderer = None;
            self.setup.settings = settings;
            let names: Vec<&str> = denoisers.iter().map(String::as_str).collect();
            gfx.renderer = Some(self.setup.renderer_shared(Arc::clone(&gfx.ctx), &names)?);
        } else {
            if renderer.denoiser_names() != denoisers {
                let names: Vec<&str> = denoisers.iter().map(String::as_str).collect();
                done.extend(renderer.set_denoisers(&names)?);
            }
            if settings.spp != renderer.settings.spp
                || settings.max_bounces != renderer.settings.max_bounces
                || settings.hg_g != renderer.settings.hg_g
            {
                renderer.settings = settings;
                self.reset = true;
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
    fn command(&mut self, c: &Command) {
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
            Command::Denoiser(name) => {
                if dvr_engine::denoise::NAMES.contains(&name.as_str()) {
                    self.model.left = name.clone();
                } else {
                    self.ui.set_status(format!("unknown denoiser {name:?}"));
                }
            }
            Command::Split(right) => self.model.right = right.clone(),
            _ => {}
        }
    }

    /// The rendered view's size for the current window.
    fn view_size(&self) -> (u32, u32) {
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

    /// One frame: see the module docs.
    fn frame(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(window) = self.window.clone() else {
            return Ok(());
        };
        let size = window.inner_size();
        if size.width == 0 || size.height == 0 {
            return Ok(()); // minimised
        }
        let now = Instant::now();
        if let Some(t) = self.frame_started.replace(now) {
            self.frame_ms.push((now - t).as_secs_f32() * 1000.0);
        }
        if let Some(gfx) = self.gfx.as_mut() {
            let e = gfx.swapchain.extent;
            if self.resized || (e.width, e.height) != (size.width, size.height) {
                gfx.recreate_swapchain(size)?;
                self.resized = false;
            }
        }
        let due: Vec<Command> = self.script.at(self.frame).cloned().collect();
        for c in &due {
            self.command(c);
        }

        // The UI edits the model.
        let Some(egui_state) = self.egui_state.as_mut() else {
            return Ok(());
        };
        let raw = egui_state.take_egui_input(&window);
        let (ui_state, model) = (&mut self.ui, &mut self.model);
        let mut requests = ui::UiRequests::default();
        let output = self.egui_ctx.run_ui(raw, |ui| {
            requests = ui::draw(ui, ui_state, model);
        });
        egui_state.handle_platform_output(&window, output.platform_output);
        if requests.screenshot {
            self.shots.push(self.frame);
        }
        let primitives = self
            .egui_ctx
            .tessellate(output.shapes, output.pixels_per_point);
        // Texture uploads now; frees once the frames drawing with them are done.
        let mut textures = output.textures_delta;
        self.free_textures.extend(textures.free.drain());
        let uploaded = match self.gfx.as_mut() {
            Some(gfx) => match gfx.overlay.as_mut() {
                Some(o) => {
                    o.set_primitives(primitives, output.pixels_per_point);
                    o.set_textures(&gfx.ctx, &textures)
                }
                None => Ok(()),
            },
            None => Ok(()),
        };
        textures.clear();
        uploaded?;
        for r in self.apply_model()? {
            self.completed(r)?;
        }

        // Render and present.
        let (vw, vh) = self.view_size();
        let spec = self.camera.spec();
        let inputs = inputs_for(
            &spec.camera(),
            vw as f32 / vh as f32,
            &self.model.lights,
            &self.model.tf.lut(),
        );
        let want_shot = self.shots.contains(&self.frame);
        let readback_hdr = want_shot || self.recorder.is_some();
        let split = (self.denoiser_list().len() == 2)
            .then(|| ((vw as f32 * self.model.split) as u32).clamp(1, vw - 1));
        let reset = std::mem::take(&mut self.reset);
        let want_present_copy = want_shot || self.args.screenshot.is_some();
        let Some(gfx) = self.gfx.as_mut() else {
            return Ok(());
        };
        let (Some(renderer), Some(overlay)) = (gfx.renderer.as_mut(), gfx.overlay.as_ref()) else {
            return Ok(());
        };
        let view = Extent {
            width: vw,
            height: vh,
        };
        let mut finished = Vec::new();
        if renderer.settings.size != view {
            // The graph reallocates its images at the new size: let the frames in
            // flight that use the old ones finish first.
            finished = renderer.flush()?;
            renderer.settings.size = view;
        }
        self.ui.stats.render_size = (vw, vh);
        let Some(image) = gfx.swapchain.acquire()? else {
            gfx.recreate_swapchain(size)?;
            return Ok(());
        };
        let bg = ui::PANEL_FILL.to_normalized_gamma_f32();
        let target = PresentTarget {
            image,
            left: 0,
            right: split.map(|_| 1),
            layout: PresentLayout {
                offset: [0, 0],
                split_x: split,
                exposure: self.model.exposure,
                background: [bg[0], bg[1], bg[2]],
            },
            readback: want_present_copy && gfx.swapchain.readable,
            overlay: Some(overlay),
        };
        let request = FrameRequest {
            readback: readback_hdr,
            reset,
        };
        let result = renderer.frame_presented(&inputs, &request, Some(&target))?;
        if !gfx.swapchain.present(&gfx.ctx, &image)? {
            self.resized = true;
        }
        if !self.free_textures.is_empty() {
            gfx.ctx.wait_idle()?;
            if let Some(o) = gfx.overlay.as_mut() {
                o.free_textures(&std::mem::take(&mut self.free_textures))?;
            }
        }
        if let Some(rec) = self.recorder.as_mut() {
            rec.push(spec, &self.model.lights, &self.model.tf, &self.model.left)?;
        }
        self.frame += 1;
        for r in finished.into_iter().chain(result) {
            self.completed(r)?;
        }
        if self.args.frames.is_some_and(|n| self.frame >= n) {
            event_loop.exit();
        }
        Ok(())
    }

    /// Handles the results of a finished frame: timings, screenshots, recorded frames.
    fn completed(&mut self, r: FrameResult) -> Result<()> {
        let frame_ms = self.frame_ms.last().copied().unwrap_or(0.0);
        let (w, h) = self.ui.stats.render_size;
        let shown = r.images.first();
        if let Some(rec) = &self.recorder {
            if let Some((_, pixels)) = shown {
                if pixels.len() == (w * h) as usize {
                    write_png(&rec.frame_path(r.index), &to_rgb(w, h, pixels))?;
                }
            }
        }
        if let Some(pos) = self.shots.iter().position(|&f| f == r.index) {
            self.shots.remove(pos);
            let stem = PathBuf::from(format!("dvr-explore-{:04}", self.shot_count));
            self.shot_count += 1;
            let mut saved = Vec::new();
            if let Some(s) = &r.screenshot {
                let path = stem.with_extension("png");
                save_screenshot(&path, s)?;
                saved.push(path);
            }
            if let Some((_, pixels)) = shown {
                if pixels.len() == (w * h) as usize {
                    let path = stem.with_extension("exr");
                    write_exr(&path, &to_rgb(w, h, pixels))?;
                    saved.push(path);
                }
            }
            let names: Vec<String> = saved.iter().map(|p| p.display().to_string()).collect();
            self.ui.set_status(format!("saved {}", names.join(", ")));
            println!("explore: saved {}", names.join(", "));
        }
        if r.screenshot.is_some() {
            self.last_screenshot = r.screenshot;
        }
        if r.index >= WARMUP_FRAMES as u64 {
            self.gpu_spans.push(ui::gpu_span_ms(&r.timings));
            for t in &r.timings {
                match self.pass_totals.iter_mut().find(|p| p.0 == t.pass) {
                    Some(p) => {
                        p.1 += t.ms;
                        p.2 += 1;
                    }
                    None => self.pass_totals.push((t.pass.clone(), t.ms, 1)),
                }
            }
        }
        self.ui.stats.push(frame_ms, r.timings);
        Ok(())
    }

    /// After the event loop: the last frames' results, `--screenshot`, the recorded
    /// scene, the frame-rate summary, and the first error if there was one.
    fn finish(&mut self) -> Result<()> {
        if let Some(e) = self.error.take() {
            self.gfx = None;
            return Err(e);
        }
        let flushed = match self.gfx.as_mut().and_then(|g| g.renderer.as_mut()) {
            Some(r) => r.flush()?,
            None => Vec::new(),
        };
        for r in flushed {
            self.completed(r)?;
        }
        let summary = self.gfx.as_ref().map(|g| {
            (
                g.ctx.info.name.clone(),
                format!("{:?}", g.swapchain.present_mode),
            )
        });
        self.gfx = None;
        if let Some(path) = &self.args.screenshot {
            let shot = self.last_screenshot.as_ref().with_context(|| {
                format!(
                    "--screenshot {}: no frame was read back (the surface does not allow \
                     copying from swapchain images, or no frame was presented)",
                    path.display()
                )
            })?;
            save_screenshot(path, shot)?;
            println!("explore: wrote {}", path.display());
        }
        if let Some(rec) = &self.recorder {
            if let Some(path) = rec.finish(&self.setup.scene, self.args.volume_size)? {
                println!(
                    "explore: recorded {} frames; replay with: dvr capture --scene {} --size {}x{} \
                     --volume-size {} --motion {} --denoiser {}",
                    rec.frame_count(),
                    path.display(),
                    self.ui.stats.render_size.0,
                    self.ui.stats.render_size.1,
                    self.args.volume_size,
                    match self.args.motion {
                        MotionSource::FirstHit => "first-hit",
                        MotionSource::Features => "features",
                    },
                    self.model.left,
                );
            }
        }
        let timed = self.frame_ms.iter().skip(WARMUP_FRAMES).collect::<Vec<_>>();
        if let (Some((device, mode)), false) = (summary, timed.is_empty()) {
            let mean = timed.iter().copied().sum::<f32>() / timed.len() as f32;
            println!(
                "explore: {} frames in {:.1} s; {:.1} ms/frame ({:.2} fps) after {WARMUP_FRAMES} \
                 warm-up frames, view {}x{}, {device}, {mode}",
                self.frame,
                self.started.elapsed().as_secs_f64(),
                mean,
                1000.0 / mean,
                self.ui.stats.render_size.0,
                self.ui.stats.render_size.1,
            );
            let passes: Vec<String> = self
                .pass_totals
                .iter()
                .map(|(pass, ms, n)| format!("{pass} {:.1}", ms / f64::from(*n)))
                .collect();
            if !passes.is_empty() {
                let span = self.gpu_spans.iter().sum::<f64>() / self.gpu_spans.len().max(1) as f64;
                println!(
                    "explore: GPU frame span {span:.1} ms; ms per pass: {}",
                    passes.join(", ")
                );
            }
        }
        Ok(())
    }
}

fn save_screenshot(path: &Path, s: &Screenshot) -> Result<()> {
    let rgb: Vec<u8> = s
        .rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    let png = dvr_engine::image_io::encode_srgb8_png(path, s.width, s.height, &rgb)?;
    dvr_engine::image_io::write_file(path, &png, dvr_engine::files::Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}

impl ApplicationHandler for Explorer {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_some() {
            return;
        }
        if let Err(e) = self.open_window(event_loop) {
            self.error = Some(e);
            event_loop.exit();
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
                    self.pointer.drag = DragKind::from_button(button);
                }
                ElementState::Released => self.pointer.drag = None,
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
        if self.error.is_some() {
            return;
        }
        if let Err(e) = self.frame(event_loop) {
            self.error = Some(e);
            event_loop.exit();
        }
    }
}
