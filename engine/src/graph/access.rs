//! How a pass touches a resource, and the state tracker that turns a sequence of such
//! accesses into barriers. Pure logic with no device: the unit tests below check
//! read-after-write, write-after-read, write-after-write and layout transitions, which
//! lavapipe's validation layer does not catch on its own (measured with Mesa 22.3:
//! synchronization validation let two back-to-back compute dispatches read and write
//! one storage image without a barrier).

use ash::vk;

/// The ways a pass may declare it uses an image or buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Access {
    /// Sampled through a sampler in a compute shader.
    Sampled,
    /// `imageLoad` / storage buffer read.
    StorageRead,
    /// `imageStore` / storage buffer write, previous contents not needed.
    StorageWrite,
    /// Both (read-modify-write in place).
    StorageReadWrite,
    /// Uniform buffer read.
    Uniform,
    TransferSrc,
    TransferDst,
    /// Read by the host after the frame's fence (readbacks).
    HostRead,
    /// Drawn to as a colour attachment by a graphics pipeline (load and store), e.g. the
    /// explorer's UI on top of the presented image.
    ColorAttachment,
    /// Handed to the presentation engine after the frame: the image ends in
    /// `PRESENT_SRC_KHR` and nothing in the command buffer touches it afterwards (the
    /// queue submission's signal semaphore orders presentation after it).
    Present,
}

/// The synchronisation scope of an access.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AccessInfo {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
    pub writes: bool,
}

impl Access {
    pub fn info(self) -> AccessInfo {
        use vk::AccessFlags2 as A;
        use vk::ImageLayout as L;
        use vk::PipelineStageFlags2 as S;
        let (stage, access, layout, writes) = match self {
            Access::Sampled => (
                S::COMPUTE_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
                false,
            ),
            Access::StorageRead => (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ, L::GENERAL, false),
            Access::StorageWrite => (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE, L::GENERAL, true),
            Access::StorageReadWrite => (
                S::COMPUTE_SHADER,
                A::SHADER_STORAGE_READ | A::SHADER_STORAGE_WRITE,
                L::GENERAL,
                true,
            ),
            Access::Uniform => (S::COMPUTE_SHADER, A::UNIFORM_READ, L::UNDEFINED, false),
            Access::TransferSrc => (
                S::COPY | S::CLEAR,
                A::TRANSFER_READ,
                L::TRANSFER_SRC_OPTIMAL,
                false,
            ),
            Access::TransferDst => (
                S::COPY | S::CLEAR,
                A::TRANSFER_WRITE,
                L::TRANSFER_DST_OPTIMAL,
                true,
            ),
            Access::HostRead => (S::HOST, A::HOST_READ, L::UNDEFINED, false),
            Access::ColorAttachment => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE,
                L::COLOR_ATTACHMENT_OPTIMAL,
                true,
            ),
            Access::Present => (S::NONE, A::NONE, L::PRESENT_SRC_KHR, false),
        };
        AccessInfo {
            stage,
            access,
            layout,
            writes,
        }
    }

    /// How many times a pass moves a resource it declares with this access: once per
    /// direction (read, write), so a read-modify-write counts its size twice. Accesses
    /// that record no GPU work (a host read after the fence, the hand-over to
    /// presentation) move nothing. The profiler's per-pass bytes come from this.
    pub fn traffic_count(self) -> u64 {
        match self {
            Access::Sampled
            | Access::StorageRead
            | Access::StorageWrite
            | Access::Uniform
            | Access::TransferSrc
            | Access::TransferDst => 1,
            Access::StorageReadWrite | Access::ColorAttachment => 2,
            Access::HostRead | Access::Present => 0,
        }
    }

    /// What an image must have been created for to be accessed this way.
    pub fn image_usage(self) -> vk::ImageUsageFlags {
        use vk::ImageUsageFlags as U;
        if self.is_storage() {
            return U::STORAGE;
        }
        match self {
            Access::Sampled => U::SAMPLED,
            Access::TransferSrc => U::TRANSFER_SRC,
            Access::TransferDst => U::TRANSFER_DST,
            Access::ColorAttachment => U::COLOR_ATTACHMENT,
            _ => U::empty(),
        }
    }

    pub fn is_storage(self) -> bool {
        matches!(
            self,
            Access::StorageRead | Access::StorageWrite | Access::StorageReadWrite
        )
    }
}

/// What the tracker remembers of one resource between accesses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ResourceState {
    /// Current image layout (`UNDEFINED` for buffers and for fresh images).
    pub layout: vk::ImageLayout,
    /// Stage and access of the last write, if its effects are not yet known to be visible
    /// everywhere.
    pub last_write: Option<(vk::PipelineStageFlags2, vk::AccessFlags2)>,
    /// Stages that read since the last write (a later write must wait for them).
    pub read_stages: vk::PipelineStageFlags2,
    /// Stage/access pairs the last write has already been made visible to.
    pub visible_stages: vk::PipelineStageFlags2,
    pub visible_access: vk::AccessFlags2,
}

impl Default for ResourceState {
    fn default() -> Self {
        Self {
            layout: vk::ImageLayout::UNDEFINED,
            last_write: None,
            read_stages: vk::PipelineStageFlags2::NONE,
            visible_stages: vk::PipelineStageFlags2::NONE,
            visible_access: vk::AccessFlags2::NONE,
        }
    }
}

impl ResourceState {
    /// The state of an image that arrives from outside the command buffer (a swapchain
    /// image): contents undefined, and available only after `stage` of this submission,
    /// the stage its acquire semaphore is waited on. The first access's barrier then
    /// starts at `stage`, which chains it to the semaphore wait, so its layout
    /// transition cannot run before the presentation engine has released the image.
    pub fn external(stage: vk::PipelineStageFlags2) -> Self {
        Self {
            last_write: Some((stage, vk::AccessFlags2::NONE)),
            ..Self::default()
        }
    }
}

/// A barrier the tracker asks for; images use the layouts, buffers ignore them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Barrier {
    pub src_stage: vk::PipelineStageFlags2,
    pub src_access: vk::AccessFlags2,
    pub dst_stage: vk::PipelineStageFlags2,
    pub dst_access: vk::AccessFlags2,
    pub old_layout: vk::ImageLayout,
    pub new_layout: vk::ImageLayout,
}

/// Advances `state` by one access and returns the barrier needed before it, if any.
/// `is_image` decides whether layouts matter.
pub fn transition(state: &mut ResourceState, access: Access, is_image: bool) -> Option<Barrier> {
    let next = access.info();
    let new_layout = if is_image && next.layout != vk::ImageLayout::UNDEFINED {
        next.layout
    } else {
        state.layout
    };
    let layout_change = is_image && new_layout != state.layout;

    if next.writes || layout_change {
        // A write (or a layout transition, which is a write) must wait for every earlier
        // access: the last write (memory dependency) and the reads since (execution).
        let src_stage = state
            .last_write
            .map(|(s, _)| s)
            .unwrap_or(vk::PipelineStageFlags2::NONE)
            | state.read_stages;
        let src_access = state
            .last_write
            .map(|(_, a)| a)
            .unwrap_or(vk::AccessFlags2::NONE);
        let needed = layout_change || src_stage != vk::PipelineStageFlags2::NONE;
        let barrier = needed.then_some(Barrier {
            src_stage,
            src_access,
            dst_stage: next.stage,
            dst_access: next.access,
            old_layout: state.layout,
            new_layout,
        });
        state.layout = new_layout;
        if next.writes {
            state.last_write = Some((next.stage, next.access));
            state.read_stages = vk::PipelineStageFlags2::NONE;
            state.visible_stages = vk::PipelineStageFlags2::NONE;
            state.visible_access = vk::AccessFlags2::NONE;
        } else {
            // A read after a layout transition: the transition made everything visible
            // to this reader.
            state.last_write = None;
            state.read_stages = next.stage;
            state.visible_stages = next.stage;
            state.visible_access = next.access;
        }
        return barrier;
    }

    // A read in the current layout.
    state.read_stages |= next.stage;
    let (w_stage, w_access) = state.last_write?;
    let already_visible =
        state.visible_stages.contains(next.stage) && state.visible_access.contains(next.access);
    if already_visible {
        return None;
    }
    state.visible_stages |= next.stage;
    state.visible_access |= next.access;
    Some(Barrier {
        src_stage: w_stage,
        src_access: w_access,
        dst_stage: next.stage,
        dst_access: next.access,
        old_layout: state.layout,
        new_layout: state.layout,
    })
}

#[cfg(test)]
mod tests;
