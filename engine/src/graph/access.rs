//! How a pass touches a resource, and the state tracker that turns a sequence of such
//! accesses into barriers. Pure logic with no device: the unit tests below check
//! read-after-write, write-after-read, write-after-write and layout transitions, which
//! lavapipe's validation layer does not catch on its own (see shared/LAVAPIPE.md).

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
mod tests {
    use super::*;
    use vk::AccessFlags2 as A;
    use vk::ImageLayout as L;
    use vk::PipelineStageFlags2 as S;

    #[test]
    fn traffic_counts_each_direction_once() {
        assert_eq!(Access::StorageRead.traffic_count(), 1);
        assert_eq!(Access::Sampled.traffic_count(), 1);
        assert_eq!(Access::StorageWrite.traffic_count(), 1);
        assert_eq!(Access::TransferDst.traffic_count(), 1);
        assert_eq!(Access::StorageReadWrite.traffic_count(), 2);
        assert_eq!(Access::HostRead.traffic_count(), 0);
        assert_eq!(Access::Present.traffic_count(), 0);
    }

    #[test]
    fn first_write_transitions_from_undefined() {
        let mut s = ResourceState::default();
        let b = transition(&mut s, Access::StorageWrite, true).expect("layout transition");
        assert_eq!(b.old_layout, L::UNDEFINED);
        assert_eq!(b.new_layout, L::GENERAL);
        assert_eq!(b.src_stage, S::NONE);
        assert_eq!(b.dst_access, A::SHADER_STORAGE_WRITE);
    }

    #[test]
    fn read_after_write_waits_for_the_write_once() {
        let mut s = ResourceState::default();
        transition(&mut s, Access::StorageWrite, true);
        let b = transition(&mut s, Access::StorageRead, true).expect("RAW barrier");
        assert_eq!(b.src_stage, S::COMPUTE_SHADER);
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.dst_access, A::SHADER_STORAGE_READ);
        assert_eq!(b.old_layout, b.new_layout);
        // A second reader of the same kind needs nothing more.
        assert_eq!(transition(&mut s, Access::StorageRead, true), None);
    }

    #[test]
    fn compute_to_compute_storage_write_then_write_is_ordered() {
        // The hazard lavapipe's validation misses: two dispatches writing one image.
        let mut s = ResourceState::default();
        transition(&mut s, Access::StorageWrite, true);
        let b = transition(&mut s, Access::StorageWrite, true).expect("WAW barrier");
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.dst_access, A::SHADER_STORAGE_WRITE);
    }

    #[test]
    fn write_after_read_waits_for_the_reader() {
        let mut s = ResourceState::default();
        transition(&mut s, Access::StorageWrite, true);
        transition(&mut s, Access::StorageRead, true);
        let b = transition(&mut s, Access::StorageWrite, true).expect("WAR barrier");
        assert!(b.src_stage.contains(S::COMPUTE_SHADER));
    }

    #[test]
    fn sampled_read_after_storage_write_changes_layout() {
        let mut s = ResourceState::default();
        transition(&mut s, Access::StorageWrite, true);
        let b = transition(&mut s, Access::Sampled, true).expect("transition");
        assert_eq!(b.old_layout, L::GENERAL);
        assert_eq!(b.new_layout, L::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(b.src_access, A::SHADER_STORAGE_WRITE);
        assert_eq!(b.dst_access, A::SHADER_SAMPLED_READ);
        assert_eq!(transition(&mut s, Access::Sampled, true), None);
        // Writing again goes back to GENERAL and waits for the sampled reads.
        let w = transition(&mut s, Access::StorageWrite, true).expect("back to GENERAL");
        assert_eq!(w.old_layout, L::SHADER_READ_ONLY_OPTIMAL);
        assert!(w.src_stage.contains(S::COMPUTE_SHADER));
    }

    #[test]
    fn read_of_a_different_kind_needs_its_own_visibility() {
        let mut s = ResourceState::default();
        transition(&mut s, Access::TransferDst, false);
        let a = transition(&mut s, Access::Uniform, false).expect("uniform visibility");
        assert_eq!(a.dst_access, A::UNIFORM_READ);
        let b = transition(&mut s, Access::StorageRead, false).expect("storage visibility");
        assert_eq!(b.src_access, A::TRANSFER_WRITE);
        assert_eq!(transition(&mut s, Access::StorageRead, false), None);
    }

    #[test]
    fn buffers_never_change_layout() {
        let mut s = ResourceState::default();
        assert_eq!(transition(&mut s, Access::StorageRead, false), None);
        assert_eq!(transition(&mut s, Access::Uniform, false), None);
        let b = transition(&mut s, Access::TransferDst, false).expect("WAR");
        assert_eq!(b.old_layout, L::UNDEFINED);
        assert_eq!(b.new_layout, L::UNDEFINED);
        let h = transition(&mut s, Access::HostRead, false).expect("host visibility");
        assert_eq!(h.dst_stage, S::HOST);
        assert_eq!(h.src_access, A::TRANSFER_WRITE);
    }

    #[test]
    fn swapchain_image_goes_undefined_to_present_src() {
        // Acquired image: written by the present pass (compute), drawn over by the UI
        // (colour attachment), then handed to the presentation engine.
        let mut s = ResourceState::external(S::COMPUTE_SHADER);
        let first = transition(&mut s, Access::StorageWrite, true).expect("first write");
        assert_eq!(first.old_layout, L::UNDEFINED);
        assert_eq!(first.new_layout, L::GENERAL);
        // Chained to the acquire semaphore's wait stage.
        assert_eq!(first.src_stage, S::COMPUTE_SHADER);
        assert_eq!(first.src_access, A::NONE);
        let ui = transition(&mut s, Access::ColorAttachment, true).expect("to attachment");
        assert_eq!(ui.old_layout, L::GENERAL);
        assert_eq!(ui.new_layout, L::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(ui.src_access, A::SHADER_STORAGE_WRITE);
        assert!(ui.dst_access.contains(A::COLOR_ATTACHMENT_WRITE));
        let present = transition(&mut s, Access::Present, true).expect("final transition");
        assert_eq!(present.old_layout, L::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(present.new_layout, L::PRESENT_SRC_KHR);
        assert_eq!(present.src_stage, S::COLOR_ATTACHMENT_OUTPUT);
        assert!(present.src_access.contains(A::COLOR_ATTACHMENT_WRITE));
        assert_eq!(present.dst_access, A::NONE);
        assert_eq!(s.layout, L::PRESENT_SRC_KHR);
        // Nothing further is needed once presented.
        assert_eq!(transition(&mut s, Access::Present, true), None);
    }

    #[test]
    fn screenshot_copy_then_present_waits_for_the_copy() {
        let mut s = ResourceState::external(S::COMPUTE_SHADER);
        transition(&mut s, Access::StorageWrite, true);
        let copy = transition(&mut s, Access::TransferSrc, true).expect("to transfer src");
        assert_eq!(copy.new_layout, L::TRANSFER_SRC_OPTIMAL);
        assert_eq!(copy.src_access, A::SHADER_STORAGE_WRITE);
        let present = transition(&mut s, Access::Present, true).expect("final transition");
        assert_eq!(present.old_layout, L::TRANSFER_SRC_OPTIMAL);
        assert_eq!(present.new_layout, L::PRESENT_SRC_KHR);
        assert!(
            present.src_stage.contains(S::COPY),
            "waits for the copy's read"
        );
    }

    #[test]
    fn history_swap_orders_last_frames_write_before_this_frames_read() {
        // Two images ping-pong: frame 0 writes A; frame 1 reads A (as "previous") and
        // writes B; frame 2 reads B and writes A again, which must wait for frame 1's read.
        let mut a = ResourceState::default();
        let mut b = ResourceState::default();
        transition(&mut a, Access::StorageWrite, true);
        let raw = transition(&mut a, Access::Sampled, true).expect("frame 1 reads A");
        assert_eq!(raw.src_access, A::SHADER_STORAGE_WRITE);
        transition(&mut b, Access::StorageWrite, true);
        transition(&mut b, Access::Sampled, true).expect("frame 2 reads B");
        let war = transition(&mut a, Access::StorageWrite, true).expect("frame 2 rewrites A");
        assert!(war.src_stage.contains(S::COMPUTE_SHADER));
        assert_eq!(war.old_layout, L::SHADER_READ_ONLY_OPTIMAL);
        assert_eq!(war.new_layout, L::GENERAL);
    }
}
