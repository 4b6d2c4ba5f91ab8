//! `dvr eval`: every listed denoiser on scripted animations against high-sample
//! references, in one run.
//!
//! For each scene: references at `--ref-spp` per frame (cached under
//! `DIR/<scene>/reference/`, reused when the settings match), then one renderer with all
//! denoisers renders each noisy frame once and feeds it to every method; each method's
//! HDR output is tone-mapped with [`tonemap_srgb`](dvr_engine::metrics::tonemap_srgb)
//! (exposure [`EXPOSURE`](plan::settings::EXPOSURE)) and scored against the tone-mapped reference (PSNR, SSIM,
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
//! A one-way pipeline of layers, each importing only those below it:
//!
//! ```text
//! farm          --references-only, --verify, --merge: the eval split over machines
//! report        csv, plots, html (+ page.html), videos: written from results and scores
//! run | scores  the frames of a scene, scored | the means and recoveries of the results
//! references | results   the reference cache | what a scene produced, its result.json
//! plan          settings (the options), scenes, keys: what runs, under which keys
//! ```
//!
//! This file drives them in order (plan → references → run → scores → reports); progress
//! lines come from [`crate::progress`], shards from [`crate::shard`].

mod farm;
pub mod plan;
pub mod references;
pub mod report;
pub mod results;
pub mod run;
pub mod scores;

pub use plan::settings::EvalArgs;

use anyhow::{Context, Result};
use plan::scenes;
use plan::Plan;
use results::record;
use run::timing;
use std::time::Instant;

/// Runs the eval; returns where its time went.
pub fn eval(args: &EvalArgs) -> Result<timing::Outcome> {
    let started = Instant::now();
    let methods = crate::setup::denoiser_list(&args.denoiser)?;
    // Fail before hours of rendering, not after: the plots need a font, videos ffmpeg,
    // and a parameter override must be in range.
    dvr_engine::denoise::check_env_overrides()?;
    crate::setup::warn_unused_overrides(&methods);
    let names = scenes::select(&args.scene)?;
    let plan = Plan::new(args, &names, &methods)?;
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
    crate::font::init_font()?;
    if farm.merge {
        let (results, seconds) = farm::results(args, &plan, &methods)?;
        let device = results.last().map(|r| r.device.clone()).unwrap_or_default();
        report::write(args, &methods, &results, &device, seconds)?;
        report::print_summary(args, &methods, &results, seconds);
        return Ok(timing.outcome(started.elapsed()));
    }
    if args.video.video {
        crate::video::require_ffmpeg()?;
    }
    crate::setup::create_out_dir(&args.out)?;
    let take = |i: usize| farm.shard.takes(i);
    let mut progress = crate::progress::Progress::new(run::total_units(&plan, take));
    let mut run_report = crate::shard::RunReport::new(&farm.shard);
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
            &mut run_report,
        )
        .with_context(|| format!("evaluating {}", scene.name))?;
        device.clone_from(&r.device);
        timing.reports.time(|| -> Result<()> {
            record::save(
                &scene.dir,
                &scene.result_key(args, &methods),
                scene_started.elapsed().as_secs_f64(),
                &r,
            )?;
            run_report.scenes.push(r.name.clone());
            run_report.write(farm.shard.report.as_deref())?;
            report::plots::scene_plots(&args.out, &r)?;
            if args.video.video {
                progress.newline();
                let dir = crate::video::dir(&args.out.join(&r.dir));
                eprintln!("{label}: writing videos to {}", dir.display());
                report::videos::write_scene_videos(&args.out, &r, args.video.video_fps)?;
            }
            results.push(r);
            // Everything is rewritten after each scene, so an interrupted eval leaves a
            // consistent report of the scenes it finished. A shard leaves the reports
            // to `--merge`.
            if farm.shard.shard.is_none() {
                report::write(
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
    run_report.write(farm.shard.report.as_deref())?;
    if let Some(shard) = farm.shard.label() {
        println!(
            "eval: shard {shard} evaluated {} of {} scene(s) into {}; when every shard has \
             finished, `dvr eval --merge` with the same options writes the reports",
            results.len(),
            plan.scenes.len(),
            args.out.display()
        );
    } else {
        report::print_summary(args, &methods, &results, started.elapsed().as_secs_f64());
    }
    let wall = started.elapsed();
    eprintln!("{}", timing.summary(wall));
    Ok(timing.outcome(wall))
}
