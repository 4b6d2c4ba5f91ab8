//! GPU timestamps around every pass. Each frame slot owns a query pool; results are read
//! when the slot comes round again (its fence has signalled), so timing never stalls the
//! frame being recorded. The pass name is the key everywhere: debug label, timestamp pair,
//! profiler row.
//!
//! Every timestamp is followed by a second one that is never read. On lavapipe, once a
//! graphics pass has bound a framebuffer (the explorer's UI), llvmpipe bins a timestamp
//! query into its current scene and records it at the *next* flush, which the next
//! timestamp command triggers: without the follower each value would land one pass late
//! (compute passes reading ~0 ms, their time falling between passes). The follower's
//! flush records the real one at once; elsewhere it costs one query.

use super::context::GpuContext;
use crate::error::{Result, VkContext};
use ash::vk;

/// Most passes one frame may time.
pub const MAX_TIMED_PASSES: u32 = 128;
/// Queries per pass: begin, its follower, end, its follower.
const QUERIES_PER_PASS: u32 = 4;

/// Whom a pass works for, recorded with its time so that reports add GPU time up per
/// method from the graph's own record rather than from pass names.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PassOwner {
    /// Work every method of the frame shares (path trace, motion, presentation).
    #[default]
    Shared,
    /// One method's own pass (a denoiser, by its name).
    Method(String),
    /// A pass that some of the frame's methods need and would each pay for alone (the
    /// surface features, the guide images): part of each one's cost.
    Methods(Vec<String>),
    /// Moves data into or out of the frame (uploads, readbacks): part of no method's
    /// rendering cost.
    Transfer,
}

impl PassOwner {
    /// Whether the pass is work `method` needs beyond the shared frame: its own, or one
    /// it needs with others.
    pub fn serves(&self, method: &str) -> bool {
        match self {
            PassOwner::Method(m) => m == method,
            PassOwner::Methods(ms) => ms.iter().any(|m| m == method),
            PassOwner::Shared | PassOwner::Transfer => false,
        }
    }

    /// Whether the pass is part of `method`'s GPU time: shared work and what it needs.
    pub fn counts_for(&self, method: &str) -> bool {
        *self == PassOwner::Shared || self.serves(method)
    }
}

/// GPU time of one pass in one frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PassTiming {
    pub pass: String,
    #[serde(default)]
    pub owner: PassOwner,
    /// Start, relative to the first timestamp of the frame, in milliseconds.
    pub start_ms: f64,
    pub ms: f64,
    /// Bytes the pass's declared accesses touch (the render graph's count; see
    /// `RenderGraph::declared_bytes`): with `ms`, the bandwidth it achieved.
    #[serde(default)]
    pub bytes: u64,
}

impl PassTiming {
    /// Achieved bandwidth in GB/s (10^9 bytes per second) of the declared bytes.
    pub fn gb_per_s(&self) -> f64 {
        gb_per_s(self.bytes as f64, self.ms)
    }
}

/// GB/s (10^9 bytes per second) of `bytes` moved in `ms` milliseconds; 0 for no time.
pub fn gb_per_s(bytes: f64, ms: f64) -> f64 {
    if ms > 0.0 {
        bytes / (ms * 1e6)
    } else {
        0.0
    }
}

pub struct TimestampPool {
    pool: vk::QueryPool,
    /// Name, owner and declared bytes of each pass timed in the recorded frame.
    names: Vec<(String, PassOwner, u64)>,
    period_ns: f64,
}

impl TimestampPool {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(MAX_TIMED_PASSES * QUERIES_PER_PASS);
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.vk("vkCreateQueryPool")?;
        Ok(Self {
            pool,
            names: Vec::new(),
            period_ns: ctx.info.timestamp_period,
        })
    }

    /// Resets the pool at the start of a frame's command buffer.
    pub fn reset(&mut self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        self.names.clear();
        unsafe {
            ctx.device
                .cmd_reset_query_pool(cmd, self.pool, 0, MAX_TIMED_PASSES * QUERIES_PER_PASS)
        };
    }

    /// Writes the opening timestamp of `pass`, done for `owner`, which touches `bytes`
    /// (reported with its time); returns false when the pool is full (the pass then runs untimed).
    pub fn begin(
        &mut self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        pass: &str,
        owner: &PassOwner,
        bytes: u64,
    ) -> bool {
        let index = self.names.len() as u32;
        if index >= MAX_TIMED_PASSES {
            return false;
        }
        self.names.push((pass.to_string(), owner.clone(), bytes));
        self.write(ctx, cmd, index * QUERIES_PER_PASS);
        true
    }

    pub fn end(&mut self, ctx: &GpuContext, cmd: vk::CommandBuffer) {
        let index = self.names.len() as u32 - 1;
        self.write(ctx, cmd, index * QUERIES_PER_PASS + 2);
    }

    /// A timestamp at `query` and its follower at `query + 1` (see the module docs).
    fn write(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, query: u32) {
        for q in [query, query + 1] {
            unsafe {
                ctx.device.cmd_write_timestamp2(
                    cmd,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    self.pool,
                    q,
                )
            };
        }
    }

    /// Reads the results of the last recorded frame. Call only after its fence signalled.
    pub fn read(&self, ctx: &GpuContext) -> Result<Vec<PassTiming>> {
        if self.names.is_empty() {
            return Ok(Vec::new());
        }
        let n = QUERIES_PER_PASS as usize;
        let mut raw = vec![0u64; self.names.len() * n];
        unsafe {
            ctx.device.get_query_pool_results(
                self.pool,
                0,
                &mut raw,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .vk("vkGetQueryPoolResults")?;
        let t0 = raw[0];
        let to_ms = |ticks: u64| ticks as f64 * self.period_ns * 1e-6;
        Ok(self
            .names
            .iter()
            .enumerate()
            .map(|(i, (name, owner, bytes))| PassTiming {
                pass: name.clone(),
                owner: owner.clone(),
                start_ms: to_ms(raw[n * i].saturating_sub(t0)),
                ms: to_ms(raw[n * i + 2].saturating_sub(raw[n * i])),
                bytes: *bytes,
            })
            .collect())
    }

    pub fn destroy(&mut self, ctx: &GpuContext) {
        unsafe { ctx.device.destroy_query_pool(self.pool, None) };
    }
}
