//! The built binary's `dvr eval`, as the tests that judge per-frame curves run it.

use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

/// Runs the built `dvr` with `args` (the subcommand first) and `--out out`; fails the
/// test with dvr's stderr unless it exits 0 (with `DVR_VALIDATION=1` a validation
/// message makes it exit 3).
pub fn dvr_ok(args: &[&str], out: &Path) -> Output {
    let o = Command::new(env!("CARGO_BIN_EXE_dvr"))
        .args(args)
        .arg("--out")
        .arg(out)
        .output()
        .expect("running dvr");
    assert!(
        o.status.success(),
        "dvr {args:?} failed ({:?}):\n{}",
        o.status.code(),
        String::from_utf8_lossy(&o.stderr)
    );
    o
}

/// Runs `dvr eval` with `args` into `out` (cleared first: every test run renders its own
/// references) and returns each (method, frame)'s PSNR from its metrics.csv; fails the
/// test with dvr's stderr if the eval fails.
pub fn run_eval(args: &[&str], out: &Path) -> HashMap<(String, u32), f64> {
    if out.exists() {
        std::fs::remove_dir_all(out).expect("clearing the old output");
    }
    dvr_ok(&[&["eval"], args].concat(), out);
    let csv = std::fs::read_to_string(out.join("metrics.csv")).expect("metrics.csv");
    let mut psnr = HashMap::new();
    for line in csv.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let frame: u32 = f[2].parse().expect("frame");
        psnr.insert((f[1].to_string(), frame), f[3].parse().expect("psnr"));
    }
    psnr
}
