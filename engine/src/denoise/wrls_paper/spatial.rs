//! The spatial pass: the paper's 5×5 model blending (`<name>.spatial`, wrls_spatial.comp)
//! for the feature models, or for the constant model one 5×5 level of the à-trous filter
//! over the predictions (`<name>.atrous0`, variance_atrous.comp), edge-stopped by their
//! standard errors.

use super::update::FeatureModels;
use super::Wrls;
use crate::denoise::variance_atrous::{add_level, Level, VarianceAtrousPush};
use crate::denoise::DenoiseInputs;
use crate::gpu::Pipeline;
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle};

gpu_block! {
    /// `WrlsSpatialPush` in wrls_spatial.comp.
    pub struct WrlsSpatialPush {
        pub width: u32,
        pub height: u32,
        pub sigma_spatial: f32,
        pub sigma_range: f32,
        pub kappa: f32,
        pub pad0: f32,
        pub pad1: f32,
        pub pad2: f32,
    }
}

impl Wrls {
    /// One 5×5 level over the constant model's predictions, from `prediction` into `out`.
    pub(super) fn add_atrous<'f>(
        &'f self,
        pipeline: &'f Pipeline<VarianceAtrousPush>,
        frame: &mut Frame<'f>,
        size: Extent,
        prediction: ImageHandle,
        out: ImageHandle,
    ) {
        let level = Level {
            step: 1,
            kappa: self.params.kappa,
            keep: 0.0,
            last: true,
        };
        let name = format!("{}.atrous0", self.name);
        add_level(frame, pipeline, name, size, level, prediction, out, None);
    }

    /// The paper's spatial pass: each pixel blends the predictions of the 25 models of
    /// its 5×5 window applied to its own predictor.
    pub(super) fn add_paper_spatial<'f>(
        &'f self,
        pipeline: &Pipeline<WrlsSpatialPush>,
        frame: &mut Frame<'f>,
        input: &DenoiseInputs,
        m: &FeatureModels,
        out: ImageHandle,
    ) {
        let size = input.size;
        let p = self.params;
        let push = WrlsSpatialPush {
            width: size.width,
            height: size.height,
            sigma_spatial: p.sigma_spatial,
            sigma_range: p.sigma_range,
            kappa: p.kappa,
            pad0: 0.0,
            pad1: 0.0,
            pad2: 0.0,
        };
        let name = format!("{}.spatial", self.name);
        frame.add_compute(name, pipeline, push, size, |b| {
            b.read("z", m.z.cur)
                .read("beta_r", m.beta[0].cur)
                .read("beta_g", m.beta[1].cur)
                .read("beta_b", m.beta[2].cur)
                .read("noisy", input.noisy)
                .read("p0", m.p[0].cur)
                .read("p2", m.p[2].cur)
                .read("constant", m.constant.cur)
                .read("errors", m.errors.cur)
                .write("denoised", out);
        });
    }
}
