//! The paper's weighted-RLS family (TVCG §5–6): `wrls-paper` (its exact formulation) and
//! `rls-paper` (the same without weights), the family's base `wrls` (the feature from the
//! reprojected history, residual weights, restarts) and its Fig. 8 ablations `rls` (no
//! weighting), `wrls-nf` (no temporal feature, p = \[1\]) and `rls-nf` (neither), from the
//! same passes through specialisation constants.
//!
//! Passes of a frame, in order (each in its own file here):
//! - `<name>.update` ([`update`]): the per-pixel models reprojected and updated by
//!   weighted RLS: `wrls_update.comp` for the paper's p = [1, z] (nine state images),
//!   `wrls_constant.comp` for p = \[1\] (two);
//! - `<name>.spatial` (`wrls_spatial.comp`): the paper's 5×5 model blending, or for p =
//!   \[1\] `<name>.atrous0` (`variance_atrous.comp`): one 5×5 level over the predictions
//!   ([`spatial`]).

mod spatial;
mod update;

use super::variance_atrous::{self, VarianceAtrousPush};
use super::{
    Build, Built, DenoiseFrame, Denoiser, DenoiserConfig, MotionSource, Overridable, Tunables,
};
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline, SpecValue};
use crate::graph::ImageHandle;
use spatial::WrlsSpatialPush;
use update::{WrlsConstantPush, WrlsUpdatePush};

/// The paper's parameters (λ, α, h, δ, the 5×5 blending) and the weights and restarts
/// its ablations share.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrlsParams {
    pub lambda: f32,
    /// Forgetting factor of a pixel whose surface moved on screen (p = \[1\] models).
    pub lambda_moving: f32,
    pub alpha: f32,
    /// Bandwidth of the paper's relative-distance weights (`wrls-paper` only).
    pub h: f32,
    /// Initial P = delta · I for a new model.
    pub delta: f32,
    /// Disocclusion tolerance in pixels (see [`super::REPROJECTION_TOLERANCE_PX`]).
    pub tolerance: f32,
    pub sigma_spatial: f32,
    pub sigma_range: f32,
    /// Standard errors by which a neighbour's prediction may differ from the pixel's own
    /// and still be blended.
    pub kappa: f32,
    /// Squared a-priori residual over its running noise level that counts as a change.
    pub change_ratio: f32,
    /// Residual weights of the p = \[1\] models: a sample's weight falls off with its
    /// a-priori residual in units of the model's running noise level, exp(−r²/(k²·noise));
    /// this is k. Only samples many standard deviations out (spikes) lose weight.
    pub outlier_sigmas: f32,
}

impl Default for WrlsParams {
    fn default() -> Self {
        Self {
            lambda: 0.998,
            lambda_moving: 0.9,
            alpha: 0.75,
            h: 0.75,
            delta: 100.0,
            tolerance: super::REPROJECTION_TOLERANCE_PX,
            sigma_spatial: 2.0,
            sigma_range: 0.5,
            kappa: 2.0,
            change_ratio: 12.0,
            outlier_sigmas: 10.0,
        }
    }
}

/// The parameters `DVR_WRLS` may set, the range each takes, and where each goes.
const OVERRIDABLE: &[Overridable<WrlsParams>] = &[
    ("lambda", 0.01, 1.0, |p, v| p.lambda = v),
    ("lambda_moving", 0.01, 1.0, |p, v| p.lambda_moving = v),
    ("alpha", 0.0, 1.0, |p, v| p.alpha = v),
    ("h", 1e-3, 1e3, |p, v| p.h = v),
    ("kappa", 0.0, 1e3, |p, v| p.kappa = v),
    ("change_ratio", 0.0, 1e6, |p, v| p.change_ratio = v),
    ("outlier_sigmas", 1e-3, 1e3, |p, v| p.outlier_sigmas = v),
];

/// `DVR_WRLS="lambda=0.99,kappa=3"` sets parameters for a study with `dvr eval`.
impl Tunables for WrlsParams {
    const VARIABLE: &'static str = "DVR_WRLS";
    const TABLE: &'static [Overridable<Self>] = OVERRIDABLE;
}

/// Which variant: the paper's ablation switches (weighting, temporal feature), its exact
/// predictor, and the restarts its ablations share.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WrlsVariant {
    pub weighted: bool,
    pub feature: bool,
    /// The paper's exact predictor p = [1, z(t)] (z contains this frame's noisy colour).
    pub paper_predictor: bool,
    /// A model whose residual is far above its noise level twice in a row starts over (a
    /// light/TF change).
    pub restart_on_change: bool,
}

impl WrlsVariant {
    /// The family's base: weighted RLS on p = [1, z] with its 5×5 model blending, the
    /// feature built from the reprojected, clamped history (not the paper's z(t), which
    /// contains this frame's colour) and restarts on confirmed jumps. `wrls-paper` sets
    /// the paper's exact predictor and no restarts; the Fig. 8 ablations switch weighting
    /// or the feature off.
    pub const BASE: Self = Self {
        weighted: true,
        feature: true,
        paper_predictor: false,
        restart_on_change: true,
    };
}

/// The update's and the spatial pass's pipelines: the constant model with one à-trous
/// level over its predictions, or the paper's feature models with their 5×5 blending.
enum Passes {
    Constant(Pipeline<WrlsConstantPush>, Pipeline<VarianceAtrousPush>),
    Feature(Pipeline<WrlsUpdatePush>, Pipeline<WrlsSpatialPush>),
}

/// The pipelines of one variant.
pub struct Wrls {
    name: String,
    pub params: WrlsParams,
    /// What the temporal denoisers reproject with.
    pub motion: MotionSource,
    passes: Passes,
}

impl Wrls {
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        variant: WrlsVariant,
        motion: MotionSource,
    ) -> Result<Self> {
        let weighted = ("WEIGHTED", SpecValue::Bool(variant.weighted));
        let use_feature = ("USE_FEATURE", SpecValue::Bool(variant.feature));
        let motion_source = ("MOTION_SOURCE", SpecValue::I32(motion.spec()));
        let paper_predictor = ("PAPER_PREDICTOR", SpecValue::Bool(variant.paper_predictor));
        let restart = (
            "RESTART_ON_CHANGE",
            SpecValue::Bool(variant.restart_on_change),
        );
        let selection = ("MODEL_SELECTION", SpecValue::Bool(false));
        let passes = if variant.feature {
            Passes::Feature(
                ctx.pipeline(
                    "wrls_update",
                    &[
                        weighted,
                        use_feature,
                        motion_source,
                        paper_predictor,
                        restart,
                        selection,
                    ],
                )?,
                ctx.pipeline("wrls_spatial", &[use_feature, paper_predictor, selection])?,
            )
        } else {
            Passes::Constant(
                ctx.pipeline("wrls_constant", &[weighted, motion_source, restart])?,
                variance_atrous::pipeline(ctx, false, false)?,
            )
        };
        let params = WrlsParams::from_env()?;
        Ok(Self {
            name: name.to_string(),
            params,
            motion,
            passes,
        })
    }
}

/// A row's variant builds the family's member with its switches.
impl Build for WrlsVariant {
    fn build(&self, ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        Ok(Box::new(Wrls::new(ctx, name, *self, config.motion)?))
    }
}

impl Denoiser for Wrls {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, _, input) = f.parts();
        let desc = input.rgba32f();
        let n = &self.name;
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        let prediction = graph.image(ctx, &format!("{n}.prediction"), desc)?;
        match &self.passes {
            Passes::Feature(update, spatial) => {
                let m = self.add_feature_update(update, &mut f, prediction)?;
                self.add_paper_spatial(spatial, f.frame, input, &m, out);
            }
            Passes::Constant(update, atrous) => {
                self.add_constant_update(update, &mut f, prediction)?;
                self.add_atrous(atrous, f.frame, input.size, prediction, out);
            }
        }
        Ok(out)
    }
}
