//! `dvr demo`, the main job (`tools/run.sh`): a small `dvr eval` of the default scene
//! that answers "which method is right, and how fast" in minutes. The noisy input and
//! the denoisers are scored against cached references, and the results page shows the
//! reference beside every method with their numbers, plots and videos.
//!
//! How big it is depends on the device: on a discrete GPU it renders 1280×720 with
//! 1024-spp references; anywhere else (lavapipe on a CPU) it is sized for a 2-core
//! CPU ([`CPU_PRESET`]). The page says which was chosen.

use crate::args::{parse_size, DEFAULT_SCENE};
use crate::eval::{self, EvalArgs};
use crate::video::{self, VideoArgs};
use anyhow::Result;
use ash::vk;
use dvr_engine::gpu::GpuContext;
use std::path::PathBuf;

#[derive(clap::Args, Clone, Debug)]
pub struct DemoArgs {
    /// Output folder (its references are reused by the next run).
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Image size, WIDTHxHEIGHT (default: by device; the first line printed says which).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Frames of the animation (default: by device).
    #[arg(long, value_parser = crate::args::parse_frames)]
    pub frames: Option<u32>,
    /// Samples per pixel of the references (default: by device; at least 1).
    #[arg(long = "ref-spp", value_parser = clap::value_parser!(u32).range(1..))]
    pub ref_spp: Option<u32>,
    /// Edge length of the procedural volume, 8 to 4096.
    #[arg(long, default_value_t = 128, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub volume_size: u32,
    /// Comma-separated denoisers, all fed the same noisy frames.
    #[arg(long, default_value = "none,taa,svgf,ours,rae", value_delimiter = ',', value_parser = crate::args::parse_denoiser)]
    pub denoiser: Vec<String>,
    /// Skip the videos (written by default when ffmpeg is on PATH).
    #[arg(long)]
    pub no_video: bool,
}

/// Size, length and reference samples of the main job on one kind of device.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preset {
    pub size: (u32, u32),
    pub frames: u32,
    pub ref_spp: u32,
}

/// Without a discrete GPU: sized so that the whole job (references, five methods,
/// scores, the accumulation baseline, videos) stays short on two cores with lavapipe
/// (the measured time is in the book's results, from assets/results/demo/meta.json). The references are most of it; 256 spp keeps their
/// noise well below the 2-spp input's and the errors of the methods compared.
pub const CPU_PRESET: Preset = Preset {
    size: (128, 128),
    frames: 16,
    ref_spp: 256,
};

/// On a discrete GPU: the paper's resolution and reference samples.
pub const GPU_PRESET: Preset = Preset {
    size: (1280, 720),
    frames: 30,
    ref_spp: 1024,
};

fn describe(p: &Preset) -> String {
    format!(
        "{}×{}, {} frames, {}-spp references",
        p.size.0, p.size.1, p.frames, p.ref_spp
    )
}

pub fn run(args: &DemoArgs) -> Result<()> {
    let (device, discrete) = {
        let ctx = GpuContext::headless()?;
        (
            ctx.info.name.clone(),
            ctx.info.device_type == vk::PhysicalDeviceType::DISCRETE_GPU,
        )
    };
    let preset = if discrete { GPU_PRESET } else { CPU_PRESET };
    let chosen = Preset {
        size: args.size.unwrap_or(preset.size),
        frames: args.frames.unwrap_or(preset.frames),
        ref_spp: args.ref_spp.unwrap_or(preset.ref_spp),
    };
    let why = if chosen != preset {
        format!(
            "Settings from the command line ({} for this device).",
            describe(&preset)
        )
    } else if discrete {
        format!("{device} is a discrete GPU, so the main job runs at the paper's size.")
    } else {
        format!(
            "No discrete GPU ({device}), so the main job is sized for a 2-core CPU \
             (its GPU ms are lavapipe's, i.e. the CPU's); on a \
             discrete GPU it runs {}.",
            describe(&GPU_PRESET)
        )
    };
    let video = !args.no_video
        && match video::ffmpeg_missing() {
            None => true,
            Some(reason) => {
                eprintln!("dvr demo: no videos this time: {reason}");
                false
            }
        };
    let note = format!(
        "The main job (tools/run.sh): {DEFAULT_SCENE}, {}, {} spp per frame of noisy input, \
         every method fed the same noisy frames and scored against the reference. {why} \
         The references are cached in {}, so the next run renders only the methods.",
        describe(&chosen),
        dvr_engine::scene::Scene::open(DEFAULT_SCENE)?.render.spp(),
        args.out.display(),
    );
    eprintln!("dvr demo: {}", describe(&chosen));
    eval::eval(&EvalArgs {
        scene: DEFAULT_SCENE.to_string(),
        frames: Some(chosen.frames),
        ref_spp: chosen.ref_spp,
        size: chosen.size,
        denoiser: args.denoiser.clone(),
        out: args.out.clone(),
        render: crate::args::RenderArgs {
            volume_size: args.volume_size,
            ..Default::default()
        },
        video: VideoArgs {
            video,
            video_fps: video::DEFAULT_FPS,
        },
        aux: false,
        no_baseline: false,
        note: Some(note),
        farm: Default::default(),
    })?;
    Ok(())
}
