//! High-sample references: accumulated in as few path-tracing dispatches as the device
//! takes, from a sample stream of their own.

use super::uniforms::check_light_count;
use super::{add_readbacks, read_pixels, FrameInputs, Renderer};
use crate::error::{EngineError, Result};
use crate::graph::Frame;
use crate::shaders::frame::SampleStream;

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

impl Renderer {
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
            return Err(EngineError::InvalidSetting {
                name: "reference spp",
                value: spp.to_string(),
                allowed: "a reference needs at least 1 sample per pixel".into(),
            });
        }
        let batch = batch.clamp(1, spp.clamp(1, self.samples_per_dispatch()));
        self.graph.reset_history("reference.");
        let mut done = 0;
        let mut image = Vec::new();
        while done < spp {
            let n = batch.min(spp - done);
            let mut frame = Frame::new();
            let majorant_max = self.upload_transfer_function(&mut frame, 0, inputs, false)?;
            let stream = SampleStream::Reference {
                after_frames: self.frame_index,
            };
            let block = self.frame_block(inputs, majorant_max, stream);
            let scene = self.write_uniforms(0, &block)?;
            let (ctx, graph, passes, size) =
                (&self.ctx, &mut self.graph, &self.passes, self.config.size);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::DeviceInfo;
    use ash::vk;

    fn device(driver_id: vk::DriverId) -> DeviceInfo {
        DeviceInfo {
            name: "a device".into(),
            device_type: vk::PhysicalDeviceType::DISCRETE_GPU,
            driver_id,
            timestamp_period: 1.0,
            max_image_dimension_3d: 2048,
            max_image_dimension_2d: 16384,
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
