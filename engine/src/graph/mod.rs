//! The explicit render graph. Each frame the application declares passes; each pass
//! declares the images and buffers it touches and how ([`Access`]). At execution the
//! graph derives every barrier and layout transition from those declarations (nothing
//! else in the engine issues barriers), clears newly allocated resources, wraps each pass
//! in a debug label and a timestamp pair keyed by the pass name, and swaps history
//! resources at the end of the frame. A pass records commands through a [`PassContext`]
//! that refuses resources the pass did not declare. How a frame is declared: [`Frame`].

pub mod access;
mod context;
mod frame;
mod resources;

pub use access::{Access, Barrier, ResourceState};
pub use context::PassContext;
pub use frame::{Bindings, Frame, PassBuilder};
pub use resources::{BufferHandle, Extent, History, ImageHandle, Res};

use crate::error::{EngineError, Result};
use crate::gpu::resources::format_size;
use crate::gpu::timestamps::TimestampPool;
use crate::gpu::{GpuBuffer, GpuContext, GpuImage, ImageDesc};
use ash::vk;
use gpu_allocator::MemoryLocation;
use resources::{BufferSlot, HistorySlot, ImageSlot};
use std::collections::{BTreeMap, HashMap};

/// Frames after which an image replaced during a frame is released: more than the frames
/// a renderer keeps in flight (two), so none still uses it.
const RETIRE_AFTER_FRAMES: u64 = 3;

/// Persistent graph resources and their synchronisation state.
pub struct RenderGraph {
    images: Vec<ImageSlot>,
    image_names: HashMap<String, ImageHandle>,
    buffers: Vec<BufferSlot>,
    buffer_names: HashMap<String, BufferHandle>,
    histories: HashMap<String, HistorySlot>,
    /// Images replaced by a larger-usage copy, with the frame count when they were.
    retired: Vec<(GpuImage, u64)>,
    /// Frames ended so far.
    frames_ended: u64,
    linear_sampler: vk::Sampler,
    nearest_sampler: vk::Sampler,
}

impl RenderGraph {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let make = |filter: vk::Filter| {
            let info = vk::SamplerCreateInfo::default()
                .mag_filter(filter)
                .min_filter(filter)
                .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
                .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                .max_lod(0.0);
            unsafe { ctx.device.create_sampler(&info, None) }.map_err(|result| EngineError::Vk {
                call: "vkCreateSampler",
                result,
            })
        };
        Ok(Self {
            images: Vec::new(),
            image_names: HashMap::new(),
            buffers: Vec::new(),
            buffer_names: HashMap::new(),
            histories: HashMap::new(),
            retired: Vec::new(),
            frames_ended: 0,
            linear_sampler: make(vk::Filter::LINEAR)?,
            nearest_sampler: make(vk::Filter::NEAREST)?,
        })
    }

    /// The image named `name` with shape `desc`: allocated when a frame first uses it,
    /// for the ways that frame declares (see [`RenderGraph::execute`]), cleared to zero
    /// before its first access, reused on later frames, recreated if `desc` changes (a
    /// resize).
    pub fn image(&mut self, ctx: &GpuContext, name: &str, desc: ImageDesc) -> Result<ImageHandle> {
        if let Some(&h) = self.image_names.get(name) {
            let slot = &mut self.images[h.0 as usize];
            if slot.image.is_external() {
                return Err(EngineError::Resource {
                    resource: name.into(),
                    problem: "is an imported image; the graph cannot reallocate it".into(),
                });
            }
            if slot.image.desc == desc {
                return Ok(h);
            }
            slot.image.destroy(ctx);
            slot.image = GpuImage::unallocated(desc);
            slot.state = ResourceState::default();
            slot.needs_clear = true;
            return Ok(h);
        }
        let h = ImageHandle(self.images.len() as u32);
        self.images.push(ImageSlot {
            name: name.to_string(),
            image: GpuImage::unallocated(desc),
            state: ResourceState::default(),
            needs_clear: true,
            used_in: self.frames_ended,
        });
        self.image_names.insert(name.to_string(), h);
        Ok(h)
    }

    /// Imports an image the graph does not own (a swapchain image acquired this frame)
    /// under `name`, or updates the import of that name (a recreated swapchain). Its
    /// state restarts every import: contents undefined, usable after `available_stage`,
    /// the stage at which this frame's submission waits for the image (see
    /// [`ResourceState::external`]). It is never cleared and never destroyed by the graph.
    pub fn import_image(
        &mut self,
        name: &str,
        image: vk::Image,
        view: vk::ImageView,
        desc: ImageDesc,
        available_stage: vk::PipelineStageFlags2,
    ) -> Result<ImageHandle> {
        let imported = GpuImage::external(image, view, desc);
        let state = ResourceState::external(available_stage);
        if let Some(&h) = self.image_names.get(name) {
            let slot = &mut self.images[h.0 as usize];
            if !slot.image.is_external() {
                return Err(EngineError::Resource {
                    resource: name.into(),
                    problem: "is a graph-owned image; imports need a name of their own".into(),
                });
            }
            slot.image = imported;
            slot.state = state;
            slot.needs_clear = false;
            return Ok(h);
        }
        let h = ImageHandle(self.images.len() as u32);
        self.images.push(ImageSlot {
            name: name.to_string(),
            image: imported,
            state,
            needs_clear: false,
            used_in: self.frames_ended,
        });
        self.image_names.insert(name.to_string(), h);
        Ok(h)
    }

    /// A ping-pong pair: `prev` holds what the pass wrote last frame, `cur` is written
    /// this frame. `valid` is false on the first frame, after a resize and after
    /// [`RenderGraph::reset_history`]; shaders must be told and not read `prev` then.
    pub fn history(&mut self, ctx: &GpuContext, name: &str, desc: ImageDesc) -> Result<History> {
        let a = self.image(ctx, &format!("{name}#0"), desc)?;
        let b = self.image(ctx, &format!("{name}#1"), desc)?;
        let slot = self
            .histories
            .entry(name.to_string())
            .or_insert(HistorySlot {
                images: [a, b],
                flip: false,
                valid: false,
                used: false,
            });
        slot.used = true;
        let (prev, cur) = if slot.flip { (b, a) } else { (a, b) };
        // Valid only if `prev` holds what a frame wrote: not a new image (the first
        // frame, a resize). `cur` is new on the second frame, which is written before
        // it is read, so it does not matter.
        if self.images[prev.0 as usize].needs_clear {
            slot.valid = false;
        }
        Ok(History {
            prev,
            cur,
            valid: slot.valid,
        })
    }

    /// Keeps `h` as a frame that used it would: [`RenderGraph::release_unused`] counts
    /// this frame as one that did (images a frame keeps for later frames without a pass
    /// touching them, as a kept features march's).
    pub fn retain(&mut self, h: ImageHandle) {
        self.images[h.0 as usize].used_in = self.frames_ended;
    }

    /// Whether `h` holds what an earlier frame wrote: false for an image made (or made
    /// again at a new size, or after [`RenderGraph::release_unused`]) since.
    pub fn holds_content(&self, h: ImageHandle) -> bool {
        let slot = &self.images[h.0 as usize];
        slot.image.is_allocated() && !slot.needs_clear
    }

    /// The image named `name` as this frame writes it: a history's `cur`, or the image of
    /// that name; `None` if the graph has neither.
    pub fn find_image(&self, name: &str) -> Option<ImageHandle> {
        match self.histories.get(name) {
            Some(slot) => Some(slot.images[usize::from(!slot.flip)]),
            None => self.image_names.get(name).copied(),
        }
    }

    /// Marks every history whose name starts with `prefix` invalid (a camera cut, a
    /// scene change, a denoiser reset). `""` resets all.
    pub fn reset_history(&mut self, prefix: &str) {
        for (name, slot) in self.histories.iter_mut() {
            if name.starts_with(prefix) {
                slot.valid = false;
            }
        }
    }

    /// A buffer named `name`; recreated when the size changes.
    pub fn buffer(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        size: u64,
        location: MemoryLocation,
    ) -> Result<BufferHandle> {
        self.buffer_slot(ctx, name, size, location, false)
    }

    /// A host-visible buffer named `name` that a copy of this frame reads from: released
    /// by [`RenderGraph::release_unused`] once no frame in flight asked for it (a
    /// volume's set-up staging does not outlive its upload), made again when asked for.
    pub fn staging(&mut self, ctx: &GpuContext, name: &str, size: u64) -> Result<BufferHandle> {
        self.buffer_slot(ctx, name, size, MemoryLocation::CpuToGpu, true)
    }

    /// A host-readable buffer named `name` that a copy of this frame writes into: like
    /// [`RenderGraph::staging`], released once no frame in flight asked for it (the
    /// readback of a denoiser no longer read, or of a size no longer drawn).
    pub fn readback(&mut self, ctx: &GpuContext, name: &str, size: u64) -> Result<BufferHandle> {
        self.buffer_slot(ctx, name, size, MemoryLocation::GpuToCpu, true)
    }

    fn buffer_slot(
        &mut self,
        ctx: &GpuContext,
        name: &str,
        size: u64,
        location: MemoryLocation,
        transient: bool,
    ) -> Result<BufferHandle> {
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER
            | vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST;
        let used_in = self.frames_ended;
        if let Some(&h) = self.buffer_names.get(name) {
            let slot = &mut self.buffers[h.0 as usize];
            slot.used_in = used_in;
            slot.transient = transient;
            let same = slot.buffer.size == size && slot.location == location;
            if same && slot.buffer.is_allocated() {
                return Ok(h);
            }
            slot.buffer.destroy(ctx);
            slot.buffer = GpuBuffer::new(ctx, name, size, usage, location)?;
            slot.location = location;
            slot.state = ResourceState::default();
            return Ok(h);
        }
        let h = BufferHandle(self.buffers.len() as u32);
        self.buffers.push(BufferSlot {
            name: name.to_string(),
            buffer: GpuBuffer::new(ctx, name, size, usage, location)?,
            state: ResourceState::default(),
            location,
            transient,
            used_in,
        });
        self.buffer_names.insert(name.to_string(), h);
        Ok(h)
    }

    pub fn image_desc(&self, h: ImageHandle) -> ImageDesc {
        self.images[h.0 as usize].image.desc
    }

    pub fn buffer_ref(&self, h: BufferHandle) -> &GpuBuffer {
        &self.buffers[h.0 as usize].buffer
    }

    pub fn buffer_mut(&mut self, h: BufferHandle) -> &mut GpuBuffer {
        &mut self.buffers[h.0 as usize].buffer
    }

    pub fn image_name(&self, h: ImageHandle) -> &str {
        &self.images[h.0 as usize].name
    }

    /// Bytes of a graph resource: the image's texels times their size, or the buffer's
    /// size.
    pub fn resource_bytes(&self, r: Res) -> u64 {
        match r {
            Res::Image(h) => {
                let desc = self.images[h.0 as usize].image.desc;
                desc.texel_count() * format_size(desc.format)
            }
            Res::Buffer(h) => self.buffers[h.0 as usize].buffer.size,
        }
    }

    /// The bytes a pass's declared accesses touch: each resource's size once per
    /// direction it is declared to move (see [`Access::traffic_count`]). A lower bound
    /// on the pass's memory traffic when it touches all of what it declares (the
    /// image-space passes); for a pass that samples sparsely (the path tracer's volume)
    /// an upper estimate of what it needs.
    pub fn declared_bytes(&self, accesses: &[(Res, Access)]) -> u64 {
        accesses
            .iter()
            .map(|&(r, a)| a.traffic_count() * self.resource_bytes(r))
            .sum()
    }

    fn res_name(&self, r: Res) -> &str {
        match r {
            Res::Image(h) => &self.images[h.0 as usize].name,
            Res::Buffer(h) => &self.buffers[h.0 as usize].name,
        }
    }

    /// Checks a frame before recording: handles exist, no resource is declared twice with
    /// conflicting accesses in one pass, storage images have storage-capable formats.
    pub fn validate(&self, frame: &Frame) -> Result<()> {
        let mut presented: Vec<Res> = Vec::new();
        for pass in &frame.passes {
            if let Some((r, _)) = pass.accesses.iter().find(|(r, _)| presented.contains(r)) {
                return Err(EngineError::Pass {
                    pass: pass.name.clone(),
                    problem: format!(
                        "uses {:?} after it was handed to presentation",
                        self.res_name(*r)
                    ),
                });
            }
            presented.extend(
                pass.accesses
                    .iter()
                    .filter(|(_, a)| *a == Access::Present)
                    .map(|(r, _)| *r),
            );
            let mut seen: HashMap<Res, Access> = HashMap::new();
            for &(r, a) in &pass.accesses {
                let exists = match r {
                    Res::Image(h) => (h.0 as usize) < self.images.len(),
                    Res::Buffer(h) => (h.0 as usize) < self.buffers.len(),
                };
                if !exists {
                    return Err(EngineError::Pass {
                        pass: pass.name.clone(),
                        problem: format!("declares unknown resource {r:?}"),
                    });
                }
                if let Some(prev) = seen.insert(r, a) {
                    if prev != a {
                        return Err(EngineError::Pass {
                            pass: pass.name.clone(),
                            problem: format!(
                                "declares {:?} twice ({prev:?} and {a:?}); use one access",
                                self.res_name(r)
                            ),
                        });
                    }
                }
                let image_only = matches!(
                    a,
                    Access::Sampled | Access::ColorAttachment | Access::Present
                );
                if matches!(r, Res::Buffer(_)) && image_only {
                    return Err(EngineError::Pass {
                        pass: pass.name.clone(),
                        problem: format!(
                            "buffer {:?} cannot be used as {a:?} (images only)",
                            self.res_name(r)
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Records `frame` into `cmd`: image allocations, barriers, clears of new resources,
    /// labels, timestamps.
    pub fn execute(
        &mut self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        timestamps: Option<&mut TimestampPool>,
        frame: Frame,
    ) -> Result<()> {
        self.validate(&frame)?;
        self.release_retired(ctx);
        self.allocate_images(ctx, cmd, &frame)?;
        for pass in &frame.passes {
            for &(r, _) in &pass.accesses {
                if let Res::Image(h) = r {
                    self.images[h.0 as usize].used_in = self.frames_ended;
                }
            }
        }
        let mut timestamps = timestamps;
        for mut pass in frame.passes {
            self.clear_new_resources(ctx, cmd, &pass.accesses);
            let mut image_barriers = Vec::new();
            let mut buffer_barriers = Vec::new();
            for &(r, a) in &pass.accesses {
                match r {
                    Res::Image(h) => {
                        let slot = &mut self.images[h.0 as usize];
                        if let Some(b) = access::transition(&mut slot.state, a, true) {
                            image_barriers.push(image_barrier(slot.image.image, &b));
                        }
                    }
                    Res::Buffer(h) => {
                        let slot = &mut self.buffers[h.0 as usize];
                        if let Some(b) = access::transition(&mut slot.state, a, false) {
                            buffer_barriers.push(buffer_barrier(slot.buffer.buffer, &b));
                        }
                    }
                }
            }
            if !image_barriers.is_empty() || !buffer_barriers.is_empty() {
                let dep = vk::DependencyInfo::default()
                    .image_memory_barriers(&image_barriers)
                    .buffer_memory_barriers(&buffer_barriers);
                unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
            }
            let Some(record) = pass.record.take() else {
                continue;
            };
            begin_label(ctx, cmd, &pass.name);
            let bytes = self.declared_bytes(&pass.accesses);
            let timed = timestamps
                .as_deref_mut()
                .is_some_and(|t| t.begin(ctx, cmd, &pass.name, &pass.owner, bytes));
            let mut pc = PassContext::new(
                ctx,
                cmd,
                self,
                &pass.name,
                &pass.accesses,
                &pass.bound,
                [self.linear_sampler, self.nearest_sampler],
            );
            record(&mut pc)?;
            if timed {
                if let Some(t) = timestamps.as_deref_mut() {
                    t.end(ctx, cmd);
                }
            }
            end_label(ctx, cmd);
        }
        Ok(())
    }

    /// Clears images created since the last frame to zero before their first access, so
    /// a fresh history or accumulation buffer never holds garbage.
    fn clear_new_resources(
        &mut self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        accesses: &[(Res, Access)],
    ) {
        for &(r, _) in accesses {
            let Res::Image(h) = r else { continue };
            let slot = &mut self.images[h.0 as usize];
            if !slot.needs_clear {
                continue;
            }
            slot.needs_clear = false;
            if let Some(b) = access::transition(&mut slot.state, Access::TransferDst, true) {
                let barriers = [image_barrier(slot.image.image, &b)];
                let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
                unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
            }
            let zero = vk::ClearColorValue { float32: [0.0; 4] };
            unsafe {
                ctx.device.cmd_clear_color_image(
                    cmd,
                    slot.image.image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &zero,
                    &[crate::gpu::resources::color_range()],
                )
            };
        }
    }

    /// Gives every image `frame` uses memory, created for all the ways the frame
    /// declares it (a history's two images for both sides' ways, since they trade
    /// places; always transfer source and destination, for clears and readbacks at any
    /// time). An image a frame uses in a way it was not created for is created again
    /// with that way added, its contents copied over, and the old one released once no
    /// frame in flight can still use it.
    fn allocate_images(
        &mut self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        frame: &Frame,
    ) -> Result<()> {
        let mut needed: BTreeMap<u32, vk::ImageUsageFlags> = BTreeMap::new();
        for pass in &frame.passes {
            for &(r, a) in &pass.accesses {
                if let Res::Image(h) = r {
                    *needed.entry(h.0).or_default() |= a.image_usage();
                }
            }
        }
        for history in self.histories.values() {
            let [a, b] = history.images.map(|h| h.0);
            if needed.contains_key(&a) || needed.contains_key(&b) {
                let both = needed.get(&a).copied().unwrap_or_default()
                    | needed.get(&b).copied().unwrap_or_default();
                needed.insert(a, both);
                needed.insert(b, both);
            }
        }
        let always = vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        for (i, usage) in needed {
            let slot = &mut self.images[i as usize];
            let usage = usage | always;
            if slot.image.is_external() || slot.image.usage.contains(usage) {
                continue;
            }
            if !slot.image.is_allocated() {
                slot.image = GpuImage::new(ctx, &slot.name, slot.image.desc, usage)?;
                continue;
            }
            let grown = GpuImage::new(ctx, &slot.name, slot.image.desc, slot.image.usage | usage)?;
            let old = std::mem::replace(&mut slot.image, grown);
            let mut state = ResourceState::default();
            if !slot.needs_clear {
                copy_image(ctx, cmd, (&old, &mut slot.state), (&slot.image, &mut state));
            }
            slot.state = state;
            self.retired.push((old, self.frames_ended));
        }
        Ok(())
    }

    /// Releases images replaced long enough ago that no frame in flight uses them.
    fn release_retired(&mut self, ctx: &GpuContext) {
        let now = self.frames_ended;
        self.retired.retain_mut(|(image, at)| {
            let done = now >= *at + RETIRE_AFTER_FRAMES;
            if done {
                image.destroy(ctx);
            }
            !done
        });
    }

    /// Releases the memory of every image none of the last `frames` ended frames declared
    /// (a removed denoiser's, a split view switched off), and of every staging buffer
    /// none of them asked for: the frames in flight must be
    /// among those `frames`, so none uses a released image. A released image keeps its
    /// name and shape and is allocated and cleared again when a frame uses it; a history
    /// with a released side restarts. Called after every frame, it makes the memory held
    /// a function of what the recent frames drew, not of everything drawn since start.
    pub fn release_unused(&mut self, ctx: &GpuContext, frames: u64) {
        let Some(last) = self.frames_ended.checked_sub(1) else {
            return;
        };
        let mut released = Vec::new();
        for (i, slot) in self.images.iter_mut().enumerate() {
            if slot.used_in + frames.max(1) <= last
                && !slot.image.is_external()
                && slot.image.is_allocated()
            {
                let desc = slot.image.desc;
                slot.image.destroy(ctx);
                slot.image = GpuImage::unallocated(desc);
                slot.state = ResourceState::default();
                slot.needs_clear = true;
                released.push(ImageHandle(i as u32));
            }
        }
        for slot in &mut self.buffers {
            if slot.transient && slot.used_in + frames.max(1) <= last && slot.buffer.is_allocated()
            {
                slot.buffer.destroy(ctx);
                slot.state = ResourceState::default();
            }
        }
        for h in self.histories.values_mut() {
            if h.images.iter().any(|i| released.contains(i)) {
                h.valid = false;
            }
        }
    }

    /// Ends the frame: histories used this frame swap and become valid.
    pub fn end_frame(&mut self) {
        self.frames_ended += 1;
        for slot in self.histories.values_mut() {
            if slot.used {
                slot.flip = !slot.flip;
                slot.valid = true;
                slot.used = false;
            }
        }
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        for s in &mut self.images {
            s.image.destroy(ctx);
        }
        for (image, _) in &mut self.retired {
            image.destroy(ctx);
        }
        self.retired.clear();
        for s in &mut self.buffers {
            s.buffer.destroy(ctx);
        }
        self.images.clear();
        self.buffers.clear();
        self.image_names.clear();
        self.buffer_names.clear();
        self.histories.clear();
        unsafe {
            ctx.device.destroy_sampler(self.linear_sampler, None);
            ctx.device.destroy_sampler(self.nearest_sampler, None);
        }
    }
}

/// Copies all of `from` into `to` (the same shape), with the barriers each needs.
fn copy_image(
    ctx: &GpuContext,
    cmd: vk::CommandBuffer,
    (from, from_state): (&GpuImage, &mut ResourceState),
    (to, to_state): (&GpuImage, &mut ResourceState),
) {
    let barriers: Vec<_> = [
        access::transition(from_state, Access::TransferSrc, true)
            .map(|b| image_barrier(from.image, &b)),
        access::transition(to_state, Access::TransferDst, true)
            .map(|b| image_barrier(to.image, &b)),
    ]
    .into_iter()
    .flatten()
    .collect();
    let layers = vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    };
    let [width, height, depth] = from.desc.extent;
    let region = vk::ImageCopy::default()
        .src_subresource(layers)
        .dst_subresource(layers)
        .extent(vk::Extent3D {
            width,
            height,
            depth,
        });
    unsafe {
        let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        ctx.device.cmd_pipeline_barrier2(cmd, &dep);
        ctx.device.cmd_copy_image(
            cmd,
            from.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            to.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
    }
}

fn image_barrier(image: vk::Image, b: &Barrier) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(b.src_stage)
        .src_access_mask(b.src_access)
        .dst_stage_mask(b.dst_stage)
        .dst_access_mask(b.dst_access)
        .old_layout(b.old_layout)
        .new_layout(b.new_layout)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(crate::gpu::resources::color_range())
}

fn buffer_barrier(buffer: vk::Buffer, b: &Barrier) -> vk::BufferMemoryBarrier2<'static> {
    vk::BufferMemoryBarrier2::default()
        .src_stage_mask(b.src_stage)
        .src_access_mask(b.src_access)
        .dst_stage_mask(b.dst_stage)
        .dst_access_mask(b.dst_access)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .buffer(buffer)
        .offset(0)
        .size(vk::WHOLE_SIZE)
}

fn begin_label(ctx: &GpuContext, cmd: vk::CommandBuffer, name: &str) {
    if let (Some(du), Ok(c)) = (&ctx.debug_utils, std::ffi::CString::new(name)) {
        let label = vk::DebugUtilsLabelEXT::default().label_name(&c);
        unsafe { du.cmd_begin_debug_utils_label(cmd, &label) };
    }
}

fn end_label(ctx: &GpuContext, cmd: vk::CommandBuffer) {
    if let Some(du) = &ctx.debug_utils {
        unsafe { du.cmd_end_debug_utils_label(cmd) };
    }
}
