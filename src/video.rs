//! Videos of the frames `dvr capture` and `dvr eval` write: one H.264 MP4 per method
//! (and the reference) at the frames' own size, and a side-by-side comparison with a
//! label over each tile, all under `<folder>/videos/`.
//!
//! Encoding is the `ffmpeg` program's (libx264, yuv420p so every player can show it),
//! fed raw RGB frames on its stdin: no codec is linked into dvr. Its presence is
//! checked before anything renders ([`require_ffmpeg`]), and each video is written
//! under a temporary name and renamed when ffmpeg succeeded, so a failed or interrupted
//! encode never leaves a file that looks finished.

use anyhow::{anyhow, bail, Context, Result};
use image::imageops::FilterType;
use image::RgbImage;
use plotters::prelude::*;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, ExitStatus, Stdio};

/// Frames per second of the videos unless `--video-fps` says otherwise.
pub const DEFAULT_FPS: u32 = 12;

/// The program videos are encoded with (looked up on PATH).
const FFMPEG: &str = "ffmpeg";

/// The comparison video's tiles are scaled up (by a whole factor, pixels kept sharp)
/// to at least this width, so small frames stay visible ...
const MIN_TILE_WIDTH: u32 = 320;
/// ... and scaled down so that the whole video is at most this wide.
const MAX_VIDEO_WIDTH: u32 = 1920;
/// Height of the label bar above each tile, and its text size.
const LABEL_HEIGHT: u32 = 28;
const LABEL_TEXT: u32 = 18;
/// Dark pixels between tiles, so similar backgrounds do not run together.
const GAP: u32 = 4;

/// The video options of `dvr capture` and `dvr eval`.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct VideoArgs {
    /// Also write each method's frames as an H.264 MP4, and a side-by-side comparison
    /// with labels, to `<out>/videos/` (needs `ffmpeg` on PATH).
    #[arg(long)]
    pub video: bool,
    /// Frames per second of the videos.
    #[arg(long, default_value_t = DEFAULT_FPS, value_parser = clap::value_parser!(u32).range(1..=240))]
    pub video_fps: u32,
}

/// The folder the videos of an output folder go to.
pub fn dir(out: &Path) -> PathBuf {
    out.join("videos")
}

/// The comparison video's file name (the others are `<track>.mp4`).
pub const COMPARISON: &str = "comparison.mp4";

/// Why videos cannot be written here, or `None` when ffmpeg with libx264 is on PATH.
pub fn ffmpeg_missing() -> Option<String> {
    let install = "install ffmpeg (Debian/Ubuntu: `sudo apt install ffmpeg`; \
                   tools/setup.sh installs it) or leave out --video";
    match Command::new(FFMPEG)
        .args(["-hide_banner", "-encoders"])
        .stdin(Stdio::null())
        .stderr(Stdio::null())
        .output()
    {
        Err(_) => Some(format!(
            "--video needs the `{FFMPEG}` program, which is not on PATH: {install}"
        )),
        Ok(o) if !String::from_utf8_lossy(&o.stdout).contains("libx264") => Some(format!(
            "--video needs `{FFMPEG}` with the libx264 H.264 encoder, which this ffmpeg \
             lacks: {install}"
        )),
        Ok(_) => None,
    }
}

/// Fails with what to install when videos cannot be written (call it before rendering).
pub fn require_ffmpeg() -> Result<()> {
    match ffmpeg_missing() {
        Some(why) => bail!("{why}"),
        None => Ok(()),
    }
}

/// One sequence to encode: its name (the file name and the comparison's label), its
/// frames as PNG files, and optionally a caption per frame for the comparison's label.
pub struct Track {
    pub name: String,
    pub frames: Vec<PathBuf>,
    pub captions: Vec<String>,
}

impl Track {
    /// The frames `NNNN.png` of `folder`, 0..frames.
    pub fn from_folder(name: &str, folder: &Path, frames: u32) -> Self {
        Self {
            name: name.to_string(),
            frames: (0..frames)
                .map(|f| folder.join(format!("{f:04}.png")))
                .collect(),
            captions: Vec::new(),
        }
    }

    fn label(&self, frame: usize) -> String {
        match self.captions.get(frame) {
            Some(c) if !c.is_empty() => format!("{}  {c}", self.name),
            _ => self.name.clone(),
        }
    }
}

/// Writes `<out>/videos/<track>.mp4` for every track and `<out>/videos/comparison.mp4`
/// with all tracks side by side; returns the files written.
pub fn write_videos(out: &Path, tracks: &[Track], fps: u32) -> Result<Vec<PathBuf>> {
    crate::font::init_font()?;
    let dir = dir(out);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut written = Vec::new();
    for t in tracks {
        let path = dir.join(format!("{}.mp4", t.name));
        let frames = t.frames.iter().map(|p| load(p));
        encode(&path, fps, frames)?;
        written.push(path);
    }
    let count = tracks.iter().map(|t| t.frames.len()).min().unwrap_or(0);
    if !tracks.is_empty() && count > 0 {
        let path = dir.join(COMPARISON);
        let layout = Layout::new(tracks.len(), image::image_dimensions(&tracks[0].frames[0])?);
        let frames = (0..count).map(|f| {
            let tiles = tracks
                .iter()
                .map(|t| Ok((load(&t.frames[f])?, t.label(f))))
                .collect::<Result<Vec<_>>>()?;
            layout.compose(&tiles)
        });
        encode(&path, fps, frames)?;
        written.push(path);
    }
    Ok(written)
}

fn load(path: &Path) -> Result<RgbImage> {
    Ok(image::open(path)
        .with_context(|| format!("reading {} for a video", path.display()))?
        .to_rgb8())
}

/// Where each tile of the comparison goes.
struct Layout {
    columns: u32,
    rows: u32,
    tile: (u32, u32),
}

impl Layout {
    fn new(tiles: usize, frame: (u32, u32)) -> Self {
        let n = tiles.max(1) as u32;
        // One row up to three tiles, then a near-square grid (6 → 3×2, 4 → 2×2).
        let columns = if n <= 3 {
            n
        } else {
            (f64::from(n).sqrt().ceil()) as u32
        };
        let rows = n.div_ceil(columns);
        let (w, h) = (frame.0.max(1), frame.1.max(1));
        let up = MIN_TILE_WIDTH.div_ceil(w).max(1);
        let tile_w = (w * up).min(MAX_VIDEO_WIDTH / columns - GAP).max(2);
        let tile_h = ((u64::from(h) * u64::from(tile_w)) / u64::from(w)).max(2) as u32;
        Self {
            columns,
            rows,
            tile: (tile_w, tile_h),
        }
    }

    fn size(&self) -> (u32, u32) {
        let (x, y) = self.stride();
        (self.columns * x - GAP, self.rows * y - GAP)
    }

    /// Distance from one tile's corner to the next, label and gap included.
    fn stride(&self) -> (u32, u32) {
        (self.tile.0 + GAP, self.tile.1 + LABEL_HEIGHT + GAP)
    }

    /// One comparison frame: each image scaled into its tile under a label bar.
    fn compose(&self, tiles: &[(RgbImage, String)]) -> Result<RgbImage> {
        let (w, h) = self.size();
        let mut frame = RgbImage::from_pixel(w, h, image::Rgb([16, 16, 16]));
        for (i, (img, _)) in tiles.iter().enumerate() {
            let filter = if img.width() <= self.tile.0 {
                FilterType::Nearest
            } else {
                FilterType::Triangle
            };
            let scaled = image::imageops::resize(img, self.tile.0, self.tile.1, filter);
            let (x, y) = self.origin(i);
            image::imageops::replace(&mut frame, &scaled, x.into(), (y + LABEL_HEIGHT).into());
        }
        {
            let root = BitMapBackend::with_buffer(&mut frame, (w, h)).into_drawing_area();
            let style = ("sans-serif", LABEL_TEXT).into_font().color(&WHITE);
            for (i, (_, label)) in tiles.iter().enumerate() {
                let (x, y) = self.origin(i);
                let at = (
                    x as i32 + 8,
                    (y + (LABEL_HEIGHT - LABEL_TEXT) / 2 + 1) as i32,
                );
                root.draw_text(label, &style, at)
                    .map_err(|e| anyhow!("drawing the label {label:?}: {e}"))?;
            }
            root.present()
                .map_err(|e| anyhow!("drawing the labels: {e}"))?;
        }
        Ok(frame)
    }

    fn origin(&self, tile: usize) -> (u32, u32) {
        let (c, r) = (tile as u32 % self.columns, tile as u32 / self.columns);
        let (x, y) = self.stride();
        (c * x, r * y)
    }
}

/// Encodes `frames` (all of one size) as an H.264 MP4 at `path`.
fn encode(path: &Path, fps: u32, frames: impl Iterator<Item = Result<RgbImage>>) -> Result<()> {
    let mut encoder: Option<Encoder> = None;
    for frame in frames {
        let frame = frame?;
        let enc = match &mut encoder {
            Some(e) => e,
            None => encoder.insert(Encoder::start(path, frame.dimensions(), fps)?),
        };
        enc.push(&frame)?;
    }
    match encoder {
        Some(e) => e.finish(),
        None => bail!("{}: no frames to encode", path.display()),
    }
}

/// A running ffmpeg writing one video under a temporary name.
struct Encoder {
    child: Child,
    stdin: Option<ChildStdin>,
    path: PathBuf,
    partial: PathBuf,
    /// The frames' size, and the video's (rounded up to even: yuv420p needs it).
    size: (u32, u32),
    even: (u32, u32),
    finished: bool,
}

impl Encoder {
    fn start(path: &Path, size: (u32, u32), fps: u32) -> Result<Self> {
        let even = (size.0.next_multiple_of(2), size.1.next_multiple_of(2));
        // The rename at the end puts a regular file at the target: only a new path, a
        // regular file or a link to one may be replaced.
        let path = &dvr_engine::files::output_target(path)
            .with_context(|| format!("writing {}", path.display()))?;
        let partial = path.with_extension("partial.mp4");
        let mut child = Command::new(FFMPEG)
            .args(["-hide_banner", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
            .args(["-s", &format!("{}x{}", even.0, even.1)])
            .args(["-framerate", &fps.max(1).to_string(), "-i", "-"])
            .args(["-c:v", "libx264", "-preset", "medium", "-crf", "18"])
            .args([
                "-pix_fmt",
                "yuv420p",
                "-movflags",
                "+faststart",
                "-f",
                "mp4",
            ])
            .arg(&partial)
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .with_context(|| format!("starting {FFMPEG} for {}", path.display()))?;
        Ok(Self {
            stdin: child.stdin.take(),
            child,
            path: path.to_path_buf(),
            partial,
            size,
            even,
            finished: false,
        })
    }

    fn push(&mut self, frame: &RgbImage) -> Result<()> {
        if frame.dimensions() != self.size {
            bail!(
                "{}: a frame is {}x{}, the others {}x{}",
                self.path.display(),
                frame.width(),
                frame.height(),
                self.size.0,
                self.size.1
            );
        }
        let bytes = if self.even == self.size {
            frame.as_raw().clone()
        } else {
            // Odd sizes get one black column or row.
            let mut padded = RgbImage::new(self.even.0, self.even.1);
            image::imageops::replace(&mut padded, frame, 0, 0);
            padded.into_raw()
        };
        let stdin = self.stdin.as_mut().expect("stdin is open until finish");
        if stdin.write_all(&bytes).is_err() {
            // ffmpeg quit; its message says why.
            let (status, message) = self.wait()?;
            bail!(
                "{FFMPEG} stopped ({status}) while writing {}: {message}",
                self.path.display()
            );
        }
        Ok(())
    }

    /// Closes ffmpeg's input, waits for it, and returns its status and what it printed.
    fn wait(&mut self) -> Result<(ExitStatus, String)> {
        self.stdin = None;
        let mut message = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            std::io::Read::read_to_string(&mut e, &mut message).ok();
        }
        let status = self
            .child
            .wait()
            .with_context(|| format!("waiting for {FFMPEG}"))?;
        Ok((status, message.trim().to_string()))
    }

    fn finish(mut self) -> Result<()> {
        let (status, message) = self.wait()?;
        if !status.success() {
            bail!(
                "{FFMPEG} failed ({status}) writing {}: {message}",
                self.path.display()
            );
        }
        std::fs::rename(&self.partial, &self.path).with_context(|| {
            format!(
                "renaming {} to {}",
                self.partial.display(),
                self.path.display()
            )
        })?;
        self.finished = true;
        Ok(())
    }
}

impl Drop for Encoder {
    /// An encode that did not finish leaves nothing behind.
    fn drop(&mut self) {
        if !self.finished {
            self.stdin = None;
            let _ = self.child.kill();
            let _ = self.child.wait();
            let _ = std::fs::remove_file(&self.partial);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts() {
        let l = Layout::new(6, (128, 128));
        assert_eq!((l.columns, l.rows), (3, 2));
        assert_eq!(
            l.tile,
            (384, 384),
            "small frames scale up by a whole factor"
        );
        assert_eq!(
            l.size(),
            (3 * 384 + 2 * GAP, 2 * (384 + LABEL_HEIGHT) + GAP)
        );
        let l = Layout::new(2, (1280, 720));
        assert_eq!((l.columns, l.rows), (2, 1));
        assert_eq!(l.tile, (960 - GAP, (960 - GAP) * 720 / 1280));
        assert!(l.size().0 <= MAX_VIDEO_WIDTH);
        let l = Layout::new(4, (32, 24));
        assert_eq!((l.columns, l.rows, l.tile), (2, 2, (320, 240)));
        assert_eq!(Layout::new(3, (100, 50)).origin(2), (2 * (400 + GAP), 0));
    }

    #[test]
    fn captions_join_the_label() {
        let mut t = Track::from_folder("ours", Path::new("x"), 2);
        assert_eq!(t.frames[1], Path::new("x/0001.png"));
        assert_eq!(t.label(0), "ours");
        t.captions = vec!["31.20 dB".into()];
        assert_eq!(t.label(0), "ours  31.20 dB");
        assert_eq!(t.label(1), "ours");
    }
}
