//! The one-call GPU benchmark (`tools/gpu-bench.sh` around `dvr bench`) at tiny sizes on
//! whatever device there is (lavapipe in CI), so it cannot rot before a GPU runs it.

use std::path::Path;
use std::process::Command;

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

#[test]
fn gpu_bench_writes_one_small_folder_and_a_tarball() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("bench");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tools/gpu-bench.sh");
    let o = Command::new("bash")
        .arg(&script)
        .args(["--out", out.to_str().expect("utf-8")])
        .args(["--bin", env!("CARGO_BIN_EXE_dvr")])
        .args([
            "--",
            "--sizes",
            "16x16,24x16",
            "--frames",
            "3",
            "--volume-size",
            "16",
            "--denoiser",
            "none,taa,svgf,ours",
            "--eval-scene",
            "phantom/orbit,cloud/area-light",
            "--eval-size",
            "16x16",
            "--eval-frames",
            "2",
            "--ref-spp",
            "4",
        ])
        .env("DVR_VALIDATION", "1")
        .output()
        .expect("run tools/gpu-bench.sh");
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "gpu-bench failed:\n{stderr}");

    for file in [
        "bench.json",
        "profile.csv",
        "methods.csv",
        "profile_16x16.json",
        "profile_16x16.svg",
        "profile_24x16.png",
        "eval/metrics.csv",
        "eval/summary.csv",
        "eval/baseline.csv",
        "eval/speed_accuracy.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing:\n{stderr}");
    }
    // The eval's images stay outside the folder to bring back.
    assert!(!out.join("eval/phantom_orbit").exists());
    assert!(dir.path().join("bench-eval/phantom_orbit/ours").is_dir());
    assert!(dir.path().join("bench.tar.gz").is_file());

    let profile = read(&out.join("profile.csv"));
    assert!(profile.starts_with("size,pass,mean_ms,median_ms,p95_ms,mb,gb_per_s,percent_of_peak"));
    assert!(
        profile.lines().any(|l| l.starts_with("24x16,ours.update,")),
        "{profile}"
    );
    let methods = read(&out.join("methods.csv"));
    for m in ["none", "taa", "svgf", "ours"] {
        assert!(methods.contains(&format!("16x16,{m},")), "{methods}");
    }
    let bench: serde_json::Value =
        serde_json::from_str(&read(&out.join("bench.json"))).expect("bench.json parses");
    assert!(bench["peak_bandwidth"]["gb_per_s"].as_f64().expect("peak") > 0.0);
    assert!(bench["eval"]["timing"]["gpu_s"].as_f64().expect("GPU time") > 0.0);
    assert!(bench["eval"]["wall_over_gpu"].as_f64().expect("ratio") > 0.0);
    // 2 scenes × 4 methods × 2 frames.
    assert_eq!(read(&out.join("eval/metrics.csv")).lines().count(), 1 + 16);
}
