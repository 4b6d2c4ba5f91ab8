//! `dvr bench`: the one-call GPU benchmark. Profiles every denoiser at a few sizes
//! (256², 720p and 1080p by default) and runs the eval suite at 256×256 against
//! 1024-spp references, then writes one small folder to bring back from a GPU machine:
//!
//! ```text
//! DIR/bench.json                   device, peak bandwidth, settings, eval wall vs GPU time
//! DIR/profile.csv                  size,pass,mean_ms,median_ms,p95_ms,mb,gb_per_s,percent_of_peak
//! DIR/methods.csv                  each denoiser's own passes, those it needs, dispatches, bytes
//! DIR/profile_<WxH>.json           the full `dvr profile --json` report of each size
//! DIR/profile_<WxH>.{svg,png}      GPU ms per pass, labelled with its share of the peak
//! DIR/eval/{metrics,summary,baseline}.csv, DIR/eval/speed_accuracy.{svg,png}
//! ```
//!
//! The eval's images stay in `--eval-out` (large). `tools/gpu-bench.sh` wraps this
//! command for a bare GPU machine (Vulkan loader, font, assets) and tars the folder.

mod plots;

use crate::args::{RenderArgs, SceneArgs};
use crate::capture::run_profile;
use crate::eval::EvalArgs;
use crate::output::{opt, write_text as write};
use crate::profile::methods::method_rows;
use crate::profile::{self, Profile};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Clone, Debug)]
pub struct BenchArgs {
    /// Output folder (small: CSV, JSON and plots).
    #[arg(long, default_value = "out/bench")]
    pub out: PathBuf,
    /// Where the eval writes its full results (images included); default `<out>-eval`.
    #[arg(long)]
    pub eval_out: Option<PathBuf>,
    /// Sizes to profile at.
    #[arg(long, default_value = "256x256,1280x720,1920x1080", value_delimiter = ',',
          value_parser = crate::args::parse_size)]
    pub sizes: Vec<(u32, u32)>,
    /// Scene to profile.
    #[arg(long, default_value = crate::args::DEFAULT_SCENE)]
    pub scene: String,
    /// Frames per profile.
    #[arg(long, default_value_t = 60, value_parser = crate::args::parse_frames)]
    pub frames: u32,
    /// Denoisers to profile and evaluate (default: every one).
    #[arg(long, value_delimiter = ',', value_parser = crate::args::parse_denoiser)]
    pub denoiser: Vec<String>,
    /// Scenes of the eval (`suite`, `stress` or a list).
    #[arg(long, default_value = "suite")]
    pub eval_scene: String,
    /// Image size of the eval.
    #[arg(long, default_value = "256x256", value_parser = crate::args::parse_size)]
    pub eval_size: (u32, u32),
    /// Frames of each eval scene (default: each scene's own length).
    #[arg(long, value_parser = crate::args::parse_frames)]
    pub eval_frames: Option<u32>,
    /// Samples per pixel of the eval's references (at least 1).
    #[arg(long = "ref-spp", default_value_t = 1024,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub ref_spp: u32,
    /// Edge length of procedural volumes (phantom, cloud), 8 to 4096.
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub volume_size: u32,
    /// Profile only.
    #[arg(long)]
    pub skip_eval: bool,
}

/// What `bench.json` records.
#[derive(serde::Serialize)]
struct Record<'a> {
    device: &'a str,
    peak_bandwidth: Option<&'a dvr_engine::passes::bandwidth::PeakBandwidth>,
    profile_scene: &'a str,
    profile_frames: u32,
    sizes: Vec<String>,
    denoisers: &'a [String],
    profile_seconds: f64,
    eval: Option<EvalRecord<'a>>,
}

#[derive(serde::Serialize)]
struct EvalRecord<'a> {
    scenes: &'a str,
    size: String,
    ref_spp: u32,
    frames: Option<u32>,
    timing: crate::eval::run::timing::Outcome,
    /// Eval wall time over the GPU time it spends (the goal is at most 1.5).
    wall_over_gpu: f64,
}

fn size_name((w, h): (u32, u32)) -> String {
    format!("{w}x{h}")
}

pub fn run(args: &BenchArgs) -> Result<()> {
    let denoisers: Vec<String> = if args.denoiser.is_empty() {
        dvr_engine::denoise::registry::names()
            .map(String::from)
            .collect()
    } else {
        args.denoiser.clone()
    };
    // Fail before the long part, not after: the plots need a font.
    crate::font::init_font()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let started = Instant::now();
    let mut profiles = Vec::new();
    for &size in &args.sizes {
        eprintln!("bench: profile {} at {}", args.scene, size_name(size));
        let scene = SceneArgs {
            scene: args.scene.clone(),
            frames: Some(args.frames),
            size,
            render: RenderArgs {
                volume_size: args.volume_size,
                ..Default::default()
            },
        };
        let (report, _) = run_profile(&scene, &denoisers, None)?;
        let stem = args.out.join(format!("profile_{}", size_name(size)));
        crate::output::write_json(&stem.with_extension("json"), &report)?;
        plots::pass_chart(&report, &stem)?;
        print!("{}", profile::table(&report));
        profiles.push(report);
    }
    write(&args.out.join("profile.csv"), &profile_csv(&profiles))?;
    write(&args.out.join("methods.csv"), &methods_csv(&profiles))?;
    let profile_seconds = started.elapsed().as_secs_f64();

    let eval = if args.skip_eval {
        None
    } else {
        Some(run_eval(args, &denoisers)?)
    };
    let first = profiles.first();
    let record = Record {
        device: first.map(|p| p.run.device.as_str()).unwrap_or(""),
        peak_bandwidth: first.and_then(|p| p.peak_bandwidth.as_ref()),
        profile_scene: &args.scene,
        profile_frames: args.frames,
        sizes: args.sizes.iter().map(|&s| size_name(s)).collect(),
        denoisers: &denoisers,
        profile_seconds,
        eval,
    };
    crate::output::write_json(&args.out.join("bench.json"), &record)?;
    println!(
        "bench: wrote {} in {:.0} s",
        args.out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// Runs the eval into `--eval-out` and copies its small results into `DIR/eval/`.
fn run_eval<'a>(args: &'a BenchArgs, denoisers: &[String]) -> Result<EvalRecord<'a>> {
    let eval_out = args.eval_out.clone().unwrap_or_else(|| {
        let mut name = args.out.file_name().unwrap_or_default().to_os_string();
        name.push("-eval");
        args.out.with_file_name(name)
    });
    let eval_args = EvalArgs {
        scene: args.eval_scene.clone(),
        frames: args.eval_frames,
        ref_spp: args.ref_spp,
        size: args.eval_size,
        denoiser: denoisers.to_vec(),
        out: eval_out.clone(),
        render: RenderArgs {
            volume_size: args.volume_size,
            ..Default::default()
        },
        video: crate::video::VideoArgs {
            video: false,
            video_fps: crate::video::DEFAULT_FPS,
        },
        aux: false,
        no_baseline: false,
        note: None,
        farm: Default::default(),
    };
    eprintln!(
        "bench: eval {} into {}",
        args.eval_scene,
        eval_out.display()
    );
    let timing = crate::eval::eval(&eval_args)?;
    let small = args.out.join("eval");
    std::fs::create_dir_all(&small).with_context(|| format!("creating {}", small.display()))?;
    for (from, to) in [
        ("metrics.csv", "metrics.csv"),
        ("summary.csv", "summary.csv"),
        ("baseline.csv", "baseline.csv"),
        ("plots/speed_accuracy.svg", "speed_accuracy.svg"),
        ("plots/speed_accuracy.png", "speed_accuracy.png"),
    ] {
        let (from, to) = (eval_out.join(from), small.join(to));
        std::fs::copy(&from, &to)
            .with_context(|| format!("copying {} to {}", from.display(), to.display()))?;
    }
    Ok(EvalRecord {
        scenes: &args.eval_scene,
        size: size_name(args.eval_size),
        ref_spp: args.ref_spp,
        frames: args.eval_frames,
        wall_over_gpu: timing.wall_s / timing.gpu_s.max(1e-9),
        timing,
    })
}

/// Every pass of every size, the total last.
fn profile_csv(profiles: &[Profile]) -> String {
    let mut s = String::from("size,pass,mean_ms,median_ms,p95_ms,mb,gb_per_s,percent_of_peak\n");
    for p in profiles {
        for r in p.passes.iter().chain(std::iter::once(&p.total)) {
            let _ = writeln!(
                s,
                "{}x{},{},{:.4},{:.4},{:.4},{:.3},{:.2},{}",
                p.run.width,
                p.run.height,
                r.pass,
                r.mean_ms,
                r.median_ms,
                r.p95_ms,
                r.bytes / 1e6,
                r.gb_per_s,
                opt(r.percent_of_peak, 2)
            );
        }
    }
    s
}

fn methods_csv(profiles: &[Profile]) -> String {
    let mut s = String::from(
        "size,method,own_ms,needed_ms,cost_ms,dispatches,bytes_per_pixel,percent_of_peak,frame_ms\n",
    );
    for p in profiles {
        for r in method_rows(p) {
            let _ = writeln!(
                s,
                "{}x{},{},{:.4},{:.4},{:.4},{:.2},{:.1},{},{:.4}",
                p.run.width,
                p.run.height,
                r.method,
                r.own_ms,
                r.needed_ms,
                r.cost_ms,
                r.dispatches,
                r.bytes_per_pixel,
                opt(r.percent_of_peak, 2),
                r.frame_ms
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::methods::tests::two_method_profile;

    #[test]
    fn methods_csv_has_a_row_per_method() {
        let csv = methods_csv(&[two_method_profile()]);
        assert!(
            csv.starts_with("size,method,own_ms,needed_ms,cost_ms,dispatches,"),
            "{csv}"
        );
        assert!(
            csv.contains("8x8,ours,2.5000,1.0000,3.5000,3.50,93750.0,42.86,7.5000"),
            "{csv}"
        );
    }
}
