//! Runs one denoiser on synthetic frames: the test supplies the noisy radiance, the scene
//! is static (fixed world positions, zero motion), so a denoiser's temporal behaviour can
//! be probed exactly (spikes, long static runs) without the path tracer's noise. A test
//! with a scene of its own gives each frame's images itself ([`Harness::step_with`]).

use ash::vk;
use dvr_engine::denoise::{self, Changes, DenoiseFrame, DenoiseInputs, Denoiser};
use dvr_engine::gpu::{GpuContext, ImageDesc};
use dvr_engine::graph::Extent;
use dvr_engine::graph::{Frame, History, ImageHandle, RenderGraph};
use dvr_engine::passes::surface_features::FeatureImages;
use dvr_engine::renderer::scene_gpu::add_upload;
use dvr_engine::renderer::CameraMatrices;
use dvr_engine::shaders::frame::FrameBlock;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

type Px = [f32; 4];

pub struct Harness {
    pub ctx: GpuContext,
    graph: RenderGraph,
    denoiser: Box<dyn Denoiser>,
    pub width: u32,
    pub height: u32,
    frame: u64,
}

/// One synthetic frame: the noisy radiance and everything a denoiser reads beside it,
/// one value per pixel for the images.
pub struct Synthetic<'a> {
    pub noisy: &'a [Px],
    /// Luminance moments (x mean, y second moment).
    pub moments: &'a [Px],
    /// World positions, for both the first hit and the surface features.
    pub position: &'a [Px],
    pub normal: &'a [Px],
    pub albedo: &'a [Px],
    pub uniforms: FrameBlock,
    pub camera: Vec3,
    pub spp: u32,
    pub changes: Changes,
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

    fn desc(&self) -> ImageDesc {
        ImageDesc::d2(self.width, self.height, vk::Format::R32G32B32A32_SFLOAT)
    }

    fn upload(&mut self, f: &mut Frame<'_>, name: &str, img: ImageHandle, px: &[Px]) {
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

    fn history(&mut self, f: &mut Frame<'_>, name: &str, px: &[Px]) -> History {
        let h = self
            .graph
            .history(&self.ctx, name, self.desc())
            .expect("history");
        self.upload(f, &format!("upload_{name}"), h.cur, px);
        h
    }

    /// Uploads `px` as the image `name` of this frame.
    fn image(&mut self, f: &mut Frame<'_>, name: &str, px: &[Px]) -> ImageHandle {
        let img = self
            .graph
            .image(&self.ctx, name, self.desc())
            .expect("image");
        self.upload(f, &format!("upload_{name}"), img, px);
        img
    }

    /// Fills both images of the history `name` with `px` (without ending a frame, so
    /// the next step sees the same pair and the same `valid`).
    pub fn poison_history(&mut self, name: &str, px: &[Px]) {
        let h = self
            .graph
            .history(&self.ctx, name, self.desc())
            .expect("history");
        let mut f = Frame::new();
        self.upload(&mut f, &format!("poison_{name}_prev"), h.prev, px);
        self.upload(&mut f, &format!("poison_{name}_cur"), h.cur, px);
        let graph = &mut self.graph;
        let ctx = &self.ctx;
        ctx.submit_and_wait(|cmd| graph.execute(ctx, cmd, None, f))
            .expect("submit");
    }

    /// Resets the histories whose names start with `prefix`.
    pub fn reset(&mut self, prefix: &str) {
        self.graph.reset_history(prefix);
    }

    /// Feeds one noisy frame of a flat surface at z = 0, seen by a still camera one unit
    /// away; returns the denoiser's output.
    pub fn step(&mut self, noisy: &[Px]) -> Vec<Px> {
        let (w, h) = (self.width, self.height);
        let n = (w * h) as usize;
        // Each pixel's world position is where its centre ray meets the plane, so
        // reprojection round trips land exactly on the pixel.
        let camera = CameraMatrices::look_at(
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::ZERO,
            Vec3::Y,
            60f32.to_radians(),
            w as f32 / h as f32,
        );
        let view_proj = camera.proj * camera.view;
        let inv = view_proj.inverse();
        let positions: Vec<Px> = (0..n as u32)
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
        let mut uniforms: FrameBlock = bytemuck::Zeroable::zeroed();
        uniforms.view_proj = view_proj;
        uniforms.inv_view_proj = inv;
        uniforms.prev_view_proj = view_proj;
        uniforms.camera_pos = camera.position.extend(1.0);
        let moments: Vec<Px> = noisy
            .iter()
            .map(|p| {
                let y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                [y, y * y, 0.0, 0.0]
            })
            .collect();
        self.step_with(&Synthetic {
            noisy,
            moments: &moments,
            position: &positions,
            normal: &vec![[0.0, 0.0, 1.0, 1.0]; n],
            albedo: &vec![[0.8, 0.8, 0.8, 1.0]; n],
            uniforms,
            camera: Vec3::new(0.0, 0.0, 1.0),
            // One sample per pixel: the moments above are those of one sample (no
            // variance), so a method that estimates noise from them must use the frame's
            // spread instead.
            spp: 1,
            changes: Changes {
                camera: self.frame == 0,
                ..Changes::default()
            },
        })
    }

    /// Feeds one synthetic frame with zero motion; returns the denoiser's output.
    pub fn step_with(&mut self, s: &Synthetic) -> Vec<Px> {
        let n = (self.width * self.height) as usize;
        assert_eq!(s.noisy.len(), n);
        let mut f = Frame::new();
        let uniforms = self
            .graph
            .buffer(
                &self.ctx,
                "h.uniforms",
                std::mem::size_of::<FrameBlock>() as u64,
                MemoryLocation::CpuToGpu,
            )
            .expect("buffer");
        self.graph
            .buffer_mut(uniforms)
            .write(bytemuck::bytes_of(&s.uniforms))
            .expect("uniforms");
        let noisy = self.image(&mut f, "h.noisy", s.noisy);
        let moments = self.image(&mut f, "h.moments", s.moments);
        let normal = self.image(&mut f, "h.normal", s.normal);
        let albedo = self.image(&mut f, "h.albedo", s.albedo);
        let motion = self.image(&mut f, "h.motion", &vec![[0.0; 4]; n]);
        let first_hit = self.history(&mut f, "h.first_hit", s.position);
        let feature_position = self.history(&mut f, "h.features_position", s.position);
        let input = DenoiseInputs {
            uniforms,
            noisy,
            moments,
            features: Some(FeatureImages {
                position: feature_position,
                normal,
                albedo,
            }),
            guides: None,
            first_hit,
            motion,
            size: Extent {
                width: self.width,
                height: self.height,
            },
            camera: s.camera,
            spp: s.spp,
            changes: s.changes,
            retrace: None,
        };
        let out = self
            .denoiser
            .add(DenoiseFrame {
                ctx: &self.ctx,
                graph: &mut self.graph,
                frame: &mut f,
                input: &input,
            })
            .expect("add");
        let rb = self
            .graph
            .buffer(
                &self.ctx,
                "h.readback",
                (n * 16) as u64,
                MemoryLocation::GpuToCpu,
            )
            .expect("buffer");
        f.add_readback("output", out, rb);
        let graph = &mut self.graph;
        self.ctx
            .submit_and_wait(|cmd| graph.execute(&self.ctx, cmd, None, f))
            .expect("submit");
        self.graph.end_frame();
        self.frame += 1;
        bytemuck::cast_slice::<u8, Px>(self.graph.buffer_ref(rb).mapped().expect("mapped")).to_vec()
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
