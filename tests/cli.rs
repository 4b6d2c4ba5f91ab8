//! The `dvr` binary end to end, as a user runs it: capture, reference and profile write
//! what they promise with the validation layer on, and bad input gets a clear error that
//! names the file or value, never a panic.

use std::path::Path;
use std::process::{Command, Output};

fn dvr(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(args)
        .env("DVR_VALIDATION", "1")
        .output()
        .expect("run dvr")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn assert_ok(o: &Output) {
    assert!(
        o.status.success(),
        "dvr failed ({:?}):\n{}",
        o.status.code(),
        stderr(o)
    );
}

/// Fails with exit status 1 and a message containing every one of `needles`.
fn assert_error(o: &Output, needles: &[&str]) {
    let err = stderr(o);
    assert_eq!(
        o.status.code(),
        Some(1),
        "expected a clean error exit, got:\n{err}"
    );
    assert!(!err.contains("panicked"), "panicked:\n{err}");
    for n in needles {
        assert!(err.contains(n), "message should mention {n:?}:\n{err}");
    }
}

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

/// Every file of `dir`, by name, with its bytes.
fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .expect("reading the folder")
        .map(|e| {
            let p = e.expect("entry").path();
            let name = p.file_name().expect("name").to_string_lossy().into_owned();
            (name, std::fs::read(&p).expect("reading"))
        })
        .collect();
    out.sort();
    out
}

/// The references the shard tests split: 5 frames of a small scene.
const SHARDED_REFERENCE: [&str; 11] = [
    "reference",
    "--scene",
    "cloud/orbit",
    "--frames",
    "5",
    "--size",
    "12x10",
    "--volume-size",
    "16",
    "--ref-spp",
    "8",
];

#[test]
fn sharded_references_write_the_bytes_of_one_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (one, sharded) = (tmp.path().join("one"), tmp.path().join("sharded"));
    let with = |out: &Path, extra: &[&str]| {
        let mut args: Vec<String> = SHARDED_REFERENCE.iter().map(|s| s.to_string()).collect();
        args.extend(["--out".into(), out.to_str().expect("utf-8").to_string()]);
        args.extend(extra.iter().map(|s| s.to_string()));
        args
    };
    let run = |args: Vec<String>| dvr(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_ok(&run(with(&one, &[])));
    // Three shards at once on one folder, as separate processes (a job array).
    let children: Vec<_> = (0..3)
        .map(|i| {
            Command::new(env!("CARGO_BIN_EXE_dvr"))
                .args(with(&sharded, &["--shard", &format!("{i}/3")]))
                .env("DVR_VALIDATION", "1")
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("starting a shard")
        })
        .collect();
    for c in children {
        assert_ok(&c.wait_with_output().expect("running a shard"));
    }
    let (a, b) = (
        files(&one.join("reference")),
        files(&sharded.join("reference")),
    );
    assert_eq!(
        a.len(),
        12,
        "5 frames × EXR + PNG, the key and the folder's lock"
    );
    assert!(a == b, "sharded files differ from one run's");

    // A range selects its frames only; past the animation is an error naming it, a
    // malformed shard a usage error.
    let part = tmp.path().join("part");
    assert_ok(&run(with(&part, &["--frame-range", "1..3"])));
    let names: Vec<String> = files(&part.join("reference"))
        .into_iter()
        .map(|(n, _)| n)
        .collect();
    assert_eq!(
        names,
        [
            ".lock",
            "0001.exr",
            "0001.png",
            "0002.exr",
            "0002.png",
            "reference.json"
        ]
    );
    assert_error(
        &run(with(&part, &["--frame-range", "2..9"])),
        &["--frame-range 2..9", "5 frame(s)"],
    );
    for bad in ["3/3", "1/0", "x"] {
        let o = run(with(&part, &["--shard", bad]));
        assert_eq!(o.status.code(), Some(2), "--shard {bad}: {}", stderr(&o));
    }
}

/// Runs `dvr` with `common`, `--out out` and `extra`.
fn dvr_with(common: &[&str], out: &Path, extra: &[&str]) -> Output {
    let mut args = common.to_vec();
    args.extend(["--out", out.to_str().expect("utf-8")]);
    args.extend_from_slice(extra);
    dvr(&args)
}

#[test]
fn verify_names_missing_and_corrupt_reference_frames_and_a_rerun_refills_them() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (one, sharded) = (tmp.path().join("one"), tmp.path().join("sharded"));
    let common = SHARDED_REFERENCE;
    let verify = |out: &Path| dvr_with(&common, out, &["--verify"]);
    assert_error(
        &verify(&one),
        &["5 frame(s) missing", "no reference rendered yet"],
    );
    assert!(!one.exists(), "--verify renders and creates nothing");
    assert_ok(&dvr_with(&common, &one, &[]));
    assert_ok(&verify(&one));
    // Three shards one after another, as a job array on one machine, each saying
    // which frames it rendered.
    for i in 0..3 {
        let report = tmp.path().join(format!("shard{i}.json"));
        let shard = format!("{i}/3");
        let r = report.to_str().expect("utf-8");
        assert_ok(&dvr_with(
            &common,
            &sharded,
            &["--shard", &shard, "--report", r],
        ));
        let json = std::fs::read_to_string(&report).expect("the report");
        let expect: Vec<u32> = (i..5).step_by(3).collect();
        let rendered = format!("\"rendered\": {}", serde_json_list(&expect));
        assert!(
            json.replace([' ', '\n'], "")
                .contains(&rendered.replace(' ', "")),
            "shard {i} rendered {expect:?}: {json}"
        );
    }
    assert!(files(&one.join("reference")) == files(&sharded.join("reference")));
    // A frame gone and one cut short: both named, and only they are rendered again.
    let dir = sharded.join("reference");
    std::fs::remove_file(dir.join("0003.png")).expect("removing");
    std::fs::write(dir.join("0001.exr"), b"v/1\x01").expect("cutting");
    let o = verify(&sharded);
    assert_error(
        &o,
        &[
            "0003.png: missing",
            "0001.exr: does not read back",
            "2 problem(s)",
        ],
    );
    assert!(
        !stderr(&o).contains("0002"),
        "only the broken frames: {}",
        stderr(&o)
    );
    let o = dvr_with(&common, &sharded, &[]);
    assert_ok(&o);
    let said = String::from_utf8_lossy(&o.stdout).into_owned();
    assert!(said.contains("2 rendered, 3 already there"), "{said}");
    assert_ok(&verify(&sharded));
    assert!(files(&one.join("reference")) == files(&sharded.join("reference")));
    // Other settings: every frame is named as missing.
    let mut fewer = common;
    fewer[4] = "4";
    let o = dvr_with(&fewer, &sharded, &["--verify"]);
    assert_error(&o, &["4 frame(s) missing", "other settings"]);
}

/// `[a, b]` as JSON writes it.
fn serde_json_list(v: &[u32]) -> String {
    let items: Vec<String> = v.iter().map(u32::to_string).collect();
    format!("[{}]", items.join(","))
}

/// Each line of a CSV without its last `drop` columns (the measured GPU times).
fn csv_without_times(path: &Path, drop: usize) -> Vec<String> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .lines()
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            cells[..cells.len() - drop].join(",")
        })
        .collect()
}

#[test]
fn a_sharded_eval_merges_into_the_reports_of_one_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (one, sharded) = (tmp.path().join("one"), tmp.path().join("sharded"));
    let common = [
        "eval",
        "--scene",
        "cloud/orbit,phantom/tf-sweep,cloud/point-light",
        "--frames",
        "4",
        "--size",
        "16x12",
        "--volume-size",
        "16",
        "--ref-spp",
        "8",
        "--denoiser",
        "none,ours,svgf",
    ];
    assert_ok(&dvr_with(&common, &one, &[]));
    assert_ok(&dvr_with(&common, &one, &["--verify"]));
    // References in 5 shards (a unit per frame: 12 over 3 scenes), then the scenes in
    // 2, then the merge.
    for i in 0..5 {
        let shard = format!("{i}/5");
        assert_ok(&dvr_with(
            &common,
            &sharded,
            &["--references-only", "--shard", &shard],
        ));
    }
    assert_ok(&dvr_with(
        &common,
        &sharded,
        &["--references-only", "--verify"],
    ));
    assert_error(
        &dvr_with(&common, &sharded, &["--verify"]),
        &["result.json: missing", "3 problem(s)"],
    );
    assert_ok(&dvr_with(&common, &sharded, &["--shard", "1/2"]));
    assert!(
        !sharded.join("metrics.csv").exists(),
        "a shard leaves the reports to --merge"
    );
    let o = dvr_with(&common, &sharded, &["--merge"]);
    assert_error(&o, &["2 of 3 scene(s)", "cloud_orbit/result.json: missing"]);
    assert_ok(&dvr_with(&common, &sharded, &["--shard", "0/2"]));
    assert_ok(&dvr_with(&common, &sharded, &["--merge"]));
    for scene in ["cloud_orbit", "phantom_tf-sweep", "cloud_point-light"] {
        for folder in ["reference", "none", "ours", "svgf"] {
            assert!(
                files(&one.join(scene).join(folder)) == files(&sharded.join(scene).join(folder)),
                "{scene}/{folder} differs from one run's"
            );
        }
    }
    // The scores are one run's to the last digit; GPU times are measured anew.
    for (csv, times) in [("metrics.csv", 1), ("summary.csv", 2), ("baseline.csv", 2)] {
        assert_eq!(
            csv_without_times(&one.join(csv), times),
            csv_without_times(&sharded.join(csv), times),
            "{csv}"
        );
    }
    assert!(sharded.join("index.html").is_file());
    // A result made under other settings is not merged.
    let o = dvr_with(&common, &sharded, &["--merge", "--spp", "1"]);
    assert_error(&o, &["made under other settings", "spp"]);
}

/// `dvr reference` on a small scene into `out` with `spp` samples (more args after).
fn reference_args(out: &Path, spp: u32, frames: u32) -> Vec<String> {
    let mut args: Vec<String> = [
        "reference",
        "--scene",
        "cloud/orbit",
        "--size",
        "12x10",
        "--volume-size",
        "16",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    args.extend(["--frames".into(), frames.to_string()]);
    args.extend(["--ref-spp".into(), spp.to_string()]);
    args.extend(["--out".into(), out.to_str().expect("utf-8").to_string()]);
    args
}

fn spawn_dvr(args: &[String]) -> std::process::Child {
    Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(args)
        .env("DVR_VALIDATION", "1")
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("starting dvr")
}

/// The files of a reference folder without its lock and run records.
fn frames_and_key(dir: &Path) -> Vec<(String, Vec<u8>)> {
    files(dir)
        .into_iter()
        .filter(|(n, _)| !n.starts_with('.'))
        .collect()
}

/// Defect (reliability round 2): two runs with different settings on one `--out` mixed
/// their frames under one key. Now a run claims the folder: while a live run with other
/// settings holds it, a run is refused, naming the folder and the other run; equal
/// settings share it; a dead run's claim is cleared.
#[test]
fn a_reference_folder_is_never_shared_by_runs_with_other_settings() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let out = tmp.path().join("c");
    let run = |args: Vec<String>| dvr(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_ok(&run(reference_args(&out, 8, 3)));
    let dir = out.join("reference");
    let single = frames_and_key(&dir);
    assert!(
        files(&dir).iter().all(|(n, _)| !n.starts_with(".run-")),
        "a finished run leaves no claim"
    );

    // A live run holding the folder with 8 spp, as a run file locked by this process.
    let key: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("reference.json")).expect("key"))
            .expect("key json");
    let held = dir.join(".run-424242-0.json");
    std::fs::write(
        &held,
        serde_json::json!({ "pid": 424242, "key": key }).to_string(),
    )
    .expect("run file");
    let lock = std::fs::File::open(&held).expect("open");
    lock.lock().expect("lock");
    let refused = run(reference_args(&out, 4, 3));
    assert_error(
        &refused,
        &[
            dir.to_str().expect("utf-8"),
            "in use by another dvr run (pid 424242",
            "8 spp",
            "4 spp",
        ],
    );
    assert_eq!(
        frames_and_key(&dir),
        single,
        "the refused run changed nothing"
    );
    // Equal settings share the folder.
    assert_ok(&run(reference_args(&out, 8, 3)));
    // The holder dies (its lock goes): its file is stale, removed by the next claim.
    drop(lock);
    assert_ok(&run(reference_args(&out, 4, 3)));
    assert!(!held.exists(), "a dead run's claim is cleared");
    let fresh = tmp.path().join("fresh");
    assert_ok(&run(reference_args(&fresh, 4, 3)));
    assert!(frames_and_key(&dir) == frames_and_key(&fresh.join("reference")));

    // Two runs with different settings started together: whichever claims first
    // renders, the other is refused (or runs after it); either way every frame in the
    // folder is the one its key describes.
    let both = tmp.path().join("both");
    let children = [
        spawn_dvr(&reference_args(&both, 16, 6)),
        spawn_dvr(&reference_args(&both, 4, 6)),
    ];
    let outputs: Vec<Output> = children
        .into_iter()
        .map(|c| c.wait_with_output().expect("running dvr"))
        .collect();
    for o in &outputs {
        assert!(
            o.status.success() || stderr(o).contains("in use by another dvr run"),
            "{}",
            stderr(o)
        );
    }
    let key: serde_json::Value =
        serde_json::from_slice(&std::fs::read(both.join("reference/reference.json")).expect("key"))
            .expect("key json");
    let spp = key["ref_spp"].as_u64().expect("ref_spp") as u32;
    let alone = tmp.path().join(format!("alone{spp}"));
    assert_ok(&run(reference_args(&alone, spp, 6)));
    assert!(
        frames_and_key(&both.join("reference")) == frames_and_key(&alone.join("reference")),
        "the folder holds frames of another key than its own ({spp} spp)"
    );

    // Two identical runs at once: the bytes of one run.
    let twins = tmp.path().join("twins");
    let children = [
        spawn_dvr(&reference_args(&twins, 4, 6)),
        spawn_dvr(&reference_args(&twins, 4, 6)),
    ];
    for c in children {
        assert_ok(&c.wait_with_output().expect("running dvr"));
    }
    let alone4 = if spp == 4 {
        alone.clone()
    } else {
        tmp.path().join("alone4")
    };
    if spp != 4 {
        assert_ok(&run(reference_args(&alone4, 4, 6)));
    }
    assert!(frames_and_key(&twins.join("reference")) == frames_and_key(&alone4.join("reference")));
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
