//! `ours`: the paper's weighted-RLS denoiser (TVCG §5–6), and its ablations from the same
//! code through specialisation constants: `rls` (w = 1, the paper's RLS-F), `wrls-nf` and
//! `rls-nf` (no temporal feature, p = [1]). Two passes: `<name>.update` (temporal feature,
//! reprojected models, weighted RLS update) and `<name>.spatial` (5×5 model blending).

use super::{DenoiseInputs, Denoiser, MotionSource};
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc, SpecValue};
use crate::graph::{Bind, Frame, ImageHandle, RenderGraph};
use crate::renderer::uniforms::{WrlsSpatialPush, WrlsUpdatePush};
use ash::vk;

/// The paper's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WrlsParams {
    pub lambda: f32,
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
    /// and still be blended (ours' spatial weights).
    pub kappa: f32,
    /// Squared a-priori residual over its running noise level that counts as a change.
    pub change_ratio: f32,
    /// Residual weights (not the paper's): a sample's weight falls off with its a-priori
    /// residual in units of the model's running noise level, exp(−r²/(k²·noise)); this
    /// is k. Only samples many standard deviations out (spikes) lose weight.
    pub outlier_sigmas: f32,
}

impl Default for WrlsParams {
    fn default() -> Self {
        Self {
            lambda: 0.998,
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
}

impl WrlsVariant {
    pub fn from_name(name: &str) -> Option<Self> {
        let ours = Self {
            weighted: true,
            feature: true,
            paper_predictor: false,
            restart_on_change: true,
            model_selection: true,
        };
        Some(match name {
            "ours" => ours,
            "ours-fixed-lambda" => Self {
                restart_on_change: false,
                ..ours
            },
            "wrls-paper" => Self {
                paper_predictor: true,
                restart_on_change: false,
                model_selection: false,
                ..ours
            },
            // The paper's ablations keep its single model.
            "rls" => Self {
                weighted: false,
                model_selection: false,
                ..ours
            },
            "wrls-nf" => Self {
                feature: false,
                model_selection: false,
                ..ours
            },
            "rls-nf" => Self {
                weighted: false,
                feature: false,
                model_selection: false,
                ..ours
            },
            _ => return None,
        })
    }
}

pub struct Wrls {
    name: String,
    update: ComputePipeline,
    spatial: ComputePipeline,
    pub params: WrlsParams,
    /// 0: motion from the first real collision (the paper's), 1: from surface features.
    pub motion: MotionSource,
}

impl Wrls {
    pub fn new(
        ctx: &GpuContext,
        name: &str,
        variant: WrlsVariant,
        motion: MotionSource,
    ) -> Result<Self> {
        let spec = [
            ("WEIGHTED", SpecValue::Bool(variant.weighted)),
            ("USE_FEATURE", SpecValue::Bool(variant.feature)),
            ("MOTION_SOURCE", SpecValue::I32(motion.spec())),
            ("PAPER_PREDICTOR", SpecValue::Bool(variant.paper_predictor)),
            (
                "RESTART_ON_CHANGE",
                SpecValue::Bool(variant.restart_on_change),
            ),
            ("MODEL_SELECTION", SpecValue::Bool(variant.model_selection)),
        ];
        Ok(Self {
            name: name.to_string(),
            update: ComputePipeline::new(ctx, "wrls_update", &spec)?,
            spatial: ComputePipeline::new(ctx, "wrls_spatial", &[spec[1], spec[3], spec[5]])?,
            params: WrlsParams::default(),
            motion,
        })
    }
}

impl Denoiser for Wrls {
    fn uses_surface_features(&self) -> bool {
        self.motion == MotionSource::Features
    }

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
        let size = input.size;
        let desc = ImageDesc::d2(size.width, size.height, vk::Format::R32G32B32A32_SFLOAT);
        let n = &self.name;
        let z = graph.history(ctx, &format!("{n}.z"), desc)?;
        let beta = [
            graph.history(ctx, &format!("{n}.beta_r"), desc)?,
            graph.history(ctx, &format!("{n}.beta_g"), desc)?,
            graph.history(ctx, &format!("{n}.beta_b"), desc)?,
        ];
        let pm = [
            graph.history(ctx, &format!("{n}.p0"), desc)?,
            graph.history(ctx, &format!("{n}.p1"), desc)?,
            graph.history(ctx, &format!("{n}.p2"), desc)?,
        ];
        // The constant model and both models' a-priori errors (model selection).
        let constant = graph.history(ctx, &format!("{n}.constant"), desc)?;
        let errors = graph.history(ctx, &format!("{n}.errors"), desc)?;
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        let reproj = input.reprojection(self.name(), self.motion)?;
        let valid = z.valid && reproj.valid;
        let p = self.params;
        let push = WrlsUpdatePush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: valid as u32,
            lambda: p.lambda,
            alpha: p.alpha,
            h: p.h,
            delta: p.delta,
            tolerance: p.tolerance,
            change_ratio: p.change_ratio,
            outlier_sigmas: p.outlier_sigmas,
            pad0: 0.0,
            pad1: 0.0,
        };
        let noisy = input.noisy;
        frame.add_pass(
            format!("{n}.update"),
            |b| {
                reproj.declare(b);
                b.read(noisy).sampled(z.prev);
                for h in beta.iter().chain(&pm).chain([&constant, &errors]) {
                    b.sampled(h.prev);
                    b.write(h.cur);
                }
                b.write(z.cur);
            },
            move |pc| {
                let mut binds = reproj.binds();
                binds.extend([
                    ("noisy", Bind::Image(noisy)),
                    ("z_prev", Bind::Image(z.prev)),
                    ("beta_r_prev", Bind::Image(beta[0].prev)),
                    ("beta_g_prev", Bind::Image(beta[1].prev)),
                    ("beta_b_prev", Bind::Image(beta[2].prev)),
                    ("p0_prev", Bind::Image(pm[0].prev)),
                    ("p1_prev", Bind::Image(pm[1].prev)),
                    ("p2_prev", Bind::Image(pm[2].prev)),
                    ("z_cur", Bind::Image(z.cur)),
                    ("beta_r_cur", Bind::Image(beta[0].cur)),
                    ("beta_g_cur", Bind::Image(beta[1].cur)),
                    ("beta_b_cur", Bind::Image(beta[2].cur)),
                    ("p0_cur", Bind::Image(pm[0].cur)),
                    ("p1_cur", Bind::Image(pm[1].cur)),
                    ("p2_cur", Bind::Image(pm[2].cur)),
                    ("constant_prev", Bind::Image(constant.prev)),
                    ("errors_prev", Bind::Image(errors.prev)),
                    ("constant_cur", Bind::Image(constant.cur)),
                    ("errors_cur", Bind::Image(errors.cur)),
                ]);
                let groups = self.update.groups_2d(size.width, size.height);
                pc.dispatch(&self.update, &binds, &push, groups)
            },
        );
        let spush = WrlsSpatialPush {
            width: size.width,
            height: size.height,
            sigma_spatial: p.sigma_spatial,
            sigma_range: p.sigma_range,
            kappa: p.kappa,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        frame.add_pass(
            format!("{n}.spatial"),
            |b| {
                b.read(z.cur)
                    .read(noisy)
                    .read(pm[0].cur)
                    .read(pm[2].cur)
                    .read(constant.cur)
                    .read(errors.cur)
                    .write(out);
                for h in &beta {
                    b.read(h.cur);
                }
            },
            move |pc| {
                let binds = [
                    ("z", Bind::Image(z.cur)),
                    ("beta_r", Bind::Image(beta[0].cur)),
                    ("beta_g", Bind::Image(beta[1].cur)),
                    ("beta_b", Bind::Image(beta[2].cur)),
                    ("noisy", Bind::Image(noisy)),
                    ("denoised", Bind::Image(out)),
                    ("p0", Bind::Image(pm[0].cur)),
                    ("p2", Bind::Image(pm[2].cur)),
                    ("constant", Bind::Image(constant.cur)),
                    ("errors", Bind::Image(errors.cur)),
                ];
                let groups = self.spatial.groups_2d(size.width, size.height);
                pc.dispatch(&self.spatial, &binds, &spush, groups)
            },
        );
        Ok(out)
    }

    fn destroy(&mut self, ctx: &GpuContext) {
        self.update.destroy(ctx);
        self.spatial.destroy(ctx);
    }
}
