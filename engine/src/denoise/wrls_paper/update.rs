//! `<name>.update`: the per-pixel models reprojected from last frame and updated by
//! weighted RLS with this frame's noisy colour: the constant model p = \[1\]
//! (`wrls_constant.comp`, two state images) or the paper's p = [1, z] (`wrls_update.comp`,
//! nine: the feature, β per channel, the shared P, and the constant model and both
//! models' errors that the shaders' model selection would use).

use super::Wrls;
use crate::denoise::DenoiseFrame;
use crate::error::Result;
use crate::gpu::{ImageDesc, Pipeline};
use crate::gpu_block;
use crate::graph::{History, ImageHandle, RenderGraph};
use ash::vk;
use glam::Vec4;

gpu_block! {
    /// `WrlsConstantPush` in wrls_constant.comp.
    pub struct WrlsConstantPush {
        pub camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub history_valid: u32,
        pub lambda: f32,
        pub delta: f32,
        pub tolerance: f32,
        pub change_ratio: f32,
        pub outlier_sigmas: f32,
        pub spp: f32,
        pub lambda_moving: f32,
        pub pad0: f32,
        pub pad1: f32,
    }
}

gpu_block! {
    /// `WrlsUpdatePush` in wrls_update.comp.
    pub struct WrlsUpdatePush {
        pub camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub history_valid: u32,
        pub lambda: f32,
        pub alpha: f32,
        pub h: f32,
        pub delta: f32,
        pub tolerance: f32,
        pub change_ratio: f32,
        pub outlier_sigmas: f32,
        pub pad0: f32,
        pub pad1: f32,
    }
}

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
    /// The constant model: `model` (rgb β, a P) and `stats` (running noise level, frames
    /// in a row with a far residual); writes its prediction with its variance.
    pub(super) fn add_constant_update<'f>(
        &'f self,
        pipeline: &Pipeline<WrlsConstantPush>,
        f: &mut DenoiseFrame<'_, 'f>,
        prediction: ImageHandle,
    ) -> Result<()> {
        let (ctx, graph, frame, input) = f.parts();
        let desc = input.rgba32f();
        let n = &self.name;
        let model = graph.history(ctx, &format!("{n}.model"), desc)?;
        // Two channels are all the stats need: half the bytes of an rgba32f image.
        let stats_desc = ImageDesc {
            format: vk::Format::R32G32_SFLOAT,
            ..desc
        };
        let stats = graph.history(ctx, &format!("{n}.stats"), stats_desc)?;
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
            spp: input.spp as f32,
            lambda_moving: p.lambda_moving,
            pad0: 0.0,
            pad1: 0.0,
        };
        let (noisy, moments) = (input.noisy, input.moments);
        frame.add_compute(format!("{n}.update"), pipeline, push, size, |b| {
            reproj.bind(b);
            b.read("noisy", noisy)
                .read("moments", moments)
                .write("prediction", prediction)
                .sampled("model_prev", model.prev)
                .write("model_cur", model.cur)
                .sampled("stats_prev", stats.prev)
                .write("stats_cur", stats.cur);
        });
        Ok(())
    }

    /// The paper's models: the temporal feature z, β per channel, the shared P, and the
    /// constant model and both models' errors its spatial pass binds.
    pub(super) fn add_feature_update<'f>(
        &'f self,
        pipeline: &Pipeline<WrlsUpdatePush>,
        f: &mut DenoiseFrame<'_, 'f>,
        prediction: ImageHandle,
    ) -> Result<FeatureModels> {
        let (ctx, graph, frame, input) = f.parts();
        let desc = input.rgba32f();
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
            pad0: 0.0,
            pad1: 0.0,
        };
        let noisy = input.noisy;
        frame.add_compute(format!("{n}.update"), pipeline, push, size, |b| {
            reproj.bind(b);
            b.read("noisy", noisy).write("prediction", prediction);
            let state: [(&'static str, &'static str, History); 9] = [
                ("z_prev", "z_cur", m.z),
                ("constant_prev", "constant_cur", m.constant),
                ("errors_prev", "errors_cur", m.errors),
                ("beta_r_prev", "beta_r_cur", m.beta[0]),
                ("beta_g_prev", "beta_g_cur", m.beta[1]),
                ("beta_b_prev", "beta_b_cur", m.beta[2]),
                ("p0_prev", "p0_cur", m.p[0]),
                ("p1_prev", "p1_cur", m.p[1]),
                ("p2_prev", "p2_cur", m.p[2]),
            ];
            for (prev, cur, h) in state {
                b.sampled(prev, h.prev).write(cur, h.cur);
            }
        });
        Ok(m)
    }
}
