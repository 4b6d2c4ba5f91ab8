//! `dvr explore`: the desktop volume explorer. A window (winit) whose swapchain the
//! renderer presents to every frame: path trace → denoise → tone map into the swapchain
//! image → the egui panel on top, all in the renderer's one render graph.
//!
//! The explorer is a client of the engine's live [`Session`], as `dvr capture`, `dvr eval`
//! and the Python package are: mouse drags, keys and `--script` commands become session
//! edits (orbit, pan, zoom, reset, fit), and the panel's model (TF, lights, settings,
//! denoisers) is sent as edits where it differs from the session's state.
//!
//! The loop, once per frame ([`Explorer::frame`]): scripted commands due → the UI (egui)
//! edits the [`ui::Model`] → model changes go to the session as edits (a
//! pipeline-specialising setting makes it build a new renderer) → acquire a swapchain
//! image → `Session::frame` (the frame's inputs from the session's view, the path
//! scripted frames take) → present → handle the results of the frame that finished
//! (timings, screenshots, recorded frames).
//!
//! Mouse and keys: see [`input::SHORTCUTS`]; `--script` plays the same commands at given
//! frames (see [`input`]).
//!
//! Here: the arguments and the explorer's state. `window.rs` the window, its device and
//! swapchain, the session, and winit's events; `model.rs` model application and
//! commands as edits; `frame.rs` the frame and
//! what happens to its results; `moving.rs` the rendered size while the view moves;
//! `ui.rs` the panel that edits the model.

mod channel_panel;
mod cut_panel;
mod frame;
mod input;
mod label_panel;
mod model;
mod moving;
mod orientation;
mod overlay;
mod record;
mod tf_editor;
mod ui;
mod window;

use anyhow::{bail, Context, Result};
use ash::vk;
use dvr_engine::denoise::registry;
use dvr_engine::gpu::{ContextOptions, GpuContext, Swapchain};
use dvr_engine::graph::Extent;
use dvr_engine::image_io::{to_rgb, write_exr, write_png, PNG_EXPOSURE};
use dvr_engine::passes::present::PresentLayout;
use dvr_engine::renderer::medium::load_channels;
use dvr_engine::renderer::scene_setup::{load_volume, on_demand, SceneSetup};
use dvr_engine::renderer::{FrameRequest, FrameResult, PresentTarget, Screenshot};
use dvr_engine::scene::{Scene, TfState, View, VolumeSource};
use dvr_engine::session::{Edit, Session};
use input::{camera_edit, Command, Key, Pointer, Script};
use moving::MovingScale;
use overlay::EguiOverlay;
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use record::Recorder;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;
use ui::{Model, UiState, PANEL_WIDTH};
use window::Gfx;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key as WinitKey, NamedKey};
use winit::window::{Window, WindowId};

/// What `dvr explore` says when there is no display to open a window on.
pub const NO_DISPLAY: &str =
    "dvr explore needs a display; run under Xvfb: Xvfb :99 & DISPLAY=:99 dvr explore …";

/// Bins of the density histogram behind the transfer-function editor.
const HISTOGRAM_BINS: usize = 128;

#[derive(clap::Args, Clone, Debug)]
pub struct ExploreArgs {
    /// Built-in scene (`dvr scenes` lists them) or a scene TOML file; its camera,
    /// lights, TF and render settings at frame 0 are the starting point.
    #[arg(long, default_value = crate::args::DEFAULT_SCENE)]
    pub scene: String,
    /// A volume file (NRRD, NIfTI, DICOM folder, raw with sidecar, OME-Zarr image,
    /// OME-TIFF stack) to explore instead of the scene's.
    #[arg(long)]
    pub volume: Option<PathBuf>,
    /// Size of the rendered view, WIDTHxHEIGHT (the window adds the panel's width).
    #[arg(long, default_value = "512x512", value_parser = crate::args::parse_size)]
    pub size: (u32, u32),
    /// Denoiser shown; `A,B` starts in a split view of A (left) and B (right).
    #[arg(long, default_value = "ours", value_parser = crate::args::parse_view_denoisers)]
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
    /// Scripted input, e.g. "orbit:30,0@10;zoom:2@20" (see the book's explorer page).
    #[arg(long)]
    pub script: Option<String>,
    /// GPU ms per frame to aim for while the view moves: a still frame slower than this
    /// makes camera, light and TF changes render at 1/k of the view per side (k ≤ 8,
    /// upsampled); 0 keeps every frame at full size. Off while recording.
    #[arg(long, default_value_t = 100.0, value_parser = parse_moving_ms)]
    pub moving_ms: f32,
    #[command(flatten)]
    pub render: crate::args::RenderArgs,
}

/// `--moving-ms`: a finite number of milliseconds, 0 or more.
fn parse_moving_ms(s: &str) -> std::result::Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!(
            "'{s}' is not a frame time in ms (a finite number, 0 or more)"
        )),
    }
}

/// True when the environment names an X11 or Wayland display.
fn has_display() -> bool {
    ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

pub fn run(args: ExploreArgs) -> Result<()> {
    // Checked names (args::parse_view_denoisers): one, or two for a split view.
    let names: Vec<String> = args.denoiser.split(',').map(str::to_string).collect();
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
    args.render.apply_budget(&mut scene)?;
    let size = Extent {
        width: args.size.0,
        height: args.size.1,
    };
    // A volume made on demand has no dense array to count: the TF editor shows no
    // histogram for it.
    let mut channel_histograms = Vec::new();
    let (mut setup, histogram) = if on_demand(&scene, args.render.volume_size).is_some() {
        let setup = SceneSetup::new(scene, size, args.render.spp, args.render.volume_size)?;
        (setup, vec![0u32; HISTOGRAM_BINS])
    } else if let Some(channels) = load_channels(&scene)? {
        // Channels and time points: each channel's histogram at time point 0.
        channel_histograms = channels
            .volumes
            .iter()
            .map(|v| v.histogram(HISTOGRAM_BINS))
            .collect();
        let first = channel_histograms[0].clone();
        let setup = SceneSetup::with_channels(scene, channels, size, args.render.spp)?;
        (setup, first)
    } else {
        let volume = load_volume(&scene, args.render.volume_size)?;
        let histogram = volume.histogram(HISTOGRAM_BINS);
        (
            SceneSetup::with_volume(scene, &volume, size, args.render.spp)?,
            histogram,
        )
    };
    setup.config.motion_source = args.render.motion;
    let event_loop = EventLoop::new().map_err(|e| anyhow::anyhow!("{NO_DISPLAY} ({e})"))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = Explorer::new(args, setup, &histogram, script, &names)?;
    app.ui.channel_histograms = channel_histograms
        .iter()
        .map(|h| ui::log_histogram(h))
        .collect();
    event_loop
        .run_app(&mut app)
        .context("the window's event loop failed")?;
    app.finish()
}

struct Explorer {
    args: ExploreArgs,
    /// The scene as opened (the window's title, the recorded session's base).
    scene: Scene,
    /// What the session is made from when the window (and its device) opens.
    setup: Option<SceneSetup>,
    script: Script,
    model: Model,
    /// The model the session currently reflects.
    applied: Model,
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
    /// Fewer pixels while the view moves (`--moving-ms`).
    moving: MovingScale,
    /// Last frame's camera, lights and TF: what a change is measured against.
    last_view: Option<View>,
    /// (divisor, rendered size) of each submitted frame whose results have not come
    /// back, oldest first (results arrive in submission order).
    in_flight: VecDeque<(u32, (u32, u32))>,
    resized: bool,
    /// Frame indices whose results should be saved as F12 screenshots.
    shots: Vec<u64>,
    shot_count: u32,
    /// Which planes (and whether the crop box) were on when C switched the cuts off.
    cuts_off: Vec<bool>,
    crop_off: bool,
    /// Device memory allocated and resident memory after the warm-up and after the last
    /// frame of a `--frames` run (for the summary).
    memory_samples: [(u64, Option<u64>); 2],
    last_screenshot: Option<Screenshot>,
    frame_started: Option<Instant>,
    /// CPU frame intervals, ms, with the divisor each frame was rendered at.
    frame_ms: Vec<(f32, u32)>,
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
        let view = setup.scene.view_at(0);
        let model = Model {
            tf: view.tf.a,
            lights: view.lights,
            cut: view.cut,
            render: setup.settings,
            exposure: PNG_EXPOSURE,
            vsync: !args.no_vsync,
            left: names[0].clone(),
            right: names.get(1).cloned(),
            split: 0.5,
            channels: view.channels,
            time: view.time,
            labels: view.labels,
        };
        let mut ui = UiState::new(histogram, setup.volume.window);
        ui.playback =
            channel_panel::Playback::new(setup.timeline.as_ref().map_or(1, |t| t.times()));
        let recorder = match &args.record {
            Some(dir) => {
                ui.recording = true;
                Some(Recorder::new(dir)?)
            }
            None => None,
        };
        let egui_ctx = egui::Context::default();
        ui::style(&egui_ctx);
        // Recorded frames keep one size, the one the replay renders.
        let moving = MovingScale::new(if args.record.is_some() {
            0.0
        } else {
            args.moving_ms
        });
        Ok(Self {
            args,
            scene: setup.scene.clone(),
            setup: Some(setup),
            script,
            applied: model.clone(),
            model,
            ui,
            pointer: Pointer::default(),
            egui_ctx,
            egui_state: None,
            gfx: None,
            window: None,
            recorder,
            frame: 0,
            moving,
            last_view: None,
            in_flight: VecDeque::new(),
            resized: false,
            shots: Vec::new(),
            shot_count: 0,
            cuts_off: Vec::new(),
            crop_off: false,
            memory_samples: [(0, None); 2],
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
}
