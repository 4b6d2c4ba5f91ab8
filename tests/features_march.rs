//! The features march runs only in frames whose inputs changed: where the camera, the
//! TF, the cut and the medium are those of the last march (a light moves, or nothing
//! does), the frame keeps the last march's images (`features.kept`), and those images
//! are bit for bit what a march of that frame writes. Bricks landing in the pool change
//! the medium outside the frame inputs, and the march runs in every frame they land in.

mod common;

use common::*;
use dvr_engine::gpu::timestamps::{PassOwner, PassTiming};
use dvr_engine::renderer::{FrameInputs, FrameRequest, FrameResult, Renderer, FEATURE_IMAGES};
use dvr_engine::scene::{ClipPlane, Cut};
use dvr_engine::volume::{Volume, VolumeData};
use glam::Vec3;
use std::sync::Arc;

const SIZE: u32 = 24;
const MARCHES: [&str; 2] = ["surface_features", "aux_features"];

fn marched(timings: &[PassTiming]) -> bool {
    timings.iter().any(|t| MARCHES.contains(&t.pass.as_str()))
}

fn kept(timings: &[PassTiming]) -> bool {
    timings.iter().any(|t| t.pass == "features.kept")
}

/// The surface features and the methods' outputs of a frame, by name.
fn images(done: &FrameResult) -> Vec<(String, Vec<[f32; 4]>)> {
    done.images.clone()
}

fn bits(a: &[[f32; 4]]) -> Vec<u32> {
    a.iter().flat_map(|p| p.map(f32::to_bits)).collect()
}

/// Renders `frames` in one renderer (features read back); returns each frame's result.
fn run(r: &mut Renderer, frames: &[(FrameInputs, bool)]) -> Vec<FrameResult> {
    let mut done = Vec::new();
    for (inputs, reset) in frames {
        let request = FrameRequest {
            readback: true,
            features: true,
            reset: *reset,
            ..Default::default()
        };
        done.extend(r.frame(inputs, &request).expect("frame"));
    }
    done.extend(r.flush().expect("flush"));
    done.sort_by_key(|f| f.index);
    assert_eq!(done.len(), frames.len());
    done
}

#[test]
fn the_march_runs_only_when_what_it_reads_changed() {
    // The phantom under a moving light, camera still: then a camera move, a TF edit, a
    // cut and a reset, each followed by a still frame.
    let setup = builtin_setup("phantom/point-light", 6, SIZE);
    let base = |f: u32| setup.frame_inputs(f);
    let mut moved = base(0);
    moved.camera = front_camera(2.5, 40.0);
    let mut edited = moved.clone();
    for e in &mut edited.lut.diffuse_opacity {
        e[3] *= 0.5;
    }
    let mut cut = edited.clone();
    cut.cut = Cut {
        planes: vec![ClipPlane {
            point: glam::DVec3::new(0.1, 0.0, 0.0),
            normal: glam::DVec3::X,
            enabled: true,
        }],
        crop: None,
    };
    let frames = [
        (base(0), false),
        (base(1), false),
        (base(2), false),
        (base(3), false),
        (moved.clone(), false),
        (moved, false),
        (edited.clone(), false),
        (edited, false),
        (cut.clone(), false),
        (cut.clone(), false),
        (cut.clone(), true),
        (cut.clone(), false),
        // A long still run: kept throughout (the graph releases images no frame used for
        // a few frames, so a kept march's images must count as used).
        (cut.clone(), false),
        (cut.clone(), false),
        (cut.clone(), false),
        (cut.clone(), false),
        (cut.clone(), false),
        (cut, false),
    ];
    // What each frame must do: march (true) or keep (false).
    let mut expect = vec![
        true, false, false, false, true, false, true, false, true, false, true, false,
    ];
    expect.extend([false; 6]);
    for methods in [&["ours", "svgf"][..], &["svgf"][..], &["taa"][..]] {
        let mut r = builtin_setup("phantom/point-light", 6, SIZE)
            .renderer(context(), methods)
            .expect("renderer");
        let done = run(&mut r, &frames);
        // The copy that keeps the march is owned as the march is (the methods that read
        // it: each one's cost), not a transfer.
        let owner = |d: &FrameResult, passes: &[&str]| {
            d.timings
                .iter()
                .find(|t| passes.contains(&t.pass.as_str()))
                .map(|t| t.owner.clone())
        };
        let march_owner = owner(&done[0], &MARCHES).expect("frame 0 marches");
        assert_ne!(march_owner, PassOwner::Transfer);
        for (f, (d, &march)) in done.iter().zip(&expect).enumerate() {
            assert_eq!(
                (marched(&d.timings), kept(&d.timings)),
                (march, !march),
                "{methods:?} frame {f}: march expected {march}"
            );
            let own = owner(d, &["features.kept", MARCHES[0], MARCHES[1]]);
            assert_eq!(own.as_ref(), Some(&march_owner), "{methods:?} frame {f}");
        }
        // A kept frame's images (features and methods) are those of a renderer whose
        // first frame marched them, given the same history of inputs: here, the
        // same frames with every frame marching (each renderer marches its first frame,
        // so one renderer per kept frame's features).
        for (f, d) in done.iter().enumerate().filter(|(f, _)| !expect[*f]) {
            let mut fresh = builtin_setup("phantom/point-light", 6, SIZE)
                .renderer(context(), methods)
                .expect("renderer");
            let first = run(&mut fresh, &frames[f..=f]);
            assert!(marched(&first[0].timings));
            for name in FEATURE_IMAGES {
                let get = |r: &FrameResult| {
                    images(r)
                        .into_iter()
                        .find(|(n, _)| n == name)
                        .unwrap_or_else(|| panic!("{name} read back"))
                        .1
                };
                assert!(
                    bits(&get(d)) == bits(&get(&first[0])),
                    "{methods:?} frame {f}: kept {name} differs from a march of that frame"
                );
            }
        }
    }
}

#[test]
fn a_frame_whose_bricks_land_in_the_pool_marches() {
    // 288³ (729 bricks) of a ramp, paged through a pool a little smaller than the dense texture
    // size. Frame 0's TF shows only the far corner's bricks; frame 1's shows every
    // brick, more than one frame streams (`STREAM_PER_FRAME`), so bricks land in later
    // frames whose inputs are frame 1's.
    const N: u32 = 288;
    let mut data = Vec::with_capacity((N * N * N) as usize);
    for z in 0..N {
        for y in 0..N {
            for x in 0..N {
                data.push(((x + y + z) * 255 / (3 * N)) as u8);
            }
        }
    }
    let volume = dvr_engine::renderer::uploads::VolumeUpload::from_volume(
        &Volume::new("ramps", [N; 3], [1.0; 3], VolumeData::U8(data)).expect("volume"),
    );
    let mut s = settings(SIZE, 1);
    s.config.gpu_memory = Some(u64::from(N * N * N) / 20 * 19);
    s.config.density_scale = 50.0;
    let mut r = Renderer::new(
        context(),
        s.settings,
        s.config,
        Arc::new(volume),
        None,
        &["svgf"],
        LUT as u32,
    )
    .expect("renderer");
    assert!(
        matches!(
            r.volume_residency(),
            dvr_engine::renderer::VolumeResidency::Pool { .. }
        ),
        "the volume is paged"
    );
    let all = inputs(
        front_camera(2.2, 40.0),
        vec![point_light(Vec3::new(0.8, 1.0, 1.5), 6.0)],
        constant_lut(0.3, 0.8),
    );
    let mut corner = all.clone();
    for (i, e) in corner.lut.diffuse_opacity.iter_mut().enumerate() {
        e[3] = if i > LUT * 9 / 10 { 0.3 } else { 0.0 };
    }
    let mut frames = vec![(corner, false)];
    frames.extend((0..7).map(|_| (all.clone(), false)));
    let done = run(&mut r, &frames);
    let landed: Vec<bool> = done
        .iter()
        .map(|d| d.timings.iter().any(|t| t.pass == "upload_brick_table"))
        .collect();
    assert!(
        landed[2..].iter().any(|&l| l),
        "bricks land after the TF's frame: {landed:?}"
    );
    for (f, d) in done.iter().enumerate() {
        if landed[f] {
            assert!(marched(&d.timings), "frame {f}: bricks landed, no march");
        }
    }
    assert!(
        done.iter().any(|d| kept(&d.timings)),
        "once the bricks are in, the still frames keep the march"
    );
}
