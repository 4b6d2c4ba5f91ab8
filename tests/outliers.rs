//! No filter leaves isolated outliers: on two suite scenes at the suite's 64×64 against
//! 1024-spp references (12 frames: the animations run at four times the suite's speed),
//! every registered method but the two that show the noisy input itself (`none`, and
//! `accum`, which restarts on every change) keeps its share of pixels whose error
//! exceeds K times the median error of their 5×5 window (and FLOOR in display units:
//! visible) at or below the scene's bound, averaged over the frames after the first
//! few. Through the built binary's `dvr eval`, so the frames are the ones it reports.
//!
//! The bounds, from this test's own setting (frames 4–11):
//! - phantom/orbit, 1.5%: svgf demodulated by the threshold surface's albedo turned the
//!   phantom's thin vessels into dark red dots, 1.69% (commit 311d772's binary); with
//!   the composited albedo 1.11%, now the highest; ours 0.03%, the RAE 0.01%, the noisy
//!   input 0.20%.
//! - mri/point-light, 2.5%: the paper's per-pixel models without a spatial filter keep
//!   fireflies at the cortex's edge (wrls-paper 1.95%, rls-paper 2.00%; neither the
//!   paper nor Falcor's SVGF clamps fireflies, so no method here does); svgf 1.15%,
//!   ours 0.23%; the noisy input 5.0%.

mod common;

use dvr_engine::metrics::{outlier_fraction, Rgb32Image};
use std::path::Path;

const K: f32 = 4.0;
const FLOOR: f32 = 0.1;
/// Each scene's folder and its bound (see the module's comment).
const SCENES: [(&str, f64); 2] = [("phantom_orbit", 0.015), ("mri_point-light", 0.025)];
/// Methods whose output is the noisy input: what they show is the input's noise.
const UNFILTERED: [&str; 2] = ["none", "accum"];
const FRAMES: u32 = 12;
const FIRST_CHECKED_FRAME: u32 = 4;

fn png(path: &Path) -> Rgb32Image {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8();
    Rgb32Image::from_srgb8(img.width(), img.height(), img.as_raw())
}

#[test]
fn no_method_leaves_isolated_outliers() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("outliers");
    let methods: Vec<&str> = dvr_engine::denoise::registry::names().collect();
    common::eval::run_eval(
        &[
            "--scene",
            "phantom/orbit,mri/point-light",
            "--frames",
            &FRAMES.to_string(),
            "--size",
            "64x64",
            "--ref-spp",
            "1024",
            "--denoiser",
            &methods.join(","),
        ],
        &out,
    );
    let mut failures = Vec::new();
    let mut table = String::new();
    for (scene, bound) in SCENES {
        let dir = out.join(scene);
        for m in methods.iter().filter(|m| !UNFILTERED.contains(m)) {
            let shares: Vec<f64> = (FIRST_CHECKED_FRAME..FRAMES)
                .map(|f| {
                    let name = format!("{f:04}.png");
                    let r = png(&dir.join("reference").join(&name));
                    outlier_fraction(&png(&dir.join(m).join(&name)), &r, K, FLOOR)
                })
                .collect();
            let mean = shares.iter().sum::<f64>() / shares.len() as f64;
            table.push_str(&format!("{scene} {m}: {:.3}%\n", 100.0 * mean));
            if mean > bound {
                failures.push(format!(
                    "{scene} {m}: {:.3}% > {:.1}%",
                    100.0 * mean,
                    100.0 * bound
                ));
            }
        }
    }
    eprintln!("{table}");
    assert!(
        failures.is_empty(),
        "isolated outliers: {failures:?}\n{table}"
    );
}
