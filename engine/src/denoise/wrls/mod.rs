//! `ours` and the paper's weighted-RLS family (TVCG §5–6), from the same passes through
//! specialisation constants and variant switches.
//!
//! Passes of a frame, in order (each in its own file here):
//! - `<name>.gradient` ([`gradient`], `wrls_gradient.comp`): temporal gradients, when the
//!   scene changed: last frame's samples re-traced in this frame's scene;
//! - `<name>.gradient_pool` ([`gradient_pool`], `wrls_gradient_pool.comp`): the gradients
//!   pooled over 3×3, 5×5 and 9×9 strata and shrunk, once per stratum;
//! - `<name>.update` ([`update`]): the per-pixel models reprojected, adjusted for the
//!   measured change and updated by weighted RLS: `wrls_constant.comp` for ours' constant
//!   model p = [1] (two state images), `wrls_update.comp` for the paper's p = [1, z]
//!   (nine state images);
//! - `<name>.drift` ([`spatial`], `wrls_drift.comp`): the pooled lag test;
//! - `<name>.atrous0..k` ([`spatial`], `wrls_atrous.comp`): ours' à-trous spatial filter
//!   on the models' standard errors, or `<name>.spatial` (`wrls_spatial.comp`): the
//!   paper's 5×5 model blending.
//!
//! Variants: `ours` and its ablations (one part each: `ours-feature`,
//! `ours-no-gradient`, `ours-no-atrous`, `ours-no-drift`, `ours-fixed-lambda`), the paper's
//! exact form `wrls-paper` and its Fig. 8 ablations `rls`, `wrls-nf`, `rls-nf`.

mod gradient;
mod gradient_pool;
mod spatial;
mod update;

use super::{DenoiseInputs, Denoiser, MotionSource};
use crate::error::{EngineError, Result};
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
use crate::graph::{Frame, ImageHandle, RenderGraph};
use crate::passes::path_trace::{self, PathTraceFeatures};
use ash::vk;
use gradient::WrlsGradientPush;
use gradient_pool::WrlsGradientPoolPush;
use spatial::{WrlsAtrousPush, WrlsDriftPush, WrlsSpatialPush};
use update::{WrlsConstantPush, WrlsUpdatePush};

/// The paper's parameters (λ, α, h, δ, the 5×5 blending) and ours'.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrlsParams {
    pub lambda: f32,
    /// Ours' forgetting factor for a pixel whose surface moved on screen (camera motion).
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
    /// and still be blended (ours' spatial weights, 5×5 and à-trous alike).
    pub kappa: f32,
    /// Squared a-priori residual over its running noise level that counts as a change.
    pub change_ratio: f32,
    /// Residual weights (not the paper's): a sample's weight falls off with its a-priori
    /// residual in units of the model's running noise level, exp(−r²/(k²·noise)); this
    /// is k. Only samples many standard deviations out (spikes) lose weight.
    pub outlier_sigmas: f32,
    /// Edge of the temporal-gradient strata in pixels: one pixel in S×S is re-traced.
    pub stratum: u32,
    /// Smallest forgetting factor the temporal gradients may set (a sudden change).
    pub lambda_min: f32,
    /// How fast the forgetting factor falls towards λ_min with the change the gradients
    /// measure: ours by gain × relative change × luminance / noise σ (the change per
    /// frame against the pixel's noise, as a steady-state Kalman gain); the paper's
    /// models (`ours-feature`) by gain × relative change.
    pub change_gain: f32,
    /// Shrinkage of the pooled gradient ratios, each towards the next wider pool's (the
    /// widest towards 1): a ratio `k` standard errors away keeps k²/(k² + shrink) of its
    /// departure.
    pub shrink: f32,
    /// Pooled residual, in standard errors of its mean, from which the pooled lag test
    /// starts to correct the models (fully at twice this).
    pub drift_z: f32,
    /// Share of the way to λ_min the forgetting factor goes where the pooled residual
    /// is clearly significant (from `drift_forget_z` standard errors, fully at twice that).
    pub drift_forget: f32,
    pub drift_forget_z: f32,
    /// Radius of the pooled lag test's square neighbourhood, in pixels (at most 8: the
    /// shader unrolls its window).
    pub drift_radius: u32,
    /// Weight of this frame's a-posteriori residual in the running residual the pooled
    /// lag test averages (1: this frame's alone).
    pub lag_alpha: f32,

    /// À-trous iterations of the spatial filter (steps 1, 2, 4, …).
    pub atrous_iterations: u32,
    /// Relative standard error of a prediction below which the à-trous levels keep the
    /// pixel as it is (a converged model; 0 filters every pixel).
    pub atrous_keep: f32,
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
            stratum: 4,
            lambda_min: 0.1,
            change_gain: 4.0,
            shrink: 4.0,
            drift_z: 1.5,
            drift_forget: 0.5,
            drift_forget_z: 2.0,
            drift_radius: 2,
            lag_alpha: 0.5,
            atrous_iterations: 3,
            atrous_keep: 0.05,
        }
    }
}

/// The parameters `DVR_WRLS` may set, and where each goes.
#[allow(clippy::type_complexity)]
const OVERRIDABLE: &[(&str, fn(&mut WrlsParams, f32))] = &[
    ("lambda", |p, v| p.lambda = v),
    ("lambda_moving", |p, v| p.lambda_moving = v),
    ("alpha", |p, v| p.alpha = v),
    ("kappa", |p, v| p.kappa = v),
    ("change_ratio", |p, v| p.change_ratio = v),
    ("outlier_sigmas", |p, v| p.outlier_sigmas = v),
    ("lambda_min", |p, v| p.lambda_min = v),
    ("change_gain", |p, v| p.change_gain = v),
    ("shrink", |p, v| p.shrink = v),
    ("drift_z", |p, v| p.drift_z = v),
    ("drift_radius", |p, v| p.drift_radius = (v as u32).min(8)),
    ("drift_forget", |p, v| p.drift_forget = v),
    ("drift_forget_z", |p, v| p.drift_forget_z = v),
    ("lag_alpha", |p, v| p.lag_alpha = v.clamp(0.01, 1.0)),
    ("stratum", |p, v| p.stratum = v as u32),
    ("atrous_iterations", |p, v| p.atrous_iterations = v as u32),
    ("atrous_keep", |p, v| p.atrous_keep = v),
];

impl WrlsParams {
    /// These parameters with `name=value` pairs (comma-separated) applied, e.g. from
    /// `DVR_WRLS="change_gain=2,kappa=3"`: for parameter studies with `dvr eval`.
    pub fn with_overrides(mut self, spec: Option<&str>) -> Result<Self> {
        let Some(spec) = spec else { return Ok(self) };
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let bad = |problem: String| EngineError::InvalidSetting {
                name: "DVR_WRLS",
                value: format!("{item:?}"),
                allowed: problem,
            };
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| bad("expected name=value pairs, comma-separated".into()))?;
            let v: f32 = value
                .trim()
                .parse()
                .map_err(|e| bad(format!("the value must be a number ({e})")))?;
            let (_, set) = OVERRIDABLE
                .iter()
                .find(|(n, _)| *n == name.trim())
                .ok_or_else(|| {
                    let known: Vec<&str> = OVERRIDABLE.iter().map(|(n, _)| *n).collect();
                    bad(format!("parameters: {}", known.join(", ")))
                })?;
            set(&mut self, v);
        }
        Ok(self)
    }
}

/// Which variant: the paper's ablation switches (weighting, temporal feature) and our
/// changes to it (predictor from the reprojected history, residual-scaled weights,
/// automatic forgetting, constant/feature model selection).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WrlsVariant {
    pub weighted: bool,
    pub feature: bool,
    /// The paper's exact predictor p = [1, z(t)] (z contains this frame's noisy colour).
    pub paper_predictor: bool,
    /// Automatic forgetting: a model whose residual is far above its noise level twice in
    /// a row starts over (a light/TF change); without it λ stays 0.998.
    pub restart_on_change: bool,
    /// Also keep the constant model p = [1] and use the temporal feature only where it
    /// predicts measurably better (see include/wrls.glsl).
    pub model_selection: bool,
    /// Temporal gradients (wrls_gradient.comp): last frame's samples re-traced in this
    /// frame's scene measure how much each region changed; the models are scaled by it
    /// and forget in proportion.
    pub gradients: bool,
    /// The spatial filter: an à-trous wavelet over the per-pixel predictions
    /// (wrls_atrous.comp) instead of the paper's 5×5 model blending (wrls_spatial.comp).
    pub atrous: bool,
    /// The pooled lag test (wrls_drift.comp): a residual that the models of a
    /// neighbourhood share, clearly above its noise, is added to them.
    pub drift: bool,
}

impl WrlsVariant {
    /// Ours: weighted RLS on the constant model p = [1] (the temporal feature buys
    /// nothing once the gradients follow change: see README, "What each part buys"),
    /// temporal gradients, the pooled lag test, an à-trous spatial filter, restarts on
    /// confirmed jumps. Its ablations (the registry's `ours-*` rows) switch one part off.
    pub const OURS: Self = Self {
        weighted: true,
        feature: false,
        paper_predictor: false,
        restart_on_change: true,
        model_selection: false,
        gradients: true,
        atrous: true,
        drift: true,
    };

    /// The paper's single model p = [1, z] with its 5×5 model blending (the Fig. 8
    /// ablations in the registry switch weighting or the feature off).
    pub const PAPER: Self = Self {
        feature: true,
        gradients: false,
        atrous: false,
        drift: false,
        ..Self::OURS
    };
}

/// The model update's pipeline: ours' constant model or the paper's feature models.
enum Update {
    Constant(Pipeline<WrlsConstantPush>),
    Feature(Pipeline<WrlsUpdatePush>),
}

/// The pipelines of one variant.
pub struct Wrls {
    name: String,
    variant: WrlsVariant,
    pub params: WrlsParams,
    /// What the temporal denoisers reproject with.
    pub motion: MotionSource,
    gradients: Option<Pipeline<WrlsGradientPush>>,
    gradient_pool: Option<Pipeline<WrlsGradientPoolPush>>,
    update: Update,
    drift: Option<Pipeline<WrlsDriftPush>>,
    /// The à-trous filter over the predictions (one level for variants without it).
    atrous: Pipeline<WrlsAtrousPush>,
    /// The paper's 5×5 model blending, for feature models without the à-trous filter.
    paper_spatial: Option<Pipeline<WrlsSpatialPush>>,
}

impl Wrls {
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        variant: WrlsVariant,
        motion: MotionSource,
        features: PathTraceFeatures,
    ) -> Result<Self> {
        let weighted = ("WEIGHTED", SpecValue::Bool(variant.weighted));
        let use_feature = ("USE_FEATURE", SpecValue::Bool(variant.feature));
        let motion_source = ("MOTION_SOURCE", SpecValue::I32(motion.spec()));
        let paper_predictor = ("PAPER_PREDICTOR", SpecValue::Bool(variant.paper_predictor));
        let restart = (
            "RESTART_ON_CHANGE",
            SpecValue::Bool(variant.restart_on_change),
        );
        let selection = ("MODEL_SELECTION", SpecValue::Bool(variant.model_selection));
        let update = if variant.feature {
            Update::Feature(ctx.pipeline(
                "wrls_update",
                &[
                    weighted,
                    use_feature,
                    motion_source,
                    paper_predictor,
                    restart,
                    selection,
                ],
            )?)
        } else {
            Update::Constant(ctx.pipeline("wrls_constant", &[weighted, motion_source, restart])?)
        };
        // The paper's 5×5 blending applies the neighbours' feature models; the constant
        // model's predictions are filtered by the à-trous pass (one level without it).
        let paper_spatial = (variant.feature && !variant.atrous)
            .then(|| ctx.pipeline("wrls_spatial", &[use_feature, paper_predictor, selection]))
            .transpose()?;
        let params =
            WrlsParams::default().with_overrides(std::env::var("DVR_WRLS").ok().as_deref())?;
        Ok(Self {
            name: name.to_string(),
            variant,
            params,
            motion,
            // The gradient pass traces paths: it is specialised like the path tracer.
            gradients: variant
                .gradients
                .then(|| ctx.pipeline("wrls_gradient", &path_trace::specialization(features)))
                .transpose()?,
            gradient_pool: variant
                .gradients
                .then(|| ctx.pipeline("wrls_gradient_pool", &[]))
                .transpose()?,
            update,
            drift: variant
                .drift
                .then(|| {
                    // A constant radius lets the compiler unroll the window (lavapipe:
                    // 1.5 → 1.3 ms at 256²).
                    let radius = SpecValue::I32(params.drift_radius as i32);
                    ctx.pipeline("wrls_drift", &[("DRIFT_RADIUS", radius)])
                })
                .transpose()?,
            atrous: ctx.pipeline(
                "wrls_atrous",
                &[("SHARED_TILES", SpecValue::Bool(ctx.shared_tiles))],
            )?,
            paper_spatial,
        })
    }
}

impl Denoiser for Wrls {
    fn name(&self) -> &str {
        &self.name
    }

    fn add<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
    ) -> Result<ImageHandle> {
        let desc = ImageDesc::d2(
            input.size.width,
            input.size.height,
            vk::Format::R32G32B32A32_SFLOAT,
        );
        let n = &self.name;
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        let lag = spatial::LagImages {
            prediction: graph.image(ctx, &format!("{n}.prediction"), desc)?,
            residual: graph.history(ctx, &format!("{n}.residual"), desc)?,
            drift: graph.history(ctx, &format!("{n}.drift"), desc)?,
        };
        let gradients = self.add_gradients(ctx, graph, frame, input)?;
        let models = match &self.update {
            Update::Feature(pipeline) => {
                Some(self.add_feature_update(pipeline, ctx, graph, frame, input, &gradients, &lag)?)
            }
            Update::Constant(pipeline) => {
                self.add_constant_update(pipeline, ctx, graph, frame, input, &gradients, &lag)?;
                None
            }
        };
        self.add_drift(frame, input.size, &lag);
        match (&self.paper_spatial, models) {
            (Some(pipeline), Some(m)) => self.add_paper_spatial(pipeline, frame, input, &m, out),
            _ => self.add_atrous(ctx, graph, frame, input.size, lag.prediction, out)?,
        }
        Ok(out)
    }
}
