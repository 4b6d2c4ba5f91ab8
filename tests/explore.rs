//! `dvr explore` in a real window under Xvfb, as a user runs it, with the validation
//! layer on: the screenshot shows the rendered volume and the UI panel; a scripted drag
//! changes the view; a moving view renders fewer pixels, upsampled into the view, until
//! it is still again; a recorded session replays through `dvr capture` to the same
//! frames; and without a display the command says how to get one.
//!
//! Each test starts its own `Xvfb` on a free display and kills it at the end. Without
//! Xvfb the window tests are skipped with a message, unless `CI` is set (then Xvfb is
//! required: tools/setup.sh installs it).

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

/// The panel's fill colour (src/explore/ui.rs `PANEL_FILL`) and width in pixels at
/// scale 1 (`PANEL_WIDTH`).
const PANEL_FILL: [u8; 3] = [30, 34, 42];
const PANEL_WIDTH: u32 = 300;

struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn has_xvfb() -> bool {
    Command::new("sh")
        .args(["-c", "command -v Xvfb"])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// Starts Xvfb on a free display, or returns None (after saying why) when it is not
/// installed and this is not CI.
fn xvfb() -> Option<Xvfb> {
    if !has_xvfb() {
        if std::env::var_os("CI").is_some() {
            panic!("Xvfb is required in CI (tools/setup.sh installs the xvfb package)");
        }
        eprintln!("skipping: Xvfb is not installed (apt-get install xvfb)");
        return None;
    }
    static NEXT: AtomicU32 = AtomicU32::new(0);
    let base = 100 + (std::process::id() % 400) * 8;
    for _ in 0..64 {
        let n = base + NEXT.fetch_add(1, Ordering::SeqCst) % 3000;
        let socket = PathBuf::from(format!("/tmp/.X11-unix/X{n}"));
        if socket.exists() || Path::new(&format!("/tmp/.X{n}-lock")).exists() {
            continue;
        }
        let mut child = Command::new("Xvfb")
            .args([
                &format!(":{n}"),
                "-screen",
                "0",
                "1280x1024x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn Xvfb");
        let started = Instant::now();
        while started.elapsed() < Duration::from_secs(10) {
            if socket.exists() {
                return Some(Xvfb {
                    child,
                    display: format!(":{n}"),
                });
            }
            if child.try_wait().ok().flatten().is_some() {
                break; // lost a race for the display: try the next one
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        let _ = child.kill();
        let _ = child.wait();
    }
    panic!("could not start Xvfb on any display");
}

fn dvr(display: Option<&str>, args: &[&str], dir: &Path) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_dvr"));
    cmd.args(args)
        .current_dir(dir)
        .env("DVR_VALIDATION", "1")
        .env_remove("WAYLAND_DISPLAY");
    match display {
        Some(d) => cmd.env("DISPLAY", d),
        None => cmd.env_remove("DISPLAY"),
    };
    cmd.output().expect("run dvr")
}

fn assert_clean(o: &Output) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        o.status.success(),
        "dvr failed ({:?}):\n{err}",
        o.status.code()
    );
    assert!(!err.contains("validation"), "validation messages:\n{err}");
}

struct Shot {
    width: u32,
    height: u32,
    rgb: Vec<u8>,
}

impl Shot {
    fn open(path: &Path) -> Self {
        let img = image::open(path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .to_rgb8();
        Self {
            width: img.width(),
            height: img.height(),
            rgb: img.into_raw(),
        }
    }

    fn px(&self, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * self.width + x) * 3) as usize;
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }

    /// Mean luminance-ish value and variance over a rectangle.
    fn stats(&self, x0: u32, y0: u32, x1: u32, y1: u32) -> (f64, f64) {
        let mut v = Vec::new();
        for y in y0..y1 {
            for x in x0..x1 {
                let p = self.px(x, y);
                v.push((p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0);
            }
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|a| (a - mean).powi(2)).sum::<f64>() / v.len() as f64;
        (mean, var)
    }
}

/// Mean absolute difference of the render regions (the `w × h` left part).
fn mean_abs_diff(a: &Shot, b: &Shot, w: u32, h: u32) -> f64 {
    let mut sum = 0.0;
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (a.px(x, y), b.px(x, y));
            sum += (0..3)
                .map(|c| (p[c] as f64 - q[c] as f64).abs())
                .sum::<f64>()
                / 3.0;
        }
    }
    sum / (w * h) as f64
}

const SIZE: u32 = 256;

fn explore_shot(x: &Xvfb, dir: &Path, name: &str, extra: &[&str]) -> Shot {
    explore_scene_shot(x, dir, name, "phantom/orbit", extra)
}

fn explore_scene_shot(x: &Xvfb, dir: &Path, name: &str, scene: &str, extra: &[&str]) -> Shot {
    explore_run(x, dir, name, scene, "30", extra).0
}

/// `dvr explore` of `scene` for `frames` frames, its screenshot `name` and its stdout.
fn explore_run(
    x: &Xvfb,
    dir: &Path,
    name: &str,
    scene: &str,
    frames: &str,
    extra: &[&str],
) -> (Shot, String) {
    let shot = dir.join(name);
    let size = format!("{SIZE}x{SIZE}");
    let mut args = vec![
        "explore",
        "--scene",
        scene,
        "--size",
        &size,
        "--frames",
        frames,
        "--screenshot",
        shot.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    let out = dvr(Some(&x.display), &args, dir);
    assert_clean(&out);
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        stdout.contains("ms/frame"),
        "no frame-rate summary:\n{stdout}"
    );
    (Shot::open(&shot), stdout)
}

#[test]
fn window_shows_the_volume_and_the_panel_and_a_scripted_drag_turns_it() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    let a = explore_shot(&x, dir.path(), "a.png", &[]);
    assert_eq!((a.width, a.height), (SIZE + PANEL_WIDTH, SIZE));

    // The volume: the centre of the view differs from the background at its border
    // (a smooth environment gradient), pixel by pixel and in its structure.
    let (border, border_var) = a.stats(0, 0, SIZE, 6);
    let (c0, c1) = (SIZE / 2 - 40, SIZE / 2 + 40);
    let (_, centre_var) = a.stats(c0, c0, c1, c1);
    let mut off_background = 0.0;
    for y in c0..c1 {
        for px in c0..c1 {
            let p = a.px(px, y);
            off_background += ((p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0 - border).abs();
        }
    }
    off_background /= ((c1 - c0) * (c1 - c0)) as f64;
    eprintln!(
        "border mean {border:.1} var {border_var:.1}; centre var {centre_var:.1}, \
         mean |centre - border| {off_background:.1}"
    );
    assert!(border_var < 50.0, "the border is not plain background");
    // The centre's variance is the phantom's structure (skin, vessels, texture), not
    // noise: the denoised view is smooth (measured 68 against the background's 0.1).
    assert!(
        off_background > 15.0 && centre_var > 4.0 * border_var + 20.0,
        "no volume in view"
    );

    // The UI: the panel's fill covers much of the panel region (text and widgets the
    // rest), and the panel is not the render.
    let mut fill = 0;
    let mut total = 0;
    for y in 0..SIZE {
        for px in SIZE + 4..SIZE + PANEL_WIDTH - 4 {
            total += 1;
            let p = a.px(px, y);
            if (0..3).all(|c| (p[c] as i32 - PANEL_FILL[c] as i32).abs() <= 3) {
                fill += 1;
            }
        }
    }
    assert!(
        fill * 4 > total,
        "panel colour on only {fill} of {total} pixels of the panel region"
    );
    let (_, panel_var) = a.stats(SIZE + 4, 0, SIZE + PANEL_WIDTH - 4, SIZE);
    assert!(panel_var > 1.0, "the panel shows no widgets or text");

    // A scripted drag at frame 5 orbits the camera by 1.5 rad: a different view.
    let b = explore_shot(&x, dir.path(), "b.png", &["--script", "orbit:150,20@5"]);
    let d = mean_abs_diff(&a, &b, SIZE, SIZE);
    assert!(
        d > 8.0,
        "the drag barely changed the view (mean |Δ| = {d:.2})"
    );
}

#[test]
fn a_clip_plane_and_a_crop_box_cut_into_the_view_and_c_switches_them_off() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    let plain = explore_shot(&x, dir.path(), "plain.png", &[]);
    // A plane facing the view is added, dragged back by script, and a crop box closes
    // in from the top: the near half of the phantom goes, its inside shows.
    let script =
        "clip:add@3;clip:offset:0.05@6;clip:offset:0.05@9;crop:on@12;crop:max:0.5,0.5,0.2@13";
    let cut = explore_shot(&x, dir.path(), "cut.png", &["--script", script]);
    let d_cut = mean_abs_diff(&plain, &cut, SIZE, SIZE);
    // C switches every cut off: the view returns to the plain one (up to the noise of
    // histories restarted by the switch).
    let off_script = format!("{script};key:c@16");
    let off = explore_shot(&x, dir.path(), "off.png", &["--script", &off_script]);
    let d_off = mean_abs_diff(&plain, &off, SIZE, SIZE);
    eprintln!("mean |Δ| plain vs cut {d_cut:.2}, plain vs switched off {d_off:.2}");
    assert!(d_cut > 8.0, "the cut barely changed the view ({d_cut:.2})");
    assert!(
        d_off < 0.5 * d_cut,
        "C did not switch the cut off ({d_off:.2})"
    );
}

#[test]
fn a_recorded_session_replays_to_the_same_frames() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    let rec = dir.path().join("rec");
    let out = dvr(
        Some(&x.display),
        &[
            "explore",
            "--scene",
            "phantom/orbit",
            "--size",
            "64x64",
            "--volume-size",
            "48",
            "--frames",
            "8",
            "--denoiser",
            "ours",
            "--record",
            rec.to_str().expect("utf-8"),
            "--script",
            "orbit:40,10@3;zoom:1@5;pan:6,-4@6",
        ],
        dir.path(),
    );
    assert_clean(&out);
    let session = rec.join("session.toml");
    assert!(session.is_file(), "no session.toml");
    let lines = std::fs::read_to_string(rec.join("state.jsonl")).expect("state.jsonl");
    assert_eq!(lines.lines().count(), 8);
    let cap = dir.path().join("cap");
    let replay = dvr(
        None,
        &[
            "capture",
            "--scene",
            session.to_str().expect("utf-8"),
            "--size",
            "64x64",
            "--volume-size",
            "48",
            "--denoiser",
            "ours",
            "--out",
            cap.to_str().expect("utf-8"),
        ],
        dir.path(),
    );
    assert_clean(&replay);
    for f in [0, 4, 7] {
        let name = format!("{f:04}.png");
        let a = Shot::open(&rec.join("frames").join(&name));
        let b = Shot::open(&cap.join("ours").join(&name));
        assert_eq!((a.width, a.height), (64, 64));
        let d = mean_abs_diff(&a, &b, 64, 64);
        assert!(
            d < 0.5,
            "frame {f}: replay differs from the session (mean |Δ| = {d:.3})"
        );
    }
    // The camera moved, so the frames before and after the drag differ.
    let first = Shot::open(&rec.join("frames").join("0000.png"));
    let last = Shot::open(&rec.join("frames").join("0007.png"));
    assert!(mean_abs_diff(&first, &last, 64, 64) > 2.0);
}

#[test]
fn a_moving_view_renders_fewer_pixels_and_the_full_size_returns_when_still() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    // A drag every frame from 6 to 10, F12 in the middle of it (frame 8) and after the
    // view has settled (frame 15). A 0.001 ms target puts any still frame slower than
    // 0.064 ms past 8² times it, so the motion renders at the largest divisor, 8: 16×16
    // for a 128² view (a 1 ms target chose 6 for a still frame under 36 ms).
    let out = dvr(
        Some(&x.display),
        &[
            "explore",
            "--scene",
            "phantom/orbit",
            "--size",
            "128x128",
            "--volume-size",
            "48",
            "--frames",
            "16",
            "--moving-ms",
            "0.001",
            "--script",
            "orbit:6,0@6;orbit:6,0@7;orbit:6,0@8;orbit:6,0@9;orbit:6,0@10;key:f12@8;key:f12@15",
        ],
        dir.path(),
    );
    assert_clean(&out);
    let stdout = String::from_utf8_lossy(&out.stdout);
    // Frames 6..=10 moving, 11 the slack frame, full size from 12 on; the summary
    // leaves out the first 5 (warm-up) and the last (no interval ends it).
    assert!(
        stdout.contains("by rendered size (--moving-ms): full size: 4 frames")
            && stdout.contains("1/8: 6 frames"),
        "{stdout}"
    );
    let exr_size = |name: &str| {
        let img = dvr_engine::image_io::read_exr(&dir.path().join(name))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        (img.width, img.height)
    };
    assert_eq!(
        exr_size("dvr-explore-0000.exr"),
        (16, 16),
        "mid-motion frame"
    );
    assert_eq!(
        exr_size("dvr-explore-0001.exr"),
        (128, 128),
        "settled frame"
    );
    // The window shows the upsampled frame over the whole 128² view (no pixel of the
    // view is the background the present pass gives pixels outside the frame), and the
    // same volume as the full-size frame after it.
    let moving = Shot::open(&dir.path().join("dvr-explore-0000.png"));
    let still = Shot::open(&dir.path().join("dvr-explore-0001.png"));
    assert_eq!((moving.width, moving.height), (128 + PANEL_WIDTH, 128));
    let outside = (0..128u32)
        .flat_map(|y| (0..128u32).map(move |px| (px, y)))
        .filter(|&(px, y)| moving.px(px, y) == PANEL_FILL)
        .count();
    assert_eq!(outside, 0, "{outside} view pixels show no frame");
    let (mean_moving, _) = moving.stats(32, 32, 96, 96);
    let (mean_still, _) = still.stats(32, 32, 96, 96);
    assert!(
        (mean_moving - mean_still).abs() < 25.0,
        "the moving frame ({mean_moving:.1}) is not the still one's volume ({mean_still:.1})"
    );

    // A frame time that is not one is refused, naming the option.
    let bad = dvr(
        Some(&x.display),
        &["explore", "--moving-ms", "nan"],
        dir.path(),
    );
    let err = String::from_utf8_lossy(&bad.stderr);
    assert_eq!(bad.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--moving-ms") && err.contains("not a frame time"),
        "{err}"
    );
}

#[test]
fn without_a_display_it_says_how_to_get_one() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dvr(None, &["explore", "--frames", "1"], dir.path());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert!(
        err.contains("needs a display") && err.contains("Xvfb :99"),
        "{err}"
    );
}

/// Pixels of the orientation cue's colour (a light blue, far from the volume's and the
/// background's greys) in a rectangle of a shot.
fn cue_pixels(s: &Shot, x0: u32, y0: u32, x1: u32, y1: u32) -> usize {
    let mut n = 0;
    for y in y0..y1 {
        for x in x0..x1 {
            let [r, g, b] = s.px(x, y);
            if b > 200 && i32::from(b) - i32::from(r) > 80 && g > 150 {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn the_view_shows_orientation_letters_and_a_scale_bar_that_follow_the_camera() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    // Key 1: the anterior view (R on the left edge); key 3: from the left (A there).
    let front = explore_shot(&x, dir.path(), "front.png", &["--script", "key:1@0"]);
    let side = explore_shot(&x, dir.path(), "side.png", &["--script", "key:3@0"]);
    let mid = SIZE / 2;
    for (name, s) in [("front", &front), ("side", &side)] {
        let left = cue_pixels(s, 0, mid - 14, 24, mid + 14);
        let right = cue_pixels(s, SIZE - 24, mid - 14, SIZE, mid + 14);
        let top = cue_pixels(s, mid - 14, 0, mid + 14, 30);
        let bar = cue_pixels(s, 0, SIZE - 50, 140, SIZE);
        eprintln!("{name}: cue pixels left {left}, right {right}, top {top}, scale bar {bar}");
        assert!(
            left > 5 && right > 5 && top > 5,
            "{name}: no letters at the edges"
        );
        assert!(bar > 40, "{name}: no scale bar");
    }
    // The left edge's letter changes with the view (R from the front, A from the left).
    let mut differ = 0;
    for y in mid - 14..mid + 14 {
        for px in 0..24 {
            differ += usize::from(front.px(px, y) != side.px(px, y));
        }
    }
    let letters_differ = (0..24)
        .flat_map(|px| (mid - 14..mid + 14).map(move |y| (px, y)))
        .filter(|&(px, y)| {
            let cue = |s: &Shot| cue_pixels(s, px, y, px + 1, y + 1) == 1;
            cue(&front) != cue(&side)
        })
        .count();
    assert!(
        differ > 0 && letters_differ > 5,
        "the left edge's letter is the same from the front and the side"
    );
}

#[test]
fn a_channel_switches_off_takes_a_tf_and_the_time_slider_scrubs_a_series() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    let scenes = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/scenes/development/");
    let head = format!("{scenes}mri-statmap-light.toml");
    let shot = |name: &str, scene: &str, script: &str| {
        let extra: Vec<&str> = if script.is_empty() {
            vec![]
        } else {
            vec!["--script", script]
        };
        explore_scene_shot(&x, dir.path(), name, scene, &extra)
    };
    let both = shot("both.png", &head, "");
    // The statistical map's clusters switched off: only they change.
    let off = shot("off.png", &head, "channel:1:off@3");
    let d_off = mean_abs_diff(&both, &off, SIZE, SIZE);
    // The T1 (channel 0) given the opaque cortex TF: the whole head changes.
    let tf = shot("tf.png", &head, "channel:0:select@2;tf:mri-opaque@3");
    let d_tf = mean_abs_diff(&both, &tf, SIZE, SIZE);
    // A quarter beat later the shell is at its largest (times 0 and 12 are both at its
    // mean size).
    let shell = format!("{scenes}shell-beat-still.toml");
    let t0 = shot("t0.png", &shell, "");
    let t6 = shot("t6.png", &shell, "time:6@3");
    let d_time = mean_abs_diff(&t0, &t6, SIZE, SIZE);
    eprintln!("mean |Δ|: channel off {d_off:.2}, channel TF {d_tf:.2}, time 0 -> 6 {d_time:.2}");
    assert!(
        d_off > 0.3,
        "switching the map off barely changed the view ({d_off:.2})"
    );
    assert!(
        d_tf > 3.0,
        "the channel's TF barely changed the view ({d_tf:.2})"
    );
    assert!(
        d_time > 0.5,
        "scrubbing the time barely changed the view ({d_time:.2})"
    );
}

#[test]
fn labels_hide_and_take_a_colour_and_a_click_picks_the_label_under_it() {
    let Some(x) = xvfb() else { return };
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/scenes/development/phantom-labels-skull-orbit.toml"
    );
    let run = |name: &str, script: &str| {
        let extra: Vec<&str> = if script.is_empty() {
            vec![]
        } else {
            vec!["--script", script]
        };
        explore_run(&x, dir.path(), name, scene, "20", &extra)
    };
    let (all, _) = run("all.png", "");
    // The scalp and skull hidden, the vessels green, then a click at the view's centre.
    let (edited, stdout) = run(
        "edited.png",
        "label:1:off@2;label:2:off@2;label:5:colour:0,1,0@3;pick:128,128@6;pick:2,2@7",
    );
    let d = mean_abs_diff(&all, &edited, SIZE, SIZE);
    eprintln!("mean |Δ| with the scalp and skull hidden: {d:.2}\n{stdout}");
    assert!(
        d > 1.0,
        "hiding two labels barely changed the view ({d:.2})"
    );
    let picked = stdout
        .lines()
        .find(|l| l.starts_with("pick (128, 128): label"))
        .unwrap_or_else(|| panic!("no pick line:\n{stdout}"));
    // Inside the open head the ray meets the brain, its ventricles or a vessel: never
    // the hidden scalp or skull.
    assert!(
        [
            "label 3 \"brain\"",
            "label 4 \"ventricles\"",
            "label 5 \"vessels\""
        ]
        .iter()
        .any(|l| picked.contains(l)),
        "{picked}"
    );
    assert!(
        stdout.contains("pick (2, 2): nothing"),
        "a corner of the view meets nothing:\n{stdout}"
    );
}
