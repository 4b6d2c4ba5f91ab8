//! Analytic checks of the path tracer on the device: Beer–Lambert transmittance through a
//! homogeneous slab for both estimators, a white furnace, determinism, and 1/spp error
//! convergence.

mod common;

use common::*;
use dvr_engine::scene::{Estimator, Phase};

/// Camera rays through a purely absorbing unit cube in front of a constant environment:
/// every ray that crosses the cube along z sees exp(−μt·1).
fn slab_transmittance(estimator: Estimator) -> f64 {
    let mut s = settings(8, 1);
    s.settings.set_estimator(estimator);
    s.config.density_scale = 1.5; // μt = opacity × scale = 1.5 per unit
    s.settings.set_step_size(0.25).expect("step");
    s.settings.set_filter_sigma(0.0).expect("pinhole"); // straight through the pixel centre
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

/// Both estimators see the same slab: each must give exp(−1.5) within 1 %, and a failure
/// names the estimator that missed.
#[test]
fn slab_transmittance_matches_beer_lambert_for_every_estimator() {
    let expected = (-1.5f64).exp();
    for (estimator, name) in [
        (Estimator::Delta, "delta tracking"),
        (Estimator::RayMarch, "ray marching"),
    ] {
        let t = slab_transmittance(estimator);
        assert_relative(t, expected, 0.01, &format!("{name}: T against exp(-1.5)"));
    }
    assert_validation_clean();
}

#[test]
fn white_furnace_returns_the_environment() {
    let mut s = settings(8, 1);
    s.config.density_scale = 4.0;
    s.settings.set_max_bounces(1000).expect("bounces");
    s.settings.set_russian_roulette_depth(4).expect("roulette");
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
                aux: false,
                features: false,
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

#[test]
fn henyey_greenstein_white_furnace_conserves_energy() {
    let mut s = settings(8, 1);
    s.config.density_scale = 4.0;
    s.settings.set_max_bounces(1000).expect("bounces");
    s.settings.set_russian_roulette_depth(4).expect("roulette");
    s.settings.set_hg_g(0.7).expect("g");
    s.settings.set_phase(Phase::Hg);
    let volume = constant_volume(8, 1.0);
    let mut r = renderer(context(), s, &volume, &["none"]);
    let inputs = inputs(
        front_camera(3.0, 30.0),
        vec![environment(1.0)],
        constant_lut(1.0, 1.0),
    );
    let m = mean_rgb(&r.reference(&inputs, 2048, 4).expect("reference render"));
    for c in m {
        assert!((c - 1.0).abs() < 0.01, "HG furnace mean {m:?}, expected 1");
    }
    assert_validation_clean();
}

/// Emission–absorption through the slab (albedo 0, emissive TF, no lights): every
/// collision adds the emitted radiance, so L = Le · (1 − exp(−μt·d)).
#[test]
fn emissive_slab_matches_the_emission_absorption_solution() {
    let mut s = settings(8, 1);
    s.config.density_scale = 1.5;
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    s.settings.set_emission(true);
    let volume = constant_volume(8, 1.0);
    let mut lut = constant_lut(1.0, 0.0);
    lut.emissive = vec![[2.0, 2.0, 2.0, 0.0]; LUT];
    let mut r = renderer(context(), s, &volume, &["none"]);
    let inputs = inputs(front_camera(3.0, 2.0), vec![], lut);
    let l = mean_rgb(&r.reference(&inputs, 4096, 4).expect("reference render"))[0];
    let expected = 2.0 * (1.0 - (-1.5f64).exp());
    assert_relative(l, expected, 0.01, "L against 2 (1 - exp(-1.5))");
    assert_validation_clean();
}

/// An equirectangular environment map is looked up with z up: looking horizontally, the
/// image's centre row sees the horizon (v = 0.5) and the top rows see the sky side.
#[test]
fn environment_map_is_z_up_equirectangular() {
    use dvr_engine::renderer::uploads::EnvironmentUpload;
    use dvr_engine::shaders::frame::{ENV_MAP, LIGHT_ENV};
    let (w, h) = (64u32, 32u32);
    // Radiance 1 − v: bright at the zenith (v = 0), dark at the nadir.
    let rgba: Vec<[f32; 4]> = (0..h)
        .flat_map(|y| {
            let v = (y as f32 + 0.5) / h as f32;
            (0..w).map(move |_| [1.0 - v, 1.0 - v, 1.0 - v, 1.0])
        })
        .collect();
    let env = EnvironmentUpload {
        width: w,
        height: h,
        rgba,
    };
    let mut s = settings(16, 1);
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    let volume = constant_volume(8, 0.0); // empty: the camera sees the environment
                                          // The environment map specialises the path tracer for one.
    let mut r = renderer_with(context(), s, &volume, Some(&env), &["none"]);
    let light = dvr_engine::shaders::frame::GpuLight {
        position_kind: glam::Vec4::new(0.0, 0.0, 0.0, LIGHT_ENV),
        radiance: glam::Vec4::new(0.0, 0.0, 0.0, ENV_MAP),
        u_axis: glam::Vec4::new(0.0, 0.0, 0.0, 1.0), // w: intensity
        v_axis: glam::Vec4::ZERO,
    };
    let camera = dvr_engine::renderer::CameraMatrices::look_at(
        glam::Vec3::new(0.0, 3.0, 0.0),
        glam::Vec3::ZERO,
        glam::Vec3::Z,
        60f32.to_radians(),
        1.0,
    );
    let img = r
        .reference(&inputs(camera, vec![light], constant_lut(0.0, 0.0)), 4, 4)
        .expect("render");
    let row = |y: usize| {
        img[y * 16..y * 16 + 16]
            .iter()
            .map(|p| p[0] as f64)
            .sum::<f64>()
            / 16.0
    };
    let (top, middle, bottom) = (row(0), (row(7) + row(8)) / 2.0, row(15));
    assert!(
        (middle - 0.5).abs() < 0.02,
        "horizon radiance {middle}, expected 0.5"
    );
    assert!(
        top > middle + 0.1 && bottom < middle - 0.1,
        "top {top}, middle {middle}, bottom {bottom}"
    );
    assert_validation_clean();
}
