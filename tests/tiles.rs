//! The à-trous levels of ours and SVGF read their window through workgroup shared memory on
//! GPUs and straight from memory on lavapipe (include/atrous_tile.glsl). Both paths must
//! give the same output, bit for bit: run `dvr capture` both ways on lavapipe (forced by
//! `DVR_SHARED_TILES`) and compare every EXR frame. The size is not a multiple of the
//! 8×8 workgroup, so partial groups and windows over the image's edge are covered, and
//! five SVGF levels cover tiled steps (1, 2, 4) and direct ones (8, 16).

use std::path::Path;
use std::process::{Command, Output};

fn capture(tiles: &str, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dvr"))
        .env("DVR_SHARED_TILES", tiles)
        .args([
            "capture",
            "--scene",
            "mri/point-light",
            "--frames",
            "5",
            "--size",
            "50x37",
            "--denoiser",
            "ours,svgf",
            "--out",
        ])
        .arg(out)
        .output()
        .expect("running dvr")
}

#[test]
fn shared_memory_tiles_change_no_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (direct, tiled) = (dir.path().join("direct"), dir.path().join("tiled"));
    for (tiles, out) in [("0", &direct), ("1", &tiled)] {
        let o = capture(tiles, out);
        assert!(
            o.status.success(),
            "dvr capture with DVR_SHARED_TILES={tiles} failed:\n{}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let mut compared = 0;
    for method in ["ours", "svgf"] {
        for frame in 0..5 {
            let name = format!("{method}/{frame:04}.exr");
            let a = std::fs::read(direct.join(&name)).expect("direct frame");
            let b = std::fs::read(tiled.join(&name)).expect("tiled frame");
            assert!(a == b, "{name}: the shared-memory tiles changed the output");
            compared += 1;
        }
    }
    assert_eq!(compared, 10);
}

#[test]
fn a_bad_tiles_setting_is_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let o = capture("yes", dir.path());
    assert!(!o.status.success(), "DVR_SHARED_TILES=yes was accepted");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("DVR_SHARED_TILES") && err.contains("yes"),
        "the error does not name the setting: {err}"
    );
}
