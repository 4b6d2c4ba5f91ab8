//! One GPU pass per file, each with the shader of the same name in shaders/glsl. A pass
//! holds its pipeline (from the context's cache), declares its push-constant block beside
//! itself, and adds itself to a frame, declaring exactly what it touches and the shader
//! variable each resource binds to.

pub mod accumulate;
pub mod aux_features;
pub mod bandwidth;
pub mod motion;
pub mod path_trace;
pub mod present;
pub mod surface_features;

use crate::graph::{Bindings, BufferHandle, ImageHandle};

/// The scene's GPU resources that volume passes bind (declared in include/volume.glsl,
/// include/lights.glsl and include/frame.glsl).
#[derive(Clone, Copy, Debug)]
pub struct SceneBindings {
    pub uniforms: BufferHandle,
    pub volume: ImageHandle,
    pub tf_diffuse_opacity: ImageHandle,
    pub tf_specular_roughness: ImageHandle,
    pub tf_emissive: ImageHandle,
    pub majorant: ImageHandle,
    pub environment: ImageHandle,
    pub brick_pool: ImageHandle,
    pub brick_table: ImageHandle,
    /// The label map's look and shape (1×1×1 stand-ins without one).
    pub labels: ImageHandle,
    pub label_shape: ImageHandle,
}

impl SceneBindings {
    /// Binds the frame block, volume, LUTs, majorant grid and brick pool to the variables
    /// include/frame.glsl and include/volume.glsl declare.
    pub fn bind_volume(&self, b: &mut Bindings) {
        b.uniform("frame", self.uniforms)
            .sampled("volume_density", self.volume)
            .sampled("tf_diffuse_opacity", self.tf_diffuse_opacity)
            .sampled("tf_specular_roughness", self.tf_specular_roughness)
            .sampled("tf_emissive", self.tf_emissive)
            .sampled_nearest("majorant_grid", self.majorant)
            .sampled("brick_pool", self.brick_pool)
            .sampled_nearest("brick_table", self.brick_table)
            .sampled("label_look", self.labels)
            .sampled("label_shape", self.label_shape);
    }
}
