//! `dvr eval` end to end, through the built binary on the test device (lavapipe in CI):
//! the CSV schema and values, the files the page needs, the plots, the reference cache
//! (reused when the settings match, re-rendered when they do not), and the results page
//! itself in headless Chromium.
//!
//! Outputs stay in `target/tmp/eval/` for inspection (the page test leaves a
//! screenshot there).

mod common;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant, SystemTime};

const METRICS_HEADER: &str = "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms";
const SUMMARY_HEADER: &str = "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover";

/// The tiny eval: 1 scene × 2 methods × `frames` frames at 32×32, 1 spp.
fn tiny_args(frames: u32, ref_spp: u32) -> Vec<String> {
    let frames = frames.to_string();
    let ref_spp = ref_spp.to_string();
    [
        "eval",
        "--scene",
        "cloud/orbit",
        "--frames",
        &frames,
        "--size",
        "32x32",
        "--spp",
        "1",
        "--ref-spp",
        &ref_spp,
        "--denoiser",
        "none,accum",
        "--volume-size",
        "48",
    ]
    .map(String::from)
    .to_vec()
}

fn out_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("eval")
        .join(name);
    if dir.exists() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
    dir
}

/// Runs the tiny eval into `out`; fails the test if dvr fails (a validation message
/// with DVR_VALIDATION=1 makes it exit with status 3).
fn eval(out: &Path, frames: u32, ref_spp: u32, extra: &[&str]) -> Output {
    let args = tiny_args(frames, ref_spp);
    let mut args: Vec<&str> = args.iter().map(String::as_str).collect();
    args.extend_from_slice(extra);
    common::eval::dvr_ok(&args, out)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

fn mtime(path: &Path) -> SystemTime {
    std::fs::metadata(path)
        .and_then(|m| m.modified())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn png_size(path: &Path) -> (u32, u32) {
    let img = image::open(path).unwrap_or_else(|e| panic!("decoding {}: {e}", path.display()));
    (img.width(), img.height())
}

/// Progress written to a file or pipe (as here) is whole lines, no carriage returns, at
/// most one per 2 % of the run (plus the first).
fn assert_log_progress(log: &str) {
    assert!(!log.contains('\r'), "carriage return in the log:\n{log}");
    let progress = log.lines().filter(|l| l.contains("% | ")).count();
    assert!(
        (1..=51).contains(&progress),
        "{progress} progress lines:\n{log}"
    );
}

fn num(s: &str, what: &str) -> f64 {
    s.parse()
        .unwrap_or_else(|_| panic!("{what}: {s:?} is not a number"))
}

#[test]
fn tiny_eval_writes_tables_images_plots_and_reuses_references() {
    let out = out_dir("tiny");
    let first = eval(&out, 3, 16, &[]);
    let scene = out.join("cloud_orbit");

    // metrics.csv: the exact header, one row per scene × method × frame, sane values.
    let metrics = read(&out.join("metrics.csv"));
    let mut lines = metrics.lines();
    assert_eq!(lines.next(), Some(METRICS_HEADER));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows.len(),
        2 * 3,
        "1 scene × 2 methods × 3 frames:\n{metrics}"
    );
    let mut seen = BTreeSet::new();
    for r in &rows {
        assert_eq!(r.len(), 8, "{r:?}");
        assert_eq!(r[0], "cloud/orbit");
        assert!(r[1] == "none" || r[1] == "accum", "{r:?}");
        let frame: u32 = r[2].parse().unwrap();
        assert!(frame < 3);
        assert!(
            seen.insert((r[1].to_string(), frame)),
            "duplicate row {r:?}"
        );
        let psnr = num(r[3], "psnr");
        assert!(
            psnr.is_finite() && psnr > 0.0 && psnr < 100.0,
            "psnr {psnr}"
        );
        let ssim = num(r[4], "ssim");
        assert!(ssim > -1.0 && ssim < 1.0, "ssim {ssim}");
        let flip = num(r[5], "flip");
        assert!(flip > 0.0 && flip < 1.0, "flip {flip}");
        if frame == 0 {
            assert_eq!(r[6], "", "no temporal error without a previous frame");
        } else {
            let t = num(r[6], "temporal_error");
            assert!((0.0..1.0).contains(&t), "temporal {t}");
        }
        let ms = num(r[7], "gpu_ms");
        assert!(ms.is_finite() && ms > 0.0, "gpu_ms {ms}");
    }
    // `none` is the input accum starts from: identical images on frame 0, and accum
    // pays for its own pass on top of the shared ones.
    let cell =
        |m: &str, f: &str, c: usize| rows.iter().find(|r| r[1] == m && r[2] == f).unwrap()[c];
    assert_eq!(cell("none", "0", 3), cell("accum", "0", 3));

    // summary.csv: a row per method, no frames to recover on an orbit.
    let summary = read(&out.join("summary.csv"));
    let s: Vec<&str> = summary.lines().collect();
    assert_eq!(s[0], SUMMARY_HEADER);
    assert_eq!(s.len(), 1 + 2, "{summary}");
    for l in &s[1..] {
        let c: Vec<&str> = l.split(',').collect();
        assert_eq!(c.len(), 8, "{l}");
        assert!(num(c[2], "mean psnr") > 0.0);
        assert_eq!(c[7], "", "orbit has no sudden change: {l}");
    }

    // The accumulation baseline: 1, 2, 4, 8 spp (≤ ref-spp / 2) on frames 0 and 1;
    // more samples are closer to the reference.
    let baseline = read(&out.join("baseline.csv"));
    let b: Vec<Vec<&str>> = baseline
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(b.len(), 2 * 4, "{baseline}");
    for frame in ["0", "1"] {
        let at = |spp: &str| {
            num(
                b.iter().find(|r| r[1] == frame && r[2] == spp).unwrap()[4],
                "psnr",
            )
        };
        assert!(
            at("8") > at("1") + 3.0,
            "8 spp should beat 1 spp by > 3 dB:\n{baseline}"
        );
        let ms = |spp: &str| {
            num(
                b.iter().find(|r| r[1] == frame && r[2] == spp).unwrap()[3],
                "ms",
            )
        };
        assert!((ms("8") - 8.0 * ms("1")).abs() < 1e-3 * ms("8").max(1.0));
    }

    // Files the page links to.
    for f in 0..3 {
        let n = format!("{f:04}");
        for p in [
            format!("reference/{n}.exr"),
            format!("reference/{n}.png"),
            format!("none/{n}.png"),
            format!("none/{n}.exr"),
            format!("none/flip_{n}.png"),
            format!("accum/{n}.png"),
            format!("accum/flip_{n}.png"),
        ] {
            let path = scene.join(&p);
            assert!(path.is_file(), "missing {}", path.display());
            if p.ends_with(".png") {
                assert_eq!(png_size(&path), (32, 32), "{p}");
            }
        }
    }
    assert!(scene.join("reference/reference.json").is_file());
    assert!(scene.join("timings.json").is_file());
    for stem in [
        "cloud_orbit/plots/psnr",
        "cloud_orbit/plots/ssim",
        "cloud_orbit/plots/flip",
        "cloud_orbit/plots/temporal_error",
        "cloud_orbit/plots/speed_accuracy",
        "plots/speed_accuracy",
    ] {
        let svg = read(&out.join(format!("{stem}.svg")));
        assert!(svg.contains("<svg") && svg.contains("accum"), "{stem}.svg");
        let (w, h) = png_size(&out.join(format!("{stem}.png")));
        assert!(w >= 320 && h >= 200, "{stem}.png is {w}x{h}");
    }
    let page = read(&out.join("index.html"));
    assert!(page.contains("\"cloud/orbit\"") && !page.contains("fetch("));
    assert!(
        stderr(&first).contains("cloud/orbit"),
        "progress names the scene"
    );
    assert_log_progress(&stderr(&first));

    // Same settings again: every reference is reused, untouched.
    let refs: Vec<PathBuf> = (0..3)
        .map(|f| scene.join(format!("reference/{f:04}.exr")))
        .collect();
    let before: Vec<SystemTime> = refs.iter().map(|p| mtime(p)).collect();
    std::thread::sleep(Duration::from_millis(20));
    let second = eval(&out, 3, 16, &[]);
    assert!(
        stderr(&second).contains("reusing 3 reference frame(s)"),
        "{}",
        stderr(&second)
    );
    let after: Vec<SystemTime> = refs.iter().map(|p| mtime(p)).collect();
    assert_eq!(before, after, "references were re-rendered");
    assert_eq!(read(&out.join("metrics.csv")).lines().count(), 1 + 6);

    // Without the baseline: the same frames scored the same (the baseline runs after
    // them), and baseline.csv keeps only its header.
    let scores = |csv: &str| -> Vec<String> {
        csv.lines()
            .map(|l| l.rsplit_once(',').unwrap().0.to_string())
            .collect()
    };
    let with_baseline = scores(&read(&out.join("metrics.csv")));
    let without = eval(&out, 3, 16, &["--no-baseline"]);
    assert!(
        stderr(&without).contains("reusing 3 reference frame(s)"),
        "{}",
        stderr(&without)
    );
    assert_eq!(scores(&read(&out.join("metrics.csv"))), with_baseline);
    assert_eq!(read(&out.join("baseline.csv")).lines().count(), 1);

    // An interrupted run (frame 2 missing) renders only what is missing.
    std::fs::remove_file(&refs[2]).unwrap();
    let resumed = eval(&out, 3, 16, &[]);
    assert!(
        stderr(&resumed).contains("reusing 2 reference frame(s), rendering 1"),
        "{}",
        stderr(&resumed)
    );
    assert_eq!(mtime(&refs[0]), before[0]);
    assert!(refs[2].is_file());

    // Different reference settings: all frames are re-rendered under the new key.
    let changed = eval(&out, 3, 8, &[]);
    assert!(
        stderr(&changed).contains("reference settings changed"),
        "{}",
        stderr(&changed)
    );
    assert_ne!(mtime(&refs[0]), before[0]);
    assert!(read(&scene.join("reference/reference.json")).contains("\"ref_spp\": 8"));
    assert_eq!(read(&out.join("baseline.csv")).lines().count(), 1 + 2 * 3);
}

/// The first Chromium on PATH.
fn chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ]
    .iter()
    .flat_map(|name| std::env::split_paths(&path).map(move |d| d.join(name)))
    .find(|p| p.is_file())
}

/// Runs headless Chromium with `args` (plus the flags every run needs), killing it
/// after a minute.
fn run_chromium(bin: &Path, args: &[String]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut child = Command::new(bin)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--no-first-run",
            "--virtual-time-budget=10000",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("starting chromium");
    let started = Instant::now();
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut stdout, &mut s).ok();
        s
    });
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            assert!(status.success(), "chromium exited with {status}");
            break;
        }
        if started.elapsed() > Duration::from_secs(60) {
            child.kill().ok();
            panic!("chromium did not finish within 60 s");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    reader.join().unwrap()
}

/// The value of `attr` in the first tag that contains `marker` (e.g. `id="img-a"`).
fn attr<'a>(dom: &'a str, marker: &str, attr: &str) -> &'a str {
    let at = dom
        .find(marker)
        .unwrap_or_else(|| panic!("no {marker} in the DOM"));
    let start = dom[..at].rfind('<').unwrap();
    let end = at + dom[at..].find('>').unwrap();
    let tag = &dom[start..end];
    let key = format!(" {attr}=\"");
    let v = tag
        .find(&key)
        .unwrap_or_else(|| panic!("no {attr} in {tag}"))
        + key.len();
    &tag[v..v + tag[v..].find('"').unwrap()]
}

/// The page counted every image it showed as loaded, none failed or still pending.
fn assert_all_images_loaded(dom: &str) {
    assert_eq!(
        attr(dom, "<body", "data-failed"),
        "0",
        "{}",
        attr(dom, "<body", "data-failed-srcs")
    );
    assert_eq!(attr(dom, "<body", "data-pending"), "0");
}

/// Chromium, or `None` (the test is skipped) where it is not installed, except in CI.
fn chromium_or_skip(test: &str) -> Option<PathBuf> {
    let bin = chromium();
    if bin.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "chromium is not installed, but CI is set: tools/setup.sh installs it"
        );
        eprintln!(
            "SKIPPED {test}: chromium is not installed (apt install chromium, or run \
             tools/setup.sh)"
        );
    }
    bin
}

#[test]
fn results_page_works_in_headless_chromium() {
    let Some(bin) = chromium_or_skip("results_page_works_in_headless_chromium") else {
        return;
    };
    let out = out_dir("page");
    eval(&out, 4, 16, &[]);
    let url = |hash: &str| format!("file://{}#{hash}", out.join("index.html").display());

    // Without a hash: the last frame, the last method against the reference, side by
    // side.
    let dom = run_chromium(&bin, &["--dump-dom".into(), url("")]);
    assert_eq!(
        attr(&dom, "<body", "data-ready"),
        "1",
        "the page script ran"
    );
    assert_eq!(attr(&dom, "<body", "data-frame"), "3");
    assert_eq!(
        attr(&dom, "id=\"img-a\"", "src"),
        "cloud_orbit/accum/0003.png"
    );
    assert_eq!(
        attr(&dom, "id=\"img-b\"", "src"),
        "cloud_orbit/reference/0003.png"
    );

    // The hash drives the controls through their own handlers: the frame slider to
    // frame 2, the wipe view at 25 %, FLIP error maps, `none` against `accum`.
    let dom = run_chromium(
        &bin,
        &[
            "--dump-dom".into(),
            url("scene=cloud/orbit&frame=2&a=none&b=accum&view=wipe&split=25&flip=1"),
        ],
    );
    assert_eq!(attr(&dom, "<body", "data-frame"), "2");
    assert_eq!(attr(&dom, "<body", "data-view"), "wipe");
    assert_eq!(attr(&dom, "id=\"frame\"", "max"), "3");
    assert_eq!(
        attr(&dom, "id=\"img-a\"", "src"),
        "cloud_orbit/none/flip_0002.png"
    );
    assert_eq!(
        attr(&dom, "id=\"wipe-b\"", "src"),
        "cloud_orbit/accum/flip_0002.png"
    );
    assert!(attr(&dom, "id=\"wipe-a\"", "style").contains("inset(0px 75% 0px 0px)"));
    assert!(dom.contains("<title>dvr eval — cloud/orbit — none vs accum — frame 2</title>"));
    // Every image the page shows loaded: 4 frames (side and wipe), the grid's 3 (the
    // reference and both methods) and 5 scene plots.
    assert_all_images_loaded(&dom);
    let loaded: usize = attr(&dom, "<body", "data-loaded").parse().unwrap();
    assert!(loaded >= 10, "only {loaded} images loaded");
    assert!(dom.contains("cloud_orbit/plots/speed_accuracy.svg"));

    let shot = out.join("screenshot.png");
    run_chromium(
        &bin,
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1280,1800".into(),
            url("frame=2&a=accum&b=reference&x=16&y=16"),
        ],
    );
    assert_eq!(png_size(&shot), (1280, 1800));
}

#[test]
fn scene_files_are_labelled_by_their_name_and_never_share_a_folder() {
    let out = out_dir("names");
    let files = out.with_file_name("names-scenes");
    if files.exists() {
        std::fs::remove_dir_all(&files).unwrap();
    }
    // Two files with the same stem in different folders, neither with a `name`.
    let scene = "[volume]\nbuiltin = \"cloud\"\nsize = 16\n[transfer]\na = \"cloud\"\n\
                 [[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 4.0\n";
    let a = files.join("some/dir/my-scene.toml");
    let b = files.join("other/my-scene.toml");
    for p in [&a, &b] {
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, scene).unwrap();
    }
    let o = Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(["eval", "--scene"])
        .arg(format!("{},{}", a.display(), b.display()))
        .args([
            "--frames",
            "2",
            "--size",
            "16x16",
            "--spp",
            "1",
            "--ref-spp",
            "4",
        ])
        .args(["--denoiser", "none", "--volume-size", "16", "--out"])
        .arg(&out)
        .output()
        .expect("running dvr");
    assert!(o.status.success(), "{}", stderr(&o));
    let summary = read(&out.join("summary.csv"));
    let scenes: Vec<&str> = summary
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap())
        .collect();
    assert_eq!(scenes, ["my-scene", "my-scene-2"], "{summary}");
    for dir in ["my-scene", "my-scene-2"] {
        assert!(out.join(dir).join("reference/0001.png").is_file(), "{dir}");
    }
    let page = read(&out.join("index.html"));
    assert!(page.contains("\"name\":\"my-scene\"") && !page.contains("some/dir"));
}

#[test]
fn main_job_page_shows_the_reference_and_a_row_per_method() {
    let Some(bin) = chromium_or_skip("main_job_page_shows_the_reference_and_a_row_per_method")
    else {
        return;
    };
    // `dvr demo` as tools/run.sh runs it, at a test's size.
    let out = out_dir("demo");
    let o = Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(["demo", "--size", "32x32", "--frames", "3", "--ref-spp", "8"])
        .args(["--volume-size", "32", "--out"])
        .arg(&out)
        .output()
        .expect("running dvr demo");
    assert!(o.status.success(), "dvr demo failed:\n{}", stderr(&o));
    assert_log_progress(&stderr(&o));
    let methods = ["none", "taa", "svgf", "ours", "rae"];

    let url = format!("file://{}", out.join("index.html").display());
    let dom = run_chromium(&bin, &["--dump-dom".into(), url]);
    assert_eq!(attr(&dom, "<body", "data-ready"), "1");
    // The reference and every method at the last frame, all loaded.
    assert_eq!(
        attr(&dom, "id=\"grid-reference\"", "src"),
        "phantom_orbit/reference/0002.png"
    );
    for m in methods {
        let src = attr(&dom, &format!("id=\"grid-{m}\""), "src");
        assert_eq!(src, format!("phantom_orbit/{m}/0002.png"));
    }
    assert_all_images_loaded(&dom);
    // One metrics row per method, in the order they ran.
    let start = dom.find("id=\"scene-table\"").expect("the metrics table");
    let table = &dom[start..start + dom[start..].find("</table>").unwrap()];
    let rows: Vec<&str> = table
        .match_indices("<tr data-method=\"")
        .map(|(i, m)| {
            let v = &table[i + m.len()..];
            &v[..v.find('"').unwrap()]
        })
        .collect();
    assert_eq!(rows, methods, "metrics rows");
    assert!(
        dom.contains("The main job (tools/run.sh)"),
        "the page says what ran"
    );
    if std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join("ffmpeg").is_file()))
    {
        assert!(out.join("phantom_orbit/videos/comparison.mp4").is_file());
        assert!(dom.contains("phantom_orbit/videos/comparison.mp4"));
    }
}
