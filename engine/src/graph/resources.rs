//! Handles and slots of graph resources, and a resource bound to a shader variable.

use super::access::ResourceState;
use crate::gpu::{GpuBuffer, GpuImage};
use gpu_allocator::MemoryLocation;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageHandle(pub(crate) u32);

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferHandle(pub(crate) u32);

/// Either kind of graph resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Res {
    Image(ImageHandle),
    Buffer(BufferHandle),
}

impl From<ImageHandle> for Res {
    fn from(h: ImageHandle) -> Self {
        Res::Image(h)
    }
}

impl From<BufferHandle> for Res {
    fn from(h: BufferHandle) -> Self {
        Res::Buffer(h)
    }
}

/// A resource bound to a shader variable of a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Bound {
    /// The variable's name in the shader.
    pub var: &'static str,
    pub res: Res,
    /// Sampled with the nearest (not the linear) clamp sampler.
    pub nearest: bool,
}

/// Image size of a frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Extent {
    pub width: u32,
    pub height: u32,
}

impl Extent {
    pub fn pixels(&self) -> u64 {
        u64::from(self.width) * u64::from(self.height)
    }

    /// Width over height (a zero height counts as 1).
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height.max(1) as f32
    }
}

/// The two sides of a history resource for this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct History {
    /// Written last frame; read this frame only when `valid`.
    pub prev: ImageHandle,
    /// Written this frame; becomes `prev` next frame.
    pub cur: ImageHandle,
    pub valid: bool,
}

pub(crate) struct ImageSlot {
    pub name: String,
    pub image: GpuImage,
    pub state: ResourceState,
    pub needs_clear: bool,
    /// The frame (the graph's count of ended frames) that last declared it.
    pub used_in: u64,
}

pub(crate) struct BufferSlot {
    pub name: String,
    pub buffer: GpuBuffer,
    pub state: ResourceState,
    pub location: MemoryLocation,
    /// A staging or readback buffer: released once no frame in flight copies with it, made again
    /// when next asked for.
    pub transient: bool,
    /// The frame (the graph's count of ended frames) that last asked for it.
    pub used_in: u64,
}

pub(crate) struct HistorySlot {
    /// Its two images (`name#0`, `name#1`), which trade places every frame.
    pub images: [ImageHandle; 2],
    pub flip: bool,
    pub valid: bool,
    pub used: bool,
}
