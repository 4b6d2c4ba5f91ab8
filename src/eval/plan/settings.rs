//! What `dvr eval` is asked to do: its options (the farm's among them) and the
//! constants every layer scores and reports with.

use crate::args::{RenderArgs, SceneArgs};
use crate::shard::ShardArgs;
use std::path::PathBuf;

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
    /// `static`, `paper`, `interaction`: `assets/scenes/<set>/`), or a comma-separated
    /// list of these,
    /// built-in scene names and scene files.
    #[arg(long, default_value = "suite")]
    pub scene: String,
    /// Frames of each animation (default: each scene's own length).
    #[arg(long, value_parser = crate::args::parse_frames)]
    pub frames: Option<u32>,
    /// Samples per pixel of the references (at least 1).
    #[arg(long = "ref-spp", default_value_t = 1024,
          value_parser = clap::value_parser!(u32).range(1..))]
    pub ref_spp: u32,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256", value_parser = crate::args::parse_size)]
    pub size: (u32, u32),
    /// Comma-separated denoisers, all fed the same noisy frames.
    #[arg(long, default_value = "none,accum,ours", value_delimiter = ',', value_parser = crate::args::parse_denoiser)]
    pub denoiser: Vec<String>,
    /// Output folder (references in it are reused when their settings match).
    #[arg(long, default_value = "out/eval")]
    pub out: PathBuf,
    #[command(flatten)]
    pub render: RenderArgs,
    #[command(flatten)]
    pub video: crate::video::VideoArgs,
    /// Also write each frame's guide images for single-frame denoisers
    /// (`<scene>/aux/NNNN_albedo.exr`, `NNNN_normal.exr`: the TF albedo and gradient
    /// normal composited along the ray, what `tools/oidn_eval.py` gives OIDN).
    #[arg(long)]
    pub aux: bool,
    /// Skip the accumulation baseline (plain path tracing at 1, 2, 4, … spp on two frames
    /// of each scene, the speed-accuracy plots' reference curve): parameter studies of
    /// the denoisers then take about a third of the time. `baseline.csv` keeps its header.
    #[arg(long)]
    pub no_baseline: bool,
    /// A paragraph shown at the top of the results page (what was run, and why).
    #[arg(long)]
    pub note: Option<String>,
    #[command(flatten)]
    pub farm: FarmArgs,
}

#[derive(clap::Args, Clone, Debug, Default)]
pub struct FarmArgs {
    #[command(flatten)]
    pub shard: ShardArgs,
    /// Render the references only (into `<out>/<scene>/reference/`, where an eval with
    /// the same options reuses them); with --shard, a unit is one frame of one scene.
    #[arg(long, conflicts_with = "merge")]
    pub references_only: bool,
    /// Write metrics.csv, summary.csv, the plots and the page from every scene's
    /// `result.json` (left by `--shard` runs), as one run writes them; fails, naming
    /// each, when a scene's result is missing or was made under other settings.
    #[arg(long, conflicts_with = "shard")]
    pub merge: bool,
}

/// The options `dvr capture` would take for scene `name` of this eval: how its
/// references and frames are set up.
pub fn scene_args(args: &EvalArgs, name: &str) -> SceneArgs {
    SceneArgs {
        scene: name.to_string(),
        frames: args.frames,
        size: args.size,
        render: args.render.clone(),
    }
}
