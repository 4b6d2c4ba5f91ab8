//! Each ablation of ours switches exactly one stage off, checked by behaviour: a base
//! (ours, or the ablation that differs from it in that stage alone) and the ablation run
//! in one renderer on the same noisy frames, and the stages' images
//! (`Renderer::read_back_images`: the filter's state, its running residual, the pooled lag
//! test, the prior's prediction and combination, the first à-trous level) are compared bit
//! for bit, frame by frame. What the switched stage does not reach must be identical; what
//! it does must differ, and only where it acted. The feedback carries the first à-trous
//! level, and with it the prior's combination, into the states that restarted: the state
//! is then downstream of every spatial stage. The young-pixel network, on the first
//! frame, reaches only that frame's output.

mod common;

use common::*;
use dvr_engine::renderer::FrameRequest;
use std::collections::HashMap;

const SIZE: u32 = 32;
const FRAMES: u32 = 10;
/// The stages read back, by the suffix of their graph image's name.
const STAGES: [&str; 5] = ["model", "residual", "lag", "prior_pred", "prior"];

type Pixels = Vec<[f32; 4]>;
/// One frame of a run: image name → pixels (the methods' outputs under their own names),
/// and whether ours traced temporal gradients in it.
struct Frame {
    images: HashMap<String, Pixels>,
    gradients: bool,
}

type Run = Vec<Frame>;

fn frame(done: dvr_engine::renderer::FrameResult) -> Frame {
    Frame {
        gradients: done.timings.iter().any(|t| t.pass == "ours.gradient"),
        images: done.images.into_iter().collect(),
    }
}

/// `base` and `ablation` on `scene`, every stage of both read back in every frame, and
/// `extra` images (full names) besides.
fn run(scene: &str, base: &str, ablation: &str, extra: &[&str]) -> Run {
    let setup = builtin_setup(scene, FRAMES, SIZE);
    let mut r = setup
        .renderer(context(), &[base, ablation])
        .expect("renderer");
    let names: Vec<String> = [base, ablation]
        .iter()
        .flat_map(|m| STAGES.iter().map(move |s| format!("{m}.{s}")))
        .chain(extra.iter().map(|e| e.to_string()))
        .collect();
    r.read_back_images(&names.iter().map(String::as_str).collect::<Vec<_>>());
    let request = FrameRequest {
        readback: true,
        ..Default::default()
    };
    let mut frames = Vec::new();
    for f in 0..FRAMES {
        if let Some(done) = r.frame(&setup.frame_inputs(f), &request).expect("frame") {
            frames.push(frame(done));
        }
    }
    frames.extend(r.flush().expect("flush").into_iter().map(frame));
    assert_eq!(frames.len(), FRAMES as usize);
    frames
}

/// Whether `stage` of `base` and of `ablation` are bit-identical in frame `f`.
fn same(run: &Run, f: usize, base: &str, ablation: &str, stage: &str) -> bool {
    let key = |m: &str| {
        if stage.is_empty() {
            m.to_string()
        } else {
            format!("{m}.{stage}")
        }
    };
    let (a, b) = (&run[f].images[&key(base)], &run[f].images[&key(ablation)]);
    a.iter().zip(b).all(|(p, q)| bits(p) == bits(q))
}

fn bits(p: &[f32; 4]) -> [u32; 4] {
    p.map(f32::to_bits)
}

fn assert_same(
    run: &Run,
    (base, ablation): (&str, &str),
    stage: &str,
    frames: std::ops::Range<usize>,
) {
    for f in frames {
        assert!(
            same(run, f, base, ablation, stage),
            "{ablation}: stage {stage:?} differs from {base}'s in frame {f}"
        );
    }
}

fn differs_somewhere(run: &Run, base: &str, ablation: &str, stage: &str) -> bool {
    (0..run.len()).any(|f| !same(run, f, base, ablation, stage))
}

/// Whether `method`'s state at pixel `i` of frame `f` is its first à-trous level's
/// estimate (the feedback wrote it), with `variance` kept.
fn fed_back(run: &Run, f: usize, method: &str, i: usize, variance: f32) -> bool {
    let state = run[f].images[&format!("{method}.model")][i];
    let level = run[f].images[&format!("{method}.atrous")][i];
    bits(&state)[..3] == bits(&level)[..3] && state[3].to_bits() == variance.to_bits()
}

#[test]
fn without_the_atrous_only_the_output_changes() {
    // Against ours without the feedback, which carries the à-trous into the state.
    let pair @ (base, ablation) = ("ours-no-feedback", "ours-no-atrous");
    let run = run("phantom/orbit", base, ablation, &[]);
    for stage in STAGES {
        assert_same(&run, pair, stage, 0..run.len());
    }
    // Its output is the prior's combination as the base computed it (after the first
    // frame, whose output is the young-pixel network's in both).
    for (f, frame) in run.iter().enumerate().skip(1) {
        assert_eq!(
            frame.images[ablation],
            frame.images[&format!("{base}.prior")],
            "frame {f}"
        );
    }
    assert!(differs_somewhere(&run, base, ablation, ""));
}

#[test]
fn without_the_feedback_only_the_restarted_states_change() {
    let pair @ (base, ablation) = ("ours", "ours-no-feedback");
    let run = run("phantom/orbit", base, ablation, &["ours.atrous"]);
    // In the first frame everything before the feedback is the same; every state
    // restarted, and ours' holds its first à-trous level's estimate with the variance the
    // update gave it, where the ablation's holds the update's own.
    for stage in ["residual", "lag", "prior_pred", "prior"] {
        assert_same(&run, pair, stage, 0..1);
    }
    let theirs = &run[0].images[&format!("{ablation}.model")];
    let mut fed = 0;
    for (i, t) in theirs.iter().enumerate() {
        if fed_back(&run, 0, base, i, t[3]) {
            fed += 1;
        } else {
            let ours = run[0].images["ours.model"][i];
            assert_eq!(
                bits(&ours),
                bits(t),
                "pixel {i}: neither fed back nor the update's"
            );
        }
    }
    assert!(fed > 0, "ours fed nothing back in its first frame");
    assert!(differs_somewhere(&run, base, ablation, ""));
}

#[test]
fn without_the_prior_only_its_combination_changes() {
    let pair @ (base, ablation) = ("ours", "ours-no-prior");
    let run = run("phantom/orbit", base, ablation, &["ours-no-prior.atrous"]);
    // The model is still fitted (the à-trous carries by it). The combination reaches the
    // filter only through the feedback, which follows it in the frame: in the first
    // frame every stage before it is ours'.
    for stage in ["residual", "lag", "prior_pred"] {
        assert_same(&run, pair, stage, 0..1);
    }
    // The combination passes each estimate through (its radiance clamped at zero), the
    // state as the update left it: where the feedback replaced it, the state holds the
    // first à-trous level's estimate instead.
    for (f, frame) in run.iter().enumerate() {
        let combined = &frame.images[&format!("{ablation}.prior")];
        let state = &frame.images[&format!("{ablation}.model")];
        for (i, (c, x)) in combined.iter().zip(state).enumerate() {
            if fed_back(&run, f, ablation, i, c[3]) {
                continue;
            }
            let want = [x[0].max(0.0), x[1].max(0.0), x[2].max(0.0), x[3]];
            assert_eq!(*c, want, "frame {f}, pixel {i}");
        }
    }
    assert!(differs_somewhere(&run, base, ablation, "prior"));
}

#[test]
fn without_the_lag_shift_the_state_differs_only_where_ours_shifted() {
    let ablation = "ours-no-lag";
    let run = run(
        "mri/point-light",
        "ours",
        ablation,
        &["ours.atrous", "ours-no-lag.atrous"],
    );
    let first = (0..run.len())
        .find(|&f| !same(&run, f, "ours", ablation, "model"))
        .expect("ours shifted its state somewhere (the light moves every frame)");
    // Up to that frame every stage is ours'; the lag test itself still runs.
    for stage in STAGES {
        assert_same(&run, ("ours", ablation), stage, 0..first);
    }
    // In it, the states differ only at pixels whose pooled residual in the frame before
    // was significant (the camera is still, so each pixel reads its own), or where the
    // feedback wrote a first à-trous level's estimate, which reads the neighbours.
    let lag_z = dvr_engine::denoise::ours::OursParams::default().lag_z;
    let (ours, theirs) = (
        &run[first].images["ours.model"],
        &run[first].images[&format!("{ablation}.model")],
    );
    let lag = &run[first - 1].images["ours.lag"];
    let mut differing = 0;
    for (i, (a, b)) in ours.iter().zip(theirs).enumerate() {
        if a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits()) {
            continue;
        }
        differing += 1;
        if fed_back(&run, first, "ours", i, a[3]) || fed_back(&run, first, ablation, i, b[3]) {
            continue;
        }
        let l = lag[i];
        let z2 = (l[0] * l[0] + l[1] * l[1] + l[2] * l[2]) / 3.0 / l[3].max(1e-12);
        assert!(
            z2 > lag_z * lag_z,
            "frame {first}, pixel {i}: the states differ where the pooled residual was not \
             significant (z² = {z2})"
        );
    }
    assert!(differing > 0);
}

#[test]
fn without_gradients_nothing_changes_until_a_light_or_the_tf_does() {
    let ablation = "ours-no-gradient";
    // Only the camera moves: no gradients are traced, and the two are one filter.
    let orbit = run("phantom/orbit", "ours", ablation, &[]);
    for stage in STAGES.iter().copied().chain([""]) {
        assert_same(&orbit, ("ours", ablation), stage, 0..orbit.len());
    }
    // The light moves every frame: the first frame is the same, the measured change
    // then reaches the state.
    let light = run("mri/point-light", "ours", ablation, &[]);
    assert!(!orbit.iter().any(|f| f.gradients));
    // The light moves every frame: until ours first traces gradients (it needs last
    // frame's radiance) the two are the same; from then on the measured change reaches
    // ours' state and not the ablation's.
    let first = (0..light.len())
        .find(|&f| light[f].gradients)
        .expect("ours traced gradients");
    for stage in STAGES {
        assert_same(&light, ("ours", ablation), stage, 0..first);
    }
    assert!(!same(&light, first, "ours", ablation, "model"));
}

#[test]
fn without_the_young_network_only_the_first_frames_output_changes() {
    let pair @ (base, ablation) = ("ours", "ours-no-young");
    let run = run("phantom/orbit", base, ablation, &[]);
    // The network runs where every state restarted (the first frame) and reaches the
    // output alone: every stage of every frame, and every later output, are the same.
    for stage in STAGES {
        assert_same(&run, pair, stage, 0..run.len());
    }
    assert_same(&run, pair, "", 1..run.len());
    assert!(
        !same(&run, 0, base, ablation, ""),
        "the network changed nothing"
    );
}
