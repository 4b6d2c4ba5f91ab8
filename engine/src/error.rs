//! The engine's error type. Every variant names what failed (the device, the pass, the
//! resource or the file) so a user can act on the message without a backtrace.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum EngineError {
    #[error(
        "no Vulkan loader found ({0}); install libvulkan1 and a driver \
         (mesa-vulkan-drivers provides lavapipe, the CPU device) — tools/setup.sh does both"
    )]
    NoLoader(String),
    #[error(
        "no usable Vulkan device: {0}; install mesa-vulkan-drivers for lavapipe, \
         or a GPU driver"
    )]
    NoDevice(String),
    #[error("DVR_DEVICE={wanted:?} matches no Vulkan device; available: {available}")]
    DeviceNotFound { wanted: String, available: String },
    #[error("Vulkan call {call} failed: {result}")]
    Vk {
        call: &'static str,
        result: ash::vk::Result,
    },
    #[error("GPU memory allocation for {what} failed: {source}")]
    Alloc {
        what: String,
        #[source]
        source: gpu_allocator::AllocationError,
    },
    #[error("shader {0:?} is not embedded in this build (see shaders/glsl/)")]
    UnknownShader(String),
    #[error("shader {shader}: {problem}")]
    Reflection { shader: String, problem: String },
    #[error("unknown denoiser {name:?}; available: {available}")]
    UnknownDenoiser { name: String, available: String },
    #[error("{name} = {value} is not allowed; {allowed}")]
    InvalidSetting {
        name: &'static str,
        value: String,
        allowed: String,
    },
    #[error("pass {pass:?}: {problem}")]
    Pass { pass: String, problem: String },
    #[error("render graph: resource {resource:?}: {problem}")]
    Resource { resource: String, problem: String },
    #[error("network weights {file}: {problem}")]
    Weights { file: String, problem: String },
    #[error("{what} needs {needed} bytes but the device allows {limit} ({device})")]
    TooLarge {
        what: String,
        needed: u64,
        limit: u64,
        device: String,
    },
}

/// A render setting a scene's setter refused is the engine's `InvalidSetting`, with
/// the same fields and message.
impl From<dvr_scene::SettingError> for EngineError {
    fn from(e: dvr_scene::SettingError) -> Self {
        EngineError::InvalidSetting {
            name: e.name,
            value: e.value,
            allowed: e.allowed,
        }
    }
}

pub type Result<T, E = EngineError> = std::result::Result<T, E>;

/// Shorthand for wrapping a raw `vk::Result` with the call that produced it.
pub(crate) trait VkContext<T> {
    fn vk(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, ash::vk::Result> {
    fn vk(self, call: &'static str) -> Result<T> {
        self.map_err(|result| EngineError::Vk { call, result })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_render_setting_is_invalid_setting_with_the_same_message() {
        let refused = crate::scene::RenderSettings::default()
            .set_spp(0)
            .expect_err("0 spp");
        let message = refused.to_string();
        let e = EngineError::from(refused);
        assert!(matches!(e, EngineError::InvalidSetting { name: "spp", .. }));
        assert_eq!(e.to_string(), message);
    }
}
