//! The offscreen commands: capture (sequences, and the small page beside them),
//! reference (high-sample frames) and the render loop behind profile.

use crate::args::SceneArgs;
use crate::eval::plan::keys::ReferenceKey;
use crate::eval::references::fill::FillReport;
use crate::eval::references::ReferenceCache;
use crate::profile::{self, PassStats, Profile};
use crate::progress::{FrameRate, Progress};
use crate::setup::Setup;
use crate::shard::{FolderReport, RunReport, ShardArgs};
use crate::video::{self, Track, VideoArgs};
use anyhow::{bail, Context, Result};
use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::image_io::{to_rgb, write_exr, write_png};
use dvr_engine::renderer::{FrameRequest, FrameResult, MAX_SAMPLES_PER_DISPATCH};
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

pub fn capture(
    args: &SceneArgs,
    denoisers: &[String],
    out: &Path,
    video: &VideoArgs,
) -> Result<()> {
    if video.video {
        // Before anything renders: minutes of frames are no use without the encoder.
        video::require_ffmpeg()?;
    }
    let denoisers = crate::setup::denoiser_list(denoisers)?;
    crate::setup::warn_unused_overrides(&denoisers);
    let setup = Setup::new(args)?;
    let names: Vec<&str> = denoisers.iter().map(|s| s.as_str()).collect();
    let mut session = setup.session(&names)?;
    crate::setup::create_out_dir(out)?;
    for m in session.denoisers() {
        std::fs::create_dir_all(out.join(m))
            .with_context(|| format!("creating {}", out.join(m).display()))?;
    }
    let started = Instant::now();
    let mut timings: Vec<Vec<PassTiming>> = Vec::new();
    let request = FrameRequest {
        readback: true,
        reset: false,
        aux: false,
        features: false,
    };
    let mut progress = Progress::new(f64::from(setup.frames));
    let mut rate = FrameRate::default();
    for f in 0..setup.frames {
        session.play(f)?;
        if let Some(done) = session.frame(&request, None)? {
            write_frame(out, &setup, &done)?;
            timings.push(done.timings);
            rate.finished();
        }
        progress.advance(1.0, &frame_status("capture", f + 1, setup.frames, &rate));
    }
    for done in session.flush()? {
        write_frame(out, &setup, &done)?;
        timings.push(done.timings);
    }
    progress.finish();
    crate::output::write_json(
        &out.join("timings.json"),
        &serde_json::json!({
            "device": session.ctx().info.name,
            "scene": setup.name,
            "width": setup.width(),
            "height": setup.height(),
            "spp": setup.settings.spp(),
            "denoisers": session.renderer()?.denoiser_names(),
            "frames": timings,
        }),
    )?;
    let (passes, total) = profile::aggregate(&timings);
    let methods = session.renderer()?.denoiser_names();
    let videos = if video.video {
        let tracks: Vec<Track> = methods
            .iter()
            .map(|m| Track::from_folder(m, &out.join(m), setup.frames))
            .collect();
        video::write_videos(out, &tracks, video.video_fps)?
    } else {
        Vec::new()
    };
    write_capture_page(out, &setup, &methods, &passes, &total, &videos)?;
    println!(
        "wrote {} frames × {} method(s) to {} ({:.1} s)",
        setup.frames,
        methods.len(),
        out.display(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// `dvr reference`: the same cache as `dvr eval`'s, in `out/reference/`, so a rerun with
/// the same key reuses (or finishes) what is there.
pub fn reference(
    args: &SceneArgs,
    spp: u32,
    frame_range: Option<(u32, u32)>,
    shard: &ShardArgs,
    out: &Path,
) -> Result<()> {
    // --spp above lavapipe's per-frame count most likely meant the reference's samples;
    // counts the command line refuses (past MAX_SPP) already point to --ref-spp there.
    if let Some(n) = args.render.spp.filter(|&n| n > MAX_SAMPLES_PER_DISPATCH) {
        bail!(
            "`dvr reference` takes its samples per pixel from --ref-spp: use --ref-spp {n} \
             (--spp is the noisy input's samples per frame and does not change a reference)"
        );
    }
    // A reference runs no denoiser: an override set for one does nothing here.
    crate::setup::warn_unused_overrides(&["none"]);
    let setup = Setup::new(args)?;
    let frames = crate::setup::select_frames(setup.frames, frame_range, shard.shard)?;
    let key = ReferenceKey::new(setup.scene(), args.size, spp, args.render.volume_size)?;
    let cache = ReferenceCache::new(out, key);
    if shard.verify {
        return crate::shard::verdict(
            &format!("reference frames in {}", cache.dir.display()),
            frames.len(),
            &cache.problems(&frames),
        );
    }
    crate::setup::create_out_dir(out)?;
    let mut progress = ReferenceReport {
        progress: None,
        samples_per_frame: f64::from(spp) * f64::from(setup.width() * setup.height()),
    };
    let filled = cache.fill_frames(&setup, &mut progress, &frames)?;
    if let Some(p) = &mut progress.progress {
        p.finish();
    }
    println!(
        "wrote {} of {} reference frames to {} ({} rendered, {} already there)",
        frames.len(),
        setup.frames,
        cache.dir.display(),
        filled.rendered.len(),
        filled.reused.len()
    );
    let mut report = RunReport::new(shard);
    report.references.push(FolderReport {
        scene: setup.name.clone(),
        folder: cache.dir.clone(),
        selected: frames,
        rendered: filled.rendered,
        reused: filled.reused,
    });
    report.write(shard.report.as_deref())
}

/// `dvr reference`'s progress: frames and Msamples/s on the progress line (redrawn on a
/// terminal, whole lines in a log), notes on lines of their own.
struct ReferenceReport {
    /// Over the frames to render, from the first one on (none when all are reused).
    progress: Option<Progress>,
    samples_per_frame: f64,
}

impl FillReport for ReferenceReport {
    fn note(&mut self, text: Option<&str>) {
        if let Some(p) = &mut self.progress {
            p.newline();
        }
        if let Some(text) = text {
            eprintln!("reference: {text}");
        }
    }

    fn rendered(&mut self, done: usize, of: usize) {
        let progress = self
            .progress
            .get_or_insert_with(|| Progress::new(of as f64));
        let rate = if done == 0 {
            String::new()
        } else {
            let per_s = done as f64 * self.samples_per_frame / progress.elapsed();
            format!(" | {:.2} Msamples/s", per_s / 1e6)
        };
        let status = format!("reference: frame {done}/{of}{rate}");
        if done == 0 {
            progress.show(&status);
        } else {
            progress.advance(1.0, &status);
        }
    }
}

pub fn profile(
    args: &SceneArgs,
    denoisers: &[String],
    json: Option<&Path>,
    trace: Option<&Path>,
) -> Result<()> {
    // An output that cannot be written is found before the run, not after it.
    for p in json.into_iter().chain(trace) {
        dvr_engine::files::output_target(p).with_context(|| format!("writing {}", p.display()))?;
    }
    let stop = profile::interrupt::Interrupt::install().context("installing signal handlers")?;
    let (report, window) = run_profile(args, denoisers, Some(&stop))?;
    print!("{}", profile::table(&report));
    if let Some(p) = json {
        crate::output::write_json(p, &report)?;
    }
    if let Some(p) = trace {
        let mut t = profile::chrome_trace(window.frames(), window.first(), &report.frames_note);
        if let Some(why) = &report.interrupted {
            t["metadata"]["interrupted"] = why.clone().into();
        }
        crate::output::write_json(p, &t)?;
    }
    match stop.received() {
        Some(signal) => Err(signal.into()),
        None => Ok(()),
    }
}

/// Renders the profile's frames: the report (streaming statistics of every frame, the
/// measured peak bandwidth) and the window of raw frames for the trace. A signal seen
/// by `stop` ends the run after the frame in flight; the report then covers the frames
/// so far and says so.
pub fn run_profile(
    args: &SceneArgs,
    denoisers: &[String],
    stop: Option<&profile::interrupt::Interrupt>,
) -> Result<(Profile, profile::Window)> {
    let denoisers = crate::setup::denoiser_list(denoisers)?;
    crate::setup::warn_unused_overrides(&denoisers);
    let setup = Setup::new(args)?;
    let names: Vec<&str> = denoisers.iter().map(|s| s.as_str()).collect();
    let mut session = setup.session(&names)?;
    let peak = dvr_engine::passes::bandwidth::measure(session.ctx())
        .context("measuring the peak bandwidth")?;
    // Streaming statistics and a bounded window of raw frames: memory stays flat
    // however many frames run.
    let mut stats = profile::Stats::new();
    let mut window = profile::Window::new(profile::WINDOW_FRAMES);
    let mut keep = |timings: Vec<PassTiming>| {
        stats.add_frame(&timings);
        window.push(timings);
    };
    let request = FrameRequest::default();
    let mut progress = Progress::new(f64::from(setup.frames));
    let mut rate = FrameRate::default();
    let mut interrupted = None;
    for f in 0..setup.frames {
        if let Some(signal) = stop.and_then(|s| s.received()) {
            interrupted = Some(format!(
                "{signal} after {f} of {} frames; the statistics cover those",
                setup.frames
            ));
            break;
        }
        session.play(f)?;
        if let Some(done) = session.frame(&request, None)? {
            keep(done.timings);
            rate.finished();
        }
        progress.advance(1.0, &frame_status("profile", f + 1, setup.frames, &rate));
    }
    for done in session.flush()? {
        keep(done.timings);
    }
    progress.finish();
    let renderer = session.renderer()?;
    let run = profile::RunInfo {
        device: renderer.ctx().info.name.clone(),
        scene: setup.name.clone(),
        width: setup.width(),
        height: setup.height(),
        spp: setup.settings.spp(),
        denoisers: renderer.denoiser_names(),
        shared_tiles: renderer.ctx().shared_tiles,
        volume: renderer.volume_residency().to_string(),
    };
    let mut report = Profile::new(run, &stats, &window, Some(peak));
    report.interrupted = interrupted;
    Ok((report, window))
}

/// `capture: frame 12/60 | 3.4 fps`.
fn frame_status(what: &str, submitted: u32, total: u32, rate: &FrameRate) -> String {
    format!("{what}: frame {submitted}/{total} | {}", rate.text())
}

/// A small page next to a capture: the last frame of each method, a frame slider, and
/// the per-pass timing table.
fn write_capture_page(
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
            video::COMPARISON
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
fn html_escape(text: &str) -> String {
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
