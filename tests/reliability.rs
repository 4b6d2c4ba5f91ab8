//! The `dvr` binary against failures a user can meet, each reproduced as a user would:
//! stale or corrupt cached references reused, a panic on `--ref-spp 0`, lights dropped,
//! warnings never shown, nonsense accepted with exit 0, script in a scene name running
//! in the capture page, and exit statuses that meant two things. Small: 32×24, a few
//! frames, a 16³ volume.

use std::path::Path;
use std::process::{Command, Output};

fn dvr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(args)
        .env("DVR_VALIDATION", "1")
        .env_remove("DVR_LOG")
        .output()
        .expect("run dvr")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn assert_status(o: &Output, code: i32) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(code), "stderr:\n{err}");
    assert!(!err.contains("panicked"), "panicked:\n{err}");
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p.to_str().expect("utf-8 path").to_string()
}

const TF: &str = "[[point]]\ndensity = 0.0\nopacity = 0.0\ndiffuse = [0.9, 0.9, 0.9]\n\
                  [[point]]\ndensity = 1.0\nopacity = OPACITY\ndiffuse = [0.9, 0.9, 0.9]\n";

/// A cloud scene whose TF is the file `tf.toml` beside it.
fn scene_with_tf_file(dir: &Path, opacity: f64) -> String {
    write(dir, "tf.toml", &TF.replace("OPACITY", &opacity.to_string()));
    write(
        dir,
        "scene.toml",
        "name = \"tf-file\"\n[volume]\nbuiltin = \"cloud\"\nsize = 16\n[transfer]\na = \"tf.toml\"\n\
         [[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 10\n\
         [animation]\nframes = 2\n",
    )
}

fn reference(scene: &str, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "reference",
        "--scene",
        scene,
        "--ref-spp",
        "4",
        "--size",
        "32x24",
        "--out",
        out.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    dvr(&args)
}

/// Defects 1, 2 and 6: a TF edit used to reuse the old references ("reusing 2
/// reference frame(s)"); a cached EXR cut to 0 bytes used to be "reused" and then fail
/// every run; the warning about it must reach the user, and `--quiet` silences it.
#[test]
fn references_follow_content_and_corrupt_frames_are_rendered_again() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let out = d.join("out");
    let scene = scene_with_tf_file(d, 0.8);
    assert_status(&reference(&scene, &out, &[]), 0);
    let frame0 = out.join("reference/0000.exr");
    let dense = std::fs::read(&frame0).expect("frame 0");
    assert!(out.join("reference/reference.json").is_file());

    // Same key: reused.
    let o = reference(&scene, &out, &[]);
    assert_status(&o, 0);
    assert!(
        stderr(&o).contains("reusing 2 reference frame(s)"),
        "{}",
        stderr(&o)
    );

    // The TF file edited, the scene text unchanged: re-rendered, and the image changes.
    scene_with_tf_file(d, 0.05);
    let o = reference(&scene, &out, &[]);
    assert_status(&o, 0);
    let err = stderr(&o);
    assert!(!err.contains("reusing"), "{err}");
    assert!(
        err.contains("volume, transfer function or environment map changed"),
        "{err}"
    );
    assert_ne!(std::fs::read(&frame0).expect("frame 0"), dense);

    // A frame cut to 0 bytes: a warning, re-rendered, exit 0.
    std::fs::write(&frame0, b"").expect("truncate");
    let o = reference(&scene, &out, &[]);
    assert_status(&o, 0);
    let err = stderr(&o);
    assert!(
        err.contains("dvr: warning:") && err.contains("0000.exr") && err.contains("re-rendering"),
        "{err}"
    );
    assert!(std::fs::metadata(&frame0).expect("frame 0").len() > 0);

    // --quiet: the same repair, no warning.
    std::fs::write(&frame0, b"").expect("truncate");
    let o = reference(&scene, &out, &["--quiet"]);
    assert_status(&o, 0);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    assert!(std::fs::metadata(&frame0).expect("frame 0").len() > 0);
}

/// Defect 3 and 9: `--ref-spp 0` panicked (exit 101) and left a header-only EXR; bad
/// values on the command line are usage errors (2), not the validation status.
#[test]
fn usage_errors_exit_2_and_leave_nothing_behind() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out");
    let o = reference("cloud/orbit", &out, &["--ref-spp", "0"]);
    assert_status(&o, 2);
    assert!(stderr(&o).contains("--ref-spp"), "{}", stderr(&o));
    assert!(!out.exists(), "nothing written");
    for args in [
        &["capture", "--size", "0x0"][..],
        &["capture", "--motion", "banana"],
        &["capture", "--spp", "0"],
        &["capture", "--frames", "0"],
        &["eval", "--ref-spp", "0"],
        &["demo", "--ref-spp", "0"],
        &["bench", "--ref-spp", "0"],
        &["bench", "--frames", "0"],
        &["nonsense"],
    ] {
        let o = dvr(args);
        assert_status(&o, 2);
    }
}

/// Defects 4, 7 and 8: five lights rendered four lights' worth; intensity 1e300
/// rendered black with exit 0; a scene name with a script ran in the capture page.
#[test]
fn nonsense_scenes_fail_and_names_are_escaped() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let light = "[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 10\n";
    let base = "[volume]\nbuiltin = \"cloud\"\nsize = 16\n[transfer]\na = \"cloud\"\n";
    let capture = |scene: &str| {
        dvr(&[
            "capture",
            "--scene",
            scene,
            "--frames",
            "1",
            "--size",
            "32x24",
            "--denoiser",
            "none",
            "--out",
            d.join("cap").to_str().expect("utf-8"),
        ])
    };
    let five = write(d, "five.toml", &format!("{base}{}", light.repeat(5)));
    let o = capture(&five);
    assert_status(&o, 1);
    assert!(stderr(&o).contains("five.toml") && stderr(&o).contains("at most 4"));

    let bright = write(
        d,
        "bright.toml",
        &format!(
            "{base}{}",
            light.replace("intensity = 10", "intensity = 1e300")
        ),
    );
    let o = capture(&bright);
    assert_status(&o, 1);
    assert!(stderr(&o).contains("light[0].intensity"), "{}", stderr(&o));

    let evil = write(
        d,
        "evil.toml",
        &format!("name = \"</h1><script>alert('x')</script>\"\n{base}{light}"),
    );
    assert_status(&capture(&evil), 0);
    let page = std::fs::read_to_string(d.join("cap/index.html")).expect("page");
    assert!(
        !page.contains("<script>alert"),
        "unescaped name in the page"
    );
    assert!(
        page.contains("&lt;script&gt;alert(&#39;x&#39;)"),
        "the name, escaped"
    );
}

/// A `dvr` child with piped output, for tests that signal or time it.
fn spawn(args: &[&str], envs: &[(&str, &str)]) -> std::process::Child {
    let mut c = Command::new(env!("CARGO_BIN_EXE_dvr"));
    c.args(args)
        .env("DVR_VALIDATION", "1")
        .env_remove("DVR_LOG")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped());
    for (k, v) in envs {
        c.env(k, v);
    }
    c.spawn().expect("starting dvr")
}

/// Waits at most `limit` for `child`; a child still running then is killed and the
/// test fails (the defects these tests reproduce hung).
fn wait_within(mut child: std::process::Child, limit: std::time::Duration) -> Output {
    let start = std::time::Instant::now();
    while child.try_wait().expect("waiting").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let o = child.wait_with_output().expect("output");
            panic!("dvr ran past {limit:?}; stderr:\n{}", stderr(&o));
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.wait_with_output().expect("output")
}

/// `dvr eval` of two 12×10 frames of cloud/orbit with 4-spp references into `out`.
fn tiny_eval(out: &Path) -> Vec<&str> {
    let mut args = vec![
        "eval",
        "--scene",
        "cloud/orbit",
        "--volume-size",
        "16",
        "--frames",
        "2",
        "--size",
        "12x10",
        "--ref-spp",
        "4",
        "--denoiser",
        "none",
        "--out",
    ];
    args.push(out.to_str().expect("utf-8"));
    args
}

fn profile_args<'a>(json: &'a str, trace: &'a str, frames: &'a str) -> Vec<&'a str> {
    vec![
        "profile",
        "--scene",
        "cloud/orbit",
        "--volume-size",
        "16",
        "--size",
        "16x16",
        "--frames",
        frames,
        "--denoiser",
        "none",
        "--json",
        json,
        "--trace",
        trace,
    ]
}

/// Reliability round 2, defect 1: `--trace /dev/full` replaced the device node with a
/// regular file, `--json link.json` replaced the link, a FIFO was replaced. Now a
/// link is written through and anything but a regular file or a new path is refused
/// before the run, by name; nothing is replaced.
#[test]
fn outputs_write_through_links_and_refuse_devices_fifos_and_sockets() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let p = |n: &str| d.join(n).to_str().expect("utf-8").to_string();
    std::fs::write(d.join("real.json"), "{}").expect("write");
    std::os::unix::fs::symlink("real.json", d.join("link.json")).expect("symlink");
    assert_status(&dvr(&profile_args(&p("link.json"), &p("t.json"), "3")), 0);
    let written = std::fs::read_to_string(d.join("real.json")).expect("read");
    assert!(
        written.contains("frames_rendered"),
        "written through: {written}"
    );
    assert!(std::fs::symlink_metadata(d.join("link.json"))
        .expect("meta")
        .file_type()
        .is_symlink());

    let ok = Command::new("mkfifo")
        .arg(d.join("fifo"))
        .status()
        .expect("mkfifo");
    assert!(ok.success());
    let _socket = std::os::unix::net::UnixListener::bind(d.join("socket")).expect("bind");
    let mut kinds = vec![("fifo", "named pipe"), ("socket", "socket")];
    // A character device made here (root may: c 1 7 is /dev/full's numbers).
    let made = Command::new("mknod")
        .arg(d.join("full"))
        .args(["c", "1", "7"])
        .status()
        .is_ok_and(|s| s.success());
    if made {
        kinds.push(("full", "character device"));
    }
    for (name, what) in kinds {
        let o = dvr(&profile_args(&p("j.json"), &p(name), "3"));
        assert_status(&o, 1);
        let err = stderr(&o);
        assert!(
            err.contains(&p(name)) && err.contains(what),
            "{name}: {err}"
        );
        let t = std::fs::symlink_metadata(d.join(name))
            .expect("still there")
            .file_type();
        assert!(!t.is_file(), "{name} was replaced by a regular file");
        assert!(!d.join("j.json").exists(), "refused before the run");
    }
}

/// Reliability round 2: Ctrl-C on a long `dvr profile` threw every measurement away.
/// Now SIGINT or SIGTERM stops it after the frame in flight, the JSON and trace hold
/// the statistics so far, marked as interrupted, and the exit status is the signal's.
#[test]
fn a_signalled_profile_writes_what_it_measured() {
    let dir = tempfile::tempdir().expect("temp dir");
    for (signal, code) in [("INT", 130), ("TERM", 143)] {
        let json = dir.path().join(format!("{signal}.json"));
        let trace = dir.path().join(format!("{signal}-trace.json"));
        let (j, t) = (
            json.to_str().expect("utf-8"),
            trace.to_str().expect("utf-8"),
        );
        let child = spawn(&profile_args(j, t, "1000000"), &[]);
        std::thread::sleep(std::time::Duration::from_secs(5));
        let sent = Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .expect("kill");
        assert!(sent.success());
        let o = wait_within(child, std::time::Duration::from_secs(60));
        assert_status(&o, code);
        assert!(
            stderr(&o).contains(&format!("SIG{signal}")),
            "{}",
            stderr(&o)
        );
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parse");
        let why = report["interrupted"]
            .as_str()
            .expect("marked as interrupted");
        assert!(why.contains(&format!("SIG{signal}")), "{why}");
        assert!(report["frames_rendered"].as_u64().expect("frames") > 0);
        let trace: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&trace).expect("trace")).expect("parse");
        assert!(trace["metadata"]["interrupted"].is_string());
        assert!(!trace["traceEvents"].as_array().expect("events").is_empty());
    }
}

/// Reliability round 2, defect 2: `DVR_FONT=/dev/zero` grew by 1 GB/s until killed; a
/// text file given as the font passed without a word. Both are now warnings naming the
/// file, and the usual fonts are used.
#[test]
fn a_font_that_is_not_one_is_a_warning_not_a_hang() {
    let dir = tempfile::tempdir().expect("temp dir");
    let text = dir.path().join("font.ttf");
    std::fs::write(&text, "not a font\n").expect("write");
    let out = dir.path().join("eval");
    for (font, says) in [
        ("/dev/zero", "character device"),
        (
            text.to_str().expect("utf-8"),
            "not a TrueType or OpenType font",
        ),
    ] {
        let child = spawn(&tiny_eval(&out), &[("DVR_FONT", font)]);
        let o = wait_within(child, std::time::Duration::from_secs(120));
        assert_status(&o, 0);
        let err = stderr(&o);
        assert!(
            err.contains(&format!("DVR_FONT={font}")) && err.contains(says),
            "{font}: {err}"
        );
    }
}

/// Reliability round 2: `DVR_WRLS=kappa=nan` was refused only when the method was
/// built, after the references; an empty `--denoiser` entry is a usage error (2).
#[test]
fn bad_overrides_fail_before_rendering_and_empty_entries_are_usage_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("eval");
    let args = tiny_eval(&out);
    for (var, value, says) in [
        ("DVR_WRLS", "lambda=nan", "lambda must be in"),
        ("DVR_OURS", "jump_z=1e30", "jump_z must be in"),
        ("DVR_SVGF", "sigma_l=-1", "sigma_l must be in"),
    ] {
        let o = wait_within(
            spawn(&args, &[(var, value)]),
            std::time::Duration::from_secs(60),
        );
        assert_status(&o, 1);
        assert!(stderr(&o).contains(says), "{var}={value}: {}", stderr(&o));
        assert!(
            !out.join("cloud_orbit/reference").exists(),
            "refused before rendering"
        );
    }
    for list in ["none,,ours", "none,", ","] {
        let o = dvr(&["capture", "--denoiser", list, "--frames", "1"]);
        assert_status(&o, 2);
    }
    // The explorer's split-view form is checked while parsing too (before a window).
    for view in ["foo", "ours,foo", "ours,svgf,taa", "ours,"] {
        let o = dvr(&["explore", "--denoiser", view, "--frames", "1"]);
        assert_status(&o, 2);
    }
}

/// Reliability round 3: `DVR_WRLS=atrous_keep=nan dvr capture --denoiser ours` ran, exit
/// 0, without a word: an override of a method that does not run is said so, naming the
/// variable and the methods it applies to.
#[test]
fn overrides_of_methods_that_do_not_run_are_warnings_naming_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("capture");
    let args = [
        "capture",
        "--scene",
        "cloud/orbit",
        "--frames",
        "1",
        "--size",
        "8x8",
        "--denoiser",
        "taa",
        "--out",
        out.to_str().expect("utf-8 path"),
    ];
    for (var, value, readers) in [
        ("DVR_WRLS", "atrous_keep=nan", "wrls-paper"),
        ("DVR_OURS", "lag_z=3", "ours-no-gradient"),
        ("DVR_SVGF", "sigma_l=8", "svgf"),
    ] {
        let o = wait_within(
            spawn(&args, &[(var, value)]),
            std::time::Duration::from_secs(120),
        );
        assert_status(&o, 0);
        let err = stderr(&o);
        assert!(
            err.contains(&format!("{var} is set but no method it applies to runs"))
                && err.contains(readers)
                && err.contains("running: taa"),
            "{var}: {err}"
        );
    }
    // A method that reads it runs: no warning.
    let mut with_svgf = args;
    with_svgf[8] = "svgf";
    let o = wait_within(
        spawn(&with_svgf, &[("DVR_SVGF", "sigma_l=8")]),
        std::time::Duration::from_secs(120),
    );
    assert_status(&o, 0);
    assert!(!stderr(&o).contains("is set but"), "{}", stderr(&o));

    // An eval renders its references in sessions of their own, which run no denoiser:
    // the run speaks for the methods it was asked for, once, not for each session.
    let eval_dir = dir.path().join("eval");
    for (method, warnings) in [("ours", 0), ("taa", 1)] {
        let mut eval_args = tiny_eval(&eval_dir);
        eval_args[12] = method;
        let o = wait_within(
            spawn(&eval_args, &[("DVR_OURS", "lag_z=3")]),
            std::time::Duration::from_secs(300),
        );
        assert_status(&o, 0);
        let err = stderr(&o);
        assert_eq!(
            err.matches("DVR_OURS is set but").count(),
            warnings,
            "{method}: {err}"
        );
        if warnings > 0 {
            assert!(err.contains(&format!("running: {method}")), "{err}");
        }
    }
    // `dvr reference` runs no denoiser: said once.
    let reference_dir = dir.path().join("reference");
    let reference_args = [
        "reference",
        "--scene",
        "cloud/orbit",
        "--volume-size",
        "16",
        "--frames",
        "1",
        "--size",
        "8x8",
        "--ref-spp",
        "4",
        "--out",
        reference_dir.to_str().expect("utf-8 path"),
    ];
    let o = wait_within(
        spawn(&reference_args, &[("DVR_OURS", "lag_z=3")]),
        std::time::Duration::from_secs(120),
    );
    assert_status(&o, 0);
    assert_eq!(
        stderr(&o).matches("DVR_OURS is set but").count(),
        1,
        "{}",
        stderr(&o)
    );
}
