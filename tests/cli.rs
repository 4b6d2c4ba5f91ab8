//! The `dvr` binary end to end, as a user runs it: capture, reference and profile write
//! what they promise with the validation layer on, and bad input gets a clear error that
//! names the file or value, never a panic.

mod common;

use common::cli::{assert_error, assert_ok, dvr, stderr};
use std::path::Path;
use std::process::Command;

const SMALL: &[&str] = &["--frames", "3", "--size", "32x24", "--volume-size", "32"];

#[test]
fn capture_writes_frames_timings_and_page_for_every_denoiser() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("cap");
    let mut args = vec![
        "capture",
        "--scene",
        "cloud/orbit",
        "--denoiser",
        "none,accum,ours,svgf",
    ];
    args.extend_from_slice(SMALL);
    args.extend_from_slice(&["--out", out.to_str().expect("utf-8 path")]);
    assert_ok(&dvr(&args));
    for m in ["none", "accum", "ours", "svgf"] {
        for f in 0..3 {
            for ext in ["exr", "png"] {
                let p = out.join(m).join(format!("{f:04}.{ext}"));
                assert!(p.is_file(), "missing {}", p.display());
            }
        }
        let png = image::open(out.join(m).join("0002.png")).expect("png decodes");
        assert_eq!((png.width(), png.height()), (32, 24));
    }
    let timings: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("timings.json")).expect("timings"))
            .expect("timings.json parses");
    let frames = timings["frames"].as_array().expect("frames");
    assert_eq!(frames.len(), 3);
    let passes: Vec<&str> = frames[2]
        .as_array()
        .expect("passes")
        .iter()
        .filter_map(|p| p["pass"].as_str())
        .collect();
    // ours and svgf read the guides: one march renders them with the surface features.
    assert!(!passes.contains(&"surface_features"), "{passes:?}");
    for want in [
        "aux_features",
        "path_trace",
        "motion",
        "accum",
        "ours.update",
        "ours.atrous1",
        "svgf.atrous4",
    ] {
        assert!(passes.contains(&want), "no timing for {want}: {passes:?}");
    }
    assert!(out.join("index.html").is_file());
}

#[test]
fn profile_prints_a_table_and_writes_json_and_a_chrome_trace() {
    let dir = tempfile::tempdir().expect("temp dir");
    let json = dir.path().join("p.json");
    let trace = dir.path().join("t.json");
    let o = dvr(&[
        "profile",
        "--scene",
        "phantom/orbit",
        "--frames",
        "6",
        "--size",
        "32x32",
        "--volume-size",
        "32",
        "--denoiser",
        "ours,taa",
        "--json",
        json.to_str().expect("utf-8"),
        "--trace",
        trace.to_str().expect("utf-8"),
    ]);
    assert_ok(&o);
    let table = String::from_utf8_lossy(&o.stdout);
    for row in ["path_trace", "ours.update", "total", "p95"] {
        assert!(table.contains(row), "table lacks {row}:\n{table}");
    }
    let p: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).expect("json")).expect("parses");
    assert!(p["total"]["mean_ms"].as_f64().expect("mean") > 0.0);
    for row in ["MB", "GB/s", "% peak", "peak bandwidth"] {
        assert!(table.contains(row), "table lacks {row}:\n{table}");
    }
    // Every pass carries its declared bytes, bandwidth and share of the measured peak.
    assert!(p["peak_bandwidth"]["gb_per_s"].as_f64().expect("peak") > 0.0);
    let update = p["passes"]
        .as_array()
        .expect("passes")
        .iter()
        .find(|r| r["pass"] == "ours.update")
        .expect("ours.update row");
    assert!(update["bytes"].as_f64().expect("bytes") > 0.0);
    assert!(update["gb_per_s"].as_f64().expect("GB/s") > 0.0);
    assert!(update["percent_of_peak"].as_f64().expect("% of peak") > 0.0);
    assert_eq!(p["frames_rendered"], 6);
    // Each denoiser's cost counts the features it reads: the surface features for both
    // (taa reprojects with them), the guides for ours alone, rendered by one march that
    // both pay for (each would pay for its own march alone).
    let pass_ms = |name: &str| {
        p["passes"]
            .as_array()
            .expect("passes")
            .iter()
            .find(|r| r["pass"] == name)
            .expect(name)["mean_ms"]
            .as_f64()
            .expect("ms")
    };
    let methods = p["methods"].as_array().expect("methods");
    let row = |m: &str| methods.iter().find(|r| r["method"] == m).expect(m);
    let (ours, taa) = (row("ours"), row("taa"));
    let needed = |r: &serde_json::Value| r["needed_ms"].as_f64().expect("needed_ms");
    let features = pass_ms("aux_features");
    assert!((needed(taa) - features).abs() < 1e-9, "{taa}");
    assert!((needed(ours) - features).abs() < 1e-9, "{ours}");
    assert!(!p["passes"]
        .as_array()
        .expect("passes")
        .iter()
        .any(|r| r["pass"] == "surface_features"));
    for r in [ours, taa] {
        let cost = r["cost_ms"].as_f64().expect("cost_ms");
        assert!((cost - needed(r) - r["own_ms"].as_f64().expect("own")).abs() < 1e-9);
        assert!(r["dispatches"].as_f64().expect("dispatches") >= 2.0, "{r}");
        assert!(r["bytes_per_pixel"].as_f64().expect("bytes") > 0.0, "{r}");
    }
    assert!(table.contains("bytes/pixel"), "{table}");
    let t: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&trace).expect("trace")).expect("parses");
    let events = t["traceEvents"].as_array().expect("events");
    assert!(events.len() >= 6 * 4);
    assert!(events.iter().all(|e| e["args"]["bytes"].is_u64()));
}

#[test]
fn reference_writes_one_exr_per_frame() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut args = vec![
        "reference",
        "--scene",
        "mri/area-light",
        "--ref-spp",
        "8",
        "--out",
        dir.path().to_str().expect("utf-8"),
    ];
    args.extend_from_slice(SMALL);
    assert_ok(&dvr(&args));
    for f in 0..3 {
        assert!(dir
            .path()
            .join("reference")
            .join(format!("{f:04}.exr"))
            .is_file());
    }
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write");
    p.to_str().expect("utf-8").to_string()
}

#[test]
fn bad_inputs_get_clear_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let run = |scene: &str| {
        dvr(&[
            "capture",
            "--scene",
            scene,
            "--frames",
            "1",
            "--size",
            "8x8",
            "--out",
            d.join("o").to_str().expect("utf-8"),
        ])
    };

    // A scene file that is not TOML.
    let bad = write(d, "broken.toml", "[volume\nbuiltin = ");
    assert_error(&run(&bad), &["broken.toml"]);

    // A raw volume shorter than its dims say.
    let raw = d.join("short.raw");
    std::fs::write(&raw, vec![0u8; 100]).expect("write raw");
    let scene = write(
        d,
        "short.toml",
        "[volume]\nfile = \"short.raw\"\ndims = [8, 8, 8]\nformat = \"u8\"\n[transfer]\na = \"cloud\"\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 1.0\n",
    );
    assert_error(&run(&scene), &["short.raw", "512"]);

    // A float volume with NaN.
    let nan = d.join("nan.raw");
    let mut bytes = Vec::new();
    for i in 0..8u32 {
        let v = if i == 5 { f32::NAN } else { 0.5 };
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    std::fs::write(&nan, bytes).expect("write raw");
    let scene = write(
        d,
        "nan.toml",
        "[volume]\nfile = \"nan.raw\"\ndims = [2, 2, 2]\nformat = \"f32\"\n[transfer]\na = \"cloud\"\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 1.0\n",
    );
    assert_error(&run(&scene), &["nan.raw", "NaN"]);

    // An unknown built-in scene, a missing file, an unknown denoiser, an absurd size.
    assert_error(&run("nowhere/orbit"), &["nowhere/orbit"]);
    let o = dvr(&[
        "capture",
        "--scene",
        "cloud/orbit",
        "--frames",
        "1",
        "--size",
        "8x8",
        "--volume-size",
        "16",
        "--denoiser",
        "magic",
        "--out",
        d.join("o").to_str().expect("utf-8"),
    ]);
    // A usage error (exit 2, as clap's own), with the names that exist.
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("magic") && err.contains("ours") && !err.contains("panicked"),
        "{err}"
    );
    assert!(
        !d.join("o").exists(),
        "a usage error creates no output folder"
    );
    let o = dvr(&["capture", "--size", "0x5"]);
    assert!(
        !o.status.success() && stderr(&o).contains("0x5"),
        "{}",
        stderr(&o)
    );

    // A malformed TF file referenced by a scene.
    write(
        d,
        "bad-tf.toml",
        "name = \"x\"\n[[point]]\ndensity = 0.5\nopacity = 2.0\ndiffuse = [1, 1, 1]\n",
    );
    let scene = write(
        d,
        "tf.toml",
        "[volume]\nbuiltin = \"cloud\"\nsize = 16\n[transfer]\na = \"bad-tf.toml\"\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 1.0\n",
    );
    assert_error(&run(&scene), &["bad-tf.toml"]);
}

#[test]
fn reference_samples_come_from_ref_spp() {
    // `dvr reference --spp 512` means a 512-spp reference: the answer names --ref-spp
    // (whether the command line or dvr rejects it).
    let o = dvr(&[
        "reference",
        "--spp",
        "512",
        "--frames",
        "1",
        "--size",
        "8x8",
    ]);
    let err = stderr(&o);
    assert!(!o.status.success() && !err.contains("panicked"), "{err}");
    assert!(
        err.contains("--ref-spp"),
        "should point to --ref-spp:\n{err}"
    );
}

#[test]
fn a_missing_device_is_reported_clearly() {
    let o = Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args([
            "capture",
            "--frames",
            "1",
            "--size",
            "8x8",
            "--volume-size",
            "16",
        ])
        .env("DVR_DEVICE", "no-such-gpu-9000")
        .output()
        .expect("run dvr");
    assert_error(&o, &["no-such-gpu-9000", "matches no Vulkan device"]);
}

/// A NIfTI-1 file of `t` time points of `c` channels of 2×2×2 uint8 voxels (voxel i of
/// volume v holds 30 i + v), no orientation.
fn nifti_4d(path: &Path, t: i16, c: i16) {
    let mut h = vec![0u8; 352];
    let put = |h: &mut Vec<u8>, at: usize, b: &[u8]| h[at..at + b.len()].copy_from_slice(b);
    put(&mut h, 0, &348i32.to_le_bytes());
    for (i, d) in [5i16, 2, 2, 2, t, c, 1, 1].iter().enumerate() {
        put(&mut h, 40 + 2 * i, &d.to_le_bytes());
    }
    put(&mut h, 70, &2i16.to_le_bytes());
    put(&mut h, 72, &8i16.to_le_bytes());
    for i in 0..8 {
        put(&mut h, 76 + 4 * i, &1f32.to_le_bytes());
    }
    put(&mut h, 108, &352f32.to_le_bytes());
    h[123] = 2;
    put(&mut h, 344, b"n+1\0");
    for v in 0..(t * c) as u8 {
        h.extend((0..8u8).map(|i| 30 * i + v));
    }
    std::fs::write(path, h).expect("write nifti");
}

#[test]
fn info_prints_a_series_channels_and_time_points() {
    let dir = tempfile::tempdir().expect("tempdir");
    let file = dir.path().join("fmri.nii");
    nifti_4d(&file, 3, 2);
    let path = file.to_str().expect("utf-8 path");
    let out = dvr(&["info", path, "--json"]);
    assert_ok(&out);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(info["dims"], serde_json::json!([2, 2, 2]));
    assert_eq!(info["times"], 3);
    assert_eq!(info["channels"].as_array().map(Vec::len), Some(2));
    assert_eq!(
        info["to_patient"][3],
        serde_json::json!([0.0, 0.0, 0.0, 1.0])
    );
    // A selection, in its order; the text form names the channels.
    let out = dvr(&["info", path, "--channels", "1"]);
    assert_ok(&out);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("time points 3") && text.contains("channel 1"),
        "{text}"
    );
    let out = dvr(&["info", path, "--channels", "0,5"]);
    assert_error(&out, &["fmri.nii", "channel 5 is out of range"]);
    let many = dir.path().join("many.nii");
    nifti_4d(&many, 1, 5);
    let out = dvr(&["info", many.to_str().expect("utf-8 path")]);
    assert_error(&out, &["many.nii", "5 channels", "channels = [0, 2]"]);
}

#[test]
fn info_lists_a_label_maps_labels_named_by_its_table() {
    let volumes = concat!(env!("CARGO_MANIFEST_DIR"), "/assets/volumes/");
    let map = format!("{volumes}mni152_labels.nii.gz");
    let table = format!("{volumes}mni152_labels.label");
    let out = dvr(&["info", &map, "--labels", "--label-table", &table, "--json"]);
    assert_ok(&out);
    let info: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let labels = info["labels"].as_array().expect("labels");
    let names: Vec<&str> = labels.iter().filter_map(|l| l["name"].as_str()).collect();
    assert_eq!(
        names,
        vec!["White matter", "Grey matter", "Rest of the brain"]
    );
    assert_eq!(labels[0]["colour"], "F5F0E1");
    assert!(labels.iter().all(|l| l["voxels"].as_u64() > Some(100_000)));
    // Without a table, palette colours and numbered names.
    let out = dvr(&["info", &map, "--labels"]);
    assert_ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("1: label 1"));
    // A float map is no label map; a bad table names its line.
    let out = dvr(&[
        "info",
        &format!("{volumes}mni152_statmap.nii.gz"),
        "--labels",
    ]);
    assert_error(&out, &["mni152_statmap.nii.gz", "float32", "integers"]);
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.ctbl");
    std::fs::write(&bad, "# table\n1 wm 300 0 0 255\n").expect("write");
    let out = dvr(&[
        "info",
        &map,
        "--labels",
        "--label-table",
        bad.to_str().expect("utf-8"),
    ]);
    assert_error(&out, &["bad.ctbl", "line 2", "R \"300\""]);
}
