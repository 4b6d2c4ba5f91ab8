//! The brick pool against the dense path, on a volume small enough for both: a budget
//! below the dense texture pages it through the pool, and its frames must be the dense
//! path's; a TF edit that makes hidden bricks visible must show them in the frame after
//! the edit exactly as a renderer that started with that TF.
//!
//! Tolerance: a resident brick's samples are the dense texture's (same voxels, same
//! clamping at the edge), but its texture coordinate is computed in the pool's texel
//! space, so trilinear weights round differently in the last bits. Delta tracking
//! compares a random number with the density, so a rare sample flips a decision and
//! walks another path: a few pixels of a noisy frame differ, the rest are equal.

mod common;

use common::*;
use dvr_engine::renderer::uploads::{LutUpload, VolumeUpload};
use dvr_engine::renderer::{FrameInputs, Renderer, VolumeResidency};
use dvr_engine::scene::{ClipPlane, Cut};
use dvr_engine::volume::{Volume, VolumeData};
use glam::Vec3;
use std::sync::Arc;

const N: u32 = 96;
const SIZE: u32 = 48;

/// Two blobs in a 96³ volume: a dense one (peak 1.0) in brick (1, 1, 1) and a faint one
/// (peak 0.4) in brick (0, 1, 1); both fall to 0 more than a voxel inside their brick, so
/// every other brick is empty (its range, apron included, is 0).
fn two_blobs() -> VolumeUpload {
    let blob = |p: [f32; 3], c: [f32; 3], peak: f32| {
        let r = ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2) + (p[2] - c[2]).powi(2)).sqrt();
        peak * (1.0 - r / 13.0).max(0.0).powi(2)
    };
    let mut data = Vec::with_capacity((N * N * N) as usize);
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                let p = [x as f32 + 0.5, y as f32 + 0.5, z as f32 + 0.5];
                let d = blob(p, [48.0, 48.0, 48.0], 1.0) + blob(p, [16.0, 48.0, 48.0], 0.4);
                data.push((d.min(1.0) * 255.0).round() as u8);
            }
        }
    }
    VolumeUpload::from_volume(
        &Volume::new("two-blobs", [N; 3], [1.0; 3], VolumeData::U8(data)).expect("valid volume"),
    )
}

/// Opaque, white, above `threshold`; transparent below.
fn step_tf(threshold: f32) -> LutUpload {
    let mut lut = constant_lut(0.0, 0.8);
    for (i, e) in lut.diffuse_opacity.iter_mut().enumerate() {
        if i as f32 / (LUT - 1) as f32 > threshold {
            e[3] = 1.0;
        }
    }
    lut
}

fn make(volume: &VolumeUpload, budget: Option<u64>, denoisers: &[&str]) -> Renderer {
    let mut s = settings(SIZE, 1);
    s.settings.set_max_bounces(2).expect("bounces");
    s.config.gpu_memory = budget;
    s.config.density_scale = 200.0;
    Renderer::new(
        context(),
        s.settings,
        s.config,
        Arc::new(volume.clone()),
        None,
        denoisers,
        LUT as u32,
    )
    .expect("renderer")
}

/// Renders one frame per TF in `tfs`; returns each frame's outputs by method name.
fn run(r: &mut Renderer, tfs: &[LutUpload]) -> Vec<Vec<(String, Vec<[f32; 4]>)>> {
    run_cut(r, tfs, &Cut::default())
}

/// [`run`] under a cut.
fn run_cut(r: &mut Renderer, tfs: &[LutUpload], cut: &Cut) -> Vec<Vec<(String, Vec<[f32; 4]>)>> {
    let camera = front_camera(2.2, 40.0);
    let lights = vec![point_light(Vec3::new(0.8, 1.0, 1.5), 6.0), environment(0.3)];
    let frames = tfs.iter().map(|lut| FrameInputs {
        cut: cut.clone(),
        ..inputs(camera, lights.clone(), lut.clone())
    });
    let results = render_frames(r, frames, &readback());
    results.into_iter().map(|f| f.images).collect()
}

/// PSNR of `b` against `a` (values clamped to [0, 1]) and the share of pixels that
/// differ by more than 1e-4.
fn compare(a: &[[f32; 4]], b: &[[f32; 4]]) -> (f64, f64) {
    let clamp = |p: &[[f32; 4]]| {
        p.iter()
            .map(|x| x.map(|c| c.clamp(0.0, 1.0)))
            .collect::<Vec<_>>()
    };
    let e = mse(&clamp(a), &clamp(b));
    let differ = a
        .iter()
        .zip(b)
        .filter(|(x, y)| (0..3).any(|c| (x[c] - y[c]).abs() > 1e-4))
        .count();
    (
        10.0 * (1.0 / e.max(1e-20)).log10(),
        differ as f64 / a.len() as f64,
    )
}

fn assert_same(what: &str, a: &[[f32; 4]], b: &[[f32; 4]]) {
    let (psnr, differ) = compare(a, b);
    println!(
        "{what}: {psnr:.1} dB, {:.2}% of pixels differ",
        differ * 100.0
    );
    assert!(
        psnr > 50.0 && differ < 0.02,
        "{what}: {psnr:.1} dB, {:.2}% of pixels differ",
        differ * 100.0
    );
}

/// 200 KiB: below the dense texture's 864 KiB, room for a 24³ coarse copy and 4 slots.
const BUDGET: u64 = 200 << 10;

#[test]
fn pooled_frames_equal_the_dense_path() {
    let volume = two_blobs();
    let tfs = vec![step_tf(0.1); 3];
    let mut dense = make(&volume, None, &["none", "ours"]);
    assert_eq!(dense.volume_residency(), VolumeResidency::Dense);
    let want = run(&mut dense, &tfs);
    drop(dense);
    let mut pooled = make(&volume, Some(BUDGET), &["none", "ours"]);
    let got = run(&mut pooled, &tfs);
    match pooled.volume_residency() {
        VolumeResidency::Pool {
            layout,
            visible,
            resident,
            pending,
            ..
        } => {
            assert_eq!(layout.grid, [3, 3, 3]);
            assert_eq!(
                (visible, resident, pending),
                (2, 2, 0),
                "both blobs' bricks resident"
            );
            assert!(layout.slot_count() >= 2 && layout.level >= 1, "{layout:?}");
        }
        VolumeResidency::Dense => panic!("a budget below the dense texture must page"),
    }
    for (f, (w, g)) in want.iter().zip(&got).enumerate() {
        for ((name, a), (_, b)) in w.iter().zip(g) {
            assert_same(&format!("frame {f} {name}"), a, b);
        }
    }
    assert_validation_clean();
}

#[test]
fn bricks_a_cut_removes_are_never_uploaded() {
    let volume = two_blobs();
    let show = step_tf(0.1);
    // The faint blob's pool brick spans voxels 0 to 32 along x (world x up to -1/6, a
    // voxel more for its apron): the plane keeps x >= -0.15 and removes it whole; the
    // dense blob (x within ±0.14) stays.
    let cut = Cut {
        planes: vec![ClipPlane {
            point: glam::DVec3::new(-0.15, 0.0, 0.0),
            normal: glam::DVec3::X,
            enabled: true,
        }],
        crop: None,
    };
    let residency = |r: &Renderer| match r.volume_residency() {
        VolumeResidency::Pool {
            visible, uploaded, ..
        } => (visible, uploaded),
        VolumeResidency::Dense => panic!("pooled"),
    };
    let mut r = make(&volume, Some(BUDGET), &["none"]);
    let cut_frames = run_cut(&mut r, &[show.clone(), show.clone(), show.clone()], &cut);
    assert_eq!(residency(&r), (1, 1), "one brick visible, one uploaded");
    // The same frames with the cut switched off: the faint brick shows, and only then
    // is it uploaded.
    let off = Cut {
        planes: vec![ClipPlane {
            enabled: false,
            ..cut.planes[0]
        }],
        crop: None,
    };
    let open = run_cut(&mut r, &[show.clone(), show], &off);
    assert_eq!(residency(&r), (2, 2));
    let (psnr, _) = compare(&cut_frames[2][0].1, &open[1][0].1);
    assert!(
        psnr < 40.0,
        "the cut must hide the faint blob: {psnr:.1} dB"
    );
    assert_validation_clean();
}

#[test]
fn a_tf_edit_shows_the_bricks_it_reveals_in_the_next_frame() {
    let volume = two_blobs();
    // The faint blob (peak 0.4) is hidden by a threshold of 0.6 and revealed by 0.1.
    let (hide, show) = (step_tf(0.6), step_tf(0.1));
    let mut edited = make(&volume, Some(BUDGET), &["none"]);
    let frames = run(&mut edited, &[hide.clone(), hide.clone(), show.clone()]);
    let VolumeResidency::Pool {
        visible, resident, ..
    } = edited.volume_residency()
    else {
        panic!("pooled");
    };
    assert_eq!((visible, resident), (2, 2));
    drop(edited);
    let mut fresh = make(&volume, Some(BUDGET), &["none"]);
    let want = run(&mut fresh, &[show.clone(), show.clone(), show]);
    drop(fresh);
    // The edit's frame draws the same random numbers as the fresh renderer's frame 2.
    assert_same("frame after the edit", &want[2][0].1, &frames[2][0].1);
    // The test can fail: the faint blob changes the frame (before the edit it is absent).
    let (psnr, _) = compare(&frames[1][0].1, &frames[2][0].1);
    let (hidden_psnr, _) = compare(&want[1][0].1, &frames[1][0].1);
    println!("hidden vs shown: {psnr:.1} dB; frame 1 hidden vs shown: {hidden_psnr:.1} dB");
    assert!(
        hidden_psnr < 40.0,
        "the faint blob must show: {hidden_psnr:.1} dB"
    );
    assert_validation_clean();
}

#[test]
fn a_budget_too_small_for_one_brick_is_a_clear_error() {
    let volume = two_blobs();
    let mut s = settings(SIZE, 1);
    s.config.gpu_memory = Some(20 << 10);
    let err = match Renderer::new(
        context(),
        s.settings,
        s.config,
        Arc::new(volume),
        None,
        &["none"],
        LUT as u32,
    ) {
        Ok(_) => panic!("20 KiB cannot hold a brick"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("two-blobs") && err.contains("no room for one"),
        "{err}"
    );
    assert_validation_clean();
}

/// A volume made brick by brick on demand (`sparse`: its dense array never exists on the
/// pool path) renders as the same volume held dense.
#[test]
fn a_volume_made_on_demand_pools_like_the_dense_volume() {
    use dvr_engine::transfer::TransferFunction;
    use dvr_engine::volume::sparse::Sparse;
    let blocks = Arc::new(Sparse::new(256));
    let on_demand = VolumeUpload::on_demand("sparse", blocks);
    // The same voxels held dense, with the same (analytic, looser) majorant bounds: a
    // different majorant draws different random numbers, and the frames would differ
    // as two noise samples of one image do.
    let dense = VolumeUpload {
        bricks: on_demand.bricks.clone(),
        ..VolumeUpload::from_volume(&Volume::builtin("sparse", 256).expect("sparse"))
    };
    assert_eq!(dense.bytes, on_demand.dense_bytes().as_ref());
    let lut = LutUpload::from(&TransferFunction::preset("sparse").expect("preset").lut());
    let tfs = vec![lut; 2];
    let mut d = make(&dense, None, &["none"]);
    let want = run(&mut d, &tfs);
    drop(d);
    // 12 MiB: below the 16 MiB dense texture.
    let mut p = make(&on_demand, Some(12 << 20), &["none"]);
    let got = run(&mut p, &tfs);
    let VolumeResidency::Pool {
        visible, resident, ..
    } = p.volume_residency()
    else {
        panic!("pooled");
    };
    println!("{resident} of {visible} visible bricks resident");
    assert!(
        visible > 0 && resident == visible,
        "{resident} of {visible}"
    );
    for (f, (w, g)) in want.iter().zip(&got).enumerate() {
        assert_same(&format!("frame {f}"), &w[0].1, &g[0].1);
    }
    assert_validation_clean();
}

/// A TF edit that reveals more bricks than one frame uploads streams them over several
/// frames: each frame in between is whole (the bricks without a slot yet show at the
/// coarse level, no validation message), and once they are resident the frames are a
/// fresh renderer's.
#[test]
fn bricks_past_one_frames_upload_stream_in_over_frames() {
    use dvr_engine::renderer::brick_pool::STREAM_PER_FRAME;
    use dvr_engine::volume::sparse::Sparse;
    let volume = VolumeUpload::on_demand("sparse", Arc::new(Sparse::new(768)));
    // Only the shapes' dense cores, then nearly all of them down to their rims.
    let (a, b) = (step_tf(0.9), step_tf(0.05));
    // 200 MiB: below the 432 MiB dense texture, room for every brick TF b shows.
    let budget = Some(200 << 20);
    let tfs = [a.clone(), b.clone(), b.clone(), b.clone(), b.clone()];
    let mut edited = make(&volume, budget, &["none"]);
    // Frame 0 loads every brick TF a shows; count them before the edit.
    run(&mut edited, &tfs[..1]);
    let VolumeResidency::Pool {
        visible: before, ..
    } = edited.volume_residency()
    else {
        panic!("pooled");
    };
    let mut frames = run(&mut edited, &tfs[1..]);
    let VolumeResidency::Pool {
        visible,
        resident,
        pending,
        ..
    } = edited.volume_residency()
    else {
        panic!("pooled");
    };
    println!("TF a: {before} visible; TF b: {visible}, {resident} resident, {pending} pending");
    assert!(
        visible - before > STREAM_PER_FRAME,
        "the edit must need more than one frame's upload"
    );
    assert_eq!(
        (resident, pending),
        (visible, 0),
        "all resident four frames after the edit"
    );
    frames.insert(0, Vec::new());
    drop(edited);
    let mut fresh = make(&volume, budget, &["none"]);
    let want = run(
        &mut fresh,
        &tfs.iter().map(|_| b.clone()).collect::<Vec<_>>(),
    );
    // The edit's frame (1) uploads one frame's worth and shows the rest coarse; frame 2
    // uploads the rest, and from then on the frames are the fresh renderer's.
    for (f, frame) in frames.iter().enumerate().skip(1) {
        let got = &frame[0].1;
        assert!(
            got.iter().all(|p| p.iter().all(|c| c.is_finite())),
            "frame {f} finite"
        );
        if f >= 2 {
            assert_same(&format!("frame {f}"), &want[f][0].1, got);
        }
    }
    let (psnr, _) = compare(&want[1][0].1, &frames[1][0].1);
    println!("frame 1, half streamed: {psnr:.1} dB");
    assert!(
        psnr < 50.0,
        "frame 1 must show the bricks still streaming at the coarse level: {psnr:.1} dB"
    );
    assert_validation_clean();
}
