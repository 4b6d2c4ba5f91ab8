//! Shared set-up for the integration tests: a headless context on whatever device the
//! environment selects (lavapipe in CI), synthetic volumes and transfer functions with
//! known optics, and the validation check every GPU test ends with.
#![allow(dead_code)]

pub mod cli;
pub mod cli_page;
pub mod eval;

use dvr_engine::gpu::{validation, GpuContext};
use dvr_engine::graph::Extent;
use dvr_engine::renderer::uploads::{BrickRanges, LutUpload, VolumeFormat, VolumeUpload};
use dvr_engine::renderer::{CameraMatrices, FrameInputs, FrameRequest, FrameResult};
use dvr_engine::renderer::{Renderer, RendererConfig};
use dvr_engine::scene::RenderSettings;
use dvr_engine::shaders::frame::{GpuLight, ENV_CONSTANT, LIGHT_ENV, LIGHT_POINT};
use glam::{Vec3, Vec4};

pub const LUT: usize = 256;

/// A built-in scene `frames` long at `size`² with a 32³ procedural volume.
pub fn builtin_setup(
    name: &str,
    frames: u32,
    size: u32,
) -> dvr_engine::renderer::scene_setup::SceneSetup {
    let scene = dvr_engine::scene::Scene::builtin(name)
        .expect("scene")
        .with_frames(frames)
        .expect("frames");
    let extent = Extent {
        width: size,
        height: size,
    };
    dvr_engine::renderer::scene_setup::SceneSetup::new(scene, extent, None, 32).expect("setup")
}

pub fn context() -> GpuContext {
    GpuContext::headless().expect("a Vulkan device (install mesa-vulkan-drivers for lavapipe)")
}

/// A cube of constant density `d` filling the whole box.
pub fn constant_volume(n: u32, d: f32) -> VolumeUpload {
    let v = (d.clamp(0.0, 1.0) * 255.0).round() as u8;
    let dn = v as f32 / 255.0;
    VolumeUpload {
        name: "constant".into(),
        dims: [n, n, n],
        format: VolumeFormat::R8,
        bytes: vec![v; (n * n * n) as usize],
        blocks: None,
        extra_channels: Vec::new(),
        world_size: [1.0, 1.0, 1.0],
        window: [0.0, 1.0],
        mm_per_unit: 1.0,
        bricks: BrickRanges {
            brick: n,
            grid: [1, 1, 1],
            min: vec![dn],
            max: vec![dn],
        },
    }
}

/// A LUT with constant opacity and albedo, no specular, no emission.
pub fn constant_lut(opacity: f32, albedo: f32) -> LutUpload {
    LutUpload {
        diffuse_opacity: vec![[albedo, albedo, albedo, opacity]; LUT],
        specular_roughness: vec![[0.0, 0.0, 0.0, 0.5]; LUT],
        emissive: vec![[0.0; 4]; LUT],
    }
}

pub fn environment(radiance: f32) -> GpuLight {
    GpuLight {
        position_kind: Vec4::new(0.0, 0.0, 0.0, LIGHT_ENV),
        radiance: Vec4::new(radiance, radiance, radiance, ENV_CONSTANT),
        ..Default::default()
    }
}

pub fn point_light(pos: Vec3, intensity: f32) -> GpuLight {
    GpuLight {
        position_kind: pos.extend(LIGHT_POINT),
        radiance: Vec4::new(intensity, intensity, intensity, 0.0),
        ..Default::default()
    }
}

/// Looking down −z at the box from z = `dist`, with a narrow field of view.
pub fn front_camera(dist: f32, fov_deg: f32) -> CameraMatrices {
    CameraMatrices::look_at(
        Vec3::new(0.0, 0.0, dist),
        Vec3::ZERO,
        Vec3::Y,
        fov_deg.to_radians(),
        1.0,
    )
}

/// What a test renderer is built with.
pub struct TestSettings {
    pub settings: RenderSettings,
    pub config: RendererConfig,
}

/// A `size`² renderer at `spp` samples per frame, 8 bounces and a one-voxel ray-march
/// step (the values these tests were written with), density scale 100.
pub fn settings(size: u32, spp: u32) -> TestSettings {
    let mut settings = RenderSettings::default();
    settings.set_spp(spp).expect("spp");
    settings.set_max_bounces(8).expect("bounces");
    settings.set_step_size(1.0).expect("step");
    TestSettings {
        settings,
        config: RendererConfig {
            size: Extent {
                width: size,
                height: size,
            },
            ..Default::default()
        },
    }
}

pub fn renderer(
    ctx: GpuContext,
    s: TestSettings,
    v: &VolumeUpload,
    denoisers: &[&str],
) -> Renderer {
    renderer_with(ctx, s, v, None, denoisers)
}

pub fn renderer_with(
    ctx: GpuContext,
    s: TestSettings,
    v: &VolumeUpload,
    environment: Option<&dvr_engine::renderer::uploads::EnvironmentUpload>,
    denoisers: &[&str],
) -> Renderer {
    Renderer::new(
        ctx,
        s.settings,
        s.config,
        std::sync::Arc::new(v.clone()),
        environment,
        denoisers,
        LUT as u32,
    )
    .expect("renderer")
}

pub fn inputs(camera: CameraMatrices, lights: Vec<GpuLight>, lut: LutUpload) -> FrameInputs {
    FrameInputs {
        camera,
        lights,
        lut,
        cut: Default::default(),
        time: None,
        labels: None,
    }
}

/// A frame request that reads every method's output back.
pub fn readback() -> FrameRequest {
    FrameRequest {
        readback: true,
        ..Default::default()
    }
}

/// Renders `frames` in order with `request`, then the frames still in flight: every
/// result, by frame index.
pub fn render_frames(
    r: &mut Renderer,
    frames: impl IntoIterator<Item = FrameInputs>,
    request: &FrameRequest,
) -> Vec<FrameResult> {
    let mut done = Vec::new();
    for inputs in frames {
        done.extend(r.frame(&inputs, request).expect("frame"));
    }
    done.extend(r.flush().expect("flush"));
    done.sort_by_key(|f| f.index);
    done
}

/// Mean squared error over the colour channels of two rgba images.
pub fn mse(a: &[[f32; 4]], b: &[[f32; 4]]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|c| ((x[c] - y[c]) as f64).powi(2)).sum::<f64>())
        .sum::<f64>()
        / (3 * a.len()) as f64
}

pub fn mean_rgb(pixels: &[[f32; 4]]) -> [f64; 3] {
    let mut s = [0.0f64; 3];
    for p in pixels {
        for c in 0..3 {
            s[c] += p[c] as f64;
        }
    }
    s.map(|v| v / pixels.len() as f64)
}

/// Reads an rgba32f graph image back to the host (one submit, waited for).
pub fn read_image(
    ctx: &GpuContext,
    graph: &mut dvr_engine::graph::RenderGraph,
    image: dvr_engine::graph::ImageHandle,
) -> Vec<[f32; 4]> {
    let bytes = graph.image_desc(image).texel_count() * 16;
    let buf = graph
        .buffer(
            ctx,
            "test.readback",
            bytes,
            gpu_allocator::MemoryLocation::GpuToCpu,
        )
        .expect("readback buffer");
    let mut f = dvr_engine::graph::Frame::new();
    f.add_readback("test", image, buf);
    ctx.submit_and_wait(|cmd| graph.execute(ctx, cmd, None, f))
        .expect("submit");
    bytemuck::cast_slice::<u8, [f32; 4]>(graph.buffer_ref(buf).mapped().expect("mapped")).to_vec()
}

/// Fails unless `got` is within `tolerance` of `want`, relative to `want`; the message
/// names what was measured (`what`) and both values.
pub fn assert_relative(got: f64, want: f64, tolerance: f64, what: &str) {
    assert!(
        ((got - want) / want).abs() < tolerance,
        "{what}: {got}, expected {want} (within {tolerance} of it)"
    );
}

/// Fails the test if the validation layer reported anything in this process.
pub fn assert_validation_clean() {
    let msgs = validation::messages();
    assert!(
        msgs.is_empty(),
        "validation reported {} messages:\n{}",
        msgs.len(),
        msgs.join("\n")
    );
}

pub mod harness;
