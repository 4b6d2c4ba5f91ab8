//! The GPU layer: device, memory, pipelines, reflection, timestamps. It knows nothing of
//! volumes or denoising.

pub mod context;
pub mod pipeline;
pub mod reflect;
pub mod resources;
pub mod timestamps;
pub mod validation;

pub use context::{ContextOptions, DeviceInfo, GpuContext};
pub use pipeline::{ComputePipeline, SpecValue};
pub use resources::{GpuBuffer, GpuImage, ImageDesc};
