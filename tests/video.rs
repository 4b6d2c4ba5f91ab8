//! `--video`: `dvr capture` writes H.264 MP4s that ffprobe reads back with the right
//! frame count and size, plus the labelled side-by-side comparison; without ffmpeg on
//! PATH it stops before rendering with a message that says what to install, exit 1 and
//! no file.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn dvr(args: &[&str], path_env: Option<&Path>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_dvr"));
    c.args(args).env("DVR_VALIDATION", "1");
    if let Some(p) = path_env {
        c.env("PATH", p);
    }
    c.output().expect("run dvr")
}

/// `dvr capture --video` of 3 frames of cloud/orbit into `out`, with `extra` arguments
/// and optionally another PATH.
fn capture_video(out: &Path, extra: &[&str], path_env: Option<&Path>) -> Output {
    let mut args = vec!["capture", "--scene", "cloud/orbit", "--frames", "3"];
    args.extend_from_slice(&["--volume-size", "32", "--video", "--out"]);
    args.push(out.to_str().expect("utf-8"));
    args.extend_from_slice(extra);
    dvr(&args, path_env)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// `program` on PATH, if there.
fn on_path(program: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(program))
        .find(|p| p.is_file())
}

/// (frames, width, height) of the video stream, as ffprobe counts them.
fn probe(ffprobe: &Path, video: &Path) -> (u32, u32, u32) {
    let o = Command::new(ffprobe)
        .args(["-v", "error", "-count_frames", "-select_streams", "v:0"])
        .args([
            "-show_entries",
            "stream=codec_name,nb_read_frames,width,height",
        ])
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(video)
        .output()
        .expect("run ffprobe");
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(o.status.success(), "ffprobe {}: {text}", video.display());
    let field = |k: &str| -> String {
        text.lines()
            .find_map(|l| l.strip_prefix(&format!("{k}=")))
            .unwrap_or_else(|| {
                panic!(
                    "no {k} in ffprobe's output for {}:\n{text}",
                    video.display()
                )
            })
            .to_string()
    };
    assert_eq!(field("codec_name"), "h264", "{}", video.display());
    let n = |k: &str| field(k).parse::<u32>().expect("a number");
    (n("nb_read_frames"), n("width"), n("height"))
}

#[test]
fn capture_writes_playable_videos_and_a_comparison() {
    let (Some(_), Some(ffprobe)) = (on_path("ffmpeg"), on_path("ffprobe")) else {
        assert!(
            std::env::var_os("CI").is_none(),
            "ffmpeg is not installed, but CI is set: tools/setup.sh installs it"
        );
        eprintln!("SKIPPED: ffmpeg/ffprobe not installed (tools/setup.sh installs them)");
        return;
    };
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("cap");
    let o = capture_video(&out, &["--denoiser", "none,ours", "--size", "32x24"], None);
    assert!(
        o.status.success(),
        "dvr capture --video failed:\n{}",
        stderr(&o)
    );
    for m in ["none", "ours"] {
        let v = out.join("videos").join(format!("{m}.mp4"));
        assert_eq!(probe(&ffprobe, &v), (3, 32, 24), "{}", v.display());
    }
    // Two tiles side by side, each scaled up to at least 320 pixels wide under a label.
    let (frames, w, h) = probe(&ffprobe, &out.join("videos/comparison.mp4"));
    assert_eq!(frames, 3);
    assert!(w >= 2 * 320 && h > 240, "comparison is {w}x{h}");
    let leftovers: Vec<_> = std::fs::read_dir(out.join("videos"))
        .expect("videos folder")
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    let page = std::fs::read_to_string(out.join("index.html")).expect("page");
    assert!(
        page.contains("videos/comparison.mp4"),
        "the page links the videos"
    );
}

#[test]
fn video_without_ffmpeg_says_what_to_install_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let empty = dir.path().join("empty-path");
    std::fs::create_dir(&empty).expect("mkdir");
    let out = dir.path().join("cap");
    let o = capture_video(&out, &["--size", "16x16"], Some(&empty));
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("ffmpeg") && err.contains("apt install ffmpeg"),
        "the message says what to install:\n{err}"
    );
    assert!(!out.exists(), "nothing is written before the check");
}
