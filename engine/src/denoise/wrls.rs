//! `ours`: the paper's weighted-RLS denoiser (TVCG §5–6), and its ablations from the same
//! code through specialisation constants: `rls` (w = 1, the paper's RLS-F), `wrls-nf` and
//! `rls-nf` (no temporal feature, p = [1]). Two passes: `<name>.update` (temporal feature,
//! reprojected models, weighted RLS update) and `<name>.spatial` (5×5 model blending).

use super::{DenoiseInputs, Denoiser, MotionSource};
use crate::error::Result;
use crate::gpu::{ComputePipeline, GpuContext, ImageDesc, SpecValue};
use crate::graph::{Bind, Frame, ImageHandle, RenderGraph};
use crate::passes::path_trace::{self, PathTraceFeatures};
use crate::renderer::uniforms::{
    WrlsAtrousPush, WrlsDriftPush, WrlsGradientPush, WrlsSpatialPush, WrlsUpdatePush,
};
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
    /// Edge of the temporal-gradient strata in pixels: one pixel in S×S is re-traced.
    pub stratum: u32,
    /// Smallest forgetting factor the temporal gradients may set (a sudden change).
    pub lambda_min: f32,
    /// How fast the forgetting factor falls with the relative change the gradients
    /// measure: the history keeps 1 − min(1, gain·change) of its weight.
    pub change_gain: f32,
    /// Shrinkage of the gradient ratio towards 1: a ratio `k` standard errors from 1
    /// keeps k²/(k² + shrink) of its departure.
    pub shrink: f32,
    /// Pooled residual, in standard errors of its mean, from which the pooled lag test
    /// starts to correct the models (fully at twice this).
    pub drift_z: f32,
    /// Radius of the pooled lag test's square neighbourhood, in pixels.
    pub drift_radius: u32,
    /// À-trous iterations of the spatial filter (steps 1, 2, 4, …).
    pub atrous_iterations: u32,
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
            stratum: 2,
            lambda_min: 0.1,
            change_gain: 8.0,
            shrink: 4.0,
            drift_z: 3.0,
            drift_radius: 2,
            atrous_iterations: 3,
        }
    }
}

impl WrlsParams {
    /// These parameters with `name=value` pairs (comma-separated) applied, e.g. from
    /// `DVR_WRLS="change_gain=2,kappa=3"`: for parameter studies with `dvr eval`.
    pub fn with_overrides(mut self, spec: Option<&str>) -> Result<Self> {
        let Some(spec) = spec else { return Ok(self) };
        for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let bad = |problem: String| crate::error::EngineError::Pass {
                pass: "wrls".into(),
                problem: format!("DVR_WRLS: {item:?}: {problem}"),
            };
            let (name, value) = item
                .split_once('=')
                .ok_or_else(|| bad("expected name=value".into()))?;
            let v: f32 = value
                .trim()
                .parse()
                .map_err(|e| bad(format!("not a number ({e})")))?;
            let field = match name.trim() {
                "lambda" => &mut self.lambda,
                "alpha" => &mut self.alpha,
                "kappa" => &mut self.kappa,
                "change_ratio" => &mut self.change_ratio,
                "outlier_sigmas" => &mut self.outlier_sigmas,
                "lambda_min" => &mut self.lambda_min,
                "change_gain" => &mut self.change_gain,
                "shrink" => &mut self.shrink,
                "drift_z" => &mut self.drift_z,
                "drift_radius" => {
                    self.drift_radius = v as u32;
                    continue;
                }
                "stratum" => {
                    self.stratum = v as u32;
                    continue;
                }
                "atrous_iterations" => {
                    self.atrous_iterations = v as u32;
                    continue;
                }
                other => return Err(bad(format!("unknown parameter {other:?}"))),
            };
            *field = v;
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
    pub fn from_name(name: &str) -> Option<Self> {
        // Ours: weighted RLS on the constant model p = [1] (the temporal feature buys
        // nothing once the gradients follow change: see README, "What each part buys"),
        // temporal gradients, à-trous spatial filter, restarts on confirmed jumps.
        let ours = Self {
            weighted: true,
            feature: false,
            paper_predictor: false,
            restart_on_change: true,
            model_selection: false,
            gradients: true,
            atrous: true,
            drift: true,
        };
        // The paper's single model p = [1, z] with its 5×5 model blending.
        let paper = Self {
            feature: true,
            gradients: false,
            atrous: false,
            drift: false,
            ..ours
        };
        Some(match name {
            "ours" => ours,
            // Ablations of ours: one part each.
            "ours-feature" => Self {
                feature: true,
                model_selection: true,
                ..ours
            },
            "ours-no-gradient" => Self {
                gradients: false,
                ..ours
            },
            "ours-no-atrous" => Self {
                atrous: false,
                ..ours
            },
            "ours-no-drift" => Self {
                drift: false,
                ..ours
            },
            "ours-fixed-lambda" => Self {
                restart_on_change: false,
                gradients: false,
                drift: false,
                ..ours
            },
            "wrls-paper" => Self {
                paper_predictor: true,
                restart_on_change: false,
                ..paper
            },
            // The paper's ablations (Fig. 8).
            "rls" => Self {
                weighted: false,
                ..paper
            },
            "wrls-nf" => Self {
                feature: false,
                ..paper
            },
            "rls-nf" => Self {
                weighted: false,
                feature: false,
                ..paper
            },
            _ => return None,
        })
    }
}

pub struct Wrls {
    name: String,
    gradients: Option<ComputePipeline>,
    atrous: Option<ComputePipeline>,
    drift: Option<ComputePipeline>,
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
        features: PathTraceFeatures,
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
        // The gradient pass traces paths: it is specialised like the path tracer.
        let gradients = if variant.gradients {
            Some(ComputePipeline::new(
                ctx,
                "wrls_gradient",
                &path_trace::specialization(features),
            )?)
        } else {
            None
        };
        let atrous = if variant.atrous {
            Some(ComputePipeline::new(ctx, "wrls_atrous", &[])?)
        } else {
            None
        };
        let drift = if variant.drift {
            Some(ComputePipeline::new(ctx, "wrls_drift", &[])?)
        } else {
            None
        };
        Ok(Self {
            name: name.to_string(),
            gradients,
            atrous,
            drift,
            update: ComputePipeline::new(ctx, "wrls_update", &spec)?,
            spatial: ComputePipeline::new(ctx, "wrls_spatial", &[spec[1], spec[3], spec[5]])?,
            params: WrlsParams::default()
                .with_overrides(std::env::var("DVR_WRLS").ok().as_deref())?,
            motion,
        })
    }
}

/// Ours' temporal gradients of a frame, at stratum resolution in last frame's image.
#[derive(Clone, Copy, Debug)]
struct Gradients {
    /// Re-traced radiance (this frame's scene) and last frame's, per stratum.
    new: ImageHandle,
    old: ImageHandle,
    /// Measured this frame (false: the scene did not change, or nothing to compare).
    valid: bool,
}

impl Wrls {
    /// Adds the temporal-gradient pass when the scene changed since last frame; the
    /// images exist either way (the update pass binds them, and reads them only when
    /// `valid`).
    fn add_gradients<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
    ) -> Result<Gradients> {
        let size = input.size;
        let s = self.params.stratum.max(1);
        let desc = ImageDesc::d2(
            size.width.div_ceil(s),
            size.height.div_ceil(s),
            vk::Format::R32G32B32A32_SFLOAT,
        );
        let n = &self.name;
        let g = Gradients {
            new: graph.image(ctx, &format!("{n}.gradient_new"), desc)?,
            old: graph.image(ctx, &format!("{n}.gradient_old"), desc)?,
            valid: false,
        };
        let (Some(pipeline), Some(retrace)) = (&self.gradients, input.retrace) else {
            return Ok(g);
        };
        let push = WrlsGradientPush {
            prev_inv_view_proj: retrace.inv_view_proj_prev,
            prev_camera: retrace.camera_prev.extend(1.0),
            width: size.width,
            height: size.height,
            spp: input.spp,
            prev_frame: retrace.frame_prev,
            stratum: s,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        };
        let scene = retrace.scene;
        frame.add_pass(
            format!("{n}.gradient"),
            |b| {
                scene.declare_volume(b);
                b.sampled(scene.environment)
                    .read(retrace.radiance_prev)
                    .write(g.new)
                    .write(g.old);
            },
            move |pc| {
                let mut binds = scene.volume_binds();
                binds.extend([
                    ("environment_map", Bind::Image(scene.environment)),
                    ("noisy_prev", Bind::Image(retrace.radiance_prev)),
                    ("gradient_new", Bind::Image(g.new)),
                    ("gradient_old", Bind::Image(g.old)),
                ]);
                let groups = pipeline.groups_2d(desc.extent[0], desc.extent[1]);
                pc.dispatch(pipeline, &binds, &push, groups)
            },
        );
        Ok(Gradients { valid: true, ..g })
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
        let prediction = graph.image(ctx, &format!("{n}.prediction"), desc)?;
        let residual = graph.image(ctx, &format!("{n}.residual"), desc)?;
        let drift = graph.history(ctx, &format!("{n}.drift"), desc)?;
        let reproj = input.reprojection(self.name(), self.motion)?;
        let valid = z.valid && reproj.valid;
        let p = self.params;
        let gradient = self.add_gradients(ctx, graph, frame, input)?;
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
            gradient_valid: gradient.valid as u32,
            drift_valid: (self.drift.is_some() && drift.valid) as u32,
            stratum: p.stratum,
            lambda_min: p.lambda_min,
            change_gain: p.change_gain,
            shrink: p.shrink,
            drift_z: p.drift_z,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        let noisy = input.noisy;
        frame.add_pass(
            format!("{n}.update"),
            |b| {
                reproj.declare(b);
                b.read(noisy)
                    .sampled(z.prev)
                    .read(gradient.new)
                    .read(gradient.old)
                    .sampled(drift.prev)
                    .write(residual);
                for h in beta.iter().chain(&pm).chain([&constant, &errors]) {
                    b.sampled(h.prev);
                    b.write(h.cur);
                }
                b.write(z.cur).write(prediction);
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
                    ("gradient_new", Bind::Image(gradient.new)),
                    ("gradient_old", Bind::Image(gradient.old)),
                    ("prediction", Bind::Image(prediction)),
                    ("residual", Bind::Image(residual)),
                    ("drift_prev", Bind::Image(drift.prev)),
                ]);
                let groups = self.update.groups_2d(size.width, size.height);
                pc.dispatch(&self.update, &binds, &push, groups)
            },
        );
        if let Some(pipeline) = &self.drift {
            let push = WrlsDriftPush {
                width: size.width,
                height: size.height,
                radius: p.drift_radius as i32,
                pad0: 0,
            };
            frame.add_pass(
                format!("{n}.drift"),
                |b| {
                    b.read(residual).write(drift.cur);
                },
                move |pc| {
                    let binds = [
                        ("residual", Bind::Image(residual)),
                        ("drift", Bind::Image(drift.cur)),
                    ];
                    let groups = pipeline.groups_2d(size.width, size.height);
                    pc.dispatch(pipeline, &binds, &push, groups)
                },
            );
        }
        if let Some(atrous) = &self.atrous {
            // Ping-pong between two images; the last iteration writes the output.
            let ping = graph.image(ctx, &format!("{n}.atrous"), desc)?;
            let iterations = p.atrous_iterations.max(1);
            let mut src = prediction;
            for i in 0..iterations {
                let last = i + 1 == iterations;
                let dst = if last {
                    out
                } else if src == ping {
                    prediction
                } else {
                    ping
                };
                let push = WrlsAtrousPush {
                    width: size.width,
                    height: size.height,
                    step: 1 << i,
                    kappa: p.kappa,
                    last: last as u32,
                    pad0: 0,
                    pad1: 0,
                    pad2: 0,
                };
                frame.add_pass(
                    format!("{n}.atrous{i}"),
                    |b| {
                        b.read(src).write(dst);
                    },
                    move |pc| {
                        let binds = [
                            ("color_in", Bind::Image(src)),
                            ("color_out", Bind::Image(dst)),
                        ];
                        let groups = atrous.groups_2d(size.width, size.height);
                        pc.dispatch(atrous, &binds, &push, groups)
                    },
                );
                src = dst;
            }
            return Ok(out);
        }
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
        for p in [&mut self.gradients, &mut self.atrous, &mut self.drift]
            .into_iter()
            .flatten()
        {
            p.destroy(ctx);
        }
        self.update.destroy(ctx);
        self.spatial.destroy(ctx);
    }
}
