//! The explorer's panel (egui): transfer-function editor, lights, render settings,
//! denoiser picker with split view, per-pass GPU timing, and the help overlay.
//!
//! The UI edits a [`Model`]; the frame loop compares it with last frame's copy and turns
//! differences into renderer inputs (see `mod.rs`). Nothing here touches the GPU.

use super::channel_panel;
use super::cut_panel;
use super::input::SHORTCUTS;
use super::label_panel;
use super::orientation;
use super::tf_editor::{self, TfEditor};
use dvr_engine::denoise::DENOISERS;
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::scene::{self, AreaLight, EnvSource, EnvironmentLight, Facing, Light, PointLight};
use dvr_engine::shaders::frame::MAX_LIGHTS;
use dvr_engine::transfer::TransferFunction;
use egui::{Color32, RichText};
use glam::{DVec2, DVec3};
use std::collections::VecDeque;

/// Width of the side panel in points.
pub const PANEL_WIDTH: f32 = 300.0;
/// The panel's fill (the window test looks for it).
pub const PANEL_FILL: Color32 = Color32::from_rgb(30, 34, 42);
/// Frames kept by the frame-time graph.
const HISTORY: usize = 120;

/// What the user edits; compared frame to frame to find what changed.
#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    pub tf: TransferFunction,
    pub lights: Vec<Light>,
    /// The clip planes and crop box.
    pub cut: scene::Cut,
    pub render: scene::RenderSettings,
    /// Linear scale before the tone map.
    pub exposure: f32,
    pub vsync: bool,
    /// The denoiser shown (left of the split).
    pub left: String,
    /// The denoiser right of the split, when split.
    pub right: Option<String>,
    /// Split position as a fraction of the width.
    pub split: f32,
    /// The channels of a multi-channel medium (empty for one field).
    pub channels: Vec<scene::ChannelView>,
    /// The time point of a series.
    pub time: f64,
    /// The labels of the label map (empty without one).
    pub labels: Vec<scene::LabelView>,
}

/// Frame statistics the panel shows.
#[derive(Default)]
pub struct Stats {
    pub device: String,
    pub render_size: (u32, u32),
    /// The view the frame fills (the render size times the divisor, about).
    pub view: (u32, u32),
    /// Pixels per side one rendered pixel stands for (1; more while the view moves).
    pub divisor: u32,
    pub present_mode: String,
    /// How the volume is held on the device: "dense volume" or the brick pool's residency.
    pub volume: String,
    /// Per-pass GPU times of the last completed frame.
    pub timings: Vec<PassTiming>,
    /// (CPU frame interval, GPU span) in ms, oldest first.
    pub history: VecDeque<(f32, f32)>,
}

/// The GPU time from the first pass's start to the last pass's end (the sum of the
/// per-pass times leaves out the barriers between passes).
pub fn gpu_span_ms(timings: &[PassTiming]) -> f64 {
    timings
        .iter()
        .map(|t| t.start_ms + t.ms)
        .fold(0.0, f64::max)
}

impl Stats {
    pub fn push(&mut self, frame_ms: f32, timings: Vec<PassTiming>) {
        self.history
            .push_back((frame_ms, gpu_span_ms(&timings) as f32));
        while self.history.len() > HISTORY {
            self.history.pop_front();
        }
        self.timings = timings;
    }

    /// Mean frame interval over the history, ms.
    pub fn mean_frame_ms(&self) -> f32 {
        if self.history.is_empty() {
            return 0.0;
        }
        self.history.iter().map(|h| h.0).sum::<f32>() / self.history.len() as f32
    }
}

/// UI state that is not part of the model.
pub struct UiState {
    pub show_panel: bool,
    pub show_help: bool,
    pub tf_editor: TfEditor,
    /// Histogram of the volume, log-scaled to [0, 1].
    pub histogram: Vec<f32>,
    /// The volume's data values at density 0 and 1 (the TF editor's axis).
    pub window: [f32; 2],
    pub stats: Stats,
    /// A short message (saved files, errors) and when it was set.
    pub status: Option<(String, std::time::Instant)>,
    /// Recording: light kinds and counts are locked (a scene cannot animate them).
    pub recording: bool,
    /// Most samples per pixel the renderer takes in one frame on this device.
    pub max_spp: u32,
    /// The shown view's camera and rectangle this frame (the cut's outline and "align").
    pub view: Option<cut_panel::ViewGeometry>,
    /// The channel the TF editor edits, and each channel's histogram (log-scaled).
    pub channel: usize,
    pub channel_histograms: Vec<Vec<f32>>,
    /// A series' playback (one time point: not shown).
    pub playback: channel_panel::Playback,
    /// The labels panel's search text, and what the last pick found.
    pub label_search: String,
    pub pick: Option<String>,
}

/// What the UI asks the frame loop to do besides editing the model.
#[derive(Default)]
pub struct UiRequests {
    pub screenshot: bool,
}

impl UiState {
    pub fn new(histogram: &[u32], window: [f32; 2]) -> Self {
        Self {
            show_panel: true,
            show_help: false,
            tf_editor: TfEditor::new(),
            histogram: log_histogram(histogram),
            window,
            stats: Stats::default(),
            status: None,
            recording: false,
            max_spp: 1,
            view: None,
            channel: 0,
            channel_histograms: Vec::new(),
            playback: channel_panel::Playback::new(1),
            label_search: String::new(),
            pick: None,
        }
    }

    pub fn set_status(&mut self, text: impl Into<String>) {
        self.status = Some((text.into(), std::time::Instant::now()));
    }
}

/// Counts to bar heights: log(1 + n) / log(1 + max), so sparse tissue classes stay
/// visible next to the air peak.
pub fn log_histogram(counts: &[u32]) -> Vec<f32> {
    let max = counts.iter().copied().max().unwrap_or(0) as f32;
    if max <= 0.0 {
        return vec![0.0; counts.len()];
    }
    counts
        .iter()
        .map(|&n| (1.0 + n as f32).ln() / (1.0 + max).ln())
        .collect()
}

/// Sets the explorer's look (dark, with a distinctive panel colour).
pub fn style(ctx: &egui::Context) {
    let mut visuals = egui::Visuals::dark();
    visuals.panel_fill = PANEL_FILL;
    ctx.set_visuals(visuals);
}

/// Draws the panel and overlays for one frame.
pub fn draw(ui: &mut egui::Ui, state: &mut UiState, model: &mut Model) -> UiRequests {
    let mut requests = UiRequests::default();
    if state.show_panel {
        egui::Panel::right("controls")
            .exact_size(PANEL_WIDTH)
            .resizable(false)
            .frame(egui::Frame::side_top_panel(ui.style()).fill(PANEL_FILL))
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    panel(ui, state, model, &mut requests);
                });
            });
    }
    if let Some(view) = &state.view {
        cut_panel::draw_outline(ui.ctx(), &model.cut, view);
        orientation::draw(ui.ctx(), view);
    }
    if state.show_help {
        help(ui.ctx(), &mut state.show_help);
    }
    if let Some((text, at)) = &state.status {
        if at.elapsed().as_secs_f32() < 4.0 {
            egui::Area::new(egui::Id::new("status"))
                .anchor(egui::Align2::LEFT_BOTTOM, [8.0, -8.0])
                .show(ui.ctx(), |ui| {
                    egui::Frame::popup(ui.style()).show(ui, |ui| ui.label(text.as_str()));
                });
        }
    }
    requests
}

fn panel(ui: &mut egui::Ui, state: &mut UiState, model: &mut Model, requests: &mut UiRequests) {
    ui.horizontal(|ui| {
        ui.heading("dvr explore");
        if ui.small_button("?").on_hover_text("help (H)").clicked() {
            state.show_help = !state.show_help;
        }
        if ui
            .small_button("📷")
            .on_hover_text("screenshot (F12)")
            .clicked()
        {
            requests.screenshot = true;
        }
    });
    let fps = match state.stats.mean_frame_ms() {
        ms if ms > 0.0 => 1000.0 / ms,
        _ => 0.0,
    };
    ui.label(
        RichText::new(format!(
            "{} · {}×{}{} · {fps:.1} fps{}",
            state.stats.device,
            state.stats.render_size.0,
            state.stats.render_size.1,
            match state.stats.divisor {
                k if k > 1 => format!(" (1/{k}, moving)"),
                _ => String::new(),
            },
            if state.recording { " · ● rec" } else { "" }
        ))
        .small(),
    );
    ui.label(RichText::new(&state.stats.volume).small());
    if model.channels.is_empty() {
        egui::CollapsingHeader::new("Transfer function")
            .default_open(true)
            .show(ui, |ui| {
                tf_editor::show(
                    ui,
                    &mut state.tf_editor,
                    &mut model.tf,
                    &state.histogram,
                    state.window,
                );
            });
    } else {
        egui::CollapsingHeader::new("Channels")
            .default_open(true)
            .show(ui, |ui| channel_panel::channels(ui, state, model));
    }
    if !model.labels.is_empty() {
        egui::CollapsingHeader::new("Labels")
            .default_open(true)
            .show(ui, |ui| label_panel::labels(ui, state, model));
    }
    if state.playback.times > 1 {
        egui::CollapsingHeader::new("Time")
            .default_open(true)
            .show(ui, |ui| {
                channel_panel::time(ui, &mut state.playback, &mut model.time)
            });
    }
    egui::CollapsingHeader::new("Denoiser")
        .default_open(true)
        .show(ui, |ui| denoiser_controls(ui, model));
    egui::CollapsingHeader::new("Lights")
        .default_open(true)
        .show(ui, |ui| lights(ui, state, &mut model.lights));
    egui::CollapsingHeader::new("Cuts")
        .default_open(true)
        .show(ui, |ui| {
            cut_panel::show(ui, &mut model.cut, state.view.as_ref(), state.recording)
        });
    egui::CollapsingHeader::new("Render")
        .default_open(true)
        .show(ui, |ui| render_controls(ui, state, model));
    egui::CollapsingHeader::new("GPU time per pass")
        .default_open(true)
        .show(ui, |ui| timing(ui, &state.stats));
}

fn denoiser_controls(ui: &mut egui::Ui, model: &mut Model) {
    let pick = |ui: &mut egui::Ui, id: &str, value: &mut String| {
        egui::ComboBox::from_id_salt(id)
            .selected_text(value.as_str())
            .show_ui(ui, |ui| {
                for d in DENOISERS {
                    ui.selectable_value(value, d.name.to_string(), d.name)
                        .on_hover_text(d.description);
                }
            });
    };
    ui.horizontal(|ui| {
        ui.label("show");
        pick(ui, "left", &mut model.left);
    });
    let mut split = model.right.is_some();
    ui.horizontal(|ui| {
        ui.checkbox(&mut split, "split view, right:");
        if split {
            let mut right = model.right.clone().unwrap_or_else(|| {
                DENOISERS
                    .iter()
                    .find(|d| d.name != model.left)
                    .map_or_else(|| model.left.clone(), |d| d.name.to_string())
            });
            pick(ui, "right", &mut right);
            model.right = Some(right);
        } else {
            model.right = None;
        }
    });
    if model.right.is_some() {
        ui.add(egui::Slider::new(&mut model.split, 0.05..=0.95).text("split"));
        if model.right.as_deref() == Some(model.left.as_str()) {
            ui.label(RichText::new("pick two different denoisers").color(Color32::YELLOW));
        }
    }
}

fn colour_edit(ui: &mut egui::Ui, c: &mut DVec3) {
    let mut rgb = [c.x as f32, c.y as f32, c.z as f32];
    if ui.color_edit_button_rgb(&mut rgb).changed() {
        *c = DVec3::new(rgb[0] as f64, rgb[1] as f64, rgb[2] as f64);
    }
}

fn position_edit(ui: &mut egui::Ui, p: &mut DVec3) {
    for (axis, v) in ["x", "y", "z"].iter().zip([&mut p.x, &mut p.y, &mut p.z]) {
        ui.add(egui::Slider::new(v, -3.0..=3.0).text(*axis));
    }
}

fn intensity_edit(ui: &mut egui::Ui, x: &mut f64, max: f64) {
    ui.add(
        egui::Slider::new(x, 0.0..=max)
            .logarithmic(true)
            .text("intensity"),
    );
}

const KINDS: [&str; 3] = ["point", "area", "environment"];

fn kind_index(l: &Light) -> usize {
    match l {
        Light::Point(_) => 0,
        Light::Area(_) => 1,
        Light::Environment(_) => 2,
    }
}

/// A light of kind `k` that keeps what it can of `l` (position, colour, intensity).
fn convert(l: &Light, k: usize) -> Light {
    let position = l.position().unwrap_or(DVec3::new(0.9, 1.1, 1.0));
    let colour = l.colour().unwrap_or(DVec3::ONE);
    match k {
        0 => Light::Point(PointLight {
            position,
            colour,
            intensity: if matches!(l, Light::Point(_)) {
                l.intensity()
            } else {
                20.0
            },
        }),
        1 => Light::Area(AreaLight {
            position,
            facing: Facing::Target(DVec3::ZERO),
            size: DVec2::new(0.5, 0.5),
            colour,
            intensity: 40.0,
        }),
        _ => Light::Environment(EnvironmentLight {
            source: EnvSource::Gradient {
                top: DVec3::new(0.55, 0.65, 0.8),
                bottom: DVec3::new(0.2, 0.18, 0.15),
            },
            intensity: 0.25,
        }),
    }
}

fn lights(ui: &mut egui::Ui, state: &UiState, lights: &mut Vec<Light>) {
    let mut remove = None;
    let has_env = lights.iter().any(|l| matches!(l, Light::Environment(_)));
    for (i, light) in lights.iter_mut().enumerate() {
        ui.push_id(i, |ui| {
            ui.separator();
            ui.horizontal(|ui| {
                ui.label(format!("light {i}"));
                let current = kind_index(light);
                ui.add_enabled_ui(!state.recording, |ui| {
                    egui::ComboBox::from_id_salt("kind")
                        .selected_text(KINDS[current])
                        .show_ui(ui, |ui| {
                            for (k, name) in KINDS.iter().enumerate() {
                                // One environment at most.
                                let allowed = k != 2 || !has_env || current == 2;
                                if ui
                                    .add_enabled(
                                        allowed,
                                        egui::Button::selectable(k == current, *name),
                                    )
                                    .clicked()
                                    && k != current
                                {
                                    *light = convert(light, k);
                                }
                            }
                        });
                    if ui.small_button("remove").clicked() {
                        remove = Some(i);
                    }
                });
            });
            match light {
                Light::Point(p) => {
                    position_edit(ui, &mut p.position);
                    ui.horizontal(|ui| {
                        ui.label("colour");
                        colour_edit(ui, &mut p.colour);
                    });
                    intensity_edit(ui, &mut p.intensity, 500.0);
                }
                Light::Area(a) => {
                    position_edit(ui, &mut a.position);
                    ui.add(egui::Slider::new(&mut a.size.x, 0.05..=2.0).text("width"));
                    ui.add(egui::Slider::new(&mut a.size.y, 0.05..=2.0).text("height"));
                    ui.horizontal(|ui| {
                        ui.label("colour");
                        colour_edit(ui, &mut a.colour);
                    });
                    intensity_edit(ui, &mut a.intensity, 1000.0);
                }
                Light::Environment(e) => {
                    match &mut e.source {
                        EnvSource::Constant { colour } => {
                            ui.horizontal(|ui| {
                                ui.label("colour");
                                colour_edit(ui, colour);
                            });
                        }
                        EnvSource::Gradient { top, bottom } => {
                            ui.horizontal(|ui| {
                                ui.label("top");
                                colour_edit(ui, top);
                                ui.label("bottom");
                                colour_edit(ui, bottom);
                            });
                        }
                        EnvSource::Map { path } => {
                            ui.label(format!("map {}", path.display()));
                        }
                    }
                    intensity_edit(ui, &mut e.intensity, 10.0);
                }
            }
        });
    }
    if let Some(i) = remove {
        lights.remove(i);
    }
    ui.add_enabled_ui(!state.recording && lights.len() < MAX_LIGHTS, |ui| {
        if ui.button("add point light").clicked() {
            lights.push(convert(
                &Light::Point(PointLight {
                    position: DVec3::new(-0.9, 1.1, 1.0),
                    colour: DVec3::ONE,
                    intensity: 20.0,
                }),
                0,
            ));
        }
    });
}

/// A slider over `range` starting at `value`; the new value when the user moved it.
fn slider<T: egui::emath::Numeric>(
    ui: &mut egui::Ui,
    value: T,
    range: std::ops::RangeInclusive<T>,
    label: &str,
) -> Option<T> {
    let mut v = value;
    ui.add(egui::Slider::new(&mut v, range).text(label))
        .changed()
        .then_some(v)
}

fn render_controls(ui: &mut egui::Ui, state: &mut UiState, model: &mut Model) {
    // Each edit goes through the settings' own checks; a refused value stays unapplied
    // and says why.
    let r = &mut model.render;
    let mut refused = None;
    let spp = slider(ui, r.spp(), 1..=state.max_spp.max(1), "spp / frame");
    let bounces = slider(ui, r.max_bounces(), 0..=16, "max bounces");
    for e in [
        spp.map(|n| r.set_spp(n)),
        bounces.map(|n| r.set_max_bounces(n)),
    ]
    .into_iter()
    .flatten()
    .filter_map(Result::err)
    {
        refused = Some(e);
    }
    let mut estimator = r.estimator();
    ui.horizontal(|ui| {
        ui.label("estimator");
        egui::ComboBox::from_id_salt("estimator")
            .selected_text(match estimator {
                scene::Estimator::Delta => "delta tracking",
                scene::Estimator::RayMarch => "ray marching",
            })
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut estimator, scene::Estimator::Delta, "delta tracking");
                ui.selectable_value(&mut estimator, scene::Estimator::RayMarch, "ray marching");
            });
    });
    r.set_estimator(estimator);
    if estimator == scene::Estimator::RayMarch {
        if let Some(step) = slider(ui, r.step_size(), 0.1..=4.0, "step (voxels)") {
            refused = r.set_step_size(step).err().or(refused);
        }
    }
    let mut phase = r.phase();
    ui.horizontal(|ui| {
        ui.label("phase");
        egui::ComboBox::from_id_salt("phase")
            .selected_text(format!("{phase:?}").to_lowercase())
            .show_ui(ui, |ui| {
                for p in [
                    scene::Phase::Isotropic,
                    scene::Phase::Hg,
                    scene::Phase::Hybrid,
                ] {
                    ui.selectable_value(&mut phase, p, format!("{p:?}").to_lowercase());
                }
            });
    });
    r.set_phase(phase);
    if phase != scene::Phase::Isotropic {
        if let Some(g) = slider(ui, r.hg_g(), -0.9..=0.9, "HG g") {
            refused = r.set_hg_g(g).err().or(refused);
        }
    }
    if let Some(rr) = slider(
        ui,
        r.russian_roulette_depth(),
        0..=16,
        "roulette from bounce",
    ) {
        refused = r.set_russian_roulette_depth(rr).err().or(refused);
    }
    if let Some(e) = refused {
        state.set_status(e.to_string());
    }
    ui.add(
        egui::Slider::new(&mut model.exposure, 0.1..=10.0)
            .logarithmic(true)
            .text("exposure"),
    );
    ui.checkbox(&mut model.vsync, "vsync")
        .on_hover_text(format!("present mode: {}", state.stats.present_mode));
    ui.label(RichText::new("estimator and phase rebuild the renderer").small());
}

fn timing(ui: &mut egui::Ui, stats: &Stats) {
    let total: f64 = stats.timings.iter().map(|t| t.ms).sum();
    let max = stats
        .timings
        .iter()
        .map(|t| t.ms)
        .fold(0.0f64, f64::max)
        .max(1e-6);
    let width = ui.available_width();
    for t in &stats.timings {
        let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 14.0), egui::Sense::hover());
        let p = ui.painter();
        let bar = egui::Rect::from_min_size(
            rect.min,
            egui::vec2(rect.width() * (t.ms / max) as f32, rect.height()),
        );
        p.rect_filled(bar, 2.0, Color32::from_rgb(70, 110, 160));
        p.text(
            rect.left_center() + egui::vec2(4.0, 0.0),
            egui::Align2::LEFT_CENTER,
            format!("{}  {:.2} ms", t.pass, t.ms),
            egui::FontId::monospace(10.0),
            Color32::WHITE,
        );
    }
    ui.label(format!(
        "GPU frame span {:.2} ms (sum of passes {total:.2} ms)",
        gpu_span_ms(&stats.timings)
    ));
    // Frame-time graph: CPU frame interval (orange) and GPU total (blue).
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 60.0), egui::Sense::hover());
    let p = ui.painter();
    p.rect_filled(rect, 2.0, Color32::from_gray(20));
    let peak = stats
        .history
        .iter()
        .map(|h| h.0.max(h.1))
        .fold(1.0f32, f32::max);
    let n = HISTORY as f32;
    for (series, colour) in [
        (0usize, Color32::from_rgb(230, 150, 60)),
        (1, Color32::from_rgb(90, 160, 230)),
    ] {
        let points: Vec<egui::Pos2> = stats
            .history
            .iter()
            .enumerate()
            .map(|(i, h)| {
                let v = if series == 0 { h.0 } else { h.1 };
                egui::pos2(
                    rect.left() + rect.width() * i as f32 / (n - 1.0),
                    rect.bottom() - rect.height() * v / peak,
                )
            })
            .collect();
        if points.len() > 1 {
            p.add(egui::Shape::line(points, egui::Stroke::new(1.0, colour)));
        }
    }
    p.text(
        rect.left_top() + egui::vec2(3.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!("{peak:.0} ms · frame (orange) · GPU span (blue)"),
        egui::FontId::monospace(9.0),
        Color32::LIGHT_GRAY,
    );
}

fn help(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Help")
        .open(open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| {
            egui::Grid::new("shortcuts").striped(true).show(ui, |ui| {
                for (keys, what) in SHORTCUTS {
                    ui.label(RichText::new(*keys).strong());
                    ui.label(*what);
                    ui.end_row();
                }
            });
            ui.separator();
            ui.label(
                "Transfer function: drag points; double-click adds one, right-click removes it.",
            );
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_histogram_is_normalised_and_keeps_small_bins_visible() {
        let h = log_histogram(&[1_000_000, 10, 0, 1000]);
        assert_eq!(h[0], 1.0);
        assert_eq!(h[2], 0.0);
        assert!(h[1] > 0.1 && h[1] < h[3] && h[3] < 1.0);
        assert_eq!(log_histogram(&[0, 0]), vec![0.0, 0.0]);
    }

    #[test]
    fn gpu_span_runs_from_the_first_start_to_the_last_end() {
        let t = |pass: &str, start_ms, ms| PassTiming {
            pass: pass.into(),
            owner: Default::default(),
            start_ms,
            ms,
            bytes: 0,
        };
        let timings = [t("a", 0.0, 0.01), t("b", 40.0, 0.01), t("c", 41.0, 2.0)];
        assert_eq!(gpu_span_ms(&timings), 43.0);
        assert_eq!(gpu_span_ms(&[]), 0.0);
    }

    #[test]
    fn light_kind_changes_keep_position_and_colour() {
        let p = Light::Point(PointLight {
            position: DVec3::new(1.0, 2.0, 3.0),
            colour: DVec3::new(0.5, 0.6, 0.7),
            intensity: 5.0,
        });
        let a = convert(&p, 1);
        assert_eq!(a.position(), p.position());
        assert_eq!(a.colour(), p.colour());
        assert_eq!(kind_index(&a), 1);
        assert_eq!(kind_index(&convert(&a, 2)), 2);
        assert_eq!(convert(&p, 0), p);
    }
}
