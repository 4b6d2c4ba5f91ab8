//! Runs one denoiser on synthetic frames: the test supplies the noisy radiance, the scene
//! is static (fixed world positions, zero motion), so a denoiser's temporal behaviour can
//! be probed exactly (spikes, long static runs) without the path tracer's noise.

use ash::vk;
use dvr_engine::denoise::{self, Changes, DenoiseInputs, Denoiser};
use dvr_engine::gpu::{GpuContext, ImageDesc};
use dvr_engine::graph::Extent;
use dvr_engine::graph::{Frame, History, ImageHandle, RenderGraph};
use dvr_engine::passes::surface_features::FeatureImages;
use dvr_engine::renderer::scene_gpu::add_upload;
use dvr_engine::renderer::CameraMatrices;
use dvr_engine::shaders::frame::FrameBlock;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

pub struct Harness {
    pub ctx: GpuContext,
    graph: RenderGraph,
    denoiser: Box<dyn Denoiser>,
    pub width: u32,
    pub height: u32,
    frame: u64,
}

impl Harness {
    pub fn new(name: &str, width: u32, height: u32) -> Self {
        let ctx = super::context();
        let graph = RenderGraph::new(&ctx).expect("graph");
        let denoiser =
            denoise::registry::create(&ctx, name, &Default::default()).expect("denoiser");
        Self {
            ctx,
            graph,
            denoiser,
            width,
            height,
            frame: 0,
        }
    }

    fn upload(&mut self, f: &mut Frame<'_>, name: &str, img: ImageHandle, px: &[[f32; 4]]) {
        add_upload(
            &self.ctx,
            &mut self.graph,
            f,
            name,
            img,
            bytemuck::cast_slice(px),
        )
        .expect("upload");
    }

    fn history(&mut self, f: &mut Frame<'_>, name: &str, px: &[[f32; 4]]) -> History {
        let desc = ImageDesc::d2(self.width, self.height, vk::Format::R32G32B32A32_SFLOAT);
        let h = self.graph.history(&self.ctx, name, desc).expect("history");
        self.upload(f, &format!("upload_{name}"), h.cur, px);
        h
    }

    /// Feeds one noisy frame; returns the denoiser's output.
    pub fn step(&mut self, noisy: &[[f32; 4]]) -> Vec<[f32; 4]> {
        let (w, h) = (self.width, self.height);
        let n = (w * h) as usize;
        assert_eq!(noisy.len(), n);
        let desc = ImageDesc::d2(w, h, vk::Format::R32G32B32A32_SFLOAT);
        // A flat surface at z = 0 seen by a camera one unit away: each pixel's world
        // position is where its centre ray meets the plane, so reprojection round trips
        // land exactly on the pixel.
        let camera = CameraMatrices::look_at(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::ZERO,
            Vec3::Y,
            60f32.to_radians(),
            w as f32 / h as f32,
        );
        let view_proj = camera.proj * camera.view;
        let inv = view_proj.inverse();
        let positions: Vec<[f32; 4]> = (0..n as u32)
            .map(|i| {
                let ndc_x = ((i % w) as f32 + 0.5) / w as f32 * 2.0 - 1.0;
                let ndc_y = ((i / w) as f32 + 0.5) / h as f32 * 2.0 - 1.0;
                let near = inv.project_point3(Vec3::new(ndc_x, ndc_y, 0.0));
                let far = inv.project_point3(Vec3::new(ndc_x, ndc_y, 1.0));
                let t = near.z / (near.z - far.z);
                let p = near + (far - near) * t;
                [p.x, p.y, p.z, 1.0]
            })
            .collect();
        let mut frame_uniforms: FrameBlock = bytemuck::Zeroable::zeroed();
        frame_uniforms.view_proj = view_proj;
        frame_uniforms.inv_view_proj = inv;
        frame_uniforms.prev_view_proj = view_proj;
        frame_uniforms.camera_pos = camera.position.extend(1.0);
        let normals = vec![[0.0, 0.0, 1.0, 1.0]; n];
        let albedo = vec![[0.8, 0.8, 0.8, 1.0]; n];
        let zeros = vec![[0.0f32; 4]; n];
        let moments: Vec<[f32; 4]> = noisy
            .iter()
            .map(|p| {
                let y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                [y, y * y, 0.0, 0.0]
            })
            .collect();
        let mut f = Frame::new();
        let g = &mut self.graph;
        let ctx = &self.ctx;
        let noisy_img = g.image(ctx, "h.noisy", desc).expect("image");
        let moments_img = g.image(ctx, "h.moments", desc).expect("image");
        let normal_img = g.image(ctx, "h.normal", desc).expect("image");
        let albedo_img = g.image(ctx, "h.albedo", desc).expect("image");
        let motion_img = g.image(ctx, "h.motion", desc).expect("image");
        let uniforms = g
            .buffer(
                ctx,
                "h.uniforms",
                std::mem::size_of::<FrameBlock>() as u64,
                MemoryLocation::CpuToGpu,
            )
            .expect("buffer");
        g.buffer_mut(uniforms)
            .write(bytemuck::bytes_of(&frame_uniforms))
            .expect("uniforms");
        self.upload(&mut f, "upload_noisy", noisy_img, noisy);
        self.upload(&mut f, "upload_moments", moments_img, &moments);
        self.upload(&mut f, "upload_normal", normal_img, &normals);
        self.upload(&mut f, "upload_albedo", albedo_img, &albedo);
        self.upload(&mut f, "upload_motion", motion_img, &zeros);
        let first_hit = self.history(&mut f, "h.first_hit", &positions);
        let feature_position = self.history(&mut f, "h.features_position", &positions);
        let input = DenoiseInputs {
            uniforms,
            noisy: noisy_img,
            moments: moments_img,
            features: Some(FeatureImages {
                position: feature_position,
                normal: normal_img,
                albedo: albedo_img,
            }),
            guides: None,
            first_hit,
            motion: motion_img,
            size: Extent {
                width: w,
                height: h,
            },
            camera: glam::Vec3::new(0.0, 0.0, 1.0),
            // One sample per pixel: the moments above are those of one sample (no variance), so
            // a method that estimates noise from them must use the frame's spread instead.
            spp: 1,
            changes: Changes {
                camera: self.frame == 0,
                lights: false,
                transfer_function: false,
                cut: false,
            },
            retrace: None,
        };
        let out = self
            .denoiser
            .add(&self.ctx, &mut self.graph, &mut f, &input)
            .expect("add");
        let bytes = (n * 16) as u64;
        let rb = self
            .graph
            .buffer(&self.ctx, "h.readback", bytes, MemoryLocation::GpuToCpu)
            .expect("buffer");
        f.add_readback("output", out, rb);
        let graph = &mut self.graph;
        self.ctx
            .submit_and_wait(|cmd| graph.execute(&self.ctx, cmd, None, f))
            .expect("submit");
        self.graph.end_frame();
        self.frame += 1;
        bytemuck::cast_slice::<u8, [f32; 4]>(self.graph.buffer_ref(rb).mapped().expect("mapped"))
            .to_vec()
    }
}

impl Drop for Harness {
    fn drop(&mut self) {
        let _ = self.ctx.wait_idle();
        self.graph.destroy(&self.ctx);
    }
}

/// A deterministic noisy frame: `mean` plus uniform noise of amplitude `amp`.
pub fn noisy_frame(n: usize, mean: f32, amp: f32, seed: u64) -> Vec<[f32; 4]> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            let mut next = || {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
            };
            let v = (mean + amp * next()).max(0.0);
            [v, v * 0.8, v * 0.6, 1.0]
        })
        .collect()
}
