//! Tests of `access.rs`.

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
