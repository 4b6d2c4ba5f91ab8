//! The command line: the parser ([`Cli`]), its commands ([`Command`], each variant's doc
//! comment its help), the dispatch to each command's module ([`run`]) and the process's
//! exit statuses ([`main`]).

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;

use crate::args::SceneArgs;
use crate::bench;
use crate::capture;
use crate::demo;
use crate::eval;
use crate::explore;
use crate::info;
use crate::logger;
use crate::profile;
use crate::progress;
use crate::setup;
use crate::shard;
use crate::video;

/// `dvr [--quiet] <COMMAND>`. Generic over its commands so a test can parse a set that
/// flattens [`Command`] beside a toy one (`tests/plugins.rs`); the binary parses
/// [`Command`].
#[derive(Parser)]
#[command(
    name = "dvr",
    version,
    about = "Monte Carlo direct volume rendering with temporal denoising"
)]
pub struct Cli<C: Subcommand = Command> {
    /// Show only errors (no warnings). `DVR_LOG=info|debug` shows more instead.
    #[arg(long, global = true)]
    pub quiet: bool,
    #[command(subcommand)]
    pub command: C,
}

/// dvr's commands, a variant each: its doc comment is its help (its line in `dvr --help`,
/// the head of `dvr <command> --help`), its arm in [`run`] calls its module.
#[derive(Subcommand)]
pub enum Command {
    /// The main job (tools/run.sh): a small eval of the default scene sized for the
    /// device (a discrete GPU: 1280x720 with 1024-spp references; otherwise 128x128 with
    /// 256-spp references, sized for a 2-core CPU), with videos; opens nothing,
    /// prints the page's path.
    Demo(demo::DemoArgs),
    /// Open a window: the path tracer and a denoiser live, with an orbit camera, a
    /// transfer-function editor, light and render controls and per-pass GPU timing.
    Explore(explore::ExploreArgs),
    /// Render an animation offscreen with one or more denoisers: EXR + PNG per frame,
    /// per-pass GPU timings and an HTML page.
    Capture {
        #[command(flatten)]
        scene: SceneArgs,
        /// Comma-separated denoisers (the noisy frames are rendered once and fed to all).
        #[arg(long, default_value = "none,accum", value_delimiter = ',', value_parser = crate::args::parse_denoiser)]
        denoiser: Vec<String>,
        /// Output folder.
        #[arg(long, default_value = "out/capture")]
        out: PathBuf,
        #[command(flatten)]
        video: video::VideoArgs,
    },
    /// Render high-sample references of every frame: DIR/reference/NNNN.exr.
    Reference {
        #[command(flatten)]
        scene: SceneArgs,
        /// Samples per pixel of the reference (at least 1).
        #[arg(long = "ref-spp", alias = "samples", default_value_t = 1024,
              value_parser = clap::value_parser!(u32).range(1..))]
        ref_spp: u32,
        /// Only the frames from A up to but not including B (`A..B`, 0-based).
        #[arg(long = "frame-range", value_parser = crate::args::parse_frame_range)]
        frame_range: Option<(u32, u32)>,
        #[command(flatten)]
        shard: shard::ShardArgs,
        #[arg(long, default_value = "out/reference")]
        out: PathBuf,
    },
    /// Evaluate denoisers against cached references: metrics.csv, summary.csv, plots
    /// and an HTML results page.
    Eval(eval::EvalArgs),
    /// Per-pass GPU timings over many frames, with each pass's declared bytes, GB/s and
    /// share of the peak bandwidth: table, JSON and Chrome trace.
    Profile {
        #[command(flatten)]
        scene: SceneArgs,
        #[arg(long, default_value = "none", value_delimiter = ',', value_parser = crate::args::parse_denoiser)]
        denoiser: Vec<String>,
        /// Write the statistics (per pass: times, bytes, GB/s, % of the measured peak
        /// bandwidth) and the last 300 frames' raw timings as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write a Chrome trace-event file (Perfetto, chrome://tracing) of the last 300
        /// frames.
        #[arg(long)]
        trace: Option<PathBuf>,
    },
    /// The one-call GPU benchmark: profiles every denoiser at 256x256, 1280x720 and
    /// 1920x1080 and runs the eval suite at 256x256 against 1024-spp references; writes
    /// one small folder of CSV, JSON and plots (`tools/gpu-bench.sh` wraps it).
    Bench(bench::BenchArgs),
    /// What a volume file (or a list of files) holds: its grid, spacing, orientation
    /// (to_patient), channels (name, colour, window) and time points.
    Info(info::InfoArgs),
    /// List the built-in scenes, or print one as a TOML scene file.
    Scenes {
        /// Print this scene as TOML (a starting point for your own).
        #[arg(long)]
        dump: Option<String>,
    },
}

/// Exit status of a run that failed with an error (a bad file, value or device).
pub const EXIT_ERROR: i32 = 1;
/// Exit status of a command line that does not parse (clap's convention).
pub const EXIT_USAGE: i32 = 2;
/// Exit status when the Vulkan validation layer (`DVR_VALIDATION=1`) reported anything,
/// even if the command otherwise succeeded.
pub const EXIT_VALIDATION: i32 = 3;

/// Parses the command line, runs the command and exits with its status.
pub fn main() {
    let cli = <Cli>::try_parse().unwrap_or_else(|e| {
        let _ = e.print();
        // --help and --version print to stdout and succeed.
        std::process::exit(if e.use_stderr() { EXIT_USAGE } else { 0 })
    });
    logger::init(cli.quiet);
    let result = run(cli.command);
    let validation_messages = dvr_engine::gpu::validation::message_count();
    if let Err(e) = result {
        progress::end_line();
        // A profile stopped by a signal wrote what it had: exit as the signal would.
        if let Some(signal) = e.downcast_ref::<profile::interrupt::Interrupted>() {
            eprintln!("dvr: {signal}; the outputs hold the frames rendered so far");
            std::process::exit(signal.exit_code());
        }
        eprintln!("dvr: error: {}", error_chain(&e));
        std::process::exit(EXIT_ERROR);
    }
    if validation_messages > 0 {
        eprintln!("dvr: the Vulkan validation layer reported {validation_messages} message(s)");
        std::process::exit(EXIT_VALIDATION);
    }
}

/// The error and its causes on one line; a cause whose text the message already
/// quotes (the engine's errors embed their source) is not repeated.
fn error_chain(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let part = cause.to_string();
        if !text.contains(part.as_str()) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&part);
        }
    }
    text
}

/// Runs one command: each variant's arm calls its module.
pub fn run(command: Command) -> Result<()> {
    match command {
        Command::Demo(args) => demo::run(&args),
        Command::Explore(args) => explore::run(args),
        Command::Capture {
            scene,
            denoiser,
            out,
            video,
        } => capture::capture(&scene, &denoiser, &out, &video),
        Command::Reference {
            scene,
            ref_spp,
            frame_range,
            shard,
            out,
        } => capture::reference(&scene, ref_spp, frame_range, &shard, &out),
        Command::Eval(args) => eval::eval(&args).map(|_| ()),
        Command::Profile {
            scene,
            denoiser,
            json,
            trace,
        } => capture::profile(&scene, &denoiser, json.as_deref(), trace.as_deref()),
        Command::Bench(args) => bench::run(&args),
        Command::Info(args) => info::run(&args),
        Command::Scenes { dump } => setup::list_scenes(dump.as_deref()),
    }
}
