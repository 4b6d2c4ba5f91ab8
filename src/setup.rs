//! The command line's view of a scene: open it by name or path, resample its length,
//! and hand it to the engine's `SceneSetup`; the methods a `--denoiser` list names, the
//! frames a range and a shard select, the `--out` folder; plus `dvr scenes`.

use crate::args::SceneArgs;
use anyhow::{bail, Context, Result};
use dvr_engine::denoise::registry;
use dvr_engine::gpu::GpuContext;
use dvr_engine::graph::Extent;
use dvr_engine::renderer::scene_setup::SceneSetup;
use dvr_engine::renderer::FrameInputs;
use dvr_engine::scene::{RenderSettings, Scene};
use dvr_engine::session::Session;
use std::path::Path;

/// The frames of a `frames`-frame animation that `--frame-range` and `--shard` select,
/// in order; an error when the range lies past the animation or the shard is empty.
pub fn select_frames(
    frames: u32,
    range: Option<(u32, u32)>,
    shard: Option<(u32, u32)>,
) -> Result<Vec<u32>> {
    let (a, b) = range.unwrap_or((0, frames));
    if b > frames {
        bail!("--frame-range {a}..{b}: the scene has {frames} frame(s) (0..{frames})");
    }
    let (i, n) = shard.unwrap_or((0, 1));
    Ok((a..b).skip(i as usize).step_by(n as usize).collect())
}

/// Opens `--scene`: a built-in scene or a scene file. A name that is neither gets the
/// built-in scenes that share its dataset or animation (or where to find them all),
/// not the file system's "No such file or directory".
pub fn open_scene(spec: &str) -> Result<Scene> {
    let builtins = Scene::builtin_names();
    if !builtins.iter().any(|n| n == spec) && !Path::new(spec).exists() {
        let (dataset, animation) = spec.split_once('/').unwrap_or((spec, spec));
        let close: Vec<&str> = builtins
            .iter()
            .map(String::as_str)
            .filter(|n| {
                let (d, a) = n.split_once('/').unwrap_or((n, n));
                d == dataset || a == animation
            })
            .collect();
        let hint = if close.is_empty() {
            "`dvr scenes` lists the built-in scenes".to_string()
        } else {
            format!("built-in scenes like it: {}", close.join(", "))
        };
        bail!("{spec:?} is neither a built-in scene nor a scene file; {hint}");
    }
    Scene::open(spec).with_context(|| format!("opening scene {spec:?}"))
}

/// Warns once for each parameter override in the environment (`DVR_OURS`, …) that none
/// of `running` reads. Each command says it once, for the methods the user asked for:
/// not the engine's sessions, of which a command may open several (an eval's reference
/// sessions run no denoiser, and would warn about an override the run does use).
pub fn warn_unused_overrides<S: AsRef<str>>(running: &[S]) {
    let running: Vec<&str> = running.iter().map(AsRef::as_ref).collect();
    for warning in dvr_engine::denoise::unused_overrides(&running) {
        log::warn!("{warning}");
    }
}

/// The methods a `--denoiser` list names: trimmed, each once, each one dvr has.
pub fn denoiser_list(names: &[String]) -> Result<Vec<String>> {
    let mut methods: Vec<String> = Vec::new();
    for d in names {
        let d = d.trim();
        if d.is_empty() || methods.iter().any(|m| m == d) {
            continue;
        }
        methods.push(registry::find(d)?.name.to_string());
    }
    if methods.is_empty() {
        bail!("--denoiser names no method");
    }
    Ok(methods)
}

/// Creates the `--out` folder (and its parents); a file in the way is named as such,
/// not as the system's "File exists".
pub fn create_out_dir(out: &Path) -> Result<()> {
    if out.exists() && !out.is_dir() {
        bail!(
            "--out {}: that is a file; --out names a folder",
            out.display()
        );
    }
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))
}

/// A scene opened from the command line, made ready for rendering.
pub struct Setup {
    pub name: String,
    pub frames: u32,
    pub settings: RenderSettings,
    inner: SceneSetup,
}

impl Setup {
    pub fn new(args: &SceneArgs) -> Result<Self> {
        let mut scene = open_scene(&args.scene)?;
        if let Some(n) = args.frames {
            scene = scene.with_frames(n)?;
        }
        let size = Extent {
            width: args.size.0,
            height: args.size.1,
        };
        args.render.apply_budget(&mut scene)?;
        let mut inner = SceneSetup::new(scene, size, args.render.spp, args.render.volume_size)?;
        inner.config.motion_source = args.render.motion;
        Ok(Self {
            name: inner.scene.name.clone(),
            frames: inner.scene.frames,
            settings: inner.settings,
            inner,
        })
    }

    /// The scene, after `--frames`.
    pub fn scene(&self) -> &Scene {
        &self.inner.scene
    }

    pub fn width(&self) -> u32 {
        self.inner.config.size.width
    }

    pub fn height(&self) -> u32 {
        self.inner.config.size.height
    }

    /// A live session over this scene on a headless device, running `denoisers`: the
    /// engine type the explorer and the Python package drive too. Scripted frames are
    /// [`Session::play`] then [`Session::frame`].
    pub fn session(&self, denoisers: &[&str]) -> Result<Session> {
        Ok(Session::new(
            self.inner.clone(),
            GpuContext::headless()?,
            denoisers,
        )?)
    }

    /// The renderer's inputs for animation frame `f` (what the scene's view at `f`
    /// becomes; a session playing frame `f` renders the same).
    pub fn inputs(&self, f: u32) -> FrameInputs {
        self.inner.frame_inputs(f)
    }
}

pub fn list_scenes(dump: Option<&str>) -> Result<()> {
    if let Some(name) = dump {
        let scene = open_scene(name)?;
        print!("{}", scene.to_toml()?);
        return Ok(());
    }
    for n in Scene::builtin_names() {
        println!("{n}");
    }
    Ok(())
}
