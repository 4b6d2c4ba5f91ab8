//! A medium of several channels on the device: its extinction is the channels' sum and
//! its albedo their extinction-weighted mix, so split fields render like the one field
//! they add up to, and a two-colour medium scatters the mix of its colours.

mod common;

use common::*;
use dvr_engine::renderer::uploads::{LutUpload, VolumeUpload};
use dvr_engine::volume::{Volume, Voxels};

/// A cube of `n`³ voxels whose channel c holds the constant `values[c]` (u8).
fn channels_volume(n: u32, values: &[u8]) -> VolumeUpload {
    let vols: Vec<Volume> = values
        .iter()
        .enumerate()
        .map(|(c, &v)| {
            let voxels = Voxels::U8(vec![v; (n * n * n) as usize]);
            Volume::from_voxels(&format!("c{c}"), [n; 3], [1.0; 3], voxels).expect("volume")
        })
        .collect();
    VolumeUpload::from_channels(&vols).expect("channels pack")
}

/// A LUT whose opacity is the density itself (so extinctions of split densities add up
/// to the whole's) with diffuse colour `albedo`.
fn ramp_lut(albedo: [f32; 3]) -> LutUpload {
    let ramp = |i: usize| i as f32 / (LUT - 1) as f32;
    LutUpload {
        diffuse_opacity: (0..LUT)
            .map(|i| [albedo[0], albedo[1], albedo[2], ramp(i)])
            .collect(),
        specular_roughness: vec![[0.0, 0.0, 0.0, 0.5]; LUT],
        emissive: vec![[0.0; 4]; LUT],
    }
}

/// The channels' LUTs one after another: what a multi-channel renderer takes.
fn concat(luts: &[LutUpload]) -> LutUpload {
    let cat =
        |f: fn(&LutUpload) -> &Vec<[f32; 4]>| luts.iter().flat_map(|l| f(l).clone()).collect();
    LutUpload {
        diffuse_opacity: cat(|l| &l.diffuse_opacity),
        specular_roughness: cat(|l| &l.specular_roughness),
        emissive: cat(|l| &l.emissive),
    }
}

fn render(volume: &VolumeUpload, lut: LutUpload, absorbing: bool, spp: u32) -> Vec<[f32; 4]> {
    let mut s = settings(16, 1);
    s.config.density_scale = 1.5 / 0.8; // μt = 1.5 per unit at density 0.8
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    if !absorbing {
        s.settings.set_max_bounces(1).expect("single scattering");
    }
    let mut r = renderer(context(), s, volume, &["none"]);
    let lights = if absorbing {
        vec![environment(1.0)]
    } else {
        vec![point_light(glam::Vec3::new(0.4, 1.5, 2.0), 6.0)]
    };
    let inputs = inputs(
        front_camera(3.0, if absorbing { 2.0 } else { 30.0 }),
        lights,
        lut,
    );
    r.reference(&inputs, spp, 256).expect("reference render")
}

#[test]
fn split_channels_transmit_like_the_field_they_sum_to() {
    // 204 = 2 × 102 = 3 × 68 = 4 × 51: density 0.8 split evenly, exactly in u8.
    let whole = render(&channels_volume(8, &[204]), ramp_lut([0.0; 3]), true, 2048);
    let t = mean_rgb(&whole)[0];
    let expected = (-1.5f64).exp();
    assert!(
        ((t - expected) / expected).abs() < 0.01,
        "one channel: T = {t}, exp(-1.5) = {expected}"
    );
    for split in [vec![102u8, 102], vec![68, 68, 68], vec![51, 51, 51, 51]] {
        let luts = vec![ramp_lut([0.0; 3]); split.len()];
        let img = render(&channels_volume(8, &split), concat(&luts), true, 2048);
        let ts = mean_rgb(&img)[0];
        assert!(
            ((ts - expected) / expected).abs() < 0.01,
            "{} channels: T = {ts}, exp(-1.5) = {expected}",
            split.len()
        );
    }
    assert_validation_clean();
}

#[test]
fn split_channels_of_one_colour_scatter_like_the_whole() {
    let albedo = [0.8, 0.7, 0.6];
    let whole = render(&channels_volume(8, &[204]), ramp_lut(albedo), false, 512);
    let halves = render(
        &channels_volume(8, &[102, 102]),
        concat(&[ramp_lut(albedo), ramp_lut(albedo)]),
        false,
        512,
    );
    let (a, b) = (mean_rgb(&whole), mean_rgb(&halves));
    assert!(a[0] > 0.01, "the lit cube is visible: {a:?}");
    for c in 0..3 {
        assert!(
            (a[c] - b[c]).abs() < 0.01 * a[c],
            "mean {c}: whole {a:?}, halves {b:?}"
        );
    }
    // The same random numbers decide the same paths: the images agree per pixel, not
    // only on average.
    let rel = (mse(&whole, &halves) / mean_square(&whole)).sqrt();
    assert!(rel < 0.02, "relative RMS difference {rel}");
    assert_validation_clean();
}

#[test]
fn two_colours_scatter_their_extinction_weighted_mix() {
    // Red at density 0.6 and green at 0.2: the albedo at every collision is
    // (0.6 red + 0.2 green) / 0.8, which a single field of that colour has.
    let (red, green) = ([0.9, 0.0, 0.0], [0.0, 0.9, 0.0]);
    let mixed = [0.9 * 0.75, 0.9 * 0.25, 0.0];
    let two = render(
        &channels_volume(8, &[153, 51]),
        concat(&[ramp_lut(red), ramp_lut(green)]),
        false,
        512,
    );
    let one = render(&channels_volume(8, &[204]), ramp_lut(mixed), false, 512);
    let (a, b) = (mean_rgb(&two), mean_rgb(&one));
    assert!(b[0] > 0.01 && b[2] == 0.0, "{b:?}");
    for c in 0..2 {
        assert!(
            (a[c] - b[c]).abs() < 0.01 * b[c],
            "channel {c}: two colours {a:?}, mix {b:?}"
        );
    }
    // Each scattering event multiplies red : green by 0.75 : 0.25; paths of one and two
    // events (max_bounces = 1 scatters at two vertices) put the ratio between 3 and 9.
    let ratio = a[0] / a[1];
    assert!(ratio > 3.0 && ratio < 9.0, "red : green = {ratio}");
    assert_validation_clean();
}

#[test]
fn a_channel_with_no_opacity_is_empty_medium() {
    // Switching a channel off zeroes its LUT opacity: the medium is the other alone.
    let albedo = [0.8, 0.8, 0.8];
    let off = LutUpload {
        diffuse_opacity: vec![[1.0, 0.0, 0.0, 0.0]; LUT],
        ..ramp_lut(albedo)
    };
    let with_off = render(
        &channels_volume(8, &[204, 255]),
        concat(&[ramp_lut(albedo), off]),
        false,
        256,
    );
    let alone = render(&channels_volume(8, &[204]), ramp_lut(albedo), false, 256);
    assert_eq!(with_off.len(), alone.len());
    let rel = (mse(&with_off, &alone) / mean_square(&alone)).sqrt();
    assert!(rel < 0.02, "relative RMS difference {rel}");
    assert_validation_clean();
}

fn mean_square(img: &[[f32; 4]]) -> f64 {
    img.iter()
        .flat_map(|p| &p[..3])
        .map(|&v| f64::from(v) * f64::from(v))
        .sum::<f64>()
        / (img.len() * 3) as f64
}

#[test]
fn a_played_scene_follows_its_channel_keys() {
    // The microscopy scene switches channel 1 off at frame 24: capture and eval play
    // scenes through the session, which must take the key as the references do.
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/scenes/development/microscopy-orbit.toml"
    );
    let scene = dvr_engine::scene::Scene::load(path).expect("scene");
    let size = dvr_engine::graph::Extent {
        width: 16,
        height: 16,
    };
    let setup = dvr_engine::renderer::scene_setup::SceneSetup::new(scene, size, Some(1), 32)
        .expect("setup");
    assert!(setup.frame_inputs(23).lut != setup.frame_inputs(24).lut);
    let mut s =
        dvr_engine::session::Session::new(setup.clone(), context(), &["none"]).expect("session");
    for (f, shown) in [(23, true), (24, false), (30, false)] {
        s.play(f).expect("play");
        assert_eq!(s.view().channels[1].visible, shown, "frame {f}");
        let live = s.view().lut();
        assert_eq!(
            dvr_engine::renderer::uploads::LutUpload::from(&live),
            setup.frame_inputs(f).lut,
            "frame {f}: the session's LUT is the scene's"
        );
    }
    assert_validation_clean();
}

#[test]
fn channel_sections_need_a_volume_of_channels() {
    // On a built-in volume they would be ignored: an error naming the section.
    let base = "[volume]\nbuiltin = \"cloud\"\n[transfer]\na = \"cloud\"\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 10.0\n";
    let err = dvr_engine::scene::Scene::from_toml_str(
        &format!("{base}[[channel]]\nvisible = false\n"),
        "s.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("channel") && err.contains("one field"),
        "{err}"
    );
    let keys = format!("{base}[[animation.channel]]\nindex = 0\nframe = 3\nvisible = false\n");
    let err = dvr_engine::scene::Scene::from_toml_str(&keys, "s.toml")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("animation.channel") && err.contains("one field"),
        "{err}"
    );
    // More sections than the file has channels; one section on a one-channel file applies.
    let t1 = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/assets/volumes/mni152_t1.nii.gz"
    );
    let file = format!("[volume]\nfile = \"{t1}\"\n[transfer]\na = \"mri-faint\"\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 10.0\n");
    let size = dvr_engine::graph::Extent {
        width: 8,
        height: 8,
    };
    let setup = |text: String| {
        let scene = dvr_engine::scene::Scene::from_toml_str(&text, "t1.toml").expect("parses");
        dvr_engine::renderer::scene_setup::SceneSetup::new(scene, size, None, 32)
    };
    let err = setup(format!("{file}[[channel]]\n[[channel]]\n"))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        err.contains("2 [[channel]] sections for a volume of 1 channel"),
        "{err}"
    );
    let tinted =
        setup(format!("{file}[[channel]]\ncolour = [1.0, 0.0, 0.0]\n")).expect("one channel");
    assert_eq!(tinted.volume.channels(), 1);
    let lut = tinted.frame_inputs(0).lut;
    assert!(
        lut.diffuse_opacity
            .iter()
            .all(|d| d[1] == 0.0 && d[2] == 0.0),
        "tinted red"
    );
}
