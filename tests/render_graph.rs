//! The render graph on the device: history resources swap and persist across frames,
//! undeclared resources are refused with the pass's name, new resources start at zero,
//! and the whole multi-frame run is validation clean.

mod common;

use ash::vk;
use common::*;
use dvr_engine::gpu::ImageDesc;
use dvr_engine::graph::Extent;
use dvr_engine::graph::{Frame, RenderGraph};
use dvr_engine::passes::accumulate::Accumulate;
use dvr_engine::renderer::scene_gpu::add_upload;

const W: u32 = 8;
const H: u32 = 4;

/// A W×H rgba32f graph image.
fn image(
    ctx: &dvr_engine::gpu::GpuContext,
    graph: &mut RenderGraph,
    name: &str,
) -> dvr_engine::graph::ImageHandle {
    let desc = ImageDesc::d2(W, H, vk::Format::R32G32B32A32_SFLOAT);
    graph.image(ctx, name, desc).expect("image")
}

/// A device, a graph, the accumulation pass and its input image.
fn accumulating() -> (
    dvr_engine::gpu::GpuContext,
    RenderGraph,
    Accumulate,
    dvr_engine::graph::ImageHandle,
) {
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let acc = Accumulate::new(&ctx).expect("pipeline");
    let input = image(&ctx, &mut graph, "input");
    (ctx, graph, acc, input)
}

/// Submits `f`, waits for it and ends the frame.
fn run_frame(ctx: &dvr_engine::gpu::GpuContext, graph: &mut RenderGraph, f: Frame<'_>) {
    ctx.submit_and_wait(|cmd| graph.execute(ctx, cmd, None, f))
        .expect("submit");
    graph.end_frame();
}

/// Adds an upload of `data` into `image` to `f`.
fn upload(
    ctx: &dvr_engine::gpu::GpuContext,
    graph: &mut RenderGraph,
    f: &mut Frame<'_>,
    image: dvr_engine::graph::ImageHandle,
    data: &[[f32; 4]],
) {
    add_upload(ctx, graph, f, "upload", image, bytemuck::cast_slice(data)).expect("upload");
}

#[test]
fn history_accumulates_across_frames_and_resets() {
    let (ctx, mut graph, acc, input) = accumulating();
    let size = Extent {
        width: W,
        height: H,
    };
    let mut means = Vec::new();
    for frame_index in 0..6u32 {
        if frame_index == 4 {
            graph.reset_history("acc.");
        }
        // Frame k uploads the constant value k; the running mean is the mean of the
        // values since the last reset.
        let value = frame_index as f32;
        let data = vec![[value, value, value, 1.0f32]; (W * H) as usize];
        let mut f = Frame::new();
        upload(&ctx, &mut graph, &mut f, input, &data);
        let mean = acc
            .add(&ctx, &mut graph, &mut f, "acc", input, 1.0, size)
            .expect("add");
        run_frame(&ctx, &mut graph, f);
        means.push(read_image(&ctx, &mut graph, mean)[0][0]);
    }
    assert_eq!(
        means[..4],
        [0.0, 0.5, 1.0, 1.5],
        "running mean over frames 0..3"
    );
    assert_eq!(means[4..], [4.0, 4.5], "restarted at the reset");
    graph.destroy(&ctx);
    assert_validation_clean();
}

/// A history whose first frame writes only its new side (a pass that does not read an
/// invalid history) is valid on the second frame, though that frame's new side is a
/// fresh image; a new size makes it invalid again.
#[test]
fn a_history_written_once_is_valid_on_the_next_frame() {
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let desc = ImageDesc::d2(W, H, vk::Format::R32G32B32A32_SFLOAT);
    let first = graph.history(&ctx, "h", desc).expect("history");
    assert!(!first.valid, "nothing written yet");
    let data = vec![[3.0f32, 2.0, 1.0, 1.0]; (W * H) as usize];
    let mut f = Frame::new();
    upload(&ctx, &mut graph, &mut f, first.cur, &data);
    run_frame(&ctx, &mut graph, f);
    let second = graph.history(&ctx, "h", desc).expect("history");
    assert!(second.valid, "frame 0 wrote it");
    assert_eq!(second.prev, first.cur);
    assert_eq!(read_image(&ctx, &mut graph, second.prev), data);
    run_frame(&ctx, &mut graph, Frame::new());
    let bigger = ImageDesc::d2(W * 2, H, vk::Format::R32G32B32A32_SFLOAT);
    let resized = graph.history(&ctx, "h", bigger).expect("history");
    assert!(!resized.valid, "a new size holds nothing");
    graph.destroy(&ctx);
    assert_validation_clean();
}

#[test]
fn undeclared_resources_are_refused_naming_the_pass() {
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let a = image(&ctx, &mut graph, "a");
    let b = image(&ctx, &mut graph, "b");
    // Compute passes bind only what they declare (`Bindings`); a recording closure can
    // still reach for a resource through the context, and must be refused.
    let mut f = Frame::new();
    f.add_pass(
        "sneaky",
        |d| {
            d.transfer_src(a);
        },
        move |pc| pc.image_desc(b).map(|_| ()),
    );
    let err = ctx
        .submit_and_wait(|cmd| graph.execute(&ctx, cmd, None, f))
        .expect_err("b was not declared");
    let msg = err.to_string();
    assert!(
        msg.contains("sneaky") && msg.contains("\"b\""),
        "message: {msg}"
    );
    graph.destroy(&ctx);
}

#[test]
fn new_images_start_at_zero() {
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let img = image(&ctx, &mut graph, "fresh");
    let px = read_image(&ctx, &mut graph, img);
    assert!(px.iter().all(|p| *p == [0.0; 4]));
    graph.destroy(&ctx);
    assert_validation_clean();
}

#[test]
fn a_volume_past_the_device_limits_is_paged_and_a_mis_sized_one_refused_before_allocation() {
    use dvr_engine::renderer::brick_pool::VolumePath;
    use dvr_engine::renderer::scene_gpu::plan_volume;
    use dvr_engine::renderer::uploads::{BrickRanges, VolumeFormat, VolumeUpload};
    let ctx = context();
    // A header whose bytes are missing: refused, naming the volume, before anything else.
    let huge = VolumeUpload {
        name: "huge".into(),
        dims: [4096, 4096, 4096],
        format: VolumeFormat::R16,
        bytes: Vec::new(),
        blocks: None,
        extra_channels: Vec::new(),
        world_size: [1.0; 3],
        window: [0.0, 1.0],
        mm_per_unit: 1.0,
        bricks: BrickRanges {
            brick: 8,
            grid: [1, 1, 1],
            min: vec![0.0],
            max: vec![1.0],
        },
    };
    let err = plan_volume(&ctx, &huge, None)
        .expect_err("no bytes for 128 GiB")
        .to_string();
    assert!(
        err.contains("huge") && err.contains("0 bytes"),
        "message: {err}"
    );
    // Taller than the 3D image limit: paged through the brick pool, not refused.
    let mut too_tall = huge.clone();
    too_tall.dims = [8, 8, ctx.info.max_image_dimension_3d + 1];
    too_tall.bytes = vec![0; 8 * 8 * too_tall.dims[2] as usize * 2];
    match plan_volume(&ctx, &too_tall, None).expect("pooled") {
        VolumePath::Pool(p) => assert!(p
            .pool_extent()
            .iter()
            .all(|&e| e <= ctx.info.max_image_dimension_3d)),
        VolumePath::Dense => panic!("past the 3D image limit"),
    }
    // Defect: a renderer made for a volume it could not hold failed only after its graph
    // held buffers, so the error came after the allocator's "leak detected" reports and
    // the device was torn down with objects alive. Now it fails before allocating anything.
    let s = settings(16, 1);
    let err = match dvr_engine::renderer::Renderer::new(
        ctx,
        s.settings,
        s.config,
        std::sync::Arc::new(huge),
        None,
        &["ours"],
        LUT as u32,
    ) {
        Ok(_) => panic!("a renderer for a volume without its bytes"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains("huge"), "message: {err}");
    assert_validation_clean();
}

#[test]
fn a_timed_pass_reports_the_bytes_of_what_it_declares() {
    use dvr_engine::gpu::timestamps::TimestampPool;
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let acc = Accumulate::new(&ctx).expect("pipeline");
    let mut timestamps = TimestampPool::new(&ctx).expect("timestamps");
    let input = image(&ctx, &mut graph, "input");
    let size = Extent {
        width: W,
        height: H,
    };
    let mut f = Frame::new();
    acc.add(&ctx, &mut graph, &mut f, "acc", input, 1.0, size)
        .expect("add");
    ctx.submit_and_wait(|cmd| {
        timestamps.reset(&ctx, cmd);
        graph.execute(&ctx, cmd, Some(&mut timestamps), f)
    })
    .expect("submit");
    let timings = timestamps.read(&ctx).expect("timings");
    // `accumulate` declares four rgba32f images of W×H: the input and last frame's sum
    // read, this frame's sum and the mean written.
    let image_bytes = u64::from(W * H) * 16;
    assert_eq!(timings.len(), 1);
    assert_eq!(timings[0].pass, "acc");
    assert_eq!(timings[0].bytes, 4 * image_bytes);
    assert!(timings[0].ms >= 0.0);
    timestamps.destroy(&ctx);
    graph.destroy(&ctx);
    assert_validation_clean();
}

#[test]
fn peak_bandwidth_is_measured_with_a_copy_pass() {
    let ctx = context();
    let peak = dvr_engine::passes::bandwidth::measure(&ctx).expect("probe");
    assert!(peak.gb_per_s > 0.0 && peak.gb_per_s.is_finite(), "{peak:?}");
    assert!(peak.method.contains("measured"), "{peak:?}");
    assert_validation_clean();
}

/// Images are created for the ways frames declare them: one only uploaded (a transfer
/// destination) and read as storage in a later frame is created again for that, with
/// its contents, and the run stays validation clean.
#[test]
fn an_image_used_a_new_way_keeps_its_contents() {
    let (ctx, mut graph, acc, input) = accumulating();
    let data = vec![[3.0f32, 2.0, 1.0, 1.0]; (W * H) as usize];
    let mut f = Frame::new();
    upload(&ctx, &mut graph, &mut f, input, &data);
    run_frame(&ctx, &mut graph, f);
    let size = Extent {
        width: W,
        height: H,
    };
    // Frames later, the upload is read as a storage image for the first time.
    for _ in 0..4 {
        let mut f = Frame::new();
        let mean = acc
            .add(&ctx, &mut graph, &mut f, "acc", input, 1.0, size)
            .expect("add");
        run_frame(&ctx, &mut graph, f);
        assert_eq!(read_image(&ctx, &mut graph, mean)[0], data[0]);
    }
    graph.destroy(&ctx);
    assert_validation_clean();
}

/// A denoiser switched off gives its images back after the next frame, and a smaller
/// view gives back the larger one's: a long session that switches and resizes holds the
/// memory of what it renders now, not of everything it ever rendered. A method switched
/// back on starts from cleared histories and renders the frames a fresh one does.
#[test]
fn images_no_frame_uses_any_more_are_released() {
    let volume = constant_volume(16, 0.7);
    let view = || {
        inputs(
            front_camera(2.5, 40.0),
            vec![
                point_light(glam::Vec3::new(1.0, 1.0, 2.0), 4.0),
                environment(0.2),
            ],
            constant_lut(0.6, 0.8),
        )
    };
    let request = dvr_engine::renderer::FrameRequest {
        readback: true,
        ..Default::default()
    };
    let mut r = renderer(
        context(),
        settings(32, 1),
        &volume,
        &["none", "ours", "svgf"],
    );
    for _ in 0..2 {
        r.frame(&view(), &request).expect("frame");
    }
    r.flush().expect("flush");
    let both = r.ctx().memory_in_use().allocated;
    r.set_denoisers(&["none", "taa"]).expect("switch");
    for _ in 0..2 {
        r.frame(&view(), &request).expect("frame");
    }
    r.flush().expect("flush");
    let taa = r.ctx().memory_in_use().allocated;
    assert!(
        taa < both,
        "switching ours and svgf off kept their images: {taa} >= {both} bytes"
    );
    r.resize(dvr_engine::graph::Extent {
        width: 16,
        height: 16,
    })
    .expect("resize");
    r.frame(&view(), &request).expect("frame");
    r.flush().expect("flush");
    let small = r.ctx().memory_in_use().allocated;
    assert!(
        small < taa,
        "a smaller view kept the larger images: {small} >= {taa} bytes"
    );
    assert_validation_clean();
}

/// Staging buffers go once no frame in flight copies from them: the volume's set-up
/// staging does not outlive the first frames, and a still view then holds the same
/// device memory frame after frame (what a long session holds follows what it draws).
#[test]
fn staging_is_released_and_a_still_view_holds_steady_memory() {
    let n = 32;
    let volume = constant_volume(n, 0.7);
    let view = inputs(
        front_camera(2.5, 40.0),
        vec![point_light(glam::Vec3::new(1.0, 1.0, 2.0), 4.0)],
        constant_lut(0.6, 0.8),
    );
    let request = dvr_engine::renderer::FrameRequest::default();
    let mut r = renderer(context(), settings(16, 1), &volume, &["ours"]);
    r.frame(&view, &request).expect("frame");
    r.flush().expect("flush");
    let first = r.ctx().memory_in_use().allocated;
    let mut after = Vec::new();
    for _ in 0..3 {
        for _ in 0..4 {
            r.frame(&view, &request).expect("frame");
        }
        r.flush().expect("flush");
        after.push(r.ctx().memory_in_use().allocated);
    }
    let volume_bytes = u64::from(n * n * n);
    assert!(
        first >= after[0] + volume_bytes,
        "the volume's staging ({volume_bytes} bytes) outlived the first frames: \
         {first} bytes after one frame, {} after five",
        after[0]
    );
    assert!(
        after.windows(2).all(|w| w[0] == w[1]),
        "a still view's device memory moved from frame to frame: {after:?}"
    );
    assert_validation_clean();
}
