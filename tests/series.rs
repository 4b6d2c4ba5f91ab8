//! A series played in time: scene keyframes set the time point, fractional times mix
//! the two around them, the renderer uploads each time point's volume, and bad times
//! are errors naming the range.

mod common;

use common::*;
use dvr_engine::graph::Extent;
use dvr_engine::renderer::scene_setup::SceneSetup;
use dvr_engine::renderer::timeline::lerp;
use dvr_engine::renderer::FrameRequest;
use dvr_engine::scene::Scene;

const SHELL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/assets/scenes/development/shell-beat-still.toml"
);

fn setup(size: u32) -> SceneSetup {
    let scene = Scene::load(SHELL).expect("scene");
    SceneSetup::new(
        scene,
        Extent {
            width: size,
            height: size,
        },
        Some(1),
        32,
    )
    .expect("setup")
}

#[test]
fn keyframes_set_the_time_and_fractional_times_mix_two_time_points() {
    let s = setup(32);
    let timeline = s.timeline.clone().expect("a 4D file has a timeline");
    assert_eq!(timeline.times(), 24);
    // 48 frames from time 0 to 23: frame 2 is time 46/47.
    let t = s.frame_inputs(2).time.expect("time").time;
    assert!((t - 2.0 * 23.0 / 47.0).abs() < 1e-9, "{t}");
    let (a, b) = (timeline.at(3.0).expect("t3"), timeline.at(4.0).expect("t4"));
    assert_ne!(a.bytes, b.bytes, "the shell moves between time points");
    let mid = timeline.at(3.25).expect("t3.25");
    assert_eq!(mid.bytes, lerp(&a, &b, 0.25).bytes);
    for (i, ((&m, &x), &y)) in mid.bytes.iter().zip(&a.bytes).zip(&b.bytes).enumerate() {
        let want = (f32::from(x) * 0.75 + f32::from(y) * 0.25).round() as u8;
        assert_eq!(m, want, "voxel {i}");
    }
    // The mix's brick ranges bound its voxels: the majorants stay bounds.
    for (k, (&lo, &hi)) in mid.bricks.min.iter().zip(&mid.bricks.max).enumerate() {
        assert!(
            lo <= a.bricks.min[k].min(b.bricks.min[k]) + 1e-6
                && hi >= a.bricks.max[k].max(b.bricks.max[k]) - 1e-6
        );
    }
    for bad in [-0.5, 23.5, f64::NAN] {
        let msg = timeline.at(bad).unwrap_err().to_string();
        assert!(msg.contains("outside its time points 0 to 23"), "{msg}");
    }
}

#[test]
fn a_keyframe_past_the_last_time_point_is_refused_naming_it() {
    let volume = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/volumes/beating_shell.nii.gz"
    );
    let text = std::fs::read_to_string(SHELL)
        .expect("read")
        .replace("time = 23.0", "time = 30.0")
        .replace("../../volumes/beating_shell.nii.gz", volume)
        .replace("tf/shell.toml", "phantom-opaque");
    let scene = Scene::from_toml_str(&text, "shell-bad-time.toml").expect("parses");
    let err = SceneSetup::new(
        scene,
        Extent {
            width: 8,
            height: 8,
        },
        None,
        32,
    )
    .err()
    .expect("refused")
    .to_string();
    assert!(
        err.contains("animation.time[0].time = 30") && err.contains("last time point 23"),
        "{err}"
    );
}

#[test]
fn playing_the_series_changes_the_frame_under_a_still_camera() {
    let s = setup(32);
    let mut r = s.renderer(context(), &["ours"]).expect("renderer");
    let mut means = Vec::new();
    for f in [0u32, 0, 24, 24] {
        let inputs = s.frame_inputs(f);
        let img = r.reference(&inputs, 64, 64).expect("reference");
        assert!(img.iter().all(|p| p.iter().all(|v| v.is_finite())));
        means.push(mean_rgb(&img));
    }
    // The same time renders the same; half a beat later the shell is smaller.
    assert_eq!(means[0], means[1]);
    assert_eq!(means[2], means[3]);
    assert!((means[0][0] - means[2][0]).abs() > 1e-3, "{means:?}");
    // Denoised frames through the whole beat: finite, validation clean.
    let request = FrameRequest {
        readback: true,
        ..Default::default()
    };
    for f in 0..48 {
        if let Some(done) = r.frame(&s.frame_inputs(f), &request).expect("frame") {
            for (_, px) in &done.images {
                assert!(
                    px.iter().all(|p| p.iter().all(|v| v.is_finite())),
                    "frame {f}"
                );
            }
        }
    }
    r.flush().expect("flush");
    assert_validation_clean();
}
