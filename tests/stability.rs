//! Every denoiser on every built-in animation (the stress cases included), through the
//! real path tracer: outputs stay finite, non-negative and bounded, frame after frame.

mod common;

use common::*;
use dvr_engine::denoise::registry;
use dvr_engine::graph::Extent;
use dvr_engine::renderer::scene_setup::SceneSetup;
use dvr_engine::renderer::FrameRequest;
use dvr_engine::scene::Scene;

#[test]
fn every_denoiser_stays_finite_and_bounded_on_every_built_in_animation() {
    let size = Extent {
        width: 16,
        height: 16,
    };
    for name in Scene::builtin_names() {
        let scene = Scene::builtin(&name)
            .expect("scene")
            .with_frames(8)
            .expect("frames");
        let setup = SceneSetup::new(scene, size, None, 24).expect("setup");
        let mut r = setup
            .renderer(context(), &registry::names().collect::<Vec<_>>())
            .expect("renderer");
        let frames = (0..8).map(|f| setup.frame_inputs(f));
        let results = render_frames(&mut r, frames, &readback());
        assert_eq!(results.len(), 8);
        for done in &results {
            let noisy_max = done.images[0]
                .1
                .iter()
                .flat_map(|p| p[..3].to_vec())
                .fold(0.0f32, f32::max);
            for (method, px) in &done.images {
                for p in px {
                    for &c in &p[..3] {
                        assert!(
                            c.is_finite() && c >= 0.0 && c <= 100.0 * noisy_max.max(1.0),
                            "{name}: {method} frame {}: value {c}",
                            done.index
                        );
                    }
                }
            }
        }
    }
    assert_validation_clean();
}

/// On a static view, 64 frames of `ours` at 2 spp end closer to the 1024-spp reference
/// than a 32-spp render without denoising (what `ours` must beat), with both motion
/// sources. This test found two real faults: motion vectors measured from the pixel
/// centre gave the jittered first collision a random sub-pixel motion on a still view
/// (every frame resampled the models), and the paper's relative-distance weights biased
/// and starved the fit on 2-spp noise.
#[test]
fn ours_on_a_static_scene_beats_32_spp_after_64_frames() {
    let size = Extent {
        width: 32,
        height: 32,
    };
    for (name, motion) in [
        ("mri/orbit", dvr_engine::denoise::MotionSource::FirstHit),
        ("phantom/orbit", dvr_engine::denoise::MotionSource::FirstHit),
        ("phantom/orbit", dvr_engine::denoise::MotionSource::Features),
    ] {
        let scene = Scene::builtin(name).expect("scene");
        let mut setup = SceneSetup::new(scene, size, None, 32).expect("setup");
        setup.config.motion_source = motion;
        let inputs = setup.frame_inputs(0);
        let mut r = setup.renderer(context(), &["ours"]).expect("renderer");
        let request = FrameRequest {
            readback: true,
            reset: false,
            aux: false,
            features: false,
        };
        for _ in 0..64 {
            r.frame(&inputs, &request).expect("frame");
        }
        let ours = r.flush().expect("flush").pop().expect("last frame").images[0]
            .1
            .clone();
        let reference = r.reference(&inputs, 1024, 4).expect("reference");
        setup.settings.set_seed(99); // an independent stream for the 32-spp render
        let mut plain = setup.renderer(context(), &["none"]).expect("renderer");
        let spp32 = plain.reference(&inputs, 32, 4).expect("32 spp");
        let (e_ours, e_32) = (mse(&ours, &reference), mse(&spp32, &reference));
        println!("{name} ({motion:?}): MSE ours@64 frames {e_ours:.2e}, 32 spp {e_32:.2e}");
        assert!(e_ours < e_32, "{name}: ours {e_ours} vs 32 spp {e_32}");
    }
    assert_validation_clean();
}
