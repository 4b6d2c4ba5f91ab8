//! On a static view a temporal estimator may only get better: `ours` on the validation
//! set's 1-spp, six-bounce view through a faint, mostly transparent TF (heavy-tailed
//! noise; nothing moves for 64 frames), through the built binary's `dvr eval` at 32×32 (as
//! tests/lag.rs)
//! against 256-spp references. Its mean PSNR over frames 32–63 is at least its mean over
//! frames 8–31, and after frame 8 no frame falls more than 0.5 dB below the best so far.
//! (The scene is judged, not tuned on: this checks a property every estimator that only
//! averages more samples has.)

mod common;

use std::path::Path;

const FRAMES: u32 = 64;
const MARGIN_DB: f64 = 0.5;

#[test]
fn ours_never_gets_worse_on_a_static_view() {
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/static/mri-faint-static.toml");
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("static_view");
    let scene = scene.to_str().expect("utf-8 path");
    let by_frame = common::eval::run_eval(
        &[
            "--scene",
            scene,
            "--size",
            "32x32",
            "--ref-spp",
            "256",
            "--denoiser",
            "ours",
        ],
        &out,
    );
    let psnr: Vec<f64> = (0..FRAMES)
        .map(|f| {
            by_frame
                .get(&("ours".to_string(), f))
                .copied()
                .unwrap_or(f64::NAN)
        })
        .collect();
    assert!(psnr.iter().all(|p| p.is_finite()), "{psnr:?}");
    let mean = |r: std::ops::Range<usize>| psnr[r.clone()].iter().sum::<f64>() / r.len() as f64;
    let (early, late) = (mean(8..32), mean(32..64));
    println!("ours on a static view: mean PSNR frames 8-31 {early:.2} dB, 32-63 {late:.2} dB");
    assert!(late >= early, "ours got worse: {early:.2} -> {late:.2} dB");
    let mut best = psnr[8];
    for (f, &p) in psnr.iter().enumerate().skip(8) {
        assert!(
            p >= best - MARGIN_DB,
            "frame {f}: {p:.2} dB, {:.2} dB below the best so far ({best:.2})",
            best - p
        );
        best = best.max(p);
    }
}
