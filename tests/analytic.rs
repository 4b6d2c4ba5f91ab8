//! Analytic checks of the path tracer on the device: Beer–Lambert transmittance through a
//! homogeneous slab for both estimators, a white furnace, determinism, and 1/spp error
//! convergence.

mod common;

use common::*;
use dvr_engine::passes::path_trace::{Estimator, PathTraceFeatures};

/// Camera rays through a purely absorbing unit cube in front of a constant environment:
/// every ray that crosses the cube along z sees exp(−μt·1).
fn slab_transmittance(estimator: Estimator) -> f64 {
    let mut s = settings(8, 1);
    s.features = PathTraceFeatures {
        estimator,
        ..Default::default()
    };
    s.density_scale = 1.5; // μt = opacity × scale = 1.5 per unit
    s.step_voxels = 0.25;
    s.filter_sigma = 0.0; // straight through the pixel centre
    let volume = constant_volume(8, 1.0);
    let mut r = renderer(context(), s, &volume, &["none"]);
    let inputs = inputs(
        front_camera(3.0, 2.0),
        vec![environment(1.0)],
        constant_lut(1.0, 0.0),
    );
    let img = r.reference(&inputs, 4096, 512).expect("reference render");
    mean_rgb(&img)[0]
}

#[test]
fn slab_transmittance_matches_beer_lambert_delta_tracking() {
    let t = slab_transmittance(Estimator::Delta);
    let expected = (-1.5f64).exp();
    assert!(
        ((t - expected) / expected).abs() < 0.01,
        "delta tracking: T = {t}, exp(-1.5) = {expected}"
    );
    assert_validation_clean();
}

#[test]
fn slab_transmittance_matches_beer_lambert_ray_marching() {
    let t = slab_transmittance(Estimator::RayMarch);
    let expected = (-1.5f64).exp();
    assert!(
        ((t - expected) / expected).abs() < 0.01,
        "ray marching: T = {t}, exp(-1.5) = {expected}"
    );
    assert_validation_clean();
}

#[test]
fn white_furnace_returns_the_environment() {
    let mut s = settings(8, 1);
    s.density_scale = 4.0;
    s.max_bounces = 1000;
    s.rr_depth = 4;
    let volume = constant_volume(8, 1.0);
    let mut r = renderer(context(), s, &volume, &["none"]);
    let inputs = inputs(
        front_camera(3.0, 30.0),
        vec![environment(1.0)],
        constant_lut(1.0, 1.0),
    );
    let img = r.reference(&inputs, 2048, 256).expect("reference render");
    let m = mean_rgb(&img);
    for c in m {
        assert!(
            (c - 1.0).abs() < 0.01,
            "white furnace mean {m:?}, expected 1"
        );
    }
    assert_validation_clean();
}

#[test]
fn identical_seeds_give_identical_images() {
    let render = || {
        let volume = constant_volume(8, 0.6);
        let mut r = renderer(context(), settings(16, 2), &volume, &["none"]);
        let inputs = inputs(
            front_camera(2.5, 40.0),
            vec![
                point_light(glam::Vec3::new(1.0, 1.0, 2.0), 4.0),
                environment(0.2),
            ],
            constant_lut(0.5, 0.8),
        );
        r.frame(
            &inputs,
            &dvr_engine::renderer::FrameRequest {
                readback: true,
                reset: false,
                ..Default::default()
            },
        )
        .expect("frame");
        let done = r.flush().expect("flush");
        done[0].images[0].1.clone()
    };
    let a = render();
    let b = render();
    assert!(a.iter().any(|p| p[0] > 0.0), "image is not black");
    assert_eq!(a, b);
    assert_validation_clean();
}
