//! Every embedded SPIR-V module passes `spirv-val` (SPIRV-Tools, installed by
//! tools/setup.sh) for Vulkan 1.3, and reflects into bindings the engine can bind.

use dvr_engine::gpu::pipeline::shader_reflection;
use dvr_engine::shaders::SHADERS;
use std::process::Command;

#[test]
fn every_shader_passes_spirv_val() {
    assert!(!SHADERS.is_empty());
    let dir = tempfile::tempdir().expect("temp dir");
    for (name, bytes) in SHADERS {
        let path = dir.path().join(format!("{name}.spv"));
        std::fs::write(&path, bytes).expect("write spv");
        let out = Command::new("spirv-val")
            .args(["--target-env", "vulkan1.3"])
            .arg(&path)
            .output()
            .expect("spirv-val is installed (apt-get install spirv-tools)");
        assert!(
            out.status.success(),
            "{name}: spirv-val failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// The SPIR-V names its sources relative to the shader folder, never by the checkout's
/// path: the same source must compile to the same bytes wherever the repository lies
/// (`dvr eval` keys its reference cache on the path tracer's bytes).
#[test]
fn spirv_does_not_depend_on_the_checkout_path() {
    let checkout = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let needle = format!("{}/", checkout.display());
    for (name, bytes) in SHADERS {
        assert!(
            !bytes.windows(needle.len()).any(|w| w == needle.as_bytes()),
            "{name}'s SPIR-V holds the checkout path {needle}"
        );
    }
}

#[test]
fn every_shader_reflects_named_bindings_in_set_zero() {
    for (name, _) in SHADERS {
        let r = shader_reflection(name).expect("reflects");
        assert!(!r.bindings.is_empty(), "{name} binds nothing");
        for b in &r.bindings {
            assert_eq!(b.set, 0, "{name}: {} uses set {}", b.name, b.set);
            assert!(
                !b.name.is_empty(),
                "{name}: binding {} has no name",
                b.binding
            );
        }
        assert!(r.local_size.iter().product::<u32>() > 0);
    }
}

/// Every denoiser in the registry builds, for both motion sources: each pipeline checks
/// its push-constant struct and the frame block against the shader's reflection as it
/// is built, so a struct that disagrees with its GLSL block fails here.
#[test]
fn every_registered_denoiser_builds() {
    use dvr_engine::denoise::{DenoiserConfig, MotionSource, DENOISERS};
    let ctx = dvr_engine::gpu::GpuContext::headless().expect("device");
    for motion in [MotionSource::FirstHit, MotionSource::Features] {
        let config = DenoiserConfig {
            motion,
            ..Default::default()
        };
        for d in DENOISERS {
            d.create(&ctx, &config)
                .unwrap_or_else(|e| panic!("{}: {e}", d.name));
        }
    }
}
