//! `[render]`: how the path tracer spends its work on this scene.
//!
//! These are the "model no more than a scene needs" switches: the path-tracing pipeline
//! is specialised on them (Vulkan specialisation constants), so a scene that does not
//! use emission, anisotropic scattering or ray marching pays nothing for them. Every
//! field has a default, so `[render]` may be omitted.

use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};

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

/// `[render]`. Defaults: 2 spp, 4 bounces, delta tracking, isotropic phase, Russian
/// roulette from bounce 3, ray-march step 0.5 voxel, no emission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RenderSettings {
    /// Samples per pixel per frame (>= 1).
    pub spp: u32,
    /// Maximum number of scattering events per path (0..=64). 0 leaves only emission
    /// and the unscattered background; 1 is single scattering (direct light at the first
    /// collision). The default of 4 is a starting point, not a measurement: DESIGN §7
    /// asks for the bounce count to be set from the reference difference between N and
    /// N+1 bounces. The built-in cloud scenes (albedo ~0.97, many scattering events) use 8.
    pub max_bounces: u32,
    pub estimator: Estimator,
    pub phase: Phase,
    /// Henyey–Greenstein asymmetry in (−1, 1), used by `hg` and `hybrid` (0 = isotropic).
    pub hg_g: f64,
    /// Russian roulette starts at this bounce (0 = from the first scattering event).
    pub russian_roulette_depth: u32,
    /// Ray-marching step in voxels (of the volume's longest axis), used by `ray-march`.
    pub step_size: f64,
    /// Whether the TF's emissive colour is added (off compiles emission out).
    pub emission: bool,
}

/// Cap on `max_bounces`: far past any useful value, low enough to bound a frame's cost.
pub const MAX_BOUNCES_LIMIT: u32 = 64;

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
        }
    }
}

impl RenderSettings {
    pub(crate) fn check(&self, ctx: &Ctx) -> Result<(), SceneError> {
        if !(1..=MAX_SPP).contains(&self.spp) {
            return Err(ctx.invalid(
                "render.spp",
                format!(
                    "{} is outside 1..={MAX_SPP} samples per pixel per frame (references take \
                     more through `--ref-spp`)",
                    self.spp
                ),
            ));
        }
        if self.russian_roulette_depth > MAX_BOUNCES_LIMIT {
            return Err(ctx.invalid(
                "render.russian_roulette_depth",
                format!(
                    "{} is outside 0..={MAX_BOUNCES_LIMIT} (the bounce limit)",
                    self.russian_roulette_depth
                ),
            ));
        }
        if self.max_bounces > MAX_BOUNCES_LIMIT {
            return Err(ctx.invalid(
                "render.max_bounces",
                format!(
                    "{} exceeds the limit of {MAX_BOUNCES_LIMIT}",
                    self.max_bounces
                ),
            ));
        }
        if !(self.hg_g.is_finite() && self.hg_g > -1.0 && self.hg_g < 1.0) {
            return Err(ctx.invalid("render.hg_g", format!("{} must be in (-1, 1)", self.hg_g)));
        }
        ctx.in_range(
            "render.step_size",
            self.step_size,
            MIN_STEP_VOXELS,
            MAX_STEP_VOXELS,
            " voxels (ray-march step; 0.5 is the default)",
        )
    }
}
