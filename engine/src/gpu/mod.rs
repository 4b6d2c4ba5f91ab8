//! The GPU layer: device, memory, pipelines, reflection, timestamps, and a window's
//! swapchain (given a surface). It knows nothing of volumes, denoising or windows.

pub mod context;
pub mod pipeline;
pub mod reflect;
pub mod resources;
pub mod swapchain;
pub mod timestamps;
pub mod validation;

pub use context::{ContextOptions, DeviceInfo, GpuContext, GpuMemory};
pub use pipeline::{ComputePipeline, Pipeline, SpecValue};
pub use resources::{GpuBuffer, GpuImage, ImageDesc};
pub use swapchain::{AcquiredImage, Swapchain};
