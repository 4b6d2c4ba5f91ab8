//! The frame. [`Renderer::frame`] reads like the pipeline: uniforms → surface features →
//! path trace → motion → each denoiser → readbacks → (present to a window), all in one
//! render graph, submitted once. Frames alternate between two slots so recording frame N overlaps the GPU's work
//! on frame N−1; timestamps and readbacks of a slot are collected when it comes round.

pub mod brick_pool;
mod inputs;
pub mod labels;
mod march;
pub mod medium;
pub mod packing;
pub mod present;
mod reference;
pub mod scene_gpu;
pub mod scene_setup;
mod submit;
mod tf_upload;
pub mod timeline;
mod uniforms;
pub mod uploads;

pub use inputs::{
    CameraMatrices, FrameInputs, FrameRequest, FrameResult, LabelLookRef, SeriesTime,
    FEATURE_IMAGES,
};
pub use reference::{samples_per_dispatch, MAX_SAMPLES_PER_DISPATCH, PIXEL_SAMPLES_PER_DISPATCH};
use submit::{add_readbacks, read_pixels, submit, Slot};

use crate::denoise::{
    self, Changes, DenoiseFrame, DenoiseInputs, Denoiser, DenoiserConfig, DenoiserInfo, Registry,
    Retrace,
};
use crate::error::{EngineError, Result, VkContext};
use crate::gpu::timestamps::{PassOwner, TimestampPool};
use crate::gpu::GpuContext;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};
use crate::passes::accumulate::Accumulate;
use crate::passes::aux_features::{self, AuxFeatures};
use crate::passes::motion::Motion;
use crate::passes::path_trace::{PathTrace, PathTraceFeatures, VolumeLayout};
use crate::passes::present::Present;
use crate::passes::surface_features::SurfaceFeatures;
use crate::scene::RenderSettings;
use crate::shaders::frame::{ChannelOpacity, FrameBlock, SampleStream};
use ash::vk;
pub use brick_pool::VolumeResidency;
use brick_pool::{Residency, VolumePath};
use gpu_allocator::MemoryLocation;
use march::{MarchKey, MarchPass};
pub use present::{Overlay, PresentTarget, Screenshot};
use scene_gpu::SceneImages;
use std::sync::Arc;
use uploads::{BrickRanges, EnvironmentUpload, LutUpload, VolumeUpload};

const SLOTS: usize = 2;

/// What a renderer is built for besides its [`RenderSettings`]: the image size and what
/// the scene's volume fixes for the renderer's lifetime.
#[derive(Clone, Debug, PartialEq)]
pub struct RendererConfig {
    pub size: Extent,
    /// Extinction per unit opacity (1/world unit): the scene volume's density scale.
    pub density_scale: f32,
    /// What the temporal denoisers reproject with (their pipelines are specialised on
    /// it).
    pub motion_source: denoise::MotionSource,
    /// The built-in dataset the volume is, if it is one (`rae` runs the network trained
    /// on it).
    pub dataset: Option<&'static str>,
    /// Bytes the volume may take on the device (`--gpu-memory`, `[render] gpu_memory`);
    /// `None`: half the largest device-local heap. Past it the volume is paged through
    /// the brick pool.
    pub gpu_memory: Option<u64>,
    /// How a label map beside the volume is shown (the volume passes are specialised
    /// on it); `None`: no label map.
    pub labels: Option<crate::scene::LabelMode>,
    /// The rows the renderer finds its denoisers' names in.
    pub registry: Registry,
}

impl Default for RendererConfig {
    fn default() -> Self {
        Self {
            size: Extent {
                width: 256,
                height: 256,
            },
            density_scale: 100.0,
            motion_source: denoise::MotionSource::FirstHit,
            dataset: None,
            gpu_memory: None,
            labels: None,
            registry: Registry::default(),
        }
    }
}

/// What [`Renderer::set_settings`] did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsChange {
    Unchanged,
    /// Applied; every history restarts on the next frame.
    Applied,
    /// Not applied: the settings specialise the pipelines differently (see
    /// [`RenderSettings::pipeline_key`]), which takes a new renderer.
    NeedsNewRenderer,
}

/// A denoiser the frame runs, with its registry entry.
struct Method {
    info: DenoiserInfo,
    denoiser: Box<dyn Denoiser>,
}

/// The graph image `name` (see [`Renderer::read_back_images`]), checked to be one that
/// reads back as RGBA32F pixels of the frame.
fn stage_image(graph: &RenderGraph, name: &str, size: Extent) -> Result<ImageHandle> {
    let problem = |p: String| EngineError::Resource {
        resource: name.into(),
        problem: p,
    };
    let h = graph
        .find_image(name)
        .ok_or_else(|| problem("no image of that name in the render graph".into()))?;
    let desc = graph.image_desc(h);
    let want = [size.width, size.height, 1];
    if desc.format != vk::Format::R32G32B32A32_SFLOAT || desc.extent != want {
        return Err(problem(format!(
            "is {:?} {:?}, not an RGBA32F image of the frame's size {want:?}",
            desc.format, desc.extent
        )));
    }
    Ok(h)
}

/// The names of the methods `needs` picks.
fn readers(methods: &[Method], needs: impl Fn(&Method) -> bool) -> Vec<String> {
    methods
        .iter()
        .filter(|m| needs(m))
        .map(|m| m.info.name.to_string())
        .collect()
}

struct Passes {
    features: SurfaceFeatures,
    path_trace: PathTrace,
    motion: Motion,
    accumulate: Accumulate,
    /// Built on the first presented frame (offscreen renderers never need it).
    present: Option<Present>,
    /// Built on the first frame that asks for the guide images (`FrameRequest::aux`).
    aux: Option<AuxFeatures>,
}

pub struct Renderer {
    settings: RenderSettings,
    config: RendererConfig,
    /// What the path-tracing pipelines are specialised for.
    features: PathTraceFeatures,
    /// Restart every history on the next frame (the live settings changed).
    pending_reset: bool,
    /// After the next frame, release the graph's images it did not use (the denoisers or
    /// the size changed, and nothing older is in flight).
    release_unused: bool,
    /// Graph images read back with every frame's outputs, by name (see
    /// [`Renderer::read_back_images`]).
    extra_readbacks: Vec<String>,
    graph: RenderGraph,
    passes: Passes,
    denoisers: Vec<Method>,
    scene: SceneImages,
    bricks: BrickRanges,
    /// The volume as loaded: the brick pool reads its bricks from it.
    volume: Arc<VolumeUpload>,
    /// Which brick is in which pool slot (the pool path only).
    residency: Option<Residency>,
    /// The brick table changed since it was last uploaded.
    table_dirty: bool,
    /// The current TF makes more bricks visible than the pool has slots.
    over_budget: bool,
    volume_dims: [u32; 3],
    world_size: [f32; 3],
    lut_size: u32,
    current_lut: Option<LutUpload>,
    /// The cut the majorants were masked with.
    current_cut: Option<crate::scene::Cut>,
    /// The label look on the device.
    current_labels: Option<LabelLookRef>,
    /// The largest extinction under `current_lut`.
    majorant_max: f32,
    /// Several channels: their opacity under `current_lut`, for the frame block.
    channel_opacity: Box<ChannelOpacity>,
    last_inputs: Option<FrameInputs>,
    /// What the feature images hold (`None`: unknown, march again).
    last_march: Option<MarchKey>,
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
    /// A renderer on `ctx`: a context it owns, or one the caller keeps a handle to (the
    /// explorer's, which also owns the window's swapchain and outlives renderers).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ctx: impl Into<Arc<GpuContext>>,
        settings: RenderSettings,
        config: RendererConfig,
        volume: Arc<VolumeUpload>,
        environment: Option<&EnvironmentUpload>,
        denoisers: &[&str],
        lut_size: u32,
    ) -> Result<Self> {
        let ctx = ctx.into();
        check_spp(&ctx, settings.spp(), config.size)?;
        // What the caller can get wrong (a denoiser's name, what it needs) is checked
        // before the graph exists: the graph's samplers and images are released only by
        // `RenderGraph::destroy`, which an early return here would skip.
        // So is a volume not even a brick pool can hold in the budget: found here, the
        // error is not preceded by the allocator's reports of leaked buffers.
        let volume_path = scene_gpu::plan_volume(&ctx, &volume, config.gpu_memory)?;
        // The frame block holds the channels' opacity rows at the LUTs' own size.
        if volume.channels() > 1 && lut_size as usize != crate::transfer::LUT_SIZE {
            return Err(EngineError::Resource {
                resource: "transfer function".into(),
                problem: format!(
                    "a medium of {} channels reads LUTs of {} entries, not {lut_size}",
                    volume.channels(),
                    crate::transfer::LUT_SIZE
                ),
            });
        }
        let layout = VolumeLayout {
            pooled: matches!(volume_path, VolumePath::Pool(_)),
            channels: volume.channels(),
            labels: config.labels,
        };
        if config.labels.is_some() && layout.pooled {
            return Err(EngineError::TooLarge {
                what: format!(
                    "volume {:?} ({:?} voxels) with a label map: a labelled volume is held as one dense texture (the brick pool pages one field) and does not fit",
                    volume.name, volume.dims
                ),
                needed: volume.dims.iter().map(|&d| u64::from(d)).product::<u64>()
                    * (volume.texel_bytes() as u64 + 4),
                limit: config.gpu_memory.unwrap_or_else(|| scene_gpu::default_budget(&ctx)),
                device: ctx.info.name.clone(),
            });
        }
        let features =
            PathTraceFeatures::new(settings.pipeline_key(), environment.is_some(), layout);
        let denoisers = create_methods(&ctx, &config, features, denoisers)?;
        let mut graph = RenderGraph::new(&ctx)?;
        let passes = Passes {
            features: SurfaceFeatures::new(&ctx, layout)?,
            path_trace: PathTrace::new(&ctx, features)?,
            motion: Motion::new(&ctx)?,
            accumulate: Accumulate::new(&ctx)?,
            present: None,
            aux: None,
        };
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
                std::mem::size_of::<FrameBlock>() as u64,
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
        let scene = scene_gpu::create(
            &ctx,
            &mut graph,
            &mut setup,
            &scene_gpu::SceneDesc {
                volume: &volume,
                path: &volume_path,
                environment,
                lut_size,
                labels: config.labels.is_some(),
            },
        )?;
        ctx.submit_and_wait(|cmd| graph.execute(&ctx, cmd, None, setup))?;

        Ok(Self {
            settings,
            config,
            features,
            pending_reset: false,
            release_unused: false,
            extra_readbacks: Vec::new(),
            graph,
            passes,
            denoisers,
            scene,
            bricks: volume.bricks.clone(),
            volume_dims: volume.dims,
            world_size: volume.world_size,
            residency: match &volume_path {
                VolumePath::Dense => None,
                VolumePath::Pool(layout) => Some(Residency::new(
                    layout.clone(),
                    brick_pool::pool_ranges(&volume.bricks),
                )),
            },
            volume,
            table_dirty: false,
            over_budget: false,
            lut_size,
            current_lut: None,
            current_cut: None,
            current_labels: None,
            majorant_max: 0.0,
            channel_opacity: Box::default(),
            last_inputs: None,
            last_march: None,
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

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    pub fn config(&self) -> &RendererConfig {
        &self.config
    }

    /// Most samples per pixel one path-tracing dispatch takes on this device at this
    /// size (see [`samples_per_dispatch`]).
    pub fn samples_per_dispatch(&self) -> u32 {
        samples_per_dispatch(&self.ctx.info, self.config.size.pixels())
    }

    /// Runs with `settings` from the next frame on: every history restarts then. A
    /// change of what the pipelines are specialised for is not applied (it takes a new
    /// renderer); samples per pixel beyond what the device takes in one frame are an
    /// error.
    pub fn set_settings(&mut self, settings: &RenderSettings) -> Result<SettingsChange> {
        if settings.pipeline_key() != self.settings.pipeline_key() {
            return Ok(SettingsChange::NeedsNewRenderer);
        }
        if *settings == self.settings {
            return Ok(SettingsChange::Unchanged);
        }
        check_spp(&self.ctx, settings.spp(), self.config.size)?;
        self.settings = *settings;
        self.pending_reset = true;
        Ok(SettingsChange::Applied)
    }

    /// Renders at `size` from the next frame on. The graph reallocates its images then,
    /// so the frames in flight, which use the old ones, are waited for first: their
    /// results are returned.
    pub fn resize(&mut self, size: Extent) -> Result<Vec<FrameResult>> {
        if size == self.config.size {
            return Ok(Vec::new());
        }
        check_spp(&self.ctx, self.settings.spp(), size)?;
        let done = self.flush()?;
        self.config.size = size;
        self.release_unused = true;
        Ok(done)
    }

    /// GPU time of every pass this renderer has collected results of (frames and
    /// references), in ms: the work the device did for it.
    pub fn gpu_ms(&self) -> f64 {
        self.gpu_ms
    }

    pub fn denoiser_names(&self) -> Vec<String> {
        self.denoisers
            .iter()
            .map(|m| m.info.name.to_string())
            .collect()
    }

    /// From the next frame on, also reads back these graph images by name with the
    /// methods' outputs (a frame with `readback`): a stage of a denoiser as that frame
    /// wrote it (`ours.model`, `ours.lag`, `ours.prior`, …; a history's name gives the
    /// image written this frame), for tests that check a method stage by stage. Each must
    /// be an RGBA32F image of the frame's size; a frame fails naming one that is not.
    pub fn read_back_images(&mut self, names: &[&str]) {
        self.extra_readbacks = names.iter().map(|n| n.to_string()).collect();
    }

    /// Replaces the denoisers (the explorer's picker). Waits for the frames in flight
    /// and returns their results; every history restarts, so a denoiser picked again
    /// never resumes from stale state.
    pub fn set_denoisers(&mut self, names: &[&str]) -> Result<Vec<FrameResult>> {
        let done = self.flush()?;
        let new = create_methods(&self.ctx, &self.config, self.features, names)?;
        self.denoisers = new;
        self.graph.reset_history("");
        self.release_unused = true;
        Ok(done)
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
        uniforms::check_light_count(inputs)?;
        let slot = (self.frame_index % SLOTS as u64) as usize;
        let completed = self.wait_slot(slot)?;
        if present.is_some() && self.passes.present.is_none() {
            self.passes.present = Some(Present::new(&self.ctx)?);
        }
        let guide_readers = readers(&self.denoisers, |m| m.info.guides);
        let guides = !guide_readers.is_empty();
        if (request.aux || guides) && self.passes.aux.is_none() {
            self.passes.aux = Some(AuxFeatures::new(&self.ctx, self.features.volume)?);
        }
        let reset = request.reset || std::mem::take(&mut self.pending_reset);
        let changes = self.changes(inputs, reset);
        if reset {
            self.graph.reset_history("");
        }
        let mut frame = Frame::new();

        // Scene state: the TF (only when it changed) and this frame's uniforms.
        let majorant_max = self.upload_transfer_function(&mut frame, slot, inputs, true)?;
        let block = self.frame_block(inputs, majorant_max, SampleStream::Frame(self.frame_index));
        let scene = self.write_uniforms(slot, &block)?;
        let (ctx, graph, passes, size) =
            (&self.ctx, &mut self.graph, &self.passes, self.config.size);

        // features → path trace → motion → each denoiser on the same noisy frame.
        // The features and guide passes are the cost of every method that needs them (a
        // method alone would pay for them), not of the frame: `none` and `accum` read
        // neither. The guide images: the albedo for the denoisers that read it (svgf
        // demodulates by it, ours' prior fits on it), both read back for single-frame
        // denoisers (`FrameRequest::aux`). Their march also finds the threshold surface,
        // so where they are rendered it writes the surface features too and the surface
        // pass does not run: one march, the cost of every method that reads either.
        let motion = self.config.motion_source;
        let feature_readers = readers(&self.denoisers, |m| m.info.features.needed(motion));
        let want_features = request.features || !feature_readers.is_empty();
        let pass = match &passes.aux {
            Some(_) if request.aux || guides => Some(MarchPass::Guides {
                normals: request.aux,
            }),
            _ if want_features => Some(MarchPass::Surface),
            _ => None,
        };
        let mut owners = feature_readers;
        if matches!(pass, Some(MarchPass::Guides { .. })) {
            for m in guide_readers {
                if !owners.contains(&m) {
                    owners.push(m);
                }
            }
        }
        let march = march::MarchRequest {
            pass,
            owner: PassOwner::Methods(owners),
            features: want_features,
        };
        let (features, aux) = march::add(
            ctx,
            graph,
            &mut frame,
            passes,
            &scene,
            size,
            march,
            inputs,
            &mut self.last_march,
        )?;
        let noisy = passes.path_trace.add(
            ctx,
            graph,
            &mut frame,
            "path_trace",
            &scene,
            size,
            0,
            self.settings.spp(),
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
                    && (changes.lights || changes.transfer_function || changes.cut) =>
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
            guides: aux.filter(|_| guides).map(|(albedo, _)| albedo),
            first_hit: noisy.first_hit,
            motion,
            size,
            camera: inputs.camera.position,
            spp: self.settings.spp(),
            changes,
            retrace,
        };
        let mut outputs: Vec<(String, ImageHandle)> = Vec::new();
        for m in &self.denoisers {
            let name = m.info.name;
            let out = frame.add_owned(name, |frame| {
                let input = &input;
                m.denoiser.add(DenoiseFrame {
                    ctx,
                    graph,
                    frame,
                    input,
                })
            })?;
            outputs.push((name.to_string(), out));
        }

        // The guide images of single-frame denoisers, read back beside the methods.
        let mut read = outputs.clone();
        if let (true, Some((albedo, normal))) = (request.aux, aux) {
            read.push((aux_features::ALBEDO.to_string(), albedo));
            read.push((aux_features::NORMAL.to_string(), normal));
        }
        if let (true, Some(f)) = (request.features, &features) {
            let images = [f.position.cur, f.normal, f.albedo];
            read.extend(FEATURE_IMAGES.iter().map(|n| n.to_string()).zip(images));
        }
        if request.readback {
            for name in &self.extra_readbacks {
                read.push((name.clone(), stage_image(graph, name, size)?));
            }
        }
        let readbacks = if request.readback {
            add_readbacks(ctx, graph, &mut frame, slot, &read, size)?
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
        // Right after a change (the frame before this one was waited for then), what only
        // the old state used goes now; otherwise what no frame in flight can still use.
        let idle = if std::mem::take(&mut self.release_unused) {
            1
        } else {
            SLOTS as u64 + 1
        };
        self.graph.release_unused(&self.ctx, idle);
        self.last_inputs = Some(inputs.clone());
        self.frame_index += 1;
        Ok(completed)
    }

    fn changes(&self, inputs: &FrameInputs, reset: bool) -> Changes {
        match &self.last_inputs {
            None => Changes {
                camera: true,
                lights: true,
                transfer_function: true,
                cut: true,
            },
            Some(last) => Changes {
                camera: reset || last.camera != inputs.camera,
                lights: reset || last.lights != inputs.lights,
                // A new time point changes the medium in place, as a TF edit does.
                // So does a label's look.
                transfer_function: reset
                    || last.lut != inputs.lut
                    || last.time != inputs.time
                    || last.labels != inputs.labels,
                cut: reset || last.cut != inputs.cut,
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
}

/// Samples per pixel one frame of `size` may take on this device: at least 1 (the
/// settings' own check), at most [`samples_per_dispatch`].
fn check_spp(ctx: &GpuContext, spp: u32, size: Extent) -> Result<()> {
    let max = samples_per_dispatch(&ctx.info, size.pixels());
    if (1..=max).contains(&spp) {
        return Ok(());
    }
    Err(EngineError::InvalidSetting {
        name: "spp",
        value: spp.to_string(),
        allowed: format!(
            "1 to {max} samples per pixel per frame on {} (use `dvr reference` or the \
             accum denoiser for more)",
            ctx.info.name
        ),
    })
}

/// Builds the denoisers called `names` for a renderer built for `config` whose path
/// tracer is specialised for `features`.
fn create_methods(
    ctx: &GpuContext,
    config: &RendererConfig,
    features: PathTraceFeatures,
    names: &[&str],
) -> Result<Vec<Method>> {
    let registry = &config.registry;
    let denoiser_config = DenoiserConfig {
        motion: config.motion_source,
        dataset: config.dataset,
        features,
    };
    names
        .iter()
        .map(|n| {
            let info = *registry.find(n)?;
            Ok(Method {
                info,
                denoiser: info.create(ctx, &denoiser_config)?,
            })
        })
        .collect()
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
        self.graph.destroy(ctx);
    }
}
