//! The denoisers dvr has, in one table: the name the command line, `dvr eval`, the
//! explorer and the reports use, a one-line description, what the frame must render for
//! it, the variable that overrides its parameters, and how to build it (see
//! [`DenoiserInfo`]). Everything that lists, checks or builds a denoiser by name reads a
//! [`Registry`]: the built-in one is [`DENOISERS`], and [`Registry::with`] adds a row
//! (a test's toy denoiser) that the renderer then builds as it builds any other.

use super::ours::OursParams;
use super::rae::RaeNet;
use super::svgf::SvgfParams;
use super::wrls_paper::WrlsParams;
use super::{Accum, Passthrough, Svgf, Taa};
use super::{OursVariant, WrlsVariant};
use crate::error::{EngineError, Result};
use crate::gpu::GpuContext;
use std::borrow::Cow;

pub use super::entry::{Build, Built, DenoiserConfig, DenoiserInfo, FeatureUse};
pub use super::rae::Precision;
use super::Overrides;

/// A RAE row: the shipped network `net` (None: the one trained on the scene's dataset,
/// see [`super::rae::network_for`]) at `precision`.
const fn rae(name: &'static str, description: &'static str, net: &'static RaeNet) -> DenoiserInfo {
    DenoiserInfo::new(name, description, FeatureUse::Never, net)
}

/// A row of ours or one of its ablations. Always: the spatial prior's fit reads the
/// surface's gradient normal; the guides: it fits the prior's model on the albedo.
const fn ours(
    name: &'static str,
    description: &'static str,
    variant: &'static OursVariant,
) -> DenoiserInfo {
    DenoiserInfo::new(name, description, FeatureUse::Always, variant)
        .reading_guides()
        .overridden_by(Overrides::of::<OursParams>())
}

/// A row of the paper's wRLS family.
const fn wrls(
    name: &'static str,
    description: &'static str,
    variant: &'static WrlsVariant,
) -> DenoiserInfo {
    DenoiserInfo::new(name, description, FeatureUse::ForMotion, variant)
        .overridden_by(Overrides::of::<WrlsParams>())
}

/// Ours (see [`OursVariant`]), and the paper's model family (see [`WrlsVariant`]).
const OURS: OursVariant = OursVariant::OURS;
const PAPER: WrlsVariant = WrlsVariant::BASE;

use FeatureUse::{Always, ForMotion, Never};

/// Every denoiser, in the order lists and reports show them.
pub const DENOISERS: &[DenoiserInfo] = &[
    DenoiserInfo::new("none", "the noisy input, unchanged", Never, &Passthrough::create),
    DenoiserInfo::new(
        "accum",
        "progressive accumulation; starts over on any camera, light or TF change",
        Never,
        &Accum::create,
    ),
    DenoiserInfo::new(
        "taa",
        "exponential moving average with reprojection and variance clipping",
        ForMotion,
        &Taa::create,
    ),
    DenoiserInfo::new(
        "svgf",
        "spatiotemporal variance-guided filtering (Schied et al. 2017)",
        Always,
        &Svgf::create,
    )
    .reading_guides()
    .overridden_by(Overrides::of::<SvgfParams>()),
    ours(
        "ours",
        "a per-pixel Kalman filter told by temporal gradients how much the scene changed, with a pooled lag test, a spatial prior on the guide albedo and an à-trous filter",
        &OURS,
    ),
    // Ablations of ours: one stage each (tests/ablations.rs checks it by the stages' images).
    ours(
        "ours-no-gradient",
        "ours without temporal gradients",
        &OursVariant { gradients: false, ..OURS },
    ),
    ours(
        "ours-no-lag",
        "ours without the pooled lag test's shift of the state",
        &OursVariant { lag: false, ..OURS },
    ),
    ours(
        "ours-no-prior",
        "ours without the spatial prior's combination (young estimates go to the à-trous, which still carries by the prior's model)",
        &OursVariant { prior: false, ..OURS },
    ),
    ours(
        "ours-no-atrous",
        "ours without the à-trous filter (the per-pixel estimates)",
        &OursVariant { atrous: false, ..OURS },
    ),
    ours(
        "ours-no-young",
        "ours without the young-pixel network on frames where every state restarted",
        &OursVariant { young: false, ..OURS },
    ),
    ours(
        "ours-no-feedback",
        "ours without the first à-trous level fed back into the states that restarted",
        &OursVariant { feedback: false, ..OURS },
    ),
    wrls(
        "wrls-paper",
        "the paper's weighted RLS denoiser (TVCG §5–6) as published",
        &WrlsVariant { paper_predictor: true, restart_on_change: false, ..PAPER },
    ),
    wrls(
        "rls-paper",
        "wrls-paper without its weights (w = 1): the paper's RLS-F ablation on its own predictor",
        &WrlsVariant { weighted: false, paper_predictor: true, restart_on_change: false, ..PAPER },
    ),
    wrls(
        "wrls",
        "the paper's weighted RLS on the family's base: the feature from the reprojected history, residual weights, restarts",
        &PAPER,
    ),
    // The paper's ablations (Fig. 8) of `wrls`.
    wrls(
        "rls",
        "the paper's RLS-F ablation: unweighted RLS",
        &WrlsVariant { weighted: false, ..PAPER },
    ),
    wrls(
        "wrls-nf",
        "the paper's ablation without the temporal feature",
        &WrlsVariant { feature: false, ..PAPER },
    ),
    wrls(
        "rls-nf",
        "unweighted RLS without the temporal feature",
        &WrlsVariant { weighted: false, feature: false, ..PAPER },
    ),
    rae(
        "rae",
        "recurrent denoising autoencoder (Chaitanya et al. 2017), the network trained on the scene's dataset",
        &RaeNet { net: None, precision: Precision::F32 },
    ),
    rae("rae-phantom", "the RAE trained on the phantom", &RaeNet { net: Some("phantom"), precision: Precision::F32 }),
    rae("rae-mri", "the RAE trained on the MRI", &RaeNet { net: Some("mri"), precision: Precision::F32 }),
    rae("rae-fp16", "rae with half-precision tensors", &RaeNet { net: None, precision: Precision::F16 }),
];

/// Every denoiser's name, in table order.
pub fn names() -> impl Iterator<Item = &'static str> {
    DENOISERS.iter().map(|d| d.name)
}

/// The denoiser called `name`, or [`EngineError::UnknownDenoiser`] listing them all.
pub fn find(name: &str) -> Result<&'static DenoiserInfo> {
    BUILTIN.find(name)
}

/// Builds the denoiser called `name`.
pub fn create(ctx: &GpuContext, name: &str, config: &DenoiserConfig) -> Built {
    find(name)?.create(ctx, config)
}

/// The rows the renderer finds denoisers in by name: the built-in table, or it with
/// rows added ([`Registry::with`]).
#[derive(Clone, Debug)]
pub struct Registry {
    rows: Cow<'static, [DenoiserInfo]>,
}

/// The built-in registry: [`DENOISERS`].
pub static BUILTIN: Registry = Registry {
    rows: Cow::Borrowed(DENOISERS),
};

impl Default for Registry {
    fn default() -> Self {
        BUILTIN.clone()
    }
}

/// Registries are equal when they hold the same rows: the same names, each built by the
/// same builder.
impl PartialEq for Registry {
    fn eq(&self, other: &Self) -> bool {
        self.rows.len() == other.rows.len()
            && self.rows.iter().zip(other.rows.iter()).all(|(a, b)| {
                a.name == b.name && std::ptr::addr_eq(a.build as *const _, b.build as *const _)
            })
    }
}

impl Registry {
    /// This registry with `row` added after its rows; a name it already has is refused.
    pub fn with(mut self, row: DenoiserInfo) -> Result<Self> {
        if self.find(row.name).is_ok() {
            return Err(EngineError::InvalidSetting {
                name: "denoiser",
                value: row.name.to_string(),
                allowed: "a name no other row of the registry has".into(),
            });
        }
        self.rows.to_mut().push(row);
        Ok(self)
    }

    /// Its rows, in the order lists and reports show them.
    pub fn rows(&self) -> &[DenoiserInfo] {
        &self.rows
    }

    /// The row called `name`, or [`EngineError::UnknownDenoiser`] listing them all.
    pub fn find(&self, name: &str) -> Result<&DenoiserInfo> {
        self.rows
            .iter()
            .find(|d| d.name == name)
            .ok_or_else(|| EngineError::UnknownDenoiser {
                name: name.to_string(),
                available: self.names().join(", "),
            })
    }

    fn names(&self) -> Vec<&'static str> {
        self.rows.iter().map(|d| d.name).collect()
    }

    /// The environment variables its rows' parameters are overridden by, each once with
    /// its check, in the order of the rows that first name them.
    pub fn overrides(&self) -> Vec<Overrides> {
        let mut out: Vec<Overrides> = Vec::new();
        for o in self.rows.iter().filter_map(|d| d.overrides) {
            if !out.iter().any(|seen| seen.variable == o.variable) {
                out.push(o);
            }
        }
        out
    }
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
        fn distinct<T: std::any::Any + PartialEq + std::fmt::Debug>() {
            let variants: Vec<&T> = DENOISERS.iter().filter_map(|d| d.variant::<T>()).collect();
            for (i, v) in variants.iter().enumerate() {
                assert!(!variants[..i].contains(v), "{v:?} is listed twice");
            }
        }
        distinct::<OursVariant>();
        distinct::<WrlsVariant>();
        distinct::<RaeNet>();
        assert!(DENOISERS.iter().all(|d| !d.description.is_empty()));
    }

    #[test]
    fn each_ablation_of_ours_switches_one_part_off() {
        let parts = |v: OursVariant| [v.gradients, v.lag, v.prior, v.atrous, v.feedback, v.young];
        let ours = parts(OURS);
        assert!(ours.iter().all(|&on| on), "ours has every part");
        let mut ablations = 0;
        for d in DENOISERS {
            if let Some(&v) = d.variant::<OursVariant>() {
                let off = ours.iter().zip(parts(v)).filter(|(a, b)| a != &b).count();
                let expected = usize::from(d.name != "ours");
                assert_eq!(off, expected, "{} differs from ours in {off} parts", d.name);
                ablations += expected;
            }
        }
        assert_eq!(ablations, 6, "one ablation per part");
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
        let net = |n: &str, d| {
            find(n)
                .ok()
                .and_then(|e| e.variant::<RaeNet>())
                .map(|r| r.network(d))
        };
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
    fn rows_carry_what_the_frame_needs() {
        let row = |n| find(n).expect("a row");
        assert!(row("svgf").guides && row("ours-no-lag").guides && !row("taa").guides);
        assert_eq!(row("ours").override_variable(), Some("DVR_OURS"));
        assert_eq!(row("rls-nf").override_variable(), Some("DVR_WRLS"));
        assert_eq!(row("svgf").override_variable(), Some("DVR_SVGF"));
        assert_eq!(row("rae").override_variable(), None);
        let variables: Vec<_> = BUILTIN.overrides().iter().map(|o| o.variable).collect();
        assert_eq!(variables, ["DVR_SVGF", "DVR_OURS", "DVR_WRLS"]);
    }

    #[test]
    fn a_registry_takes_a_new_row_once() {
        let toy = DenoiserInfo::new("toy", "a toy", FeatureUse::Never, &Passthrough::create);
        let with = Registry::default().with(toy).expect("a new name");
        assert_eq!(with.find("toy").map(|d| d.description).ok(), Some("a toy"));
        assert_eq!(with.rows().len(), DENOISERS.len() + 1);
        assert_ne!(with, BUILTIN);
        assert!(with.with(toy).is_err(), "a name twice");
        assert!(find("toy").is_err(), "the built-in table is unchanged");
    }
}
