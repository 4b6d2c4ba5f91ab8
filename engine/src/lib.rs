include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
pub mod scene;
pub mod transfer;
