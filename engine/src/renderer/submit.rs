//! A frame slot's command buffer, fence, timestamps and uniform buffer; recording and
//! submitting a frame into it; and the readbacks collected when it comes round.

use super::present;
use crate::error::{EngineError, Result, VkContext};
use crate::gpu::timestamps::TimestampPool;
use crate::gpu::GpuContext;
use crate::graph::{BufferHandle, Extent, Frame, ImageHandle, RenderGraph};
use ash::vk;

pub(super) struct Slot {
    pub cmd: vk::CommandBuffer,
    pub fence: vk::Fence,
    pub timestamps: TimestampPool,
    pub uniforms: BufferHandle,
    pub pending: Option<(u64, Vec<(String, BufferHandle)>)>,
    pub pending_screenshot: Option<present::PendingScreenshot>,
}

/// The rgba32f pixels of a host-visible readback buffer.
pub(super) fn read_pixels(graph: &RenderGraph, buffer: BufferHandle) -> Result<Vec<[f32; 4]>> {
    let bytes = graph
        .buffer_ref(buffer)
        .mapped()
        .ok_or_else(|| EngineError::Resource {
            resource: "readback".into(),
            problem: "buffer is not host visible".into(),
        })?;
    Ok(bytemuck::cast_slice::<u8, [f32; 4]>(bytes).to_vec())
}

pub(super) fn add_readbacks<'f>(
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
        let buffer = graph.readback(ctx, &format!("readback.{name}.{slot}"), bytes)?;
        frame.add_readback(name, *image, buffer);
        out.push((name.clone(), buffer));
    }
    Ok(out)
}

/// Records and submits a frame. `semaphores` (acquire, render-finished) when it presents:
/// the submission waits for the swapchain image at the stage the graph's first barrier
/// on it starts from, and signals the semaphore presentation waits on.
pub(super) fn submit(
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
