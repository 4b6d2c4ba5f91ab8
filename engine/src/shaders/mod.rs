//! What the GLSL in `shaders/glsl/` declares, as Rust sees it: the SPIR-V that build.rs
//! compiled (by name), the layout contract of uniform and push-constant blocks
//! ([`gpu_block!`](crate::gpu_block)), and what every shader shares
//! ([`frame`]: the frame block, the lights and the constants of `include/frame.glsl` and
//! `include/specialization.glsl`). It is the bottom layer: the GPU layer builds pipelines
//! from it, passes and denoisers fill its blocks, and nothing here knows about either.

mod block;
pub mod frame;

pub use block::{Field, GpuBlock};

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
