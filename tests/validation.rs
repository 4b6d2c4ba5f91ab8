//! The validation plumbing itself: with the layer on, a deliberate misuse is reported and
//! counted (so a clean run means something). In its own test binary because the message
//! log is process-wide.

use ash::vk;
use dvr_engine::gpu::{validation, ContextOptions, GpuContext};

#[test]
fn a_deliberate_misuse_is_reported() {
    let ctx = GpuContext::new(ContextOptions {
        validation: Some(true),
        ..Default::default()
    })
    .expect("context with validation (install vulkan-validationlayers)");
    assert!(ctx.validation_enabled);
    let before = validation::message_count();
    // Anisotropic filtering without enabling the samplerAnisotropy feature is invalid.
    let info = vk::SamplerCreateInfo::default()
        .anisotropy_enable(true)
        .max_anisotropy(4.0);
    if let Ok(s) = unsafe { ctx.device.create_sampler(&info, None) } {
        unsafe { ctx.device.destroy_sampler(s, None) };
    }
    assert!(
        validation::message_count() > before,
        "the validation layer did not report the misuse"
    );
}
