//! One GPU pass per file, each with the shader of the same name in shaders/glsl. A pass
//! owns its pipeline and adds itself to a frame, declaring exactly what it touches.

pub mod accumulate;
pub mod bandwidth;
pub mod motion;
pub mod path_trace;
pub mod present;
pub mod surface_features;

use crate::graph::{Bind, BufferHandle, ImageHandle, PassBuilder};

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
}

impl SceneBindings {
    /// Declares the volume, LUTs, majorant grid and uniforms as read.
    pub fn declare_volume(&self, b: &mut PassBuilder) {
        b.uniform(self.uniforms)
            .sampled(self.volume)
            .sampled(self.tf_diffuse_opacity)
            .sampled(self.tf_specular_roughness)
            .sampled(self.tf_emissive)
            .sampled(self.majorant);
    }

    pub fn volume_binds(&self) -> Vec<(&'static str, Bind)> {
        vec![
            ("frame", Bind::Buffer(self.uniforms)),
            ("volume_density", Bind::Image(self.volume)),
            ("tf_diffuse_opacity", Bind::Image(self.tf_diffuse_opacity)),
            (
                "tf_specular_roughness",
                Bind::Image(self.tf_specular_roughness),
            ),
            ("tf_emissive", Bind::Image(self.tf_emissive)),
            ("majorant_grid", Bind::ImageNearest(self.majorant)),
        ]
    }
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
}
