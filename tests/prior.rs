//! ours' spatial prior's combination helps where histories are young and costs little
//! where they are long: `ours` against `ours-no-prior` (the same filter without the
//! combination; its à-trous still carries by the prior's model) on the phantom under an
//! orbiting camera (the thin vessels and the shell's rim are in the guide albedo), and on
//! the static MRI view (heavy-tailed noise, the albedo explains little), through the
//! built binary's `dvr eval` at 32×32 against 256-spp references.

mod common;

use std::collections::HashMap;
use std::path::Path;

fn eval(scene: &str, frames: &str) -> HashMap<(String, u32), f64> {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("prior")
        .join(scene.replace(['/', '.'], "_"));
    common::eval::run_eval(
        &[
            "--scene",
            scene,
            "--frames",
            frames,
            "--size",
            "32x32",
            "--ref-spp",
            "256",
            "--denoiser",
            "ours,ours-no-prior",
        ],
        &out,
    )
}

fn mean(psnr: &HashMap<(String, u32), f64>, method: &str, frames: std::ops::Range<u32>) -> f64 {
    let n = frames.len() as f64;
    frames.map(|f| psnr[&(method.to_string(), f)]).sum::<f64>() / n
}

#[test]
fn the_prior_lifts_young_estimates_on_the_phantom() {
    let psnr = eval("phantom/orbit", "16");
    assert!(psnr.values().all(|p| p.is_finite()), "{psnr:?}");
    let (with, without) = (
        mean(&psnr, "ours", 0..4),
        mean(&psnr, "ours-no-prior", 0..4),
    );
    let (with_late, without_late) = (
        mean(&psnr, "ours", 4..16),
        mean(&psnr, "ours-no-prior", 4..16),
    );
    println!(
        "phantom/orbit, frames 0-3: ours {with:.2} dB, without the prior {without:.2}; \
         frames 4-15: {with_late:.2} / {without_late:.2}"
    );
    assert!(
        with >= without + 1.0,
        "frames 0-3: {with:.2} vs {without:.2} dB"
    );
    assert!(
        with_late >= without_late,
        "frames 4-15: {with_late:.2} vs {without_late:.2} dB"
    );
}

#[test]
fn the_prior_costs_nothing_on_a_long_static_history() {
    let scene =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/scenes/static/mri-faint-static.toml");
    let psnr = eval(scene.to_str().expect("utf-8 path"), "48");
    let (with, without) = (
        mean(&psnr, "ours", 32..48),
        mean(&psnr, "ours-no-prior", 32..48),
    );
    println!("static MRI, frames 32-47: ours {with:.2} dB, without the prior {without:.2}");
    // Measured: 34.89 against 35.35 dB. The combination costs here: faint pixels whose
    // estimates are long but still noisy (relative standard error above `keep`) are
    // pulled towards the window's linear model, whose residual V understates its bias on
    // the folds. A known weakness of ours (the book's experiments page); the bound keeps
    // it from growing.
    assert!(
        with >= without - 0.5,
        "frames 32-47: {with:.2} vs {without:.2} dB"
    );
}
