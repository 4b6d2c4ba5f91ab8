//! The frame. [`Renderer::frame`] reads like the pipeline: uniforms → surface features →
//! path trace → motion → each denoiser → readbacks → (present to a window), all in one
//! render graph, submitted once. Frames alternate between two slots so recording frame N overlaps the GPU's work
//! on frame N−1; timestamps and readbacks of a slot are collected when it comes round.

pub mod present;
pub mod scene_gpu;
pub mod scene_setup;
pub mod uniforms;

use crate::denoise::{self, Changes, DenoiseInputs, Denoiser, Retrace};
use crate::error::{EngineError, Result, VkContext};
use crate::gpu::timestamps::{PassTiming, TimestampPool};
use crate::gpu::GpuContext;
use crate::graph::{BufferHandle, Frame, ImageHandle, RenderGraph};
use crate::passes::accumulate::Accumulate;
use crate::passes::motion::Motion;
use crate::passes::path_trace::{PathTrace, PathTraceFeatures};
use crate::passes::present::Present;
use crate::passes::surface_features::SurfaceFeatures;
use crate::passes::{Extent, SceneBindings};
use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
pub use present::{Overlay, PresentTarget, Screenshot};
use scene_gpu::{EnvironmentUpload, LutUpload, SceneImages, VolumeUpload};
use std::sync::Arc;
use uniforms::{FrameUniforms, GpuLight, MAX_LIGHTS};

const SLOTS: usize = 2;

/// Most samples one path-tracing dispatch takes per pixel on lavapipe. llvmpipe guards
/// every shader loop with an iteration limiter (65535) whose count is not reset when an
/// inner loop is re-entered, so a dispatch whose per-pixel sample loop runs many
/// delta-tracking or ray-marching steps is silently cut short (measured: 128 samples in
/// one dispatch came out 27% dark, 512 samples 73% dark). There, references accumulate
/// batches of at most this many samples and per-frame rendering is limited to it; other
/// devices have no such limiter (see [`samples_per_dispatch`]).
pub const MAX_SAMPLES_PER_DISPATCH: u32 = 4;

/// Pixel-samples one path-tracing dispatch may take on a device without llvmpipe's loop
/// limiter: 256×256 at 1024 spp (a suite reference in one dispatch). It keeps one
/// dispatch short (about 20 ms on an H200, well under a second on a small GPU) so no
/// display watchdog fires and the queue stays responsive; larger images split their
/// references into a few dispatches.
pub const PIXEL_SAMPLES_PER_DISPATCH: u64 = 1 << 26;

/// Most samples per pixel one path-tracing dispatch of `pixels` pixels takes on the
/// device described by `info`: [`MAX_SAMPLES_PER_DISPATCH`] on lavapipe (detected by
/// its driver ID), else as many as [`PIXEL_SAMPLES_PER_DISPATCH`] allows, never fewer
/// than lavapipe's.
pub fn samples_per_dispatch(info: &crate::gpu::DeviceInfo, pixels: u64) -> u32 {
    if info.is_llvmpipe() {
        return MAX_SAMPLES_PER_DISPATCH;
    }
    let n = PIXEL_SAMPLES_PER_DISPATCH / pixels.max(1);
    n.clamp(u64::from(MAX_SAMPLES_PER_DISPATCH), u64::from(u32::MAX)) as u32
}

/// Fixed settings of a renderer (changing them means a new renderer).
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub size: Extent,
    pub spp: u32,
    pub max_bounces: u32,
    /// Bounce from which Russian roulette may end a path.
    pub rr_depth: u32,
    pub features: PathTraceFeatures,
    pub hg_g: f32,
    /// Ray-marching step in voxels (ray-march estimator only).
    pub step_voxels: f32,
    /// Accumulated opacity at which the surface-features pass stops.
    pub feature_threshold: f32,
    /// Standard deviation of the Gaussian pixel filter, in pixels.
    pub filter_sigma: f32,
    /// Extinction per unit opacity (1/world unit).
    pub density_scale: f32,
    pub seed: u32,
    /// What the temporal denoisers reproject with.
    pub motion_source: denoise::MotionSource,
    /// The built-in dataset the volume is, if it is one (`rae` runs the network trained
    /// on it).
    pub dataset: Option<&'static str>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            size: Extent {
                width: 256,
                height: 256,
            },
            spp: 2,
            max_bounces: 8,
            rr_depth: 3,
            features: PathTraceFeatures::default(),
            hg_g: 0.0,
            step_voxels: 1.0,
            feature_threshold: 0.5,
            filter_sigma: 0.5,
            density_scale: 100.0,
            seed: 1,
            motion_source: denoise::MotionSource::FirstHit,
            dataset: None,
        }
    }
}

/// A camera as the renderer needs it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMatrices {
    pub view: Mat4,
    pub proj: Mat4,
    pub position: Vec3,
}

impl CameraMatrices {
    /// A perspective camera in Vulkan conventions: right-handed view space, clip-space y
    /// pointing down (image row 0 at the top), depth in [0, 1].
    pub fn look_at(eye: Vec3, target: Vec3, up: Vec3, fov_y: f32, aspect: f32) -> Self {
        let f = (target - eye).normalize();
        let s = f.cross(up).normalize();
        let u = s.cross(f);
        let view = Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(eye), -u.dot(eye), f.dot(eye), 1.0),
        );
        let (near, far) = (0.01f32, 100.0f32);
        let h = 1.0 / (0.5 * fov_y).tan();
        let proj = Mat4::from_cols(
            Vec4::new(h / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -h, 0.0, 0.0), // y down in Vulkan clip space
            Vec4::new(0.0, 0.0, far / (near - far), -1.0),
            Vec4::new(0.0, 0.0, near * far / (near - far), 0.0),
        );
        Self {
            view,
            proj,
            position: eye,
        }
    }
}

/// The per-frame state of an animation.
#[derive(Clone, Debug)]
pub struct FrameInputs {
    pub camera: CameraMatrices,
    pub lights: Vec<GpuLight>,
    /// The transfer function this frame (uploaded only when it differs from the last).
    pub lut: LutUpload,
}

/// What one frame should produce.
#[derive(Clone, Debug, Default)]
pub struct FrameRequest {
    /// Read the outputs of these methods back to the host ("noisy" is the raw radiance).
    pub readback: bool,
    /// Restart every history (a cut).
    pub reset: bool,
}

/// Results of a completed frame.
#[derive(Clone, Debug, Default)]
pub struct FrameResult {
    pub index: u64,
    pub timings: Vec<PassTiming>,
    /// (method, rgba pixels) for each method when readback was requested.
    pub images: Vec<(String, Vec<[f32; 4]>)>,
    /// The presented image, UI included, when its readback was requested.
    pub screenshot: Option<Screenshot>,
}

struct Slot {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timestamps: TimestampPool,
    uniforms: BufferHandle,
    pending: Option<(u64, Vec<(String, BufferHandle)>)>,
    pending_screenshot: Option<present::PendingScreenshot>,
}

struct Passes {
    features: SurfaceFeatures,
    path_trace: PathTrace,
    motion: Motion,
    accumulate: Accumulate,
    /// Built on the first presented frame (offscreen renderers never need it).
    present: Option<Present>,
}

pub struct Renderer {
    pub settings: RenderSettings,
    graph: RenderGraph,
    passes: Passes,
    denoisers: Vec<Box<dyn Denoiser>>,
    scene: SceneImages,
    bricks: scene_gpu::BrickRanges,
    volume_dims: [u32; 3],
    world_size: [f32; 3],
    lut_size: u32,
    current_lut: Option<LutUpload>,
    last_inputs: Option<FrameInputs>,
    slots: Vec<Slot>,
    pool: vk::CommandPool,
    frame_index: u64,
    /// GPU time of every pass collected so far (frames and references), ms.
    gpu_ms: f64,
    // Declared last: dropped after the Drop impl has released everything above. Shared
    // so an application can keep the device (and its window's swapchain) across
    // renderers, e.g. when a setting that specialises the pipelines changes.
    ctx: Arc<GpuContext>,
}

impl Renderer {
    pub fn new(
        ctx: GpuContext,
        settings: RenderSettings,
        volume: &VolumeUpload,
        environment: Option<&EnvironmentUpload>,
        denoisers: &[&str],
        lut_size: u32,
    ) -> Result<Self> {
        Self::new_shared(
            Arc::new(ctx),
            settings,
            volume,
            environment,
            denoisers,
            lut_size,
        )
    }

    /// [`Renderer::new`] on a context the caller keeps a handle to.
    pub fn new_shared(
        ctx: Arc<GpuContext>,
        settings: RenderSettings,
        volume: &VolumeUpload,
        environment: Option<&EnvironmentUpload>,
        denoisers: &[&str],
        lut_size: u32,
    ) -> Result<Self> {
        let max_spp = samples_per_dispatch(&ctx.info, settings.size.pixels());
        if settings.spp == 0 || settings.spp > max_spp {
            return Err(EngineError::Pass {
                pass: "path_trace".into(),
                problem: format!(
                    "{} samples per pixel per frame; 1 to {max_spp} are supported on {} \
                     (use `dvr reference` or the accum denoiser for more)",
                    settings.spp, ctx.info.name
                ),
            });
        }
        let mut graph = RenderGraph::new(&ctx)?;
        let passes = Passes {
            features: SurfaceFeatures::new(&ctx)?,
            path_trace: PathTrace::new(&ctx, settings.features)?,
            motion: Motion::new(&ctx)?,
            accumulate: Accumulate::new(&ctx)?,
            present: None,
        };
        let denoisers = denoisers
            .iter()
            .map(|n| {
                denoise::create(
                    &ctx,
                    n,
                    settings.motion_source,
                    settings.dataset,
                    settings.features,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }
            .vk("vkCreateCommandPool")?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(SLOTS as u32);
        let cmds = unsafe { ctx.device.allocate_command_buffers(&alloc) }
            .vk("vkAllocateCommandBuffers")?;
        let mut slots = Vec::new();
        for (i, &cmd) in cmds.iter().enumerate() {
            let fence = unsafe {
                ctx.device.create_fence(
                    &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                    None,
                )
            }
            .vk("vkCreateFence")?;
            let uniforms = graph.buffer(
                &ctx,
                &format!("frame_uniforms.{i}"),
                std::mem::size_of::<FrameUniforms>() as u64,
                MemoryLocation::CpuToGpu,
            )?;
            slots.push(Slot {
                cmd,
                fence,
                timestamps: TimestampPool::new(&ctx)?,
                uniforms,
                pending: None,
                pending_screenshot: None,
            });
        }

        // Upload the volume and environment once, through the graph.
        let mut setup = Frame::new();
        let scene = scene_gpu::create(&ctx, &mut graph, &mut setup, volume, environment, lut_size)?;
        ctx.submit_and_wait(|cmd| graph.execute(&ctx, cmd, None, setup))?;

        Ok(Self {
            settings,
            graph,
            passes,
            denoisers,
            scene,
            bricks: volume.bricks.clone(),
            volume_dims: volume.dims,
            world_size: volume.world_size,
            lut_size,
            current_lut: None,
            last_inputs: None,
            slots,
            pool,
            frame_index: 0,
            gpu_ms: 0.0,
            ctx,
        })
    }

    pub fn ctx(&self) -> &GpuContext {
        &self.ctx
    }

    /// The shared context (to keep the device alive beyond this renderer).
    pub fn shared_ctx(&self) -> Arc<GpuContext> {
        Arc::clone(&self.ctx)
    }

    /// Most samples per pixel one path-tracing dispatch takes on this device at this
    /// size (see [`samples_per_dispatch`]).
    pub fn samples_per_dispatch(&self) -> u32 {
        samples_per_dispatch(&self.ctx.info, self.settings.size.pixels())
    }

    /// GPU time of every pass this renderer has collected results of (frames and
    /// references), in ms: the work the device did for it.
    pub fn gpu_ms(&self) -> f64 {
        self.gpu_ms
    }

    pub fn denoiser_names(&self) -> Vec<String> {
        self.denoisers
            .iter()
            .map(|d| d.name().to_string())
            .collect()
    }

    /// Replaces the denoisers (the explorer's picker). Waits for the frames in flight
    /// and returns their results; every history restarts, so a denoiser picked again
    /// never resumes from stale state.
    pub fn set_denoisers(&mut self, names: &[&str]) -> Result<Vec<FrameResult>> {
        let done = self.flush()?;
        let new = names
            .iter()
            .map(|n| {
                denoise::create(
                    &self.ctx,
                    n,
                    self.settings.motion_source,
                    self.settings.dataset,
                    self.settings.features,
                )
            })
            .collect::<Result<Vec<_>>>()?;
        for d in &mut self.denoisers {
            d.destroy(&self.ctx);
        }
        self.denoisers = new;
        self.graph.reset_history("");
        Ok(done)
    }

    fn uniforms(&self, inputs: &FrameInputs, majorant_max: f32) -> FrameUniforms {
        let s = &self.settings;
        let aspect_view_proj = inputs.camera.proj * inputs.camera.view;
        let prev = self
            .last_inputs
            .as_ref()
            .map(|p| p.camera.proj * p.camera.view)
            .unwrap_or(aspect_view_proj);
        let half = Vec3::from(self.world_size) * 0.5;
        let mut lights = [GpuLight::default(); MAX_LIGHTS];
        for (dst, src) in lights.iter_mut().zip(&inputs.lights) {
            *dst = *src;
        }
        let voxel = (Vec3::from(self.world_size) / Vec3::from(self.volume_dims.map(|d| d as f32)))
            .min_element();
        FrameUniforms {
            view_proj: aspect_view_proj,
            inv_view_proj: aspect_view_proj.inverse(),
            prev_view_proj: prev,
            camera_pos: inputs.camera.position.extend(1.0),
            box_min: (-half).extend(s.density_scale),
            box_max: half.extend(majorant_max),
            dims: glam::IVec4::new(
                self.volume_dims[0] as i32,
                self.volume_dims[1] as i32,
                self.volume_dims[2] as i32,
                self.bricks.brick as i32,
            ),
            counts: glam::IVec4::new(
                inputs.lights.len() as i32,
                self.frame_index as i32,
                s.spp as i32,
                s.max_bounces as i32,
            ),
            params: Vec4::new(
                voxel * s.step_voxels,
                s.hg_g,
                s.feature_threshold,
                s.filter_sigma,
            ),
            seeds: glam::UVec4::new(s.seed, 0, s.rr_depth, s.size.width),
            lights,
        }
    }

    /// Renders one frame of the animation: the noisy path-traced frame once, then every
    /// denoiser on that same input. Returns the results of the frame that last used this
    /// slot (two frames ago), if any.
    pub fn frame(
        &mut self,
        inputs: &FrameInputs,
        request: &FrameRequest,
    ) -> Result<Option<FrameResult>> {
        self.frame_presented(inputs, request, None)
    }

    /// [`Renderer::frame`], ending on screen when `present` is given: the denoised frame
    /// is tone-mapped into the acquired swapchain image, the overlay drawn on top, and
    /// the submission waits for and signals the image's semaphores (see [`present`]).
    pub fn frame_presented(
        &mut self,
        inputs: &FrameInputs,
        request: &FrameRequest,
        present: Option<&PresentTarget<'_>>,
    ) -> Result<Option<FrameResult>> {
        check_light_count(inputs)?;
        let slot = (self.frame_index % SLOTS as u64) as usize;
        let completed = self.wait_slot(slot)?;
        if present.is_some() && self.passes.present.is_none() {
            self.passes.present = Some(Present::new(&self.ctx)?);
        }
        let changes = self.changes(inputs, request.reset);
        if request.reset {
            self.graph.reset_history("");
        }
        let mut frame = Frame::new();

        // Scene state: the TF (only when it changed) and this frame's uniforms.
        let majorant_max = self.upload_transfer_function(&mut frame, &inputs.lut)?;
        let uniforms = self.uniforms(inputs, majorant_max);
        let scene = self.write_uniforms(slot, &uniforms)?;
        let (ctx, graph, passes, size) =
            (&self.ctx, &mut self.graph, &self.passes, self.settings.size);

        // features → path trace → motion → each denoiser on the same noisy frame.
        let features = if self.denoisers.iter().any(|d| d.uses_surface_features()) {
            Some(passes.features.add(ctx, graph, &mut frame, &scene, size)?)
        } else {
            None
        };
        let noisy = passes.path_trace.add(
            ctx,
            graph,
            &mut frame,
            "path_trace",
            &scene,
            size,
            0,
            self.settings.spp,
        )?;
        let motion = passes.motion.add(
            ctx,
            graph,
            &mut frame,
            scene.uniforms,
            noisy.first_hit.cur,
            features.map(|f| f.position.cur),
            size,
        )?;
        // Last frame's samples can be traced again in this frame's scene (ours' temporal
        // gradients) when the scene changed and last frame's radiance is still valid.
        let retrace = match &self.last_inputs {
            Some(last)
                if noisy.radiance_history.valid
                    && (changes.lights || changes.transfer_function) =>
            {
                Some(Retrace {
                    scene,
                    radiance_prev: noisy.radiance_history.prev,
                    inv_view_proj_prev: (last.camera.proj * last.camera.view).inverse(),
                    camera_prev: last.camera.position,
                    frame_prev: self.frame_index.wrapping_sub(1) as u32,
                })
            }
            _ => None,
        };
        let input = DenoiseInputs {
            uniforms: scene.uniforms,
            noisy: noisy.radiance,
            moments: noisy.moments,
            features,
            first_hit: noisy.first_hit,
            motion,
            size,
            camera: inputs.camera.position,
            spp: self.settings.spp,
            changes,
            retrace,
        };
        let mut outputs: Vec<(String, ImageHandle)> = Vec::new();
        for d in &self.denoisers {
            outputs.push((d.name().to_string(), d.add(ctx, graph, &mut frame, &input)?));
        }

        let readbacks = if request.readback {
            add_readbacks(ctx, graph, &mut frame, slot, &outputs, size)?
        } else {
            Vec::new()
        };
        // On screen: tone map into the swapchain image, UI on top, hand it over.
        let mut screenshot = None;
        let mut semaphores = None;
        if let (Some(target), Some(pass)) = (present, &passes.present) {
            screenshot = present::add_present_passes(
                ctx, graph, &mut frame, pass, slot, target, &outputs, size,
            )?;
            semaphores = Some((target.image.wait, target.image.signal));
        }
        submit(ctx, graph, &mut self.slots[slot], frame, semaphores)?;
        self.slots[slot].pending = Some((self.frame_index, readbacks));
        self.slots[slot].pending_screenshot = screenshot;
        self.graph.end_frame();
        self.last_inputs = Some(inputs.clone());
        self.frame_index += 1;
        Ok(completed)
    }

    /// Adds uploads of the TF LUTs and the majorant grid when the TF differs from the one
    /// on the device; returns the largest extinction (the global majorant).
    fn upload_transfer_function(&mut self, frame: &mut Frame, lut: &LutUpload) -> Result<f32> {
        if lut.diffuse_opacity.len() != self.lut_size as usize {
            return Err(EngineError::Resource {
                resource: "transfer function".into(),
                problem: format!(
                    "LUT has {} entries, renderer expects {}",
                    lut.diffuse_opacity.len(),
                    self.lut_size
                ),
            });
        }
        let opacity: Vec<f32> = lut.diffuse_opacity.iter().map(|c| c[3]).collect();
        let majorants = scene_gpu::majorants(&self.bricks, &opacity, self.settings.density_scale);
        let majorant_max = majorants.iter().copied().fold(0.0f32, f32::max);
        if self.current_lut.as_ref() != Some(lut) {
            let (ctx, graph) = (&self.ctx, &mut self.graph);
            let [a, b, c] = self.scene.tf;
            for (name, image, bytes) in [
                (
                    "upload_tf_diffuse",
                    a,
                    bytemuck::cast_slice(&lut.diffuse_opacity),
                ),
                (
                    "upload_tf_specular",
                    b,
                    bytemuck::cast_slice(&lut.specular_roughness),
                ),
                ("upload_tf_emissive", c, bytemuck::cast_slice(&lut.emissive)),
                (
                    "upload_majorant",
                    self.scene.majorant,
                    bytemuck::cast_slice(&majorants),
                ),
            ] {
                scene_gpu::add_upload(ctx, graph, frame, name, image, bytes)?;
            }
            self.current_lut = Some(lut.clone());
        }
        Ok(majorant_max)
    }

    /// Writes `uniforms` into slot `slot`'s uniform buffer; returns the scene bindings.
    fn write_uniforms(&mut self, slot: usize, uniforms: &FrameUniforms) -> Result<SceneBindings> {
        let ubo = self.slots[slot].uniforms;
        self.graph
            .buffer_mut(ubo)
            .write(bytemuck::bytes_of(uniforms))?;
        Ok(SceneBindings {
            uniforms: ubo,
            volume: self.scene.volume,
            tf_diffuse_opacity: self.scene.tf[0],
            tf_specular_roughness: self.scene.tf[1],
            tf_emissive: self.scene.tf[2],
            majorant: self.scene.majorant,
            environment: self.scene.environment,
        })
    }

    fn changes(&self, inputs: &FrameInputs, reset: bool) -> Changes {
        match &self.last_inputs {
            None => Changes {
                camera: true,
                lights: true,
                transfer_function: true,
            },
            Some(last) => Changes {
                camera: reset || last.camera != inputs.camera,
                lights: reset || last.lights != inputs.lights,
                transfer_function: reset || last.lut != inputs.lut,
            },
        }
    }

    /// Waits for a slot's previous frame and collects its timings and readbacks.
    fn wait_slot(&mut self, i: usize) -> Result<Option<FrameResult>> {
        let slot = &mut self.slots[i];
        let d = &self.ctx.device;
        unsafe { d.wait_for_fences(&[slot.fence], true, u64::MAX) }.vk("vkWaitForFences")?;
        let Some((index, readbacks)) = slot.pending.take() else {
            return Ok(None);
        };
        let screenshot = slot.pending_screenshot.take();
        let timings = slot.timestamps.read(&self.ctx)?;
        self.gpu_ms += timings.iter().map(|t| t.ms).sum::<f64>();
        let mut images = Vec::new();
        for (name, buffer) in readbacks {
            images.push((name, read_pixels(&self.graph, buffer)?));
        }
        let screenshot = screenshot
            .map(|p| present::read_screenshot(&self.graph, p))
            .transpose()?;
        Ok(Some(FrameResult {
            index,
            timings,
            images,
            screenshot,
        }))
    }

    /// Waits for every frame in flight; returns their results in order.
    pub fn flush(&mut self) -> Result<Vec<FrameResult>> {
        let mut out = Vec::new();
        for k in 0..SLOTS as u64 {
            let i = ((self.frame_index + k) % SLOTS as u64) as usize;
            if let Some(r) = self.wait_slot(i)? {
                out.push(r);
            }
        }
        out.sort_by_key(|r| r.index);
        Ok(out)
    }

    /// Renders a high-sample reference of one animation frame: `spp` samples accumulated
    /// in dispatches of at most `batch` (and at most what the device takes in one, see
    /// [`Renderer::samples_per_dispatch`]), from a sample stream of its own (independent
    /// of the per-frame noise the denoisers see).
    pub fn reference(
        &mut self,
        inputs: &FrameInputs,
        spp: u32,
        batch: u32,
    ) -> Result<Vec<[f32; 4]>> {
        self.flush()?;
        check_light_count(inputs)?;
        if spp == 0 {
            return Err(EngineError::Pass {
                pass: "reference.path_trace".into(),
                problem: "a reference needs at least 1 sample per pixel".into(),
            });
        }
        let batch = batch.clamp(1, spp.clamp(1, self.samples_per_dispatch()));
        self.graph.reset_history("reference.");
        let mut done = 0;
        let mut image = Vec::new();
        while done < spp {
            let n = batch.min(spp - done);
            let mut frame = Frame::new();
            let majorant_max = self.upload_transfer_function(&mut frame, &inputs.lut)?;
            let mut uniforms = self.uniforms(inputs, majorant_max);
            uniforms.counts.y = i32::MAX - self.frame_index as i32;
            let scene = self.write_uniforms(0, &uniforms)?;
            let (ctx, graph, passes, size) =
                (&self.ctx, &mut self.graph, &self.passes, self.settings.size);
            let batch_out = passes.path_trace.add(
                ctx,
                graph,
                &mut frame,
                "reference.path_trace",
                &scene,
                size,
                done,
                n,
            )?;
            let mean = passes.accumulate.add(
                ctx,
                graph,
                &mut frame,
                "reference.accumulate",
                batch_out.radiance,
                n as f32,
                size,
            )?;
            done += n;
            let readbacks = if done >= spp {
                add_readbacks(
                    ctx,
                    graph,
                    &mut frame,
                    0,
                    &[("reference".to_string(), mean)],
                    size,
                )?
            } else {
                Vec::new()
            };
            // Timed with slot 0's pool, idle after the flush above.
            let timestamps = &mut self.slots[0].timestamps;
            ctx.submit_and_wait(|cmd| {
                timestamps.reset(ctx, cmd);
                graph.execute(ctx, cmd, Some(timestamps), frame)
            })?;
            self.gpu_ms += timestamps.read(ctx)?.iter().map(|t| t.ms).sum::<f64>();
            graph.end_frame();
            if let Some((_, buffer)) = readbacks.first() {
                image = read_pixels(graph, *buffer)?;
            }
        }
        Ok(image)
    }
}

/// The light array of the frame uniforms holds [`MAX_LIGHTS`]: more is an error, never
/// a silent drop (scenes are checked against the same limit when loaded).
fn check_light_count(inputs: &FrameInputs) -> Result<()> {
    if inputs.lights.len() > MAX_LIGHTS {
        return Err(EngineError::Pass {
            pass: "path_trace".into(),
            problem: format!(
                "{} lights; the path tracer takes at most {MAX_LIGHTS}",
                inputs.lights.len()
            ),
        });
    }
    Ok(())
}

/// The rgba32f pixels of a host-visible readback buffer.
fn read_pixels(graph: &RenderGraph, buffer: BufferHandle) -> Result<Vec<[f32; 4]>> {
    let bytes = graph
        .buffer_ref(buffer)
        .mapped()
        .ok_or_else(|| EngineError::Resource {
            resource: "readback".into(),
            problem: "buffer is not host visible".into(),
        })?;
    Ok(bytemuck::cast_slice::<u8, [f32; 4]>(bytes).to_vec())
}

fn add_readbacks<'f>(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    frame: &mut Frame<'f>,
    slot: usize,
    outputs: &[(String, ImageHandle)],
    size: Extent,
) -> Result<Vec<(String, BufferHandle)>> {
    let bytes = size.width as u64 * size.height as u64 * 16;
    let mut out = Vec::new();
    for (name, image) in outputs {
        let buffer = graph.buffer(
            ctx,
            &format!("readback.{name}.{slot}"),
            bytes,
            MemoryLocation::GpuToCpu,
        )?;
        frame.add_readback(name, *image, buffer);
        out.push((name.clone(), buffer));
    }
    Ok(out)
}

/// Records and submits a frame. `semaphores` (acquire, render-finished) when it presents:
/// the submission waits for the swapchain image at the stage the graph's first barrier
/// on it starts from, and signals the semaphore presentation waits on.
fn submit(
    ctx: &GpuContext,
    graph: &mut RenderGraph,
    slot: &mut Slot,
    frame: Frame,
    semaphores: Option<(vk::Semaphore, vk::Semaphore)>,
) -> Result<()> {
    let d = &ctx.device;
    unsafe {
        d.reset_fences(&[slot.fence]).vk("vkResetFences")?;
        d.reset_command_buffer(slot.cmd, vk::CommandBufferResetFlags::empty())
            .vk("vkResetCommandBuffer")?;
        d.begin_command_buffer(
            slot.cmd,
            &vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
        )
        .vk("vkBeginCommandBuffer")?;
    }
    slot.timestamps.reset(ctx, slot.cmd);
    graph.execute(ctx, slot.cmd, Some(&mut slot.timestamps), frame)?;
    unsafe {
        d.end_command_buffer(slot.cmd).vk("vkEndCommandBuffer")?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(slot.cmd)];
        let (waits, signals) = match semaphores {
            Some((wait, signal)) => (
                vec![vk::SemaphoreSubmitInfo::default()
                    .semaphore(wait)
                    .stage_mask(crate::gpu::swapchain::ACQUIRE_WAIT_STAGE)],
                vec![vk::SemaphoreSubmitInfo::default()
                    .semaphore(signal)
                    .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)],
            ),
            None => (Vec::new(), Vec::new()),
        };
        let submit = [vk::SubmitInfo2::default()
            .command_buffer_infos(&cmds)
            .wait_semaphore_infos(&waits)
            .signal_semaphore_infos(&signals)];
        d.queue_submit2(ctx.queue, &submit, slot.fence)
            .vk("vkQueueSubmit2")?;
    }
    Ok(())
}

impl Drop for Renderer {
    fn drop(&mut self) {
        let ctx = &self.ctx;
        let _ = ctx.wait_idle();
        for s in &mut self.slots {
            s.timestamps.destroy(ctx);
            unsafe { ctx.device.destroy_fence(s.fence, None) };
        }
        unsafe { ctx.device.destroy_command_pool(self.pool, None) };
        for d in &mut self.denoisers {
            d.destroy(ctx);
        }
        self.passes.features.destroy(ctx);
        self.passes.path_trace.destroy(ctx);
        self.passes.motion.destroy(ctx);
        self.passes.accumulate.destroy(ctx);
        if let Some(p) = &mut self.passes.present {
            p.destroy(ctx);
        }
        self.graph.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::DeviceInfo;

    fn device(driver_id: vk::DriverId) -> DeviceInfo {
        DeviceInfo {
            name: "a device".into(),
            device_type: vk::PhysicalDeviceType::DISCRETE_GPU,
            driver_id,
            timestamp_period: 1.0,
            max_image_dimension_3d: 2048,
            max_memory_allocation_size: 1 << 30,
            max_storage_buffer_range: 1 << 27,
            max_push_constants_size: 128,
            device_local_heap: 1 << 30,
            storage_write_without_format: true,
        }
    }

    #[test]
    fn only_llvmpipe_caps_samples_per_dispatch() {
        let lavapipe = device(vk::DriverId::MESA_LLVMPIPE);
        assert_eq!(
            samples_per_dispatch(&lavapipe, 64 * 64),
            MAX_SAMPLES_PER_DISPATCH
        );
        let gpu = device(vk::DriverId::NVIDIA_PROPRIETARY);
        // A suite reference (256x256, 1024 spp) in one dispatch; 720p in 15.
        assert_eq!(samples_per_dispatch(&gpu, 256 * 256), 1024);
        assert_eq!(samples_per_dispatch(&gpu, 1280 * 720), 72);
        // Never fewer than lavapipe's, however large the image.
        assert_eq!(
            samples_per_dispatch(&gpu, 8192 * 8192),
            MAX_SAMPLES_PER_DISPATCH
        );
    }
}
