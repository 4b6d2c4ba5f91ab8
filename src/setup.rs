//! The command line's view of a scene: open it by name or path, resample its length,
//! and hand it to the engine's `SceneSetup`; plus `dvr scenes` and the capture page.

use crate::profile::PassStats;
use crate::SceneArgs;
use anyhow::{bail, Context, Result};
use dvr_engine::denoise::registry;
use dvr_engine::gpu::GpuContext;
use dvr_engine::graph::Extent;
use dvr_engine::renderer::scene_setup::SceneSetup;
use dvr_engine::renderer::FrameInputs;
use dvr_engine::scene::{RenderSettings, Scene};
use dvr_engine::session::Session;
use std::path::Path;

/// The scene `dvr` renders when none is named.
pub const DEFAULT_SCENE: &str = "phantom/orbit";

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

/// Parses `--frames`: a whole number of at least 1.
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

pub fn parse_frames(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "{s:?} is not a frame count (a whole number, at least 1)"
        )),
    }
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

/// A small page next to a capture: the last frame of each method, a frame slider, and
/// the per-pass timing table.
pub fn write_capture_page(
    out: &Path,
    setup: &Setup,
    methods: &[String],
    passes: &[PassStats],
    total: &PassStats,
    videos: &[std::path::PathBuf],
) -> Result<()> {
    let mut html = String::new();
    html.push_str("<!doctype html><meta charset=utf-8><title>dvr capture</title>");
    html.push_str("<style>body{font-family:sans-serif;background:#222;color:#eee}img{image-rendering:pixelated;width:384px}figure{display:inline-block;margin:8px}td,th{padding:2px 10px;text-align:right}</style>");
    html.push_str(&format!(
        "<h1>{}</h1><p>{}×{}, {} spp/frame, {} frames</p>",
        html_escape(&setup.name),
        setup.width(),
        setup.height(),
        setup.settings.spp(),
        setup.frames
    ));
    html.push_str(&format!(
        "<input id=f type=range min=0 max={} value={} style='width:600px'> frame <span id=n></span><br>",
        setup.frames.saturating_sub(1),
        setup.frames.saturating_sub(1)
    ));
    for m in methods {
        let m = html_escape(m);
        html.push_str(&format!(
            "<figure><img class=seq data-m='{m}'><figcaption>{m}</figcaption></figure>"
        ));
    }
    if !videos.is_empty() {
        html.push_str("<h2>Videos</h2><p>");
        for v in videos.iter().filter_map(|v| v.file_name()) {
            // Denoiser names and fixed file names, escaped like every string on the page.
            let name = html_escape(&v.to_string_lossy());
            html.push_str(&format!("<a href='videos/{name}'>{name}</a> "));
        }
        html.push_str(&format!(
            "</p><video controls loop src='videos/{}' style='max-width:100%'></video>",
            crate::video::COMPARISON
        ));
    }
    html.push_str(
        "<h2>GPU time per pass (ms)</h2><table><tr><th>pass<th>mean<th>median<th>p95</tr>",
    );
    for p in passes.iter().chain(std::iter::once(total)) {
        html.push_str(&format!(
            "<tr><td style=text-align:left>{}<td>{:.3}<td>{:.3}<td>{:.3}</tr>",
            html_escape(&p.pass),
            p.mean_ms,
            p.median_ms,
            p.p95_ms
        ));
    }
    html.push_str(
        "</table><script>const f=document.getElementById('f'),n=document.getElementById('n');",
    );
    html.push_str("function show(){const i=String(f.value).padStart(4,'0');n.textContent=f.value;for(const im of document.querySelectorAll('img.seq'))im.src=im.dataset.m+'/'+i+'.png';}f.oninput=show;show();</script>");
    let path = out.join("index.html");
    crate::output::write_text(&path, &html)
}

/// Text as HTML that shows exactly it: a scene's `name` is anyone's string, and a name
/// like `</h1><script>…` must not run in the page.
pub fn html_escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::html_escape;

    #[test]
    fn html_escape_leaves_no_markup() {
        assert_eq!(
            html_escape("a</script><script>alert('x')&\""),
            "a&lt;/script&gt;&lt;script&gt;alert(&#39;x&#39;)&amp;&quot;"
        );
    }
}
