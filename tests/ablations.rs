//! Each ablation of ours switches exactly one stage off, checked by behaviour: ours and
//! the ablation run in one renderer on the same noisy frames, and the stages' images
//! (`Renderer::read_back_images`: the filter's state, its running residual, the pooled lag
//! test, the prior's prediction and combination) are compared bit for bit,
//! frame by frame. What the switched stage does not reach must be identical; what it does
//! must differ, and only where it acted.

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

/// `ours` and `ablation` on `scene`, every stage of both read back in every frame.
fn run(scene: &str, ablation: &str) -> Run {
    let setup = builtin_setup(scene, FRAMES, SIZE);
    let mut r = setup
        .renderer(context(), &["ours", ablation])
        .expect("renderer");
    let names: Vec<String> = ["ours", ablation]
        .iter()
        .flat_map(|m| STAGES.iter().map(move |s| format!("{m}.{s}")))
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

/// Whether `stage` of ours and of `ablation` are bit-identical in frame `f`.
fn same(run: &Run, f: usize, ablation: &str, stage: &str) -> bool {
    let key = |m: &str| {
        if stage.is_empty() {
            m.to_string()
        } else {
            format!("{m}.{stage}")
        }
    };
    let (a, b) = (&run[f].images[&key("ours")], &run[f].images[&key(ablation)]);
    a.iter()
        .zip(b)
        .all(|(p, q)| p.iter().zip(q).all(|(x, y)| x.to_bits() == y.to_bits()))
}

fn assert_same(run: &Run, ablation: &str, stage: &str, frames: std::ops::Range<usize>) {
    for f in frames {
        assert!(
            same(run, f, ablation, stage),
            "{ablation}: stage {stage:?} differs from ours' in frame {f}"
        );
    }
}

fn differs_somewhere(run: &Run, ablation: &str, stage: &str) -> bool {
    (0..run.len()).any(|f| !same(run, f, ablation, stage))
}

#[test]
fn without_the_atrous_only_the_output_changes() {
    let ablation = "ours-no-atrous";
    let run = run("phantom/orbit", ablation);
    for stage in STAGES {
        assert_same(&run, ablation, stage, 0..run.len());
    }
    // Its output is the prior's combination as ours computed it.
    for (f, frame) in run.iter().enumerate() {
        assert_eq!(
            frame.images[ablation], frame.images["ours.prior"],
            "frame {f}"
        );
    }
    assert!(differs_somewhere(&run, ablation, ""));
}

#[test]
fn without_the_prior_only_its_combination_changes() {
    let ablation = "ours-no-prior";
    let run = run("phantom/orbit", ablation);
    // The combination never feeds back into the filter, and the model is still fitted
    // (the à-trous carries by it).
    for stage in ["model", "residual", "lag", "prior_pred"] {
        assert_same(&run, ablation, stage, 0..run.len());
    }
    // The combination passes each estimate through (its radiance clamped at zero).
    for (f, frame) in run.iter().enumerate() {
        let combined = &frame.images[&format!("{ablation}.prior")];
        let state = &frame.images[&format!("{ablation}.model")];
        for (c, x) in combined.iter().zip(state) {
            let want = [x[0].max(0.0), x[1].max(0.0), x[2].max(0.0), x[3]];
            assert_eq!(*c, want, "frame {f}");
        }
    }
    assert!(differs_somewhere(&run, ablation, "prior"));
}

#[test]
fn without_the_lag_shift_the_state_differs_only_where_ours_shifted() {
    let ablation = "ours-no-lag";
    let run = run("mri/point-light", ablation);
    let first = (0..run.len())
        .find(|&f| !same(&run, f, ablation, "model"))
        .expect("ours shifted its state somewhere (the light moves every frame)");
    // Up to that frame every stage is ours'; the lag test itself still runs.
    for stage in STAGES {
        assert_same(&run, ablation, stage, 0..first);
    }
    // In it, the states differ only at pixels whose pooled residual in the frame before
    // was significant (the camera is still, so each pixel reads its own).
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
    let orbit = run("phantom/orbit", ablation);
    for stage in STAGES.iter().copied().chain([""]) {
        assert_same(&orbit, ablation, stage, 0..orbit.len());
    }
    // The light moves every frame: the first frame is the same, the measured change
    // then reaches the state.
    let light = run("mri/point-light", ablation);
    assert!(!orbit.iter().any(|f| f.gradients));
    // The light moves every frame: until ours first traces gradients (it needs last
    // frame's radiance) the two are the same; from then on the measured change reaches
    // ours' state and not the ablation's.
    let first = (0..light.len())
        .find(|&f| light[f].gradients)
        .expect("ours traced gradients");
    for stage in STAGES {
        assert_same(&light, ablation, stage, 0..first);
    }
    assert!(!same(&light, first, ablation, "model"));
}
