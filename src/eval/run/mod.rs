//! The evaluation of one scene: references (cached), then the animation rendered once
//! with every method, each method's frames scored and written, then the accumulation
//! baseline ([`baseline`]). CPU work runs on a pool while the GPU renders
//! ([`overlap`]); where the wall time went is counted in [`timing`].
//!
//! The eval's third layer: it imports the plan, the references and the results' types,
//! and nothing above them (the scores and reports read what it returns).

pub mod baseline;
mod images;
pub mod overlap;
pub mod timing;

use super::plan::scenes;
use super::plan::settings::{scene_args, EvalArgs, GPU_WARMUP_FRAMES};
use super::plan::{Plan, PlannedScene};
use super::references::fill::FillReport;
use super::references::{frame_name, ReferenceCache};
use super::results::{MetricRow, SceneResult};
use crate::profile::method_gpu_ms;
use crate::progress::Progress;
use crate::setup::Setup;
use crate::shard::{FolderReport, RunReport};
use anyhow::{Context, Result};
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::image_io::{to_rgb, write_exr};
use dvr_engine::metrics::Rgb32Image;
use dvr_engine::metrics::{self as score, score, FrameReference};
use dvr_engine::passes::aux_features;
use dvr_engine::renderer::{FrameRequest, FrameResult};
use images::{write_display_png, write_flip_png};
use overlap::Overlap;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use timing::Timing;

/// The method whose frames are also kept as EXR: the noisy input, for external
/// denoisers (`tools/oidn_eval.py`).
pub const NOISY_METHOD: &str = "none";

/// The folder of a scene's guide images (`--aux`): `NNNN_albedo.exr`, `NNNN_normal.exr`.
pub const AUX_DIR: &str = "aux";

/// Work units of the plan's scenes that `take` accepts (by index; see [`Progress`]):
/// references still missing, frames, the baseline.
pub fn total_units(plan: &Plan, take: impl Fn(usize) -> bool) -> f64 {
    plan.scenes
        .iter()
        .enumerate()
        .filter(|(i, _)| take(*i))
        .map(|(_, s)| {
            ReferenceCache::of(s).missing().len() as f64 * f64::from(plan.ref_spp)
                + f64::from(s.frames) * (f64::from(s.spp) + plan.methods as f64)
                + if plan.baseline {
                    baseline::units(s.frames, plan.ref_spp)
                } else {
                    0.0
                }
        })
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

/// A finished frame's outputs, (method, rgba pixels) in the renderer's order, shared
/// with the scoring jobs.
type Images = Arc<Vec<(String, Vec<[f32; 4]>)>>;

/// The scoring of one finished frame, run on the thread pool: every method against the
/// frame's reference (methods in parallel), its PNGs (and the noisy EXR) written.
struct ScoreJob {
    scene: String,
    dir: PathBuf,
    frame: u32,
    size: (u32, u32),
    images: Images,
    /// GPU ms of each method, in the order of `images`.
    gpu_ms: Vec<f64>,
    reference: Arc<Rgb32Image>,
    /// The previous frame's outputs and reference (temporal error), if any.
    previous: Option<(Images, Arc<Rgb32Image>)>,
    timing: Arc<Timing>,
}

impl ScoreJob {
    fn run(self) -> Result<Vec<MetricRow>> {
        let (w, h) = self.size;
        let (reference, previous_reference) = self.timing.metrics.time(|| {
            let previous = self.previous.as_ref().map(|(_, r)| score::display(r));
            (FrameReference::new(&self.reference), previous)
        });
        self.images
            .par_iter()
            .zip(&self.gpu_ms)
            .map(|((method, pixels), &gpu_ms)| {
                let hdr = to_rgb(w, h, pixels);
                let s = self.timing.metrics.time(|| {
                    // The method's previous frame as displayed, tone-mapped again: the
                    // same values the previous job scored with.
                    let previous = self
                        .previous
                        .as_ref()
                        .and_then(|(images, _)| images.iter().find(|(m, _)| m == method))
                        .map(|(_, p)| score::display(&to_rgb(w, h, p)));
                    score(
                        &reference,
                        &hdr,
                        previous.as_ref().zip(previous_reference.as_ref()),
                    )
                });
                let dir = self.dir.join(method);
                let f = self.frame;
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
                Ok(MetricRow {
                    scene: self.scene.clone(),
                    method: method.clone(),
                    frame: f,
                    psnr: s.psnr,
                    ssim: s.ssim,
                    flip: s.flip,
                    temporal_error: s.temporal_error,
                    gpu_ms,
                })
            })
            .collect()
    }
}

/// What the frame loop keeps between frames.
struct FrameState<'a> {
    scene: &'a PlannedScene,
    references: &'a ReferenceCache,
    setup: &'a Setup,
    previous: Option<(Images, Arc<Rgb32Image>)>,
    jobs: Overlap<Vec<MetricRow>>,
    timings: Vec<Vec<PassTiming>>,
    timing: Arc<Timing>,
}

impl FrameState<'_> {
    /// Hands one finished frame (frames arrive in order) to the scoring jobs.
    fn process(&mut self, mut done: FrameResult) -> Result<()> {
        let f = done.index as u32;
        // The guide images (`--aux`) are written for external denoisers, not scored.
        let (aux, methods) = std::mem::take(&mut done.images)
            .into_iter()
            .partition(|(name, _)| name == aux_features::ALBEDO || name == aux_features::NORMAL);
        done.images = methods;
        if !aux.is_empty() {
            let dir = self.scene.dir.join(AUX_DIR);
            let (w, h) = (self.setup.width(), self.setup.height());
            self.jobs.spawn(move || {
                for (name, pixels) in aux {
                    let kind = name.trim_start_matches("aux.");
                    let path = dir.join(format!("{}_{kind}.exr", frame_name(f)));
                    write_exr(&path, &to_rgb(w, h, &pixels))?;
                }
                Ok(Vec::new())
            })?;
        }
        let reference = Arc::new(self.references.load(f)?);
        let gpu_ms = done
            .images
            .iter()
            .map(|(m, _)| method_gpu_ms(&done.timings, m))
            .collect();
        let images: Images = Arc::new(done.images);
        let job = ScoreJob {
            scene: self.scene.name.clone(),
            dir: self.scene.dir.clone(),
            frame: f,
            size: (self.setup.width(), self.setup.height()),
            images: Arc::clone(&images),
            gpu_ms,
            reference: Arc::clone(&reference),
            previous: self.previous.take(),
            timing: Arc::clone(&self.timing),
        };
        self.jobs.spawn(move || job.run())?;
        self.previous = Some((images, reference));
        self.timings.push(done.timings);
        Ok(())
    }
}

/// The eval's view of filling a scene's reference cache: notes under the progress
/// line, reference frames counted as progress, each frame written on the pool while the
/// GPU renders the next, and the renderer's GPU time counted.
pub(super) struct ReferenceProgress<'a> {
    pub progress: &'a mut Progress,
    pub label: &'a str,
    pub ref_spp: u32,
    pub timing: &'a Arc<Timing>,
    pub writes: Option<Overlap<()>>,
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

    fn store(&mut self, cache: &ReferenceCache, f: u32, img: Rgb32Image) -> Result<()> {
        let cache = cache.clone();
        self.writes
            .get_or_insert_with(|| Overlap::new(self.timing))
            .spawn(move || cache.store(f, &img))
    }

    fn finished(&mut self, renderer: &dvr_engine::renderer::Renderer) -> Result<()> {
        if let Some(writes) = self.writes.take() {
            writes.finish()?;
        }
        self.timing.add_gpu_ms(renderer.gpu_ms());
        Ok(())
    }
}

pub fn evaluate_scene(
    args: &EvalArgs,
    methods: &[String],
    scene: &PlannedScene,
    label: &str,
    progress: &mut Progress,
    timing: &Arc<Timing>,
    report: &mut RunReport,
) -> Result<SceneResult> {
    progress.show(&format!("{label} | loading"));
    let setup = Setup::new(&scene_args(args, &scene.spec))?;
    let references = ReferenceCache::of(scene);
    let filled = timing.references.time(|| {
        references.fill(
            &setup,
            &mut ReferenceProgress {
                progress,
                label,
                ref_spp: args.ref_spp,
                timing,
                writes: None,
            },
        )
    })?;
    report.references.push(FolderReport {
        scene: scene.name.clone(),
        folder: references.dir.clone(),
        selected: (0..scene.frames).collect(),
        rendered: filled.rendered,
        reused: filled.reused,
    });
    // Held until the scene's frames are scored: no run with other settings can change
    // the references meanwhile.
    let _claim = filled.claim;

    let names: Vec<&str> = methods.iter().map(String::as_str).collect();
    let mut session = setup.session(&names)?;
    let aux_dir = args.aux.then_some(AUX_DIR);
    for m in methods.iter().map(String::as_str).chain(aux_dir) {
        let dir = scene.dir.join(m);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let mut state = FrameState {
        scene,
        references: &references,
        setup: &setup,
        previous: None,
        jobs: Overlap::new(timing),
        timings: Vec::new(),
        timing: Arc::clone(timing),
    };
    let request = FrameRequest {
        readback: true,
        reset: false,
        aux: args.aux,
        features: false,
    };
    let frame_units = f64::from(setup.settings.spp()) + methods.len() as f64;
    let status = |f: u32| {
        format!(
            "{label} | {} | frame {f}/{}",
            methods.join(","),
            setup.frames
        )
    };
    let frames_started = std::time::Instant::now();
    for f in 0..setup.frames {
        session.play(f)?;
        if let Some(done) = session.frame(&request, None)? {
            state.process(done)?;
        }
        progress.advance(frame_units, &status(f + 1));
    }
    for done in session.flush()? {
        state.process(done)?;
    }
    let rows: Vec<MetricRow> = state.jobs.finish()?.into_iter().flatten().collect();
    timing.frames.add(frames_started.elapsed());

    let ms_per_spp = path_trace_ms_per_spp(&state.timings, setup.settings.spp());
    let baseline = timing.baseline.time(|| {
        if args.no_baseline {
            return Ok(Vec::new());
        }
        baseline::measure(
            &mut session,
            &setup,
            &references,
            ms_per_spp,
            args.ref_spp,
            progress,
            label,
            timing,
        )
    })?;
    let renderer = session.renderer()?;
    timing.add_gpu_ms(renderer.gpu_ms());
    let device = renderer.ctx().info.name.clone();
    crate::output::write_json(
        &scene.dir.join("timings.json"),
        &serde_json::json!({
            "device": device,
            "scene": scene.name,
            "width": setup.width(),
            "height": setup.height(),
            "spp": setup.settings.spp(),
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
        spp: setup.settings.spp(),
        methods: methods.to_vec(),
        event_frame,
        rows,
        baseline,
        path_trace_ms_per_spp: ms_per_spp,
        device,
        volume: renderer.volume_residency().to_string(),
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
    use dvr_engine::gpu::timestamps::PassOwner;

    fn t(pass: &str, ms: f64) -> PassTiming {
        let owner = match pass.split_once('.') {
            _ if pass.starts_with("upload") || pass.starts_with("readback") => PassOwner::Transfer,
            _ if pass.ends_with("features") => {
                PassOwner::Methods(vec!["ours".into(), "rls-nf".into()])
            }
            Some((method, _)) => PassOwner::Method(method.into()),
            None if pass == "accum" => PassOwner::Method(pass.into()),
            None => PassOwner::Shared,
        };
        PassTiming {
            pass: pass.into(),
            owner,
            start_ms: 0.0,
            ms,
            bytes: 0,
        }
    }

    #[test]
    fn gpu_ms_is_shared_passes_plus_own() {
        let frame = vec![
            t("upload_tf_diffuse", 100.0),
            t("surface_features", 1.0),
            t("aux_features", 0.125),
            t("path_trace", 10.0),
            t("motion", 0.5),
            t("accum", 0.25),
            t("ours.update", 2.0),
            t("ours.spatial", 3.0),
            t("rls-nf.update", 40.0),
            t("readback_ours", 7.0),
        ];
        // The features count for each method that reads them, and for no other.
        assert_eq!(method_gpu_ms(&frame, "none"), 10.5);
        assert_eq!(method_gpu_ms(&frame, "accum"), 10.75);
        assert_eq!(method_gpu_ms(&frame, "ours"), 16.625);
        assert_eq!(method_gpu_ms(&frame, "rls-nf"), 51.625);
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
