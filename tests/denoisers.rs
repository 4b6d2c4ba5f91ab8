//! Denoiser properties on synthetic input (static scene, exact control over the noisy
//! frames): no NaN/Inf and bounded output over a long static run (P wind-up), wRLS's
//! robustness to spikes compared with plain RLS, convergence on a static input, and a
//! sudden change followed within a few frames.

mod common;

use common::harness::{noisy_frame, Harness};
use common::*;

const W: u32 = 16;
const H: u32 = 16;

fn finite_and_bounded(out: &[[f32; 4]], bound: f32) -> bool {
    out.iter().all(|p| {
        p[..3]
            .iter()
            .all(|c| c.is_finite() && *c >= 0.0 && *c <= bound)
    })
}

#[test]
fn long_static_runs_stay_finite_and_bounded_for_every_temporal_method() {
    for name in [
        "ours",
        "wrls-paper",
        "rls-paper",
        "wrls",
        "rls",
        "wrls-nf",
        "rls-nf",
        "accum",
        "taa",
        "svgf",
    ] {
        let mut h = Harness::new(name, W, H);
        let n = (W * H) as usize;
        for f in 0..2000u64 {
            let out = h.step(&noisy_frame(n, 1.0, 0.5, f));
            assert!(
                finite_and_bounded(&out, 100.0),
                "{name}: non-finite or unbounded output at frame {f}"
            );
        }
    }
    assert_validation_clean();
}

fn spike_response(name: &str) -> f32 {
    let mut h = Harness::new(name, W, H);
    let n = (W * H) as usize;
    let mut before = Vec::new();
    for f in 0..40u64 {
        before = h.step(&noisy_frame(n, 1.0, 0.3, f));
    }
    let mut spiky = noisy_frame(n, 1.0, 0.3, 40);
    let spikes = [(3usize, 4usize), (10, 7), (12, 12)];
    for &(x, y) in &spikes {
        spiky[y * W as usize + x] = [100.0, 80.0, 60.0, 1.0];
    }
    let after = h.step(&spiky);
    spikes
        .iter()
        .map(|&(x, y)| {
            let i = y * W as usize + x;
            (after[i][0] - before[i][0]).abs()
        })
        .sum::<f32>()
        / spikes.len() as f32
}

#[test]
fn weighted_rls_gives_spikes_far_less_influence_than_rls() {
    let wrls = spike_response("wrls");
    let rls = spike_response("rls");
    println!("mean output change at 100× spikes: wrls {wrls:.4}, rls {rls:.4}");
    assert!(
        wrls * 5.0 < rls,
        "wrls {wrls} vs rls {rls}: weighting should suppress spikes"
    );
    let ours_nf = spike_response("wrls-nf");
    let rls_nf = spike_response("rls-nf");
    println!("without the feature: wrls-nf {ours_nf:.4}, rls-nf {rls_nf:.4}");
    assert!(ours_nf * 5.0 < rls_nf);
    assert_validation_clean();
}

#[test]
fn ours_converges_on_a_static_input() {
    let mut h = Harness::new("ours", W, H);
    let n = (W * H) as usize;
    let mut out = Vec::new();
    for f in 0..64u64 {
        out = h.step(&noisy_frame(n, 1.0, 0.5, 1000 + f));
    }
    // Single-frame noise has standard deviation 0.5/√3 ≈ 0.29 in red.
    let rmse = (out.iter().map(|p| (p[0] - 1.0).powi(2)).sum::<f32>() / n as f32).sqrt();
    println!("ours after 64 static frames: RMSE {rmse:.4} (input 0.289)");
    assert!(rmse < 0.289 / 4.0, "RMSE {rmse}");
    assert_validation_clean();
}

/// How far `ours` strays at pixels that see a firefly (a 100× sample) in `repeats`
/// successive frames of a static input, five frames after the last: the largest relative
/// error of those pixels' output.
fn firefly_error(repeats: u64) -> f32 {
    let mut h = Harness::new("ours", W, H);
    let n = (W * H) as usize;
    for f in 0..40u64 {
        h.step(&noisy_frame(n, 1.0, 0.3, 4000 + f));
    }
    let spikes = [(3usize, 4usize), (10, 7), (12, 12)];
    let mut out = Vec::new();
    for f in 0..repeats + 5 {
        let mut frame = noisy_frame(n, 1.0, 0.3, 4100 + f);
        if f < repeats {
            for &(x, y) in &spikes {
                frame[y * W as usize + x] = [100.0, 100.0, 100.0, 1.0];
            }
        }
        out = h.step(&frame);
    }
    spikes
        .iter()
        .map(|&(x, y)| (out[y * W as usize + x][0] - 1.0).abs())
        .fold(0.0, f32::max)
}

#[test]
fn ours_does_not_follow_isolated_fireflies_in_successive_frames() {
    // Heavy-tailed noise puts bright paths in one pixel two or three frames in a row now
    // and then; a jump is a change its neighbourhood shares, so these stay clipped.
    let errors: Vec<f32> = (1..=3).map(firefly_error).collect();
    println!("largest relative error 5 frames after 1, 2, 3 fireflies in a row: {errors:?}");
    for (k, e) in errors.iter().enumerate() {
        assert!(*e < 0.5, "{} firefly frame(s): error {e}", k + 1);
    }
    assert_validation_clean();
}

/// Frames after a step in the input (mean 1 → 3) until the output's mean is within 5%.
fn step_recovery(name: &str) -> usize {
    let mut h = Harness::new(name, W, H);
    let n = (W * H) as usize;
    for f in 0..60u64 {
        h.step(&noisy_frame(n, 1.0, 0.5, 2000 + f));
    }
    for k in 0..200usize {
        let out = h.step(&noisy_frame(n, 3.0, 1.5, 3000 + k as u64));
        let mean = out.iter().map(|p| p[0]).sum::<f32>() / n as f32;
        if (mean - 3.0).abs() < 0.15 {
            return k + 1;
        }
    }
    usize::MAX
}

#[test]
fn ours_follows_a_sudden_change_within_a_few_frames() {
    let ours = step_recovery("ours");
    let no_lag = step_recovery("ours-no-lag");
    let paper = step_recovery("wrls-paper");
    println!("frames to within 5% after a 3× step: ours {ours}, without the lag test {no_lag}, paper {paper}");
    assert!(ours <= 8, "ours took {ours} frames");
    assert_validation_clean();
}
