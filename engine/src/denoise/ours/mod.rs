//! `ours`: a per-pixel local-level Kalman filter on the radiance, told by temporal
//! gradients how much the scene changed, checked by a pooled lag test, leaning where it is
//! young on a local linear model of its neighbours on the guide albedo, and filtered in
//! space by an à-trous wavelet on the filters' own variances.
//!
//! The model (what the state is, what the noise is, where each comes from) is stated in
//! `shaders/glsl/ours_update.comp`; in short, per pixel x_t = g_t ∘ x_{t−1} + w_t (Q_t)
//! and y_t = x_t + v_t (R_t), with g_t the measured change, Q_t what the prediction may
//! have missed (a share of the measured change, camera motion, a shift the lag test found),
//! and R_t the samples' own variance. The spatial prior (`shaders/glsl/ours_prior.comp`)
//! is a second measurement of each estimate, from its neighbourhood.
//!
//! Passes of a frame, in order (each in its own file here):
//! - `<name>.gradient` ([`gradient`], `ours_gradient.comp`): temporal gradients, when the
//!   scene changed: last frame's samples re-traced in this frame's scene;
//! - `<name>.gradient_pool` ([`gradient_pool`], `ours_gradient_pool.comp`): the gradients
//!   pooled over 3×3, 5×5 and 9×9 strata and shrunk, once per stratum;
//! - `<name>.noise`, `<name>.update` ([`update`], `ours_noise.comp`, `ours_update.comp`):
//!   this frame's noise measurement summed over rows, then the Kalman filter's predict and
//!   update;
//! - `<name>.lag` ([`lag`], `ours_lag.comp`): the pooled lag test, read by next frame's
//!   update;
//! - `<name>.guide`, `<name>.prior_sums`, `<name>.prior_fit`, `<name>.prior` ([`prior`],
//!   `ours_guide.comp`, `ours_prior_sums.comp`, `ours_prior_fit.comp`, `ours_prior.comp`):
//!   the spatial prior, on the guide albedo composited along each ray
//!   (`aux_features.comp`, shared with svgf) and the surface's gradient normal
//!   (`surface_features.comp`); a frame without them (synthetic inputs) goes without;
//! - `<name>.atrous0..2` ([`atrous`], `variance_atrous.comp`): the à-trous spatial filter;
//! - `<name>.young_*` ([`young`], `ours_young_*.comp`): on a frame where every state
//!   restarted (the first, after a reset or a resize) and the guides are there, a small
//!   trained network's estimate of the frame from its samples, its guides and ours'
//!   estimate, which it blends with ours' (the output; the filter's states do not see
//!   it);
//! - `<name>.feedback` ([`feedback`], `ours_feedback.comp`): the first level's estimate
//!   into the states that restarted this frame, read by next frame's update.
//!
//! The ablations (`ours-no-gradient`, `ours-no-lag`, `ours-no-prior`, `ours-no-atrous`,
//! `ours-no-feedback`, `ours-no-young`)
//! switch one stage off each ([`OursVariant`]); every other pass runs as in `ours`, and
//! `tests/ablations.rs` checks by the stages' images that only that stage changed.

mod atrous;
#[cfg(test)]
mod constants;
mod feedback;
mod gradient;
mod gradient_pool;
mod lag;
mod prior;
mod update;
pub mod young;

use super::variance_atrous::{self, VarianceAtrousPush};
use super::{Build, Built, Tunables};
use super::{DenoiseFrame, Denoiser, DenoiserConfig, MotionSource, Overridable};
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline, SpecValue};
use crate::graph::ImageHandle;
use crate::passes::path_trace::{self, PathTraceFeatures};
use gradient::OursGradientPush;
use gradient_pool::OursGradientPoolPush;
use lag::OursLagPush;
use prior::PriorPipelines;
use update::{OursNoisePush, OursUpdatePush};
use young::{YoungInputs, YoungNet, YoungWeights};

/// Ours' tunables, each with what it is (the book's denoisers page, "ours").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OursParams {
    /// Edge of the temporal-gradient strata in pixels: one pixel in S×S is re-traced.
    pub stratum: u32,
    /// Shrinkage of the pooled gradient ratios, each towards the next wider pool's (the
    /// widest towards 1): a ratio `k` standard errors away keeps k²/(k² + shrink) of its
    /// departure.
    pub shrink: f32,
    /// Process noise of a measured change: the pixel's own change may differ from its
    /// neighbourhood's measured one by this share of it (Q = (change_q · change · L)², L
    /// the larger of the pixel's RMS colour and its 5×5 neighbourhood's mean colour's).
    pub change_q: f32,
    /// Process noise of a pixel whose surface moved on screen, in units of its
    /// measurement noise (the view-dependent change of a semi-transparent volume).
    pub motion_q: f32,
    /// Pooled residual, in standard errors of its mean, below which it is noise; beyond,
    /// the positive-part shrinkage of it is taken as a shift of the state.
    pub lag_z: f32,
    /// Pooled residual, in standard errors of its mean, beyond which the level jumped:
    /// the innovation's square joins the prediction's variance, so the update follows a
    /// change nothing measured.
    pub jump_z: f32,
    /// À-trous range: a neighbour's estimate farther from the pixel's than this, in the
    /// two estimates' standard errors, is not blended.
    pub kappa: f32,
    /// Relative standard error of an estimate below which the à-trous levels keep the
    /// pixel as it is (blending could only pull a converged estimate towards noisier
    /// neighbours).
    pub keep: f32,
}

impl Default for OursParams {
    fn default() -> Self {
        Self {
            stratum: 2,
            shrink: 4.0,
            change_q: 3.5,
            motion_q: 0.5,
            lag_z: 1.5,
            jump_z: 6.0,
            kappa: 6.0,
            keep: 0.02,
        }
    }
}

/// The parameters `DVR_OURS` may set (for parameter studies with `dvr eval`), with the
/// range each takes.
const OVERRIDABLE: &[Overridable<OursParams>] = &[
    ("stratum", 1.0, 16.0, |p, v| p.stratum = v as u32),
    ("shrink", 0.0, 1e3, |p, v| p.shrink = v),
    ("change_q", 0.0, 1e3, |p, v| p.change_q = v),
    ("motion_q", 0.0, 1e3, |p, v| p.motion_q = v),
    ("lag_z", 0.0, 1e3, |p, v| p.lag_z = v),
    ("jump_z", 0.5, 1e3, |p, v| p.jump_z = v),
    ("kappa", 0.5, 1e3, |p, v| p.kappa = v),
    ("keep", 0.0, 1.0, |p, v| p.keep = v),
];

/// `DVR_OURS="change_q=2,keep=0.1"` sets parameters for a study with `dvr eval`.
impl Tunables for OursParams {
    const VARIABLE: &'static str = "DVR_OURS";
    const TABLE: &'static [Overridable<Self>] = OVERRIDABLE;
}

/// Which stages act: `ours` has all; each ablation switches exactly one off and leaves
/// every other pass as it is in `ours`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OursVariant {
    /// Temporal gradients: the measured change g_t and its process noise (without them
    /// g = 1 and Q has no change term; the gradient passes do not run).
    pub gradients: bool,
    /// The pooled lag test's shift of the state (without it the lag test still runs, and
    /// its jump test, the running residual and everything else are as in `ours`; only no
    /// significant residual shifts the state).
    pub lag: bool,
    /// The à-trous spatial filter (without it the prior's combination is the output).
    pub atrous: bool,
    /// The spatial prior's combination: each young estimate combined with a local linear
    /// model of its neighbours' on the guide albedo and normal, by their variances
    /// (without it the estimates go to the à-trous as they are; the model is still
    /// fitted, and the à-trous still carries neighbours by it).
    pub prior: bool,
    /// The feedback of the first à-trous level into states that restarted this frame
    /// (without it next frame's update starts from the restarted state's own mean).
    pub feedback: bool,
    /// The young-pixel network on frames where every state restarted (without it the
    /// à-trous output is the frame's estimate there, as on every other frame).
    pub young: bool,
}

impl OursVariant {
    pub const OURS: Self = Self {
        gradients: true,
        lag: true,
        atrous: true,
        prior: true,
        feedback: true,
        young: true,
    };
}

/// The pipelines of one variant.
pub struct Ours {
    name: String,
    pub params: OursParams,
    /// What the filter reprojects with.
    pub motion: MotionSource,
    variant: OursVariant,
    gradients: Option<Pipeline<OursGradientPush>>,
    gradient_pool: Option<Pipeline<OursGradientPoolPush>>,
    noise: Pipeline<OursNoisePush>,
    update: Pipeline<OursUpdatePush>,
    lag: Pipeline<OursLagPush>,
    feedback: Pipeline<feedback::OursFeedbackPush>,
    atrous: Option<Pipeline<VarianceAtrousPush>>,
    /// The à-trous that carries neighbours by the prior's prediction (where there is one).
    atrous_carry: Option<Pipeline<VarianceAtrousPush>>,
    prior: PriorPipelines,
    young: Option<YoungNet>,
}

/// The pooled lag test's window radius (5×5).
const LAG_RADIUS: i32 = 2;

/// À-trous levels (steps 1, 2, 4: up to 25×25 pixels). Converged pixels are kept at every
/// level, so the third acts where the history is young. Fixed, not tuned: a fourth
/// bought 0.01 dB (the experiments page of the book, docs/src/experiments.md).
pub const ATROUS_LEVELS: u32 = 3;

impl Ours {
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        variant: OursVariant,
        motion: MotionSource,
        features: PathTraceFeatures,
    ) -> Result<Self> {
        let params = OursParams::from_env()?;
        let motion_source = ("MOTION_SOURCE", SpecValue::I32(motion.spec()));
        Ok(Self {
            name: name.to_string(),
            params,
            motion,
            variant,
            // The gradient pass traces paths: it is specialised like the path tracer.
            gradients: variant
                .gradients
                .then(|| ctx.pipeline("ours_gradient", &path_trace::specialization(features)))
                .transpose()?,
            gradient_pool: variant
                .gradients
                .then(|| ctx.pipeline("ours_gradient_pool", &[]))
                .transpose()?,
            noise: ctx.pipeline("ours_noise", &[])?,
            update: ctx.pipeline("ours_update", &[motion_source])?,
            lag: ctx.pipeline("ours_lag", &[("LAG_RADIUS", SpecValue::I32(LAG_RADIUS))])?,
            feedback: ctx.pipeline("ours_feedback", &[])?,
            atrous: variant
                .atrous
                .then(|| variance_atrous::pipeline(ctx, false, true))
                .transpose()?,
            atrous_carry: variant
                .atrous
                .then(|| variance_atrous::pipeline(ctx, true, true))
                .transpose()?,
            prior: PriorPipelines::new(ctx)?,
            young: variant
                .young
                .then(|| YoungNet::new(ctx, YoungWeights::builtin()?))
                .transpose()?,
        })
    }
}

/// A row's variant builds ours with its stages.
impl Build for OursVariant {
    fn build(&self, ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        let ours = Ours::new(ctx, name, *self, config.motion, config.features)?;
        Ok(Box::new(ours))
    }
}

impl Denoiser for Ours {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, _, input) = f.parts();
        let desc = input.rgba32f();
        let n = &self.name;
        let lag = lag::LagImages {
            residual: graph.history(ctx, &format!("{n}.residual"), desc)?,
            pooled: graph.history(ctx, &format!("{n}.lag"), desc)?,
        };
        let gradients = self.add_gradients(&mut f)?;
        let state = self.add_update(&mut f, &gradients, &lag)?;
        let estimate = state.model;
        self.add_lag(f.frame, input.size, &lag);
        let normal = input.features.map(|f| f.normal);
        let guides = match (input.guides, normal) {
            (Some(albedo), Some(normal)) => Some(prior::PriorGuides { albedo, normal }),
            _ => None,
        };
        let (estimate, prediction) = match guides {
            Some(guides) => {
                let (e, p) = self.add_prior(&mut f, estimate, guides)?;
                (e, Some(p))
            }
            None => (estimate, None),
        };
        // The network runs where every state restarted and it has the guides it reads
        // (and its tensors fit the device's images).
        let young = match (&self.young, guides) {
            (Some(net), Some(guides)) if state.fresh => {
                let layout = net.layout(f.ctx, f.input.size);
                layout.map(|layout| (net, guides, layout))
            }
            _ => None,
        };
        let out = self.add_atrous(&mut f, estimate, prediction, state)?;
        let Some((net, guides, layout)) = young else {
            return Ok(out);
        };
        let (ctx, graph, frame, input) = f.parts();
        let inputs = YoungInputs {
            noisy: input.noisy,
            albedo: guides.albedo,
            normal: guides.normal,
            ours: out,
        };
        net.add(ctx, graph, frame, n, input.size, layout, inputs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_are_named_and_range_checked() {
        let p = OursParams::default()
            .with_overrides(Some("change_q=2, keep=0.1"))
            .expect("valid overrides");
        assert_eq!((p.change_q, p.keep), (2.0, 0.1));
        assert_eq!(
            OursParams::default().with_overrides(None).ok(),
            Some(OursParams::default())
        );
        crate::denoise::assert_overrides_refused(
            |spec| OursParams::default().with_overrides(spec),
            "DVR_OURS",
            &[
                ("shrink=nan", "shrink must be in"),
                ("keep=1e30", "keep must be in"),
                ("jump_z=0.1", "jump_z must be in"),
                ("lambda=0.9", "parameters: stratum"),
                ("keep", "name=value"),
                ("keep=x", "a number"),
                ("outlier_z=3", "parameters: stratum"),
            ],
        );
        // Inclusive bounds hold for the value as given.
        assert!(OursParams::default().with_overrides(Some("keep=1")).is_ok());
    }
}
