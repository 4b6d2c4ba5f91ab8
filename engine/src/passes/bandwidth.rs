//! The device's memory bandwidth, measured: Vulkan has no property that tells it, so a
//! large buffer is copied back and forth through a render graph of its own and each copy
//! timed with the same timestamps and byte count (read + write, from the declarations)
//! as every profiled pass. The best copy is the peak that `dvr profile` compares passes
//! with. No shader: a transfer copy is what drivers make fastest.

use crate::error::Result;
use crate::gpu::timestamps::{gb_per_s, TimestampPool};
use crate::gpu::GpuContext;
use crate::graph::{Frame, RenderGraph};
use gpu_allocator::MemoryLocation;

/// Copies timed; the fastest counts (the others absorb clock ramp-up and noise).
const TIMED_COPIES: usize = 5;
/// Bounds of the probe buffer's size: large enough to leave any cache (an H200's L2 is
/// 60 MB), small enough to take a fraction of a second on lavapipe.
const MIN_BYTES: u64 = 16 << 20;
const MAX_BYTES: u64 = 256 << 20;

/// A measured peak bandwidth.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PeakBandwidth {
    /// Bytes read plus bytes written per second, 10^9 B/s.
    pub gb_per_s: f64,
    /// Size of each of the two buffers copied.
    pub buffer_bytes: u64,
    /// How it was obtained, for the report.
    pub method: String,
}

/// Size of the probe buffers on this device: a sixteenth of the largest device-local
/// heap, within [`MIN_BYTES`, `MAX_BYTES`] and the largest allowed allocation.
pub fn probe_bytes(device_local_heap: u64, max_allocation: u64) -> u64 {
    (device_local_heap / 16)
        .clamp(MIN_BYTES, MAX_BYTES)
        .min(max_allocation)
        & !0xff
}

/// Measures the copy bandwidth (blocks until done; the resources are freed after).
pub fn measure(ctx: &GpuContext) -> Result<PeakBandwidth> {
    let bytes = probe_bytes(
        ctx.info.device_local_heap,
        ctx.info.max_memory_allocation_size,
    );
    let mut graph = RenderGraph::new(ctx)?;
    let mut timestamps = TimestampPool::new(ctx)?;
    let result = (|| {
        let a = graph.buffer(ctx, "bandwidth.a", bytes, MemoryLocation::GpuOnly)?;
        let b = graph.buffer(ctx, "bandwidth.b", bytes, MemoryLocation::GpuOnly)?;
        let mut frame = Frame::new();
        // Both buffers are written once before timing, so no copy reads or writes
        // memory the driver has not yet backed (lavapipe maps pages on first touch).
        for (name, buffer) in [("bandwidth.fill_a", a), ("bandwidth.fill_b", b)] {
            frame.add_pass(
                name,
                |p| {
                    p.transfer_dst(buffer);
                },
                move |pc| pc.fill_buffer(buffer, 0x3f80_0000),
            );
        }
        for i in 0..TIMED_COPIES {
            let (src, dst) = if i % 2 == 0 { (a, b) } else { (b, a) };
            frame.add_pass(
                "bandwidth.copy",
                |p| {
                    p.transfer_src(src).transfer_dst(dst);
                },
                move |pc| pc.copy_buffer(src, dst),
            );
        }
        ctx.submit_and_wait(|cmd| {
            timestamps.reset(ctx, cmd);
            graph.execute(ctx, cmd, Some(&mut timestamps), frame)
        })?;
        let best = timestamps
            .read(ctx)?
            .iter()
            .filter(|t| t.pass == "bandwidth.copy")
            .map(|t| gb_per_s(t.bytes as f64, t.ms))
            .fold(0.0f64, f64::max);
        Ok(PeakBandwidth {
            gb_per_s: best,
            buffer_bytes: bytes,
            method: format!(
                "measured: best of {TIMED_COPIES} copies of a {} MiB buffer (bytes read + written)",
                bytes >> 20
            ),
        })
    })();
    timestamps.destroy(ctx);
    graph.destroy(ctx);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_size_stays_within_bounds() {
        // lavapipe: a 2 GiB heap and 2 GiB allocations.
        assert_eq!(probe_bytes(2 << 30, 2 << 30), 128 << 20);
        // A large GPU: capped.
        assert_eq!(probe_bytes(141 << 30, 1 << 40), MAX_BYTES);
        // A tiny heap: at least MIN_BYTES, unless allocations are smaller still.
        assert_eq!(probe_bytes(64 << 20, 1 << 30), MIN_BYTES);
        assert_eq!(probe_bytes(64 << 20, 8 << 20), 8 << 20);
    }
}
