//! The present pass on the device, without a window: its GLSL tone map agrees with the
//! Rust one in `metrics::tonemap` (the project's single definition) on a ramp of HDR
//! values, the split view, offset and background land where they should, and a frame
//! smaller than its place is upsampled bilinearly into it.

mod common;

use ash::vk;
use common::*;
use dvr_engine::gpu::{validation, ImageDesc};
use dvr_engine::graph::Extent;
use dvr_engine::graph::{Frame, RenderGraph};
use dvr_engine::metrics::{tonemap_srgb, Rgb32Image};
use dvr_engine::passes::present::{Present, PresentLayout};
use dvr_engine::renderer::scene_gpu::add_upload;

/// Runs the present pass from `left`/`right` (w × h) into an rgba32f target.
fn present(
    left: &[[f32; 4]],
    right: &[[f32; 4]],
    size: Extent,
    target_size: Extent,
    layout: PresentLayout,
) -> Vec<[f32; 4]> {
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let pass = Present::new(&ctx).expect("present pipeline");
    let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
    let l = graph.image(&ctx, "left", desc).expect("image");
    let r = graph.image(&ctx, "right", desc).expect("image");
    let target = graph
        .image(
            &ctx,
            "target",
            ImageDesc::d2(
                target_size.width,
                target_size.height,
                vk::Format::R32G32B32A32_SFLOAT,
            ),
        )
        .expect("image");
    let mut f = Frame::new();
    add_upload(
        &ctx,
        &mut graph,
        &mut f,
        "upload_left",
        l,
        bytemuck::cast_slice(left),
    )
    .expect("upload");
    add_upload(
        &ctx,
        &mut graph,
        &mut f,
        "upload_right",
        r,
        bytemuck::cast_slice(right),
    )
    .expect("upload");
    pass.add(&mut f, l, r, size, target, target_size, &layout);
    ctx.submit_and_wait(|cmd| graph.execute(&ctx, cmd, None, f))
        .expect("submit");
    let out = read_image(&ctx, &mut graph, target);
    graph.destroy(&ctx);
    assert_eq!(
        validation::message_count(),
        0,
        "{:?}",
        validation::messages()
    );
    out
}

#[test]
fn glsl_tone_map_matches_the_rust_one_on_a_ramp() {
    // 0, tiny values in the linear toe of the sRGB curve, mid grey, 1, the clamp at
    // ~7.24, far above it, and the non-finite and negative inputs the Rust side tames.
    let mut values = vec![0.0f32, 1e-5, 1e-4, 2e-3];
    let mut x = 1e-3f32;
    while x < 200.0 {
        values.push(x);
        x *= 1.37;
    }
    values.extend([0.18, 1.0, 7.24, 1e4, -2.0, f32::NAN, f32::INFINITY]);
    let w = values.len() as u32;
    let pixels: Vec<[f32; 4]> = values.iter().map(|&v| [v, 0.5 * v, 2.0 * v, 1.0]).collect();
    let size = Extent {
        width: w,
        height: 1,
    };
    for exposure in [1.0f32, 0.5, 3.0] {
        let out = present(
            &pixels,
            &pixels,
            size,
            size,
            PresentLayout {
                exposure,
                ..Default::default()
            },
        );
        let want = tonemap_srgb(
            &Rgb32Image::new(w, 1, pixels.iter().map(|p| [p[0], p[1], p[2]]).collect()),
            exposure,
        );
        for (i, (g, r)) in out.iter().zip(&want.data).enumerate() {
            for c in 0..3 {
                assert!(
                    (g[c] - r[c]).abs() <= 1e-3,
                    "exposure {exposure}, value {} channel {c}: GLSL {} vs Rust {}",
                    values[i],
                    g[c],
                    r[c]
                );
            }
            assert_eq!(g[3], 1.0);
        }
    }
}

#[test]
fn split_offset_and_background_land_where_they_should() {
    let size = Extent {
        width: 8,
        height: 4,
    };
    let target = Extent {
        width: 12,
        height: 6,
    };
    let n = (size.width * size.height) as usize;
    let left = vec![[1.0f32, 1.0, 1.0, 1.0]; n];
    let right = vec![[0.0f32, 0.0, 0.0, 1.0]; n];
    let layout = PresentLayout {
        offset: [2, 1],
        size: None,
        split_x: Some(5),
        exposure: 1.0,
        background: [0.25, 0.5, 0.75],
    };
    let out = present(&left, &right, size, target, layout);
    let at = |x: u32, y: u32| out[(y * target.width + x) as usize];
    let lit = tonemap_srgb(&Rgb32Image::filled(1, 1, [1.0; 3]), 1.0).data[0][0];
    // Outside the frame: the background.
    for (x, y) in [(0, 0), (1, 3), (11, 5), (10, 2), (5, 0), (5, 5)] {
        assert_eq!(&at(x, y)[..3], &[0.25, 0.5, 0.75], "({x},{y})");
    }
    // Inside: left columns 0..5 from `left`, column 5 the divider, the rest `right`.
    for y in 1..5 {
        for sx in 0..8u32 {
            let p = at(sx + 2, y);
            let want = match sx {
                0..=4 => lit,
                5 => 1.0,
                _ => 0.0,
            };
            assert!((p[0] - want).abs() < 1e-5, "source column {sx}: {p:?}");
        }
    }
}

#[test]
fn a_smaller_frame_is_upsampled_bilinearly_into_its_place() {
    // A 2×2 source of values 0, 1 (top) and 2, 3 (bottom) filling an 8×8 view at offset
    // (1, 0) of a 10×8 target: each target pixel centre maps to source coordinates
    // (x + 0.5) / 4 − 0.5, clamped at the edges; the tone map runs after the blend.
    let size = Extent {
        width: 2,
        height: 2,
    };
    let target = Extent {
        width: 10,
        height: 8,
    };
    let left: Vec<[f32; 4]> = (0..4).map(|v| [v as f32, 0.0, 0.0, 1.0]).collect();
    let right = vec![[0.0f32, 0.0, 7.0, 1.0]; 4];
    let layout = PresentLayout {
        offset: [1, 0],
        size: Some([8, 8]),
        split_x: Some(6),
        exposure: 1.0,
        background: [0.25, 0.5, 0.75],
    };
    let out = present(&left, &right, size, target, layout);
    let at = |x: u32, y: u32| out[(y * target.width + x) as usize];
    let tone = |v: f32| tonemap_srgb(&Rgb32Image::filled(1, 1, [v, 0.0, 0.0]), 1.0).data[0][0];
    let coord = |i: u32| ((i as f32 + 0.5) / 4.0 - 0.5).clamp(0.0, 1.0);
    for y in 0..8u32 {
        assert_eq!(&at(0, y)[..3], &[0.25, 0.5, 0.75], "background at (0,{y})");
        assert_eq!(&at(9, y)[..3], &[0.25, 0.5, 0.75], "background at (9,{y})");
        for vx in 0..6u32 {
            let want = tone(coord(vx) + 2.0 * coord(y));
            let got = at(vx + 1, y);
            assert!(
                (got[0] - want).abs() < 1e-4 && got[2] == 0.0,
                "view ({vx},{y}): {got:?}, want red {want}"
            );
        }
        // The divider in view column 6, then the right image.
        assert_eq!(&at(7, y)[..3], &[1.0, 1.0, 1.0], "divider at row {y}");
        let blue = tonemap_srgb(&Rgb32Image::filled(1, 1, [0.0, 0.0, 7.0]), 1.0).data[0][2];
        assert!((at(8, y)[2] - blue).abs() < 1e-5, "right image at row {y}");
    }
}
