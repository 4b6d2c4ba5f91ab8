//! The offscreen commands: capture (sequences), reference (high-sample frames) and the
//! render loop behind profile.

use crate::eval::reference::{FillReport, ReferenceCache, ReferenceKey};
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

/// `dvr reference`: the same cache as `dvr eval`'s, in `out/reference/`, so a rerun with
/// the same key reuses (or finishes) what is there.
pub fn reference(args: &SceneArgs, spp: u32, out: &Path) -> Result<()> {
    let setup = Setup::new(args)?;
    let key = ReferenceKey::new(setup.scene(), args.size, spp, args.volume_size)?;
    let cache = ReferenceCache::new(out, key);
    let mut report = ReferenceReport {
        started: Instant::now(),
        samples_per_frame: f64::from(spp) * f64::from(setup.width() * setup.height()),
    };
    cache.fill(&setup, &mut report)?;
    println!(
        "wrote {} reference frames to {}",
        setup.frames,
        cache.dir.display()
    );
    Ok(())
}

/// `dvr reference`'s progress line: frames, Msamples/s, time left.
struct ReferenceReport {
    started: Instant,
    samples_per_frame: f64,
}

impl FillReport for ReferenceReport {
    fn note(&mut self, text: Option<&str>) {
        if let Some(text) = text {
            eprintln!("reference: {text}");
        }
    }

    fn rendered(&mut self, done: usize, of: usize) {
        if done == 0 {
            return;
        }
        let secs = self.started.elapsed().as_secs_f64();
        eprint!(
            "\rreference: frame {done}/{of} | {:.2} Msamples/s | {:.0} s left   ",
            done as f64 * self.samples_per_frame / secs / 1e6,
            secs / done as f64 * (of - done) as f64
        );
        if done == of {
            eprintln!();
        }
    }
}

pub fn profile(
    args: &SceneArgs,
    denoisers: &[String],
    json: Option<&Path>,
    trace: Option<&Path>,
) -> Result<()> {
    let setup = Setup::new(args)?;
    let names: Vec<&str> = denoisers.iter().map(|s| s.as_str()).collect();
    let mut renderer = setup.renderer(&names)?;
    let started = Instant::now();
    let mut frames: Vec<Vec<PassTiming>> = Vec::new();
    let request = FrameRequest::default();
    for f in 0..setup.frames {
        if let Some(done) = renderer.frame(&setup.inputs(f), &request)? {
            frames.push(done.timings);
        }
        progress("profile", f + 1, setup.frames, started);
    }
    frames.extend(renderer.flush()?.into_iter().map(|r| r.timings));
    eprintln!();
    let (passes, total) = profile::aggregate(&frames);
    let report = Profile {
        device: renderer.ctx().info.name.clone(),
        scene: setup.name.clone(),
        width: setup.width(),
        height: setup.height(),
        spp: setup.settings.spp,
        denoisers: renderer.denoiser_names(),
        warmup_frames: profile::WARMUP_FRAMES,
        passes,
        total,
        frames: frames.clone(),
    };
    print!("{}", profile::table(&report));
    if let Some(p) = json {
        profile::write_json(p, &report)?;
    }
    if let Some(p) = trace {
        profile::write_json(p, &profile::chrome_trace(&frames))?;
    }
    Ok(())
}

fn progress(what: &str, done: u32, total: u32, started: Instant) {
    let secs = started.elapsed().as_secs_f64();
    let left = secs / done as f64 * (total - done) as f64;
    eprint!(
        "\r{what}: frame {done}/{total} | {:.1} fps | {left:.0} s left   ",
        done as f64 / secs
    );
}
