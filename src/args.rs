//! The command line's shared parts: the options every rendering command declares
//! ([`SceneArgs`], and [`RenderArgs`]: `--spp`, `--volume-size`, `--motion`,
//! `--gpu-memory`, for eval and the explorer too) and the parsers that check each value
//! as the command line is read, so a bad one is a usage error (exit 2) before anything
//! loads.

use dvr_engine::denoise::registry;
use dvr_engine::scene::RenderSettings;

/// The scene `dvr` renders when none is named.
pub const DEFAULT_SCENE: &str = "phantom/orbit";

/// Options shared by every rendering command.
#[derive(clap::Args, Clone, Debug)]
pub struct SceneArgs {
    /// Built-in scene (`dvr scenes` lists them) or a scene TOML file.
    #[arg(long, default_value = DEFAULT_SCENE)]
    pub scene: String,
    /// Frames of the animation to render (default: the scene's own length).
    #[arg(long, value_parser = parse_frames)]
    pub frames: Option<u32>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256", value_parser = parse_size)]
    pub size: (u32, u32),
    #[command(flatten)]
    pub render: RenderArgs,
}

/// How every rendering command (and the explorer) renders a scene.
#[derive(clap::Args, Clone, Debug)]
pub struct RenderArgs {
    /// Samples per pixel per frame, 1 to 64; lavapipe takes up to 4 (default: the
    /// scene's, 2 for built-ins).
    #[arg(long, value_parser = parse_spp)]
    pub spp: Option<u32>,
    /// Edge length of procedural volumes (phantom, cloud), 8 to 4096.
    #[arg(long, default_value_t = RenderArgs::default().volume_size,
          value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub volume_size: u32,
    /// Position the temporal denoisers reproject with: `features` (opacity-threshold
    /// surface, or the expected first collision through semi-transparent layers) or
    /// `first-hit` (the closest first real collision among the frame's samples, the
    /// paper's choice). References do not depend on it.
    #[arg(long, default_value_t = RenderArgs::default().motion)]
    pub motion: dvr_engine::denoise::MotionSource,
    /// Bytes the volume may take on the device, e.g. `512M`, `2G` (default: the scene's
    /// `[render] gpu_memory`, else half the device-local heap). A volume past it is paged
    /// through a brick pool of the bricks the TF makes visible.
    #[arg(long, value_parser = dvr_engine::scene::parse_gpu_memory)]
    pub gpu_memory: Option<u64>,
}

impl RenderArgs {
    /// `--gpu-memory` into the scene's render settings, where the renderer and the
    /// OME-Zarr level choice read it.
    pub fn apply_budget(&self, scene: &mut dvr_engine::scene::Scene) -> anyhow::Result<()> {
        if let Some(bytes) = self.gpu_memory {
            scene.render.set_gpu_memory(Some(bytes))?;
        }
        Ok(())
    }
}

impl Default for RenderArgs {
    fn default() -> Self {
        Self {
            spp: None,
            volume_size: dvr_engine::renderer::scene_setup::DEFAULT_VOLUME_SIZE,
            motion: dvr_engine::denoise::MotionSource::Features,
            gpu_memory: None,
        }
    }
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("size {s:?} is not WIDTHxHEIGHT"))?;
    let w: u32 = w
        .trim()
        .parse()
        .map_err(|_| format!("bad width in {s:?}"))?;
    let h: u32 = h
        .trim()
        .parse()
        .map_err(|_| format!("bad height in {s:?}"))?;
    if w == 0 || h == 0 || w > 8192 || h > 8192 {
        return Err(format!("size {s:?} must be between 1x1 and 8192x8192"));
    }
    Ok((w, h))
}

/// Parses `--spp`: samples per pixel per frame, as many as a scene's `render.spp` may
/// ask for (the settings' own check; the device may take fewer: the renderer says so).
pub fn parse_spp(s: &str) -> Result<u32, String> {
    let n = s.trim().parse::<u32>().map_err(|_| {
        format!("{s:?} is not a sample count per frame (references take more through --ref-spp)")
    })?;
    RenderSettings::default()
        .set_spp(n)
        .map_err(|e| format!("--spp {e}"))?;
    Ok(n)
}

/// One `--denoiser` name, checked against the registry while the command line is
/// parsed, so a wrong name is a usage error (exit 2) like any other bad argument, and
/// nothing has been loaded yet. An empty item of a comma list (`ours,,svgf`, a
/// trailing comma) is a usage error too: it most likely lost a name.
pub fn parse_denoiser(s: &str) -> Result<String, String> {
    let name = s.trim();
    if name.is_empty() {
        return Err("an empty entry in the list (two commas in a row, or one at an end)".into());
    }
    registry::find(name)
        .map(|info| info.name.to_string())
        .map_err(|e| e.to_string())
}

/// The explorer's `--denoiser`: one name, or two for a split view (`A,B`), each checked
/// as [`parse_denoiser`] checks one, so a wrong name is a usage error there too.
pub fn parse_view_denoisers(s: &str) -> Result<String, String> {
    let names = s
        .split(',')
        .map(parse_denoiser)
        .collect::<Result<Vec<String>, String>>()?;
    if names.len() > 2 {
        return Err("one denoiser, or two for a split view (A,B)".into());
    }
    Ok(names.join(","))
}

/// `--frame-range A..B`: frames A up to but not including B, A < B.
pub fn parse_frame_range(s: &str) -> Result<(u32, u32), String> {
    let bad = || {
        format!("{s:?} is not a frame range (A..B: from frame A up to but not including B, A < B)")
    };
    let (a, b) = s.trim().split_once("..").ok_or_else(bad)?;
    let (a, b) = (
        a.trim().parse::<u32>().map_err(|_| bad())?,
        b.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if a >= b {
        return Err(bad());
    }
    Ok((a, b))
}

/// `--shard I/N`: shard I (0-based) of N, N >= 1.
pub fn parse_shard(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("{s:?} is not a shard (I/N: shard I of N, 0 <= I < N)");
    let (i, n) = s.trim().split_once('/').ok_or_else(bad)?;
    let (i, n) = (
        i.trim().parse::<u32>().map_err(|_| bad())?,
        n.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// Parses `--frames`: a whole number of at least 1.
pub fn parse_frames(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "{s:?} is not a frame count (a whole number, at least 1)"
        )),
    }
}
