//! `<name>.noise` (ours_noise.comp) and `<name>.update` (ours_update.comp): the row sums
//! of this frame's noise measurement, then the Kalman filter's predict (the estimate
//! reprojected, scaled by the measured change, shifted by a significant pooled lag) and
//! update with this frame's noisy colour. State: `model` (rgb estimate, a its variance)
//! and `noise` (the measurement noise R).

use super::feedback::State;
use super::gradient::Gradients;
use super::lag::LagImages;
use super::Ours;
use crate::denoise::DenoiseFrame;
use crate::error::Result;
use crate::gpu::ImageDesc;
use crate::gpu_block;
use ash::vk;
use glam::Vec4;

gpu_block! {
    /// `OursNoisePush` in ours_noise.comp.
    pub struct OursNoisePush {
        pub width: u32,
        pub height: u32,
        pub spp: f32,
        pub pad: f32,
    }
}

gpu_block! {
    /// `OursUpdatePush` in ours_update.comp.
    pub struct OursUpdatePush {
        pub camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub history_valid: u32,
        pub gradient_valid: u32,
        pub lag_valid: u32,
        pub stratum: u32,
        pub spp: f32,
        pub tolerance: f32,
        pub change_q: f32,
        pub motion_q: f32,
        pub lag_z: f32,
        pub jump_z: f32,
        /// 1: a significant pooled residual shifts the state (0 in `ours-no-lag`).
        pub shift: u32,
        pub pad0: u32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

impl Ours {
    /// Adds the update; returns the filter's state: the estimate (rgb, unclamped: its
    /// readers clamp it at zero) with its variance (a), and the noise state.
    pub(super) fn add_update<'f>(
        &'f self,
        f: &mut DenoiseFrame<'_, 'f>,
        gradients: &Gradients,
        lag: &LagImages,
    ) -> Result<State> {
        let (ctx, graph, frame, input) = f.parts();
        let size = input.size;
        let desc = input.rgba32f();
        let n = &self.name;
        let model = graph.history(ctx, &format!("{n}.model"), desc)?;
        // The noise state: R, and D, the part of P that process noise put there.
        let noise_desc = ImageDesc {
            format: vk::Format::R32G32_SFLOAT,
            ..desc
        };
        let noise = graph.history(ctx, &format!("{n}.noise"), noise_desc)?;
        let rows = graph.image(ctx, &format!("{n}.noise_rows"), desc)?;
        let reproj = input.reprojection(n, self.motion)?;
        let p = self.params;
        let push = OursUpdatePush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: (model.valid && reproj.valid) as u32,
            gradient_valid: gradients.valid as u32,
            lag_valid: lag.pooled.valid as u32,
            stratum: p.stratum.max(1),
            spp: input.spp as f32,
            tolerance: crate::denoise::REPROJECTION_TOLERANCE_PX,
            change_q: p.change_q,
            motion_q: p.motion_q,
            lag_z: p.lag_z,
            jump_z: p.jump_z,
            shift: self.variant.lag as u32,
            pad0: 0,
            pad1: 0,
            pad2: 0,
        };
        let (noisy, moments, g, lag) = (input.noisy, input.moments, *gradients, *lag);
        let rows_push = OursNoisePush {
            width: size.width,
            height: size.height,
            spp: input.spp as f32,
            pad: 0.0,
        };
        frame.add_compute(format!("{n}.noise"), &self.noise, rows_push, size, |b| {
            b.read("moments", moments)
                .read("noisy", noisy)
                .write("rows", rows);
        });
        frame.add_compute(format!("{n}.update"), &self.update, push, size, |b| {
            reproj.bind(b);
            b.read("noisy", noisy)
                .read("noise_rows", rows)
                .read("gradient_ratio", g.ratio)
                .sampled("lag_prev", lag.pooled.prev)
                .sampled("residual_prev", lag.residual.prev)
                .write("residual", lag.residual.cur)
                .sampled("model_prev", model.prev)
                .write("model_cur", model.cur)
                .sampled("noise_prev", noise.prev)
                .write("noise_cur", noise.cur);
        });
        Ok(State {
            model: model.cur,
            noise: noise.cur,
            fresh: !(model.valid && reproj.valid),
        })
    }
}
