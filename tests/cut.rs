//! Cuts on the device: a clip plane through a homogeneous slab gives the analytic
//! transmittance for camera rays and for shadow rays (light entering through the cut),
//! the white furnace still holds with a cut, and cuts that remove nothing (a crop box
//! equal to the volume's bounds, a plane clear of it) render bit-identical frames.

mod common;

use common::*;
use dvr_engine::renderer::FrameInputs;
use dvr_engine::scene::{ClipPlane, CropBox, CropUnits, Cut};
use glam::{DVec3, Vec3};

const MU_T: f64 = 1.5;

fn plane(z: f64, normal_z: f64) -> Cut {
    Cut {
        planes: vec![ClipPlane {
            point: DVec3::new(0.0, 0.0, z),
            normal: DVec3::new(0.0, 0.0, normal_z),
            enabled: true,
        }],
        crop: None,
    }
}

/// Mean radiance of a reference of the unit cube of constant extinction `MU_T`, seen
/// along −z from z = 3 through a 2° pinhole view, under `cut`.
fn render(
    cut: &Cut,
    lights: Vec<dvr_engine::shaders::frame::GpuLight>,
    albedo: f32,
    bounces: u32,
) -> f64 {
    let mut s = settings(8, 1);
    s.config.density_scale = MU_T as f32;
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    s.settings.set_max_bounces(bounces).expect("bounces");
    s.settings.set_russian_roulette_depth(4).expect("roulette");
    let volume = constant_volume(8, 1.0);
    let mut r = renderer(context(), s, &volume, &["none"]);
    let i = FrameInputs {
        cut: cut.clone(),
        ..inputs(front_camera(3.0, 2.0), lights, constant_lut(1.0, albedo))
    };
    let img = r.reference(&i, 4096, 512).expect("reference");
    mean_rgb(&img)[0]
}

#[test]
fn a_clip_plane_leaves_the_slab_it_keeps_for_camera_rays() {
    // Kept z >= 0.1 (0.4 of the slab in front of the camera), or z <= 0.1 (0.6).
    for (normal, depth) in [(1.0, 0.4), (-1.0, 0.6)] {
        let t = render(&plane(0.1, normal), vec![environment(1.0)], 0.0, 1);
        let expected = (-MU_T * depth).exp();
        let what = format!("normal {normal}: T against exp(-{MU_T} * {depth})");
        assert_relative(t, expected, 0.01, &what);
    }
    assert_validation_clean();
}

/// Single scattering along the view axis from a point light behind the slab at z = −3:
/// the light reaches a point z of the kept medium through the kept medium only (the cut
/// lets it in), `kept` = [z0, 0.5]:
/// L = ∫ α μt e^(−μt (0.5 − z)) (1/4π) I/(z + 3)² e^(−μt (z − z0)) dz.
fn single_scattering(z0: f64, albedo: f64, intensity: f64) -> f64 {
    let n = 4000;
    let h = (0.5 - z0) / n as f64;
    let f = |z: f64| {
        albedo * MU_T * (-MU_T * (0.5 - z)).exp() * intensity
            / (4.0 * std::f64::consts::PI)
            / (z + 3.0).powi(2)
            * (-MU_T * (z - z0)).exp()
    };
    // Simpson's rule.
    (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(z0 + i as f64 * h)
        })
        .sum::<f64>()
        * h
        / 3.0
}

#[test]
fn light_enters_through_the_cut_for_shadow_rays() {
    let (albedo, intensity) = (0.6, 50.0);
    let light = vec![point_light(Vec3::new(0.0, 0.0, -3.0), intensity as f32)];
    // Without a cut the whole slab is in the light's way; with the plane the light
    // crosses only the kept medium behind each scattering point. One bounce: direct
    // light at the first collision only.
    for (cut, z0) in [(Cut::default(), -0.5), (plane(0.1, 1.0), 0.1)] {
        let got = render(&cut, light.clone(), albedo as f32, 0);
        let want = single_scattering(z0, albedo, intensity);
        let what = format!("kept from z = {z0}: L against single scattering");
        assert_relative(got, want, 0.02, &what);
    }
    assert_validation_clean();
}

#[test]
fn the_white_furnace_holds_with_a_cut() {
    // An albedo-1 medium in a uniform environment returns the environment whatever its
    // shape: a cut that free paths and shadow rays saw differently would not.
    let cut = Cut {
        planes: vec![ClipPlane {
            point: DVec3::new(0.1, 0.0, 0.0),
            normal: DVec3::new(1.0, 0.3, 0.5),
            enabled: true,
        }],
        crop: Some(CropBox {
            min: DVec3::new(-0.5, -0.3, -0.5),
            max: DVec3::new(0.4, 0.5, 0.2),
            units: CropUnits::Box,
            enabled: true,
        }),
    };
    let mut s = settings(8, 1);
    s.config.density_scale = 4.0;
    s.settings.set_max_bounces(1000).expect("bounces");
    s.settings.set_russian_roulette_depth(4).expect("roulette");
    let volume = constant_volume(8, 1.0);
    let mut r = renderer(context(), s, &volume, &["none"]);
    let i = FrameInputs {
        cut,
        ..inputs(
            front_camera(3.0, 30.0),
            vec![environment(1.0)],
            constant_lut(1.0, 1.0),
        )
    };
    let m = mean_rgb(&r.reference(&i, 2048, 256).expect("reference"));
    for c in m {
        assert!((c - 1.0).abs() < 0.01, "white furnace with a cut: {m:?}");
    }
    assert_validation_clean();
}

/// Three frames of ours and SVGF on a lit, scattering cube under `cut`.
fn frames(cut: &Cut) -> Vec<Vec<(String, Vec<[f32; 4]>)>> {
    let volume = constant_volume(16, 0.7);
    let mut r = renderer(
        context(),
        settings(24, 1),
        &volume,
        &["none", "ours", "svgf"],
    );
    let frames = (0..3).map(|f| FrameInputs {
        cut: cut.clone(),
        ..inputs(
            dvr_engine::renderer::CameraMatrices::look_at(
                Vec3::new(1.2 + 0.05 * f as f32, 1.0, 1.4),
                Vec3::ZERO,
                Vec3::Z,
                40f32.to_radians(),
                1.0,
            ),
            vec![point_light(Vec3::new(1.0, 1.5, 2.0), 8.0), environment(0.2)],
            constant_lut(0.6, 0.8),
        )
    });
    let out = render_frames(&mut r, frames, &readback());
    out.into_iter().map(|f| f.images).collect()
}

#[test]
fn cuts_that_remove_nothing_render_the_same_frames() {
    let none = frames(&Cut::default());
    let whole = Cut {
        planes: Vec::new(),
        crop: Some(CropBox {
            min: DVec3::splat(-0.5),
            max: DVec3::splat(0.5),
            units: CropUnits::Box,
            enabled: true,
        }),
    };
    let voxels = Cut {
        planes: Vec::new(),
        crop: Some(CropBox {
            min: DVec3::ZERO,
            max: DVec3::splat(16.0),
            units: CropUnits::Voxels,
            enabled: true,
        }),
    };
    // Clear of the box on the kept side, and one behind the camera looking away.
    let outside = Cut {
        planes: vec![
            ClipPlane {
                point: DVec3::new(0.0, 0.0, -0.8),
                normal: DVec3::Z,
                enabled: true,
            },
            ClipPlane {
                point: DVec3::new(0.9, 0.0, 0.0),
                normal: DVec3::NEG_X,
                enabled: true,
            },
        ],
        crop: None,
    };
    let disabled = Cut {
        planes: vec![ClipPlane {
            point: DVec3::ZERO,
            normal: DVec3::Z,
            enabled: false,
        }],
        crop: None,
    };
    for (what, cut) in [
        ("a crop box equal to the volume", whole),
        ("a crop box of every voxel", voxels),
        ("planes clear of the volume", outside),
        ("a disabled plane", disabled),
    ] {
        assert_eq!(frames(&cut), none, "{what}");
    }
    // The test can fail: a plane through the middle changes the frames.
    assert_ne!(frames(&plane(0.0, 1.0)), none);
    assert_validation_clean();
}

/// A crop shrunk under a still camera, motion from the features: the pixels whose ray hit
/// the cube and now miss it (their features' position flips from hit to miss) restart
/// the temporal methods' histories, and no other pixel does (svgf's history length, read
/// back; the reprojection is every temporal method's).
#[test]
fn a_crop_shrunk_under_a_still_camera_restarts_the_histories_it_uncovers() {
    let volume = constant_volume(16, 0.7);
    let mut s = settings(24, 1);
    s.config.motion_source = dvr_engine::denoise::MotionSource::Features;
    let mut r = renderer(context(), s, &volume, &["svgf"]);
    r.read_back_images(&["features.position", "svgf.moments"]);
    let camera = dvr_engine::renderer::CameraMatrices::look_at(
        Vec3::new(1.2, 1.0, 1.4),
        Vec3::ZERO,
        Vec3::Z,
        40f32.to_radians(),
        1.0,
    );
    let half = Cut {
        planes: Vec::new(),
        crop: Some(CropBox {
            min: DVec3::new(-0.5, -0.5, -0.5),
            max: DVec3::new(0.0, 0.5, 0.5),
            units: CropUnits::Box,
            enabled: true,
        }),
    };
    let frames = (0..5).map(|f| FrameInputs {
        cut: if f == 4 { half.clone() } else { Cut::default() },
        ..inputs(
            camera,
            vec![point_light(Vec3::new(1.0, 1.5, 2.0), 8.0), environment(0.2)],
            constant_lut(0.6, 0.8),
        )
    });
    let out = render_frames(&mut r, frames, &readback());
    let image = |f: usize, name: &str| {
        out[f]
            .images
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, px)| px.clone())
            .expect(name)
    };
    let (before, after) = (image(3, "features.position"), image(4, "features.position"));
    let (n3, n4) = (image(3, "svgf.moments"), image(4, "svgf.moments"));
    let mut flipped = 0;
    for i in 0..before.len() {
        let flip = (before[i][3] > 0.0) != (after[i][3] > 0.0);
        flipped += usize::from(flip);
        if flip {
            assert_eq!(
                n4[i][2], 1.0,
                "pixel {i}: its hit flipped, its history went on"
            );
        } else {
            assert_eq!(
                n4[i][2],
                n3[i][2] + 1.0,
                "pixel {i}: restarted, its hit did not flip"
            );
        }
    }
    assert!(flipped > 20, "the crop uncovered {flipped} pixels");
}
