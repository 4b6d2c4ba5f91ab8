//! The compute shaders of `shaders/glsl/`, compiled to SPIR-V by build.rs.
include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
