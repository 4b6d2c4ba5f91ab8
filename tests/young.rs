//! Ours' young-pixel network on the device: the compute shaders reproduce the framework
//! that trained it (tools/young/model.py in torch, fp32) on a frame stored as a fixture by
//! tools/young/export.py from the shipped weights, at 29×21, an odd size, so the
//! half-resolution trunk's edge windows and the bilinear upsampling's edges are
//! exercised. The shipped manifest loads; a truncated weight file, a missing one or a
//! wrong layer list are clear errors naming the file. On a rendered scene the network
//! runs on the first frame only, where every state of the filter restarted.

mod common;

use common::*;
use dvr_engine::denoise::ours::young::{Layout, YoungInputs, YoungNet, YoungWeights};
use dvr_engine::gpu::ImageDesc;
use dvr_engine::graph::{Extent, Frame, RenderGraph};
use dvr_engine::renderer::scene_gpu::add_upload;
use gpu_allocator::MemoryLocation;
use std::path::Path;

/// Agreement bound between the shaders and torch, in HDR units (the fixture's outputs
/// reach ~1): the network's own arithmetic differs by rounding only (log(1 + x) for
/// torch's log1p, the order of the sums).
const TOLERANCE: f32 = 1e-4;

type Px = [f32; 4];

/// (width, height, [noisy, albedo, normal, ours, expected]).
fn fixture() -> (u32, u32, Vec<Vec<Px>>) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/young/young.bin");
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let word = |i: usize| u32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
    let (w, h) = (word(0), word(1));
    let n = (w * h) as usize;
    let floats: Vec<f32> = bytes[8..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(floats.len(), 5 * n * 4, "{}: size", path.display());
    let images = floats
        .chunks_exact(n * 4)
        .map(|img| {
            img.chunks_exact(4)
                .map(|c| [c[0], c[1], c[2], c[3]])
                .collect()
        })
        .collect();
    (w, h, images)
}

/// The largest difference between the shaders' output (tensors laid out `columns` groups
/// to a row, or as the device's limit allows) and torch's.
fn difference_from_torch(columns: Option<u32>) -> f32 {
    let (w, h, images) = fixture();
    let ctx = context();
    let mut graph = RenderGraph::new(&ctx).expect("graph");
    let net = YoungNet::new(&ctx, YoungWeights::builtin().expect("shipped weights")).expect("net");
    let size = Extent {
        width: w,
        height: h,
    };
    let desc = ImageDesc::d2(w, h, ash::vk::Format::R32G32B32A32_SFLOAT);
    let mut f = Frame::new();
    let mut handles = Vec::new();
    for (i, px) in images[..4].iter().enumerate() {
        let img = graph.image(&ctx, &format!("t.in{i}"), desc).expect("image");
        add_upload(
            &ctx,
            &mut graph,
            &mut f,
            &format!("up{i}"),
            img,
            bytemuck::cast_slice(px),
        )
        .expect("upload");
        handles.push(img);
    }
    let inputs = YoungInputs {
        noisy: handles[0],
        albedo: handles[1],
        normal: handles[2],
        ours: handles[3],
    };
    let mut layout = net.layout(&ctx, size).expect("a layout");
    if let Some(c) = columns {
        layout.columns = c;
    }
    let out = net
        .add(&ctx, &mut graph, &mut f, "t", size, layout, inputs)
        .expect("add");
    let n = (w * h) as usize;
    let rb = graph
        .buffer(
            &ctx,
            "t.readback",
            (n * 16) as u64,
            MemoryLocation::GpuToCpu,
        )
        .expect("buffer");
    f.add_readback("out", out, rb);
    let g = &mut graph;
    ctx.submit_and_wait(|cmd| g.execute(&ctx, cmd, None, f))
        .expect("submit");
    let got: Vec<Px> =
        bytemuck::cast_slice(graph.buffer_ref(rb).mapped().expect("mapped")).to_vec();
    let expected = &images[4];
    let (mut worst, mut peak, mut moved) = (0.0f32, 0.0f32, 0.0f32);
    for ((o, e), (noisy, ours)) in got
        .iter()
        .zip(expected)
        .zip(images[0].iter().zip(&images[3]))
    {
        for c in 0..3 {
            worst = worst.max((o[c] - e[c]).abs());
            peak = peak.max(e[c]);
            // How far the network's output is from both its inputs: a test that would
            // pass on a copy of either is no test.
            moved = moved.max((e[c] - noisy[c]).abs().min((e[c] - ours[c]).abs()));
        }
    }
    println!("young, {layout:?}: max |shader - torch| = {worst:.3e} (outputs up to {peak:.3}; {moved:.3} from the nearer input)");
    assert!(
        peak > 0.1 && moved > 0.05,
        "the fixture does not exercise the network"
    );
    ctx.wait_idle().expect("idle");
    graph.destroy(&ctx);
    worst
}

#[test]
fn shaders_match_torch_on_a_frame() {
    // One row of groups, and the groups tiled three to a row (as a frame wider than the
    // device's image limit allows lays them out).
    for columns in [None, Some(3)] {
        let worst = difference_from_torch(columns);
        assert!(
            worst < TOLERANCE,
            "{columns:?}: shaders differ from torch by {worst}"
        );
    }
    assert_validation_clean();
}

#[test]
fn tensors_tile_within_the_image_limit() {
    let size = |width, height| Extent { width, height };
    // Ten groups (the head's 37 channels) of a 4K frame's half: 1920 wide, four to a row
    // within 8192 texels; one row where they fit.
    let l = Layout::new(size(3840, 2160), 10, 8192).expect("fits");
    assert_eq!((l.width, l.height, l.columns), (1920, 1080, 4));
    assert_eq!(
        Layout::new(size(256, 256), 10, 16384).map(|l| l.columns),
        Some(10)
    );
    // Odd sizes round up, as the trunk's pooling does.
    assert_eq!(
        Layout::new(size(29, 21), 3, 4096).map(|l| (l.width, l.height)),
        Some((15, 11))
    );
    // Nothing fits: no layout, and ours goes without the network.
    assert_eq!(Layout::new(size(20000, 20000), 10, 8192), None);
    assert_eq!(Layout::new(size(16000, 16000), 10, 16384), None);
}

#[test]
fn bad_weight_files_are_clear_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let shipped = dvr_engine::assets::young_manifest();
    let manifest = std::fs::read_to_string(&shipped).expect("manifest");
    let bin = std::fs::read(shipped.with_file_name("young.bin")).expect("weights");
    let load_error = |name: &str| {
        let e = YoungWeights::load(&dir.path().join(name))
            .expect_err("a bad weight file must not load")
            .to_string();
        println!("{e}");
        e
    };
    std::fs::write(dir.path().join("young.json"), &manifest).unwrap();
    std::fs::write(dir.path().join("young.bin"), &bin[..bin.len() - 8]).unwrap();
    let e = load_error("young.json");
    assert!(e.contains("young.bin") && e.contains("truncated"), "{e}");

    std::fs::remove_file(dir.path().join("young.bin")).unwrap();
    let e = load_error("young.json");
    assert!(e.contains("young.bin") && e.contains("cannot read"), "{e}");

    // A dilation the layer list does not have.
    std::fs::write(dir.path().join("young.bin"), &bin).unwrap();
    let bad = manifest.replacen("\"dilation\": 2", "\"dilation\": 3", 1);
    assert_ne!(bad, manifest, "the edit must apply");
    std::fs::write(dir.path().join("bad.json"), bad).unwrap();
    let e = load_error("bad.json");
    assert!(e.contains("bad.json") && e.contains("trunk1"), "{e}");

    std::fs::write(dir.path().join("junk.json"), "width = 12").unwrap();
    let e = load_error("junk.json");
    assert!(
        e.contains("junk.json") && e.contains("not a young-pixel"),
        "{e}"
    );
    assert!(YoungWeights::builtin().is_ok());
}
