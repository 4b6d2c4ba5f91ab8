//! `dvr eval`: every listed denoiser on scripted animations against high-sample
//! references, in one run.
//!
//! For each scene: references at `--ref-spp` per frame (cached under
//! `DIR/<scene>/reference/`, reused when the settings match), then one renderer with all
//! denoisers renders each noisy frame once and feeds it to every method; each method's
//! HDR output is tone-mapped with [`tonemap_srgb`](dvr_engine::metrics::tonemap_srgb)
//! (exposure [`EXPOSURE`]) and scored against the tone-mapped reference (PSNR, SSIM,
//! FLIP, temporal error), and its GPU time is the shared passes plus its own. A plain
//! accumulation baseline at 1, 2, 4, … spp on a few frames gives the speed-vs-accuracy
//! curve. Outputs (see the book's evaluation page):
//!
//! ```text
//! DIR/metrics.csv                 scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms
//! DIR/summary.csv                 per scene and method: means and frames to recover
//! DIR/baseline.csv                accumulation baseline: scene,frame,spp,gpu_ms,psnr
//! DIR/index.html                  the results page (works from file://)
//! DIR/plots/speed_accuracy.{svg,png}        all scenes
//! DIR/<scene>/plots/*.{svg,png}             metric vs frame, speed vs accuracy
//! DIR/<scene>/reference/NNNN.{exr,png}      + reference.json (the cache key)
//! DIR/<scene>/<method>/NNNN.png, flip_NNNN.png   (+ NNNN.exr for `none`, the noisy input)
//! DIR/<scene>/timings.json        per-frame, per-pass GPU timings
//! DIR/<scene>/result.json         the scene's scores and settings, for `--merge`
//! DIR/<scene>/aux/NNNN_{albedo,normal}.exr  with --aux: guide images for OIDN
//! ```
//!
//! One file per responsibility: [`scenes`] (which scenes, folder names, the event frame),
//! [`reference`] (the cache), [`run`] (the frame loop), [`record`] (each scene's
//! `result.json`), [`farm`] (shards, `--references-only`, `--verify`, `--merge`), [`score`] (metrics of one frame),
//! [`baseline`], [`csv`], [`plots`], [`html`]; progress lines come from
//! [`crate::progress`].

mod baseline;
mod csv;
mod farm;
mod html;
mod images;
mod overlap;
pub mod plots;
mod record;
pub(crate) mod reference;
pub mod run;
mod scenes;
pub mod timing;
mod videos;

pub use plots::init_font;

use anyhow::{Context, Result};
use std::path::PathBuf;
use std::time::Instant;

/// Exposure of the tone map every metric and PNG of an eval uses: the PNGs' own, so
/// what is measured is what is shown (and what `dvr.metrics` in Python measures).
pub const EXPOSURE: f32 = dvr_engine::image_io::PNG_EXPOSURE;

/// A method's PSNR must come back within this many dB of its level before a sudden
/// change for the change to count as recovered from.
pub const RECOVERY_TOLERANCE_DB: f64 = 1.0;

/// Frames left out of the mean GPU time: the first dispatches include driver
/// compilation (see [`crate::profile::WARMUP_FRAMES`]).
pub const GPU_WARMUP_FRAMES: usize = crate::profile::WARMUP_FRAMES;

#[derive(clap::Args, Clone, Debug)]
pub struct EvalArgs {
    /// `suite` (every built-in scene but the stress ones), `stress` (the tf-jump,
    /// light-jump and fast-orbit scenes), a shipped set (`validation`, `development`,
    /// `static`, `paper`: `assets/scenes/<set>/`), or a comma-separated list of these,
    /// built-in scene names and scene files.
    #[arg(long, default_value = "suite")]
    pub scene: String,
    /// Frames of each animation (default: each scene's own length).
    #[arg(long, value_parser = crate::setup::parse_frames)]
    pub frames: Option<u32>,
    /// Samples per pixel of the references (at least 1).
    #[arg(long = "ref-spp", default_value_t = 1024,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub ref_spp: u32,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256", value_parser = crate::setup::parse_size)]
    pub size: (u32, u32),
    /// Comma-separated denoisers, all fed the same noisy frames.
    #[arg(long, default_value = "none,accum,ours", value_delimiter = ',', value_parser = crate::setup::parse_denoiser)]
    pub denoiser: Vec<String>,
    /// Output folder (references in it are reused when their settings match).
    #[arg(long, default_value = "out/eval")]
    pub out: PathBuf,
    #[command(flatten)]
    pub render: crate::RenderArgs,
    #[command(flatten)]
    pub video: crate::video::VideoArgs,
    /// Also write each frame's guide images for single-frame denoisers
    /// (`<scene>/aux/NNNN_albedo.exr`, `NNNN_normal.exr`: the TF albedo and gradient
    /// normal composited along the ray, what `tools/oidn_eval.py` gives OIDN).
    #[arg(long)]
    pub aux: bool,
    /// A paragraph shown at the top of the results page (what was run, and why).
    #[arg(long)]
    pub note: Option<String>,
    #[command(flatten)]
    pub farm: farm::FarmArgs,
}

/// Runs the eval; returns where its time went.
pub fn eval(args: &EvalArgs) -> Result<timing::Outcome> {
    let started = Instant::now();
    let methods = crate::setup::denoiser_list(&args.denoiser)?;
    // Fail before hours of rendering, not after: the plots need a font, videos ffmpeg,
    // and a parameter override must be in range.
    dvr_engine::denoise::check_env_overrides()?;
    let names = scenes::select(&args.scene)?;
    let plan = run::Plan::new(args, &names, &methods)?;
    let timing = timing::Timing::shared();
    let farm = &args.farm;
    if farm.references_only {
        farm::references(args, &plan, &timing)?;
        return Ok(timing.outcome(started.elapsed()));
    }
    if farm.shard.verify {
        farm::verify(args, &plan, &methods)?;
        return Ok(timing.outcome(started.elapsed()));
    }
    plots::init_font()?;
    if farm.merge {
        let (results, seconds) = farm::results(args, &plan, &methods)?;
        let device = results.last().map(|r| r.device.clone()).unwrap_or_default();
        write_reports(args, &methods, &results, &device, seconds)?;
        print_summary(args, &methods, &results, seconds);
        return Ok(timing.outcome(started.elapsed()));
    }
    if args.video.video {
        crate::video::require_ffmpeg()?;
    }
    crate::setup::create_out_dir(&args.out)?;
    let take = |i: usize| farm.shard.takes(i);
    let mut progress = crate::progress::Progress::new(plan.total_units(take));
    let mut report = crate::shard::RunReport::new(&farm.shard);
    let mut results = Vec::new();
    let mut device = String::new();
    for (i, scene) in plan.scenes.iter().enumerate().filter(|(i, _)| take(*i)) {
        let scene_started = Instant::now();
        let label = format!("[{}/{}] {}", i + 1, plan.scenes.len(), scene.name);
        let r = run::evaluate_scene(
            args,
            &methods,
            scene,
            &label,
            &mut progress,
            &timing,
            &mut report,
        )
        .with_context(|| format!("evaluating {}", scene.name))?;
        device.clone_from(&r.device);
        timing.reports.time(|| -> Result<()> {
            record::save(
                &scene.dir,
                &farm::result_key(args, &methods, scene),
                scene_started.elapsed().as_secs_f64(),
                &r,
            )?;
            report.scenes.push(r.name.clone());
            report.write(farm.shard.report.as_deref())?;
            plots::scene_plots(&args.out, &r)?;
            if args.video.video {
                progress.newline();
                let dir = crate::video::dir(&args.out.join(&r.dir));
                eprintln!("{label}: writing videos to {}", dir.display());
                videos::write_scene_videos(&args.out, &r, args.video.video_fps)?;
            }
            results.push(r);
            // Everything is rewritten after each scene, so an interrupted eval leaves a
            // consistent report of the scenes it finished. A shard leaves the reports
            // to `--merge`.
            if farm.shard.shard.is_none() {
                write_reports(
                    args,
                    &methods,
                    &results,
                    &device,
                    started.elapsed().as_secs_f64(),
                )?;
            }
            Ok(())
        })?;
    }
    progress.finish();
    report.write(farm.shard.report.as_deref())?;
    if let Some(shard) = farm.shard.label() {
        println!(
            "eval: shard {shard} evaluated {} of {} scene(s) into {}; when every shard has \
             finished, `dvr eval --merge` with the same options writes the reports",
            results.len(),
            plan.scenes.len(),
            args.out.display()
        );
    } else {
        print_summary(args, &methods, &results, started.elapsed().as_secs_f64());
    }
    let wall = started.elapsed();
    eprintln!("{}", timing.summary(wall));
    Ok(timing.outcome(wall))
}

fn print_summary(args: &EvalArgs, methods: &[String], results: &[run::SceneResult], seconds: f64) {
    let overall = csv::overall_summary(results, methods);
    print!("{}", csv::summary_table(results, &overall));
    println!(
        "eval: {} scene(s) × {} method(s) in {seconds:.1} s; open {}",
        results.len(),
        methods.len(),
        args.out.join("index.html").display()
    );
}

fn write_reports(
    args: &EvalArgs,
    methods: &[String],
    results: &[run::SceneResult],
    device: &str,
    seconds: f64,
) -> Result<()> {
    let out = &args.out;
    csv::write_metrics(&out.join("metrics.csv"), results)?;
    csv::write_summary(&out.join("summary.csv"), results)?;
    csv::write_baseline(&out.join("baseline.csv"), results)?;
    let overall = csv::overall_summary(results, methods);
    plots::overall_plot(out, results, &overall)?;
    html::write_page(
        &out.join("index.html"),
        &html::PageInfo {
            args,
            methods,
            device,
            seconds,
        },
        results,
        &overall,
    )
}
