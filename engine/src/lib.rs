//! dvr engine: everything the applications share. Layers, each knowing only those below:
//! `shaders` (the compiled SPIR-V, block layouts, the frame block and shared constants) →
//! `gpu` (device, memory, pipelines, timestamps) → `graph` (explicit render graph) →
//! `passes` (one GPU pass per file) and `denoise` (each denoiser's passes and history) →
//! `renderer` (the frame) → `session` (a live view: edits in, frames out; what the
//! explorer, the scripted animations and Python drive). CPU-side data (`volume`,
//! `metrics`, `scene` and its `transfer`, crates of their own) feeds them; `assets` says
//! where the shipped files are.

pub mod denoise;
pub mod error;
pub mod gpu;
pub mod graph;
pub mod image_io;
pub mod passes;
pub mod renderer;
pub mod session;
pub mod shaders;

pub use error::{EngineError, Result};

// The GPU-free layers, crates of their own that the engine re-exports under the names
// the applications use.
pub use dvr_metrics as metrics;
pub use dvr_scene as scene;
pub use dvr_scene::transfer;
pub use dvr_volume as volume;
pub use dvr_volume::{assets, bytes, files};
