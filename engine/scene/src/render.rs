//! `[render]`: how the path tracer spends its work on this scene, and the settings
//! model every renderer and the explorer use.
//!
//! These are the "model no more than a scene needs" switches: the path-tracing pipeline
//! is specialised on them (Vulkan specialisation constants), so a scene that does not
//! use emission, anisotropic scattering or ray marching pays nothing for them. Every
//! field has a default, so `[render]` may be omitted.

use serde::{Deserialize, Serialize};

use super::error::{num, Ctx, SceneError, SettingError};
use dvr_volume::bytes::parse_memory_size;

/// What a setter returns: `Err` names the setting, the value and its range.
type Result<T, E = SettingError> = std::result::Result<T, E>;

/// How free paths and transmittance are estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Estimator {
    /// Delta tracking for free paths, ratio tracking for shadow rays, over a majorant
    /// grid: unbiased (the default).
    #[default]
    Delta,
    /// Jittered Riemann-sum ray marching with `step_size` (Exposure Render's choice):
    /// biased, but its cost does not depend on the majorant.
    RayMarch,
}

/// The phase function at scattering events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Phase {
    /// Uniform over the sphere (the paper's choice, the default).
    #[default]
    Isotropic,
    /// Henyey–Greenstein with asymmetry `hg_g`.
    Hg,
    /// Exposure Render's hybrid: a BRDF lobe (TF diffuse/specular/roughness, gradient
    /// normal) chosen with a probability that grows with opacity and normalised gradient
    /// magnitude, otherwise the Henyey–Greenstein phase with `hg_g`.
    Hybrid,
}

/// What the path-tracing pipelines are specialised for: a change means new pipelines
/// (a new renderer), where a change of the live settings only restarts histories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PipelineKey {
    pub estimator: Estimator,
    pub phase: Phase,
    pub emission: bool,
}

/// How the path tracer spends its work: the one render-settings model. A scene file's
/// `[render]` section deserialises into it (every field optional), the renderer runs
/// with it and the explorer edits it. Fields are private; each setter states its
/// setting's allowed range, the only place it is stated, and a scene file is checked by
/// the same code (`RenderSettings::check`). Defaults: 2 spp, 4 bounces, delta
/// tracking, isotropic phase, Russian roulette from bounce 3, ray-march step 0.5 voxel,
/// no emission, seed 1, a 0.5-pixel Gaussian pixel filter, features at opacity 0.5.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Samples per pixel per frame (>= 1).
    spp: u32,
    /// Maximum number of scattering events per path. 0 leaves only emission and the
    /// unscattered background; 1 is single scattering (direct light at the first
    /// collision). The default of 4 is a starting point, not a measurement: a scene's
    /// bounce count should come from the reference difference between N and N+1
    /// bounces. The built-in cloud scenes (albedo ~0.97, many scattering events) use 8.
    max_bounces: u32,
    estimator: Estimator,
    phase: Phase,
    /// Henyey–Greenstein asymmetry, used by `hg` and `hybrid` (0 = isotropic).
    hg_g: f64,
    /// Russian roulette starts at this bounce (0 = from the first scattering event).
    russian_roulette_depth: u32,
    /// Ray-marching step in voxels (of the volume's longest axis), used by `ray-march`.
    step_size: f64,
    /// Whether the TF's emissive colour is added (off compiles emission out).
    emission: bool,
    /// Bytes the volume may take on the device ("512M", "2G" or a byte count); past it
    /// the volume is paged through the brick pool. Unset: half the device-local heap.
    #[serde(
        deserialize_with = "de_memory_size",
        serialize_with = "ser_memory_size",
        skip_serializing_if = "Option::is_none"
    )]
    gpu_memory: Option<u64>,
    // Not in scene files: a scene's frames always draw seed 1's sample streams (eval's
    // baseline and tests pick others), and the pixel filter and feature threshold are
    // the renderer's, set by tests that need a pinhole or another surface.
    #[serde(skip)]
    seed: u32,
    #[serde(skip)]
    filter_sigma: f64,
    #[serde(skip)]
    feature_threshold: f64,
}

/// Most bounces a path may take: far past any useful value with Russian roulette (the
/// white-furnace tests take up to 1000), low enough to bound a frame's cost.
pub const MAX_BOUNCES: u32 = 1024;

/// Most samples per pixel per frame a scene (or `--spp`) may ask for: a real-time
/// budget, far past the 1–2 the denoisers are made for; references take more through
/// `--ref-spp`. A device may allow fewer: the renderer says so, naming it (lavapipe
/// takes 4, see `renderer::MAX_SAMPLES_PER_DISPATCH`).
pub const MAX_SPP: u32 = 64;

/// Ray-march step range in voxels: below it a frame takes minutes, above it the march
/// steps over the volume.
pub const MIN_STEP_VOXELS: f64 = 0.05;
pub const MAX_STEP_VOXELS: f64 = 10.0;

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            spp: 2,
            max_bounces: 4,
            estimator: Estimator::Delta,
            phase: Phase::Isotropic,
            hg_g: 0.0,
            russian_roulette_depth: 3,
            step_size: 0.5,
            emission: false,
            gpu_memory: None,
            seed: 1,
            filter_sigma: 0.5,
            feature_threshold: 0.5,
        }
    }
}

/// A memory budget as `--gpu-memory` and `gpu_memory=` take it: [`parse_memory_size`],
/// then the range [`RenderSettings::set_gpu_memory`] allows.
pub fn parse_gpu_memory(s: &str) -> Result<u64, String> {
    let bytes = parse_memory_size(s)?;
    RenderSettings::default()
        .set_gpu_memory(Some(bytes))
        .map_err(|e| e.to_string())?;
    Ok(bytes)
}

fn de_memory_size<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<u64>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Size {
        Bytes(u64),
        Text(String),
    }
    match Option::<Size>::deserialize(d)? {
        None => Ok(None),
        Some(Size::Bytes(b)) => Ok(Some(b)),
        Some(Size::Text(t)) => parse_memory_size(&t)
            .map(Some)
            .map_err(serde::de::Error::custom),
    }
}

fn ser_memory_size<S: serde::Serializer>(v: &Option<u64>, s: S) -> Result<S::Ok, S::Error> {
    match v {
        Some(b) => s.serialize_u64(*b),
        None => s.serialize_none(),
    }
}

/// `Ok(())` when `ok`, else the setting's [`SettingError`].
fn allow(name: &'static str, value: impl std::fmt::Display, ok: bool, allowed: &str) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(SettingError {
            name,
            value: value.to_string(),
            allowed: allowed.to_string(),
        })
    }
}

impl RenderSettings {
    pub fn spp(&self) -> u32 {
        self.spp
    }
    pub fn max_bounces(&self) -> u32 {
        self.max_bounces
    }
    pub fn estimator(&self) -> Estimator {
        self.estimator
    }
    pub fn phase(&self) -> Phase {
        self.phase
    }
    pub fn hg_g(&self) -> f64 {
        self.hg_g
    }
    pub fn russian_roulette_depth(&self) -> u32 {
        self.russian_roulette_depth
    }
    pub fn step_size(&self) -> f64 {
        self.step_size
    }
    pub fn emission(&self) -> bool {
        self.emission
    }
    pub fn seed(&self) -> u32 {
        self.seed
    }
    pub fn gpu_memory(&self) -> Option<u64> {
        self.gpu_memory
    }
    /// The volume's memory budget on the device (see [`parse_memory_size`]): at least
    /// 64 KiB (one 8-bit brick and a little more). Renderers read it when they are made (it is
    /// the engine's `RendererConfig::gpu_memory`).
    pub fn set_gpu_memory(&mut self, bytes: Option<u64>) -> Result<()> {
        if let Some(b) = bytes {
            allow(
                "gpu_memory",
                b,
                b >= 64 << 10,
                "at least 64K (64 KiB: one 8-bit brick)",
            )?;
        }
        self.gpu_memory = bytes;
        Ok(())
    }
    pub fn filter_sigma(&self) -> f64 {
        self.filter_sigma
    }
    pub fn feature_threshold(&self) -> f64 {
        self.feature_threshold
    }

    /// Samples per pixel per frame: 1 to [`MAX_SPP`] (a device may take fewer in one
    /// frame: the renderer says how many).
    pub fn set_spp(&mut self, spp: u32) -> Result<()> {
        allow(
            "spp",
            spp,
            (1..=MAX_SPP).contains(&spp),
            &format!(
                "1..={MAX_SPP} samples per pixel per frame (references take more through \
                 `--ref-spp`)"
            ),
        )?;
        self.spp = spp;
        Ok(())
    }
    pub fn set_max_bounces(&mut self, n: u32) -> Result<()> {
        allow(
            "max_bounces",
            n,
            n <= MAX_BOUNCES,
            &format!("0 to {MAX_BOUNCES}"),
        )?;
        self.max_bounces = n;
        Ok(())
    }
    pub fn set_hg_g(&mut self, g: f64) -> Result<()> {
        allow(
            "hg_g",
            num(g),
            g.is_finite() && g > -1.0 && g < 1.0,
            "between -1 and 1, exclusive",
        )?;
        self.hg_g = g;
        Ok(())
    }
    /// Bounce from which Russian roulette may end a path: 0 to [`MAX_BOUNCES`].
    pub fn set_russian_roulette_depth(&mut self, bounce: u32) -> Result<()> {
        allow(
            "russian_roulette_depth",
            bounce,
            bounce <= MAX_BOUNCES,
            &format!("0..={MAX_BOUNCES} (the bounce limit)"),
        )?;
        self.russian_roulette_depth = bounce;
        Ok(())
    }
    /// Ray-marching step in voxels: [`MIN_STEP_VOXELS`] to [`MAX_STEP_VOXELS`].
    pub fn set_step_size(&mut self, voxels: f64) -> Result<()> {
        allow(
            "step_size",
            num(voxels),
            voxels.is_finite() && (MIN_STEP_VOXELS..=MAX_STEP_VOXELS).contains(&voxels),
            &format!(
                "[{MIN_STEP_VOXELS}, {MAX_STEP_VOXELS}] voxels (ray-march step; 0.5 is the \
                 default)"
            ),
        )?;
        self.step_size = voxels;
        Ok(())
    }
    pub fn set_estimator(&mut self, estimator: Estimator) {
        self.estimator = estimator;
    }
    pub fn set_phase(&mut self, phase: Phase) {
        self.phase = phase;
    }
    pub fn set_emission(&mut self, on: bool) {
        self.emission = on;
    }
    pub fn set_seed(&mut self, seed: u32) {
        self.seed = seed;
    }
    /// Standard deviation of the Gaussian pixel filter in pixels (0: through the
    /// pixel centre).
    pub fn set_filter_sigma(&mut self, pixels: f64) -> Result<()> {
        allow(
            "filter_sigma",
            num(pixels),
            pixels.is_finite() && pixels >= 0.0,
            "finite and >= 0",
        )?;
        self.filter_sigma = pixels;
        Ok(())
    }
    /// Accumulated opacity at which the surface-features pass stops.
    pub fn set_feature_threshold(&mut self, opacity: f64) -> Result<()> {
        allow(
            "feature_threshold",
            num(opacity),
            opacity > 0.0 && opacity <= 1.0,
            "in (0, 1]",
        )?;
        self.feature_threshold = opacity;
        Ok(())
    }

    /// What the pipelines are specialised for.
    pub fn pipeline_key(&self) -> PipelineKey {
        PipelineKey {
            estimator: self.estimator,
            phase: self.phase,
            emission: self.emission,
        }
    }

    /// Checks settings that did not come through the setters (a scene file's), with the
    /// setters' own checks.
    pub(crate) fn check(&self, ctx: &Ctx) -> Result<(), SceneError> {
        let mut copy = *self;
        copy.set_spp(self.spp)
            .and_then(|_| copy.set_max_bounces(self.max_bounces))
            .and_then(|_| copy.set_russian_roulette_depth(self.russian_roulette_depth))
            .and_then(|_| copy.set_hg_g(self.hg_g))
            .and_then(|_| copy.set_step_size(self.step_size))
            .and_then(|_| copy.set_filter_sigma(self.filter_sigma))
            .and_then(|_| copy.set_feature_threshold(self.feature_threshold))
            .and_then(|_| copy.set_gpu_memory(self.gpu_memory))
            .map_err(|e| {
                ctx.invalid(
                    format!("render.{}", e.name),
                    format!("{}: {}", e.value, e.allowed),
                )
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn setters_refuse_values_out_of_range_and_keep_the_old_one() {
        let mut s = RenderSettings::default();
        let e = s.set_spp(0).expect_err("0 spp").to_string();
        assert!(e.contains("spp = 0") && e.contains("1..=64"), "{e}");
        assert!(s.set_spp(MAX_SPP + 1).is_err());
        assert_eq!(s.spp(), 2);
        let e = s.set_step_size(1e-6).expect_err("tiny step").to_string();
        assert!(e.contains("1e-6") && e.contains("[0.05, 10] voxels"), "{e}");
        assert!(s.set_russian_roulette_depth(MAX_BOUNCES + 1).is_err());
        assert!(s.set_hg_g(1.0).is_err() && s.set_hg_g(f64::NAN).is_err());
        assert!(s.set_max_bounces(MAX_BOUNCES + 1).is_err());
        assert!(s.set_step_size(0.0).is_err() && s.set_filter_sigma(-1.0).is_err());
        assert!(s.set_feature_threshold(0.0).is_err());
        s.set_max_bounces(1000).expect("a furnace's bounces");
        s.set_hg_g(-0.5).expect("g");
        assert_eq!((s.max_bounces(), s.hg_g()), (1000, -0.5));
    }

    #[test]
    fn the_pipeline_key_is_what_specialises() {
        let mut a = RenderSettings::default();
        let b = a;
        a.set_spp(4).expect("spp");
        a.set_seed(9);
        assert_eq!(a.pipeline_key(), b.pipeline_key());
        a.set_phase(Phase::Hg);
        assert_ne!(a.pipeline_key(), b.pipeline_key());
    }
}
