//! `taa`: temporal anti-aliasing used as a denoiser. One pass, `taa` (shaders/glsl/taa.comp):
//! an exponential moving average of the reprojected history and the noisy frame, with the
//! history clipped to the variance box of the frame's 3×3 neighbourhood in YCoCg (Salvi
//! 2016; clip towards the mean as in Karis 2014). One history, `taa.color`, which is also
//! the output: the average is what the next frame reprojects. Like `svgf` it is not reset
//! on camera, light or TF changes; the clip box limits how long stale colour survives.

use super::{Built, DenoiseFrame, Denoiser, DenoiserConfig, MotionSource};
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::ImageHandle;
use glam::Vec4;

gpu_block! {
    /// `TaaPush` in taa.comp.
    pub struct TaaPush {
        pub camera: Vec4,
        pub width: u32,
        pub height: u32,
        pub history_valid: u32,
        pub alpha: f32,
        pub gamma: f32,
        pub tolerance: f32,
        pub pad0: f32,
        pub pad1: f32,
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TaaParams {
    /// Weight of the new frame in the moving average.
    pub alpha: f32,
    /// Half-size of the clip box in standard deviations of the neighbourhood.
    pub gamma: f32,
    /// Disocclusion tolerance in pixels (see [`super::REPROJECTION_TOLERANCE_PX`]).
    pub tolerance: f32,
}

impl Default for TaaParams {
    fn default() -> Self {
        Self {
            alpha: 0.1,
            gamma: 1.0,
            tolerance: super::REPROJECTION_TOLERANCE_PX,
        }
    }
}

pub struct Taa {
    /// Its registry name, which also names its pass and history (`<name>.color`).
    name: &'static str,
    pipeline: Pipeline<TaaPush>,
    pub params: TaaParams,
    /// 0: motion from the first real collision (the paper's, as `ours`), 1: from features.
    pub motion: MotionSource,
}

impl Taa {
    pub fn create(ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        let motion = config.motion;
        Ok(Box::new(Self {
            name,
            pipeline: ctx.pipeline("taa", &[("MOTION_SOURCE", SpecValue::I32(motion.spec()))])?,
            params: TaaParams::default(),
            motion,
        }))
    }
}

impl Denoiser for Taa {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
        let size = input.size;
        let desc = input.rgba32f();
        let color = graph.history(ctx, &format!("{}.color", self.name), desc)?;
        let reproj = input.reprojection(self.name, self.motion)?;
        let valid = color.valid && reproj.valid;
        let p = self.params;
        let push = TaaPush {
            camera: input.camera.extend(1.0),
            width: size.width,
            height: size.height,
            history_valid: valid as u32,
            alpha: p.alpha,
            gamma: p.gamma,
            tolerance: p.tolerance,
            pad0: 0.0,
            pad1: 0.0,
        };
        let noisy = input.noisy;
        frame.add_compute(self.name, &self.pipeline, push, size, |b| {
            reproj.bind(b);
            b.read("noisy", noisy)
                .sampled("history_prev", color.prev)
                .write("history_cur", color.cur);
        });
        Ok(color.cur)
    }
}
