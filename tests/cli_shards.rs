//! `dvr reference` and `dvr eval` split over machines, as a user runs them: shards write
//! the bytes of one run, `--verify` names what is missing, `--merge` makes the reports of
//! one run, and a reference folder is never shared by runs with other settings.

mod common;

use common::cli::{assert_error, assert_ok, dvr, stderr};
use std::path::Path;
use std::process::{Command, Output};

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
