//! The offscreen commands: capture (sequences), reference (high-sample frames) and the
//! render loop behind profile.

use crate::profile::{self, Profile};
use crate::setup::Setup;
use crate::SceneArgs;
use anyhow::{Context, Result};
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::image_io::{to_rgb, write_exr, write_png};
use dvr_engine::renderer::{FrameRequest, FrameResult};
use std::path::Path;
use std::time::Instant;

fn frame_name(i: u64) -> String {
    format!("{i:04}")
}

/// Writes each method's image of a finished frame to `out/<method>/NNNN.{exr,png}`.
fn write_frame(out: &Path, setup: &Setup, r: &FrameResult) -> Result<()> {
    for (method, pixels) in &r.images {
        let dir = out.join(method);
        let img = to_rgb(setup.width(), setup.height(), pixels);
        write_exr(&dir.join(format!("{}.exr", frame_name(r.index))), &img)?;
        write_png(&dir.join(format!("{}.png", frame_name(r.index))), &img)?;
    }
    Ok(())
}

pub fn capture(args: &SceneArgs, denoisers: &[String], out: &Path) -> Result<()> {
    let setup = Setup::new(args)?;
    let names: Vec<&str> = denoisers.iter().map(|s| s.as_str()).collect();
    let mut renderer = setup.renderer(&names)?;
    for m in renderer.denoiser_names() {
        std::fs::create_dir_all(out.join(&m))
            .with_context(|| format!("creating {}", out.join(&m).display()))?;
    }
    let started = Instant::now();
    let mut timings: Vec<Vec<PassTiming>> = Vec::new();
    let request = FrameRequest {
        readback: true,
        reset: false,
    };
    for f in 0..setup.frames {
        if let Some(done) = renderer.frame(&setup.inputs(f), &request)? {
            write_frame(out, &setup, &done)?;
            timings.push(done.timings);
        }
        progress("capture", f + 1, setup.frames, started);
    }
    for done in renderer.flush()? {
        write_frame(out, &setup, &done)?;
        timings.push(done.timings);
    }
    eprintln!();
    profile::write_json(
        &out.join("timings.json"),
        &serde_json::json!({
            "device": renderer.ctx().info.name,
            "scene": setup.name,
            "width": setup.width(),
            "height": setup.height(),
            "spp": setup.settings.spp,
            "denoisers": renderer.denoiser_names(),
            "frames": timings,
        }),
    )?;
    let (passes, total) = profile::aggregate(&timings);
    crate::setup::write_capture_page(out, &setup, &renderer.denoiser_names(), &passes, &total)?;
    println!(
        "wrote {} frames × {} method(s) to {} ({:.1} s)",
        setup.frames,
        renderer.denoiser_names().len(),
        out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

pub fn reference(args: &SceneArgs, spp: u32, out: &Path) -> Result<()> {
    let setup = Setup::new(args)?;
    let mut renderer = setup.renderer(&["none"])?;
    let dir = out.join("reference");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let started = Instant::now();
    // As few dispatches per frame as the device takes.
    let batch = renderer.samples_per_dispatch();
    for f in 0..setup.frames {
        let pixels = renderer.reference(&setup.inputs(f), spp, batch)?;
        let img = to_rgb(setup.width(), setup.height(), &pixels);
        write_exr(&dir.join(format!("{}.exr", frame_name(f as u64))), &img)?;
        write_png(&dir.join(format!("{}.png", frame_name(f as u64))), &img)?;
        let secs = started.elapsed().as_secs_f64();
        let samples = (f + 1) as f64 * spp as f64 * setup.width() as f64 * setup.height() as f64;
        eprint!(
            "\rreference: frame {}/{} | {:.2} Msamples/s | {:.0} s left   ",
            f + 1,
            setup.frames,
            samples / secs / 1e6,
            secs / (f + 1) as f64 * (setup.frames - f - 1) as f64
        );
    }
    eprintln!();
    println!(
        "wrote {} reference frames to {}",
        setup.frames,
        dir.display()
    );
    Ok(())
}

pub fn profile(
    args: &SceneArgs,
    denoisers: &[String],
    json: Option<&Path>,
    trace: Option<&Path>,
) -> Result<()> {
    let (report, window) = run_profile(args, denoisers)?;
    print!("{}", profile::table(&report));
    if let Some(p) = json {
        profile::write_json(p, &report)?;
    }
    if let Some(p) = trace {
        profile::write_json(
            p,
            &profile::chrome_trace(window.frames(), window.first(), &report.frames_note),
        )?;
    }
    Ok(())
}

/// Renders the profile's frames: the report (streaming statistics of every frame, the
/// measured peak bandwidth) and the window of raw frames for the trace.
pub fn run_profile(args: &SceneArgs, denoisers: &[String]) -> Result<(Profile, profile::Window)> {
    let setup = Setup::new(args)?;
    let names: Vec<&str> = denoisers.iter().map(|s| s.as_str()).collect();
    let mut renderer = setup.renderer(&names)?;
    let peak = dvr_engine::passes::bandwidth::measure(renderer.ctx())
        .context("measuring the peak bandwidth")?;
    let started = Instant::now();
    // Streaming statistics and a bounded window of raw frames: memory stays flat
    // however many frames run.
    let mut stats = profile::Stats::new();
    let mut window = profile::Window::new(profile::WINDOW_FRAMES);
    let mut keep = |timings: Vec<PassTiming>| {
        stats.add_frame(&timings);
        window.push(timings);
    };
    let request = FrameRequest::default();
    for f in 0..setup.frames {
        if let Some(done) = renderer.frame(&setup.inputs(f), &request)? {
            keep(done.timings);
        }
        progress("profile", f + 1, setup.frames, started);
    }
    for done in renderer.flush()? {
        keep(done.timings);
    }
    eprintln!();
    let run = profile::RunInfo {
        device: renderer.ctx().info.name.clone(),
        scene: setup.name.clone(),
        width: setup.width(),
        height: setup.height(),
        spp: setup.settings.spp,
        denoisers: renderer.denoiser_names(),
    };
    Ok((Profile::new(run, &stats, &window, Some(peak)), window))
}

fn progress(what: &str, done: u32, total: u32, started: Instant) {
    let secs = started.elapsed().as_secs_f64();
    let left = secs / done as f64 * (total - done) as f64;
    eprint!(
        "\r{what}: frame {done}/{total} | {:.1} fps | {left:.0} s left   ",
        done as f64 / secs
    );
}
