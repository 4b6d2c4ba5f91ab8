//! The evaluation of one scene: references (cached), then the animation rendered once
//! with every method, each method's frames scored and written, then the accumulation
//! baseline.

use super::baseline::{self, BaselinePoint};
use super::images::{write_display_png, write_flip_png};
use super::progress::Progress;
use super::reference::{frame_name, FillReport, ReferenceCache, ReferenceKey};
use super::score::{score, FrameReference};
use super::{scenes, EvalArgs, GPU_WARMUP_FRAMES};
use crate::setup::Setup;
use crate::SceneArgs;
use anyhow::{Context, Result};
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::image_io::{to_rgb, write_exr};
use dvr_engine::metrics::Rgb32Image;
use dvr_engine::renderer::{FrameRequest, FrameResult};
use dvr_engine::scene::Scene;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The method whose frames are also kept as EXR: the noisy input, for external
/// denoisers (`tools/oidn_eval.py`).
pub const NOISY_METHOD: &str = "none";

/// Passes of a frame that belong to no method and are not part of its cost: uploads
/// (only when the TF changes) and the readbacks an eval adds.
const UNCOUNTED_PREFIXES: [&str; 3] = ["upload_", "readback_", "host_read_"];

/// One scene as planned before anything renders.
pub struct PlannedScene {
    pub name: String,
    pub dir: PathBuf,
    pub frames: u32,
    pub spp: u32,
    pub references: ReferenceCache,
}

pub struct Plan {
    pub scenes: Vec<PlannedScene>,
    ref_spp: u32,
    methods: usize,
}

impl Plan {
    pub fn new(args: &EvalArgs, names: &[String], methods: &[String]) -> Result<Self> {
        let mut scenes = Vec::new();
        for name in names {
            let mut scene = Scene::open(name).with_context(|| {
                format!("opening scene {name:?} (built-in scenes: `dvr scenes`)")
            })?;
            if let Some(n) = args.frames {
                scene = scene.with_frames(n)?;
            }
            let dir = args.out.join(scenes::dir_name(name));
            let key = ReferenceKey::new(&scene, args.size, args.ref_spp, args.volume_size)?;
            scenes.push(PlannedScene {
                name: name.clone(),
                frames: scene.frames,
                spp: args.spp.unwrap_or(scene.render.spp),
                references: ReferenceCache::new(&dir, key),
                dir,
            });
        }
        Ok(Self {
            scenes,
            ref_spp: args.ref_spp,
            methods: methods.len(),
        })
    }

    /// Work units of the whole eval (see [`Progress`]).
    pub fn total_units(&self) -> f64 {
        self.scenes
            .iter()
            .map(|s| {
                s.references.missing().len() as f64 * f64::from(self.ref_spp)
                    + f64::from(s.frames) * (f64::from(s.spp) + self.methods as f64)
                    + baseline::units(s.frames, self.ref_spp)
            })
            .sum()
    }
}

/// Per-frame scores of one method.
#[derive(Clone, Debug)]
pub struct MetricRow {
    pub scene: String,
    pub method: String,
    pub frame: u32,
    pub psnr: f64,
    pub ssim: f64,
    pub flip: f64,
    pub temporal_error: Option<f64>,
    pub gpu_ms: f64,
}

/// Everything the reports need about one evaluated scene.
pub struct SceneResult {
    pub name: String,
    /// Folder name inside the eval folder.
    pub dir: String,
    pub frames: u32,
    pub spp: u32,
    pub methods: Vec<String>,
    /// Frame of the sudden change, for scenes that have one.
    pub event_frame: Option<u32>,
    pub rows: Vec<MetricRow>,
    pub baseline: Vec<BaselinePoint>,
    pub path_trace_ms_per_spp: f64,
    pub device: String,
}

impl SceneResult {
    /// A method's rows in frame order.
    pub fn series(&self, method: &str) -> Vec<&MetricRow> {
        let mut rows: Vec<&MetricRow> = self.rows.iter().filter(|r| r.method == method).collect();
        rows.sort_by_key(|r| r.frame);
        rows
    }
}

/// GPU time of `method` in one frame: every pass no method owns (surface features,
/// path trace, motion, …) plus the method's own passes, which are named after it
/// (`accum`, `ours.update`, `ours.spatial`; `none` has none).
pub fn method_gpu_ms(timings: &[PassTiming], method: &str, methods: &[String]) -> f64 {
    let owned_by =
        |pass: &str, m: &str| pass == m || pass.strip_prefix(m).is_some_and(|r| r.starts_with('.'));
    timings
        .iter()
        .filter(|t| !UNCOUNTED_PREFIXES.iter().any(|p| t.pass.starts_with(p)))
        .filter(|t| owned_by(&t.pass, method) || !methods.iter().any(|m| owned_by(&t.pass, m)))
        .map(|t| t.ms)
        .sum()
}

/// Mean path-trace time per sample per pixel-frame, over the frames after the warm-up.
fn path_trace_ms_per_spp(timings: &[Vec<PassTiming>], spp: u32) -> f64 {
    let skip = if timings.len() > GPU_WARMUP_FRAMES {
        GPU_WARMUP_FRAMES
    } else {
        0
    };
    let ms: Vec<f64> = timings[skip..]
        .iter()
        .map(|f| {
            f.iter()
                .filter(|t| t.pass == "path_trace")
                .map(|t| t.ms)
                .sum()
        })
        .collect();
    if ms.is_empty() {
        return 0.0;
    }
    ms.iter().sum::<f64>() / ms.len() as f64 / f64::from(spp.max(1))
}

/// What the frame loop keeps between frames.
struct FrameState<'a> {
    scene: &'a PlannedScene,
    setup: &'a Setup,
    methods: &'a [String],
    /// Displayed previous frame of each method, and of the reference.
    previous: HashMap<String, Rgb32Image>,
    previous_reference: Option<Rgb32Image>,
    rows: Vec<MetricRow>,
    timings: Vec<Vec<PassTiming>>,
}

impl FrameState<'_> {
    fn method_dir(&self, method: &str) -> PathBuf {
        self.scene.dir.join(method)
    }

    /// Scores and writes one finished frame (frames arrive in order).
    fn process(&mut self, done: FrameResult) -> Result<()> {
        let f = done.index as u32;
        let reference = FrameReference::new(&self.scene.references.load(f)?);
        let (w, h) = (self.setup.width(), self.setup.height());
        for (method, pixels) in &done.images {
            let hdr = to_rgb(w, h, pixels);
            let previous = self
                .previous
                .get(method)
                .zip(self.previous_reference.as_ref());
            let s = score(&reference, &hdr, previous);
            let dir = self.method_dir(method);
            write_display_png(&dir.join(format!("{}.png", frame_name(f))), &s.display)?;
            write_flip_png(
                &dir.join(format!("flip_{}.png", frame_name(f))),
                w,
                h,
                &s.flip_map,
            )?;
            if method == NOISY_METHOD {
                write_exr(&dir.join(format!("{}.exr", frame_name(f))), &hdr)?;
            }
            self.rows.push(MetricRow {
                scene: self.scene.name.clone(),
                method: method.clone(),
                frame: f,
                psnr: s.psnr,
                ssim: s.ssim,
                flip: s.flip,
                temporal_error: s.temporal_error,
                gpu_ms: method_gpu_ms(&done.timings, method, self.methods),
            });
            self.previous.insert(method.clone(), s.display);
        }
        self.previous_reference = Some(reference.display);
        self.timings.push(done.timings);
        Ok(())
    }
}

fn scene_args(args: &EvalArgs, name: &str) -> SceneArgs {
    SceneArgs {
        scene: name.to_string(),
        frames: args.frames,
        size: args.size,
        spp: args.spp,
        volume_size: args.volume_size,
        motion: args.motion,
    }
}

/// The eval's view of filling a scene's reference cache: notes under the progress
/// line, and reference frames counted as progress.
struct ReferenceProgress<'a> {
    progress: &'a mut Progress,
    label: &'a str,
    ref_spp: u32,
}

impl FillReport for ReferenceProgress<'_> {
    fn note(&mut self, text: Option<&str>) {
        self.progress.newline();
        if let Some(text) = text {
            eprintln!("{}: {text}", self.label);
        }
    }

    fn rendered(&mut self, done: usize, of: usize) {
        let status = format!(
            "{} | reference {done}/{of} ({} spp)",
            self.label, self.ref_spp
        );
        if done == 0 {
            self.progress.show(&status);
        } else {
            self.progress.advance(f64::from(self.ref_spp), &status);
        }
    }
}

pub fn evaluate_scene(
    args: &EvalArgs,
    methods: &[String],
    scene: &PlannedScene,
    label: &str,
    progress: &mut Progress,
) -> Result<SceneResult> {
    progress.show(&format!("{label} | loading"));
    let setup = Setup::new(&scene_args(args, &scene.name))?;
    scene.references.fill(
        &setup,
        &mut ReferenceProgress {
            progress,
            label,
            ref_spp: args.ref_spp,
        },
    )?;

    let names: Vec<&str> = methods.iter().map(String::as_str).collect();
    let mut renderer = setup.renderer(&names)?;
    for m in methods {
        let dir = scene.dir.join(m);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut state = FrameState {
        scene,
        setup: &setup,
        methods,
        previous: HashMap::new(),
        previous_reference: None,
        rows: Vec::new(),
        timings: Vec::new(),
    };
    let request = FrameRequest {
        readback: true,
        reset: false,
    };
    let frame_units = f64::from(setup.settings.spp) + methods.len() as f64;
    let status = |f: u32| {
        format!(
            "{label} | {} | frame {f}/{}",
            methods.join(","),
            setup.frames
        )
    };
    for f in 0..setup.frames {
        if let Some(done) = renderer.frame(&setup.inputs(f), &request)? {
            state.process(done)?;
        }
        progress.advance(frame_units, &status(f + 1));
    }
    for done in renderer.flush()? {
        state.process(done)?;
    }

    let ms_per_spp = path_trace_ms_per_spp(&state.timings, setup.settings.spp);
    let baseline = baseline::measure(
        &mut renderer,
        &setup,
        &scene.references,
        ms_per_spp,
        args.ref_spp,
        progress,
        label,
    )?;
    let device = renderer.ctx().info.name.clone();
    crate::profile::write_json(
        &scene.dir.join("timings.json"),
        &serde_json::json!({
            "device": device,
            "scene": scene.name,
            "width": setup.width(),
            "height": setup.height(),
            "spp": setup.settings.spp,
            "denoisers": methods,
            "frames": state.timings,
        }),
    )?;
    let event_frame = scenes::has_sudden_change(&scene.name)
        .then(|| scenes::event_frame(setup.frames, |f| setup.inputs(f)));
    Ok(SceneResult {
        name: scene.name.clone(),
        dir: dir_file_name(&scene.dir),
        frames: setup.frames,
        spp: setup.settings.spp,
        methods: methods.to_vec(),
        event_frame,
        rows: state.rows,
        baseline,
        path_trace_ms_per_spp: ms_per_spp,
        device,
    })
}

fn dir_file_name(dir: &Path) -> String {
    dir.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(pass: &str, ms: f64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            start_ms: 0.0,
            ms,
        }
    }

    #[test]
    fn gpu_ms_is_shared_passes_plus_own() {
        let frame = vec![
            t("upload_tf_diffuse", 100.0),
            t("surface_features", 1.0),
            t("path_trace", 10.0),
            t("motion", 0.5),
            t("accum", 0.25),
            t("ours.update", 2.0),
            t("ours.spatial", 3.0),
            t("rls-nf.update", 40.0),
            t("readback_ours", 7.0),
        ];
        let methods: Vec<String> = ["none", "accum", "ours", "rls-nf"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(method_gpu_ms(&frame, "none", &methods), 11.5);
        assert_eq!(method_gpu_ms(&frame, "accum", &methods), 11.75);
        assert_eq!(method_gpu_ms(&frame, "ours", &methods), 16.5);
        assert_eq!(method_gpu_ms(&frame, "rls-nf", &methods), 51.5);
    }

    #[test]
    fn path_trace_time_skips_warmup() {
        let frames: Vec<Vec<PassTiming>> = [200.0, 100.0, 4.0, 6.0]
            .iter()
            .map(|&ms| vec![t("path_trace", ms), t("motion", 1.0)])
            .collect();
        assert_eq!(path_trace_ms_per_spp(&frames, 2), 2.5);
        assert_eq!(path_trace_ms_per_spp(&frames[..1], 2), 100.0);
    }
}
