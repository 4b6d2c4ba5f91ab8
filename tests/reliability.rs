//! The `dvr` binary against the failures of issue 14, each reproduced as a user met it:
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
