//! `<name>.update`: the per-pixel models reprojected from last frame, adjusted for what
//! the temporal gradients and the pooled lag test measured, and updated by weighted RLS
//! with this frame's noisy colour. Ours' constant model p = [1] (`wrls_constant.comp`,
//! two state images) or the paper's p = [1, z] (`wrls_update.comp`, nine: the feature, β
//! per channel, the shared P, the constant model and both models' errors for selection).

use super::gradient::Gradients;
use super::spatial::LagImages;
use super::Wrls;
use crate::denoise::DenoiseInputs;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc};
use crate::graph::{Bind, Frame, History, RenderGraph};
use crate::renderer::uniforms::{WrlsConstantPush, WrlsUpdatePush};
use ash::vk;

/// The paper's model state after this frame's update (what its 5×5 blending reads).
#[derive(Clone, Copy, Debug)]
pub(super) struct FeatureModels {
    pub z: History,
    pub beta: [History; 3],
    pub p: [History; 3],
    pub constant: History,
    pub errors: History,
}

impl Wrls {
    fn state_desc(input: &DenoiseInputs) -> ImageDesc {
        ImageDesc::d2(
            input.size.width,
            input.size.height,
            vk::Format::R32G32B32A32_SFLOAT,
        )
    }

    /// Ours' constant model: `model` (rgb β, a P) and `stats` (running noise level,
    /// frames in a row with a far residual).
    pub(super) fn add_constant_update<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
        gradients: &Gradients,
        lag: &LagImages,
    ) -> Result<()> {
        let desc = Self::state_desc(input);
        let n = &self.name;
        let model = graph.history(ctx, &format!("{n}.model"), desc)?;
        let stats = graph.history(ctx, &format!("{n}.stats"), desc)?;
        let reproj = input.reprojection(&self.name, self.motion)?;
        let p = self.params;
        let size = input.size;
        let push = WrlsConstantPush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: (model.valid && reproj.valid) as u32,
            lambda: p.lambda,
            delta: p.delta,
            tolerance: p.tolerance,
            change_ratio: p.change_ratio,
            outlier_sigmas: p.outlier_sigmas,
            gradient_valid: gradients.valid as u32,
            drift_valid: (self.drift.is_some() && lag.drift.valid) as u32,
            stratum: p.stratum,
            lambda_min: p.lambda_min,
            change_gain: p.change_gain,
            shrink: p.shrink,
            drift_z: p.drift_z,
            spp: input.spp as f32,
            lambda_moving: p.lambda_moving,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        let (noisy, moments, g, lag) = (input.noisy, input.moments, *gradients, *lag);
        frame.add_pass(
            format!("{n}.update"),
            |b| {
                reproj.declare(b);
                b.read(noisy)
                    .read(moments)
                    .read(g.new)
                    .read(g.old)
                    .sampled(lag.drift.prev)
                    .write(lag.prediction)
                    .write(lag.residual);
                for h in [model, stats] {
                    b.sampled(h.prev).write(h.cur);
                }
            },
            move |pc| {
                let mut binds = reproj.binds();
                binds.extend([
                    ("noisy", Bind::Image(noisy)),
                    ("moments", Bind::Image(moments)),
                    ("model_prev", Bind::Image(model.prev)),
                    ("stats_prev", Bind::Image(stats.prev)),
                    ("model_cur", Bind::Image(model.cur)),
                    ("stats_cur", Bind::Image(stats.cur)),
                    ("prediction", Bind::Image(lag.prediction)),
                    ("residual", Bind::Image(lag.residual)),
                    ("drift_prev", Bind::Image(lag.drift.prev)),
                    ("gradient_new", Bind::Image(g.new)),
                    ("gradient_old", Bind::Image(g.old)),
                ]);
                let groups = self.update.groups_2d(size.width, size.height);
                pc.dispatch(&self.update, &binds, &push, groups)
            },
        );
        Ok(())
    }

    /// The paper's models (and ours-feature): the temporal feature z, β per channel, the
    /// shared P, and for model selection the constant model and both models' errors.
    pub(super) fn add_feature_update<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
        gradients: &Gradients,
        lag: &LagImages,
    ) -> Result<FeatureModels> {
        let desc = Self::state_desc(input);
        let n = &self.name;
        let history =
            |graph: &mut RenderGraph, what: &str| graph.history(ctx, &format!("{n}.{what}"), desc);
        let m = FeatureModels {
            z: history(graph, "z")?,
            beta: [
                history(graph, "beta_r")?,
                history(graph, "beta_g")?,
                history(graph, "beta_b")?,
            ],
            p: [
                history(graph, "p0")?,
                history(graph, "p1")?,
                history(graph, "p2")?,
            ],
            constant: history(graph, "constant")?,
            errors: history(graph, "errors")?,
        };
        let reproj = input.reprojection(&self.name, self.motion)?;
        let p = self.params;
        let size = input.size;
        let push = WrlsUpdatePush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: (m.z.valid && reproj.valid) as u32,
            lambda: p.lambda,
            alpha: p.alpha,
            h: p.h,
            delta: p.delta,
            tolerance: p.tolerance,
            change_ratio: p.change_ratio,
            outlier_sigmas: p.outlier_sigmas,
            gradient_valid: gradients.valid as u32,
            drift_valid: (self.drift.is_some() && lag.drift.valid) as u32,
            stratum: p.stratum,
            lambda_min: p.lambda_min,
            change_gain: p.change_gain,
            shrink: p.shrink,
            drift_z: p.drift_z,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        let (noisy, g, lag) = (input.noisy, *gradients, *lag);
        frame.add_pass(
            format!("{n}.update"),
            |b| {
                reproj.declare(b);
                b.read(noisy)
                    .read(g.new)
                    .read(g.old)
                    .sampled(lag.drift.prev)
                    .write(lag.prediction)
                    .write(lag.residual);
                for h in [m.z, m.constant, m.errors]
                    .iter()
                    .chain(&m.beta)
                    .chain(&m.p)
                {
                    b.sampled(h.prev).write(h.cur);
                }
            },
            move |pc| {
                let mut binds = reproj.binds();
                binds.extend([
                    ("noisy", Bind::Image(noisy)),
                    ("z_prev", Bind::Image(m.z.prev)),
                    ("beta_r_prev", Bind::Image(m.beta[0].prev)),
                    ("beta_g_prev", Bind::Image(m.beta[1].prev)),
                    ("beta_b_prev", Bind::Image(m.beta[2].prev)),
                    ("p0_prev", Bind::Image(m.p[0].prev)),
                    ("p1_prev", Bind::Image(m.p[1].prev)),
                    ("p2_prev", Bind::Image(m.p[2].prev)),
                    ("z_cur", Bind::Image(m.z.cur)),
                    ("beta_r_cur", Bind::Image(m.beta[0].cur)),
                    ("beta_g_cur", Bind::Image(m.beta[1].cur)),
                    ("beta_b_cur", Bind::Image(m.beta[2].cur)),
                    ("p0_cur", Bind::Image(m.p[0].cur)),
                    ("p1_cur", Bind::Image(m.p[1].cur)),
                    ("p2_cur", Bind::Image(m.p[2].cur)),
                    ("constant_prev", Bind::Image(m.constant.prev)),
                    ("errors_prev", Bind::Image(m.errors.prev)),
                    ("constant_cur", Bind::Image(m.constant.cur)),
                    ("errors_cur", Bind::Image(m.errors.cur)),
                    ("gradient_new", Bind::Image(g.new)),
                    ("gradient_old", Bind::Image(g.old)),
                    ("prediction", Bind::Image(lag.prediction)),
                    ("residual", Bind::Image(lag.residual)),
                    ("drift_prev", Bind::Image(lag.drift.prev)),
                ]);
                let groups = self.update.groups_2d(size.width, size.height);
                pc.dispatch(&self.update, &binds, &push, groups)
            },
        );
        Ok(m)
    }
}
