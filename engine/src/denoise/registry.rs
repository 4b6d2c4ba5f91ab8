//! The denoisers dvr has, in one table: the name the command line, `dvr eval`, the
//! explorer and the reports use, a one-line description, what the frame must render for
//! it, and how to build it. Everything that lists, checks or builds a denoiser by name
//! reads [`DENOISERS`].

use super::{Accum, Denoiser, MotionSource, Passthrough, Rae, RaeWeights, Svgf, Taa};
use super::{Ours, OursVariant, Wrls, WrlsVariant};
use crate::error::{EngineError, Result};
use crate::gpu::GpuContext;
use crate::passes::path_trace::PathTraceFeatures;

pub use super::rae::Precision;

/// Whether a denoiser reads the surface features (the deterministic opacity-threshold
/// position, normal and albedo), which cost about a path trace on lavapipe and are
/// rendered only for denoisers that read them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeatureUse {
    Never,
    /// When it reprojects with them (`--motion features`).
    ForMotion,
    /// Always (SVGF's edge-stopping and albedo demodulation).
    Always,
}

impl FeatureUse {
    pub fn needed(self, motion: MotionSource) -> bool {
        match self {
            FeatureUse::Never => false,
            FeatureUse::ForMotion => motion == MotionSource::Features,
            FeatureUse::Always => true,
        }
    }
}

/// How an entry is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Passthrough,
    Accum,
    Taa,
    Svgf,
    /// Ours or one of its ablations, with its switches.
    Ours(OursVariant),
    /// A member of the paper's wRLS family, with its switches.
    Wrls(WrlsVariant),
    /// The recurrent autoencoder: the shipped network `net` (None: the one trained on
    /// the scene's dataset, see [`super::rae::network_for`]) at `precision`.
    Rae {
        net: Option<&'static str>,
        precision: Precision,
    },
}

/// One denoiser dvr has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DenoiserInfo {
    /// The name on the command line and in every report.
    pub name: &'static str,
    pub description: &'static str,
    pub features: FeatureUse,
    kind: Kind,
}

/// What building a denoiser depends on besides its name.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DenoiserConfig<'a> {
    /// What temporal methods reproject with.
    pub motion: MotionSource,
    /// The built-in dataset the scene's volume is, if any (learned denoisers pick their
    /// network by it).
    pub dataset: Option<&'a str>,
    /// What the path tracer is specialised for (a denoiser that traces paths again must
    /// trace the same ones).
    pub features: PathTraceFeatures,
}

const fn entry(
    name: &'static str,
    description: &'static str,
    features: FeatureUse,
    kind: Kind,
) -> DenoiserInfo {
    DenoiserInfo {
        name,
        description,
        features,
        kind,
    }
}

const fn rae(
    name: &'static str,
    description: &'static str,
    net: Option<&'static str>,
    precision: Precision,
) -> DenoiserInfo {
    entry(
        name,
        description,
        FeatureUse::Never,
        Kind::Rae { net, precision },
    )
}

const fn ours(name: &'static str, description: &'static str, variant: OursVariant) -> DenoiserInfo {
    // Always: the spatial prior's fit reads the surface's gradient normal.
    entry(name, description, FeatureUse::Always, Kind::Ours(variant))
}

const fn wrls(name: &'static str, description: &'static str, variant: WrlsVariant) -> DenoiserInfo {
    entry(
        name,
        description,
        FeatureUse::ForMotion,
        Kind::Wrls(variant),
    )
}

/// Ours (see [`OursVariant`]), and the paper's model family (see [`WrlsVariant`]).
const OURS: OursVariant = OursVariant::OURS;
const PAPER: WrlsVariant = WrlsVariant::BASE;

use FeatureUse::{Always, ForMotion, Never};

/// Every denoiser, in the order lists and reports show them.
pub const DENOISERS: &[DenoiserInfo] = &[
    entry("none", "the noisy input, unchanged", Never, Kind::Passthrough),
    entry(
        "accum",
        "progressive accumulation; starts over on any camera, light or TF change",
        Never,
        Kind::Accum,
    ),
    entry(
        "taa",
        "exponential moving average with reprojection and variance clipping",
        ForMotion,
        Kind::Taa,
    ),
    entry(
        "svgf",
        "spatiotemporal variance-guided filtering (Schied et al. 2017)",
        Always,
        Kind::Svgf,
    ),
    ours(
        "ours",
        "a per-pixel Kalman filter told by temporal gradients how much the scene changed, with a pooled lag test, a spatial prior on the guide albedo and an à-trous filter",
        OURS,
    ),
    // Ablations of ours: one stage each (tests/ablations.rs checks it by the stages' images).
    ours(
        "ours-no-gradient",
        "ours without temporal gradients",
        OursVariant { gradients: false, ..OURS },
    ),
    ours(
        "ours-no-lag",
        "ours without the pooled lag test's shift of the state",
        OursVariant { lag: false, ..OURS },
    ),
    ours(
        "ours-no-prior",
        "ours without the spatial prior's combination (young estimates go to the à-trous, which still carries by the prior's model)",
        OursVariant { prior: false, ..OURS },
    ),
    ours(
        "ours-no-atrous",
        "ours without the à-trous filter (the per-pixel estimates)",
        OursVariant { atrous: false, ..OURS },
    ),
    wrls(
        "wrls-paper",
        "the paper's weighted RLS denoiser (TVCG §5–6) as published",
        WrlsVariant { paper_predictor: true, restart_on_change: false, ..PAPER },
    ),
    wrls(
        "rls-paper",
        "wrls-paper without its weights (w = 1): the paper's RLS-F ablation on its own predictor",
        WrlsVariant { weighted: false, paper_predictor: true, restart_on_change: false, ..PAPER },
    ),
    wrls(
        "wrls",
        "the paper's weighted RLS on the family's base: the feature from the reprojected history, residual weights, restarts",
        PAPER,
    ),
    // The paper's ablations (Fig. 8) of `wrls`.
    wrls(
        "rls",
        "the paper's RLS-F ablation: unweighted RLS",
        WrlsVariant { weighted: false, ..PAPER },
    ),
    wrls(
        "wrls-nf",
        "the paper's ablation without the temporal feature",
        WrlsVariant { feature: false, ..PAPER },
    ),
    wrls(
        "rls-nf",
        "unweighted RLS without the temporal feature",
        WrlsVariant { weighted: false, feature: false, ..PAPER },
    ),
    rae(
        "rae",
        "recurrent denoising autoencoder (Chaitanya et al. 2017), the network trained on the scene's dataset",
        None,
        Precision::F32,
    ),
    rae("rae-phantom", "the RAE trained on the phantom", Some("phantom"), Precision::F32),
    rae("rae-mri", "the RAE trained on the MRI", Some("mri"), Precision::F32),
    rae("rae-fp16", "rae with half-precision tensors", None, Precision::F16),
];

impl DenoiserInfo {
    /// The network and tensor precision a RAE entry runs on a scene of built-in
    /// `dataset`; None for other denoisers.
    pub fn rae_network(&self, dataset: Option<&str>) -> Option<(&'static str, Precision)> {
        match self.kind {
            Kind::Rae { net, precision } => Some((
                net.unwrap_or_else(|| super::rae::network_for(dataset)),
                precision,
            )),
            _ => None,
        }
    }

    /// The environment variable that overrides its parameters (see
    /// [`super::OVERRIDE_VARIABLES`]), if it has one.
    pub fn override_variable(&self) -> Option<&'static str> {
        match self.kind {
            Kind::Ours(_) => Some("DVR_OURS"),
            Kind::Wrls(_) => Some("DVR_WRLS"),
            Kind::Svgf => Some("DVR_SVGF"),
            _ => None,
        }
    }

    /// Whether it reads the guide albedo composited along the ray
    /// ([`DenoiseInputs::guides`](super::DenoiseInputs::guides)): SVGF demodulates by it,
    /// ours and each of its ablations fit the prior's model on it.
    pub fn guides(&self) -> bool {
        matches!(self.kind, Kind::Svgf | Kind::Ours(_))
    }

    /// Builds the denoiser.
    pub fn create(&self, ctx: &GpuContext, config: &DenoiserConfig) -> Result<Box<dyn Denoiser>> {
        let motion = config.motion;
        Ok(match self.kind {
            Kind::Passthrough => Box::new(Passthrough(self.name)),
            Kind::Accum => Box::new(Accum::new(ctx, self.name)?),
            Kind::Taa => Box::new(Taa::new(ctx, self.name, motion)?),
            Kind::Svgf => Box::new(Svgf::new(ctx, self.name, motion)?),
            Kind::Ours(variant) => {
                Box::new(Ours::new(ctx, self.name, variant, motion, config.features)?)
            }
            Kind::Wrls(variant) => Box::new(Wrls::new(ctx, self.name, variant, motion)?),
            Kind::Rae { .. } => {
                let (net, precision) = self
                    .rae_network(config.dataset)
                    .ok_or_else(|| unknown(self.name))?;
                Box::new(Rae::new(
                    ctx,
                    self.name,
                    RaeWeights::builtin(net)?,
                    precision,
                )?)
            }
        })
    }
}

fn unknown(name: &str) -> EngineError {
    EngineError::UnknownDenoiser {
        name: name.to_string(),
        available: names().collect::<Vec<_>>().join(", "),
    }
}

/// Every denoiser's name, in table order.
pub fn names() -> impl Iterator<Item = &'static str> {
    DENOISERS.iter().map(|d| d.name)
}

/// The denoiser called `name`, or [`EngineError::UnknownDenoiser`] listing them all.
pub fn find(name: &str) -> Result<&'static DenoiserInfo> {
    DENOISERS
        .iter()
        .find(|d| d.name == name)
        .ok_or_else(|| unknown(name))
}

/// Builds the denoiser called `name`.
pub fn create(ctx: &GpuContext, name: &str, config: &DenoiserConfig) -> Result<Box<dyn Denoiser>> {
    find(name)?.create(ctx, config)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_described() {
        let all: Vec<&str> = names().collect();
        for (i, n) in all.iter().enumerate() {
            assert!(!all[..i].contains(n), "{n} is listed twice");
        }
        // Each wRLS or ours row is a different variant (a copied row would rename one).
        let variants: Vec<_> = DENOISERS
            .iter()
            .filter(|d| matches!(d.kind, Kind::Wrls(_) | Kind::Ours(_)))
            .map(|d| d.kind)
            .collect();
        for (i, v) in variants.iter().enumerate() {
            assert!(!variants[..i].contains(v), "{v:?} is listed twice");
        }
        assert!(DENOISERS.iter().all(|d| !d.description.is_empty()));
    }

    #[test]
    fn each_ablation_of_ours_switches_one_part_off() {
        let parts = |v: OursVariant| [v.gradients, v.lag, v.prior, v.atrous];
        let ours = parts(OURS);
        assert!(ours.iter().all(|&on| on), "ours has every part");
        let mut ablations = 0;
        for d in DENOISERS {
            if let Kind::Ours(v) = d.kind {
                let off = ours.iter().zip(parts(v)).filter(|(a, b)| a != &b).count();
                let expected = usize::from(d.name != "ours");
                assert_eq!(off, expected, "{} differs from ours in {off} parts", d.name);
                ablations += expected;
            }
        }
        assert_eq!(ablations, 4, "one ablation per part");
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        let e = find("oracle").expect_err("not a denoiser").to_string();
        assert!(
            e.contains("oracle") && e.contains("svgf") && e.contains("rae-fp16"),
            "{e}"
        );
    }

    #[test]
    fn rae_entries_pick_their_network() {
        let net = |n: &str, d| find(n).ok().and_then(|e| e.rae_network(d));
        assert_eq!(
            net("rae", Some("phantom")),
            Some(("phantom", Precision::F32))
        );
        assert_eq!(net("rae", None), Some(("mri", Precision::F32)));
        assert_eq!(net("rae-fp16", None), Some(("mri", Precision::F16)));
        assert_eq!(
            net("rae-mri", Some("phantom")),
            Some(("mri", Precision::F32))
        );
        assert_eq!(net("svgf", None), None);
    }

    #[test]
    fn feature_use_follows_the_motion_source() {
        assert!(FeatureUse::Always.needed(MotionSource::FirstHit));
        assert!(FeatureUse::ForMotion.needed(MotionSource::Features));
        assert!(!FeatureUse::ForMotion.needed(MotionSource::FirstHit));
        assert!(!FeatureUse::Never.needed(MotionSource::Features));
    }
}
