//! After the update: `<name>.drift` (wrls_drift.comp), the pooled lag test, and the
//! spatial filter: ours' à-trous over the models' predictions (`<name>.atrous0..k`,
//! wrls_atrous.comp) or the paper's 5×5 model blending (`<name>.spatial`,
//! wrls_spatial.comp).

use super::update::FeatureModels;
use super::Wrls;
use crate::denoise::DenoiseInputs;
use crate::error::Result;
use crate::gpu::{GpuContext, Pipeline};
use crate::gpu_block;
use crate::graph::{Extent, Frame, History, ImageHandle, RenderGraph};

gpu_block! {
    /// `WrlsDriftPush` in wrls_drift.comp.
    pub struct WrlsDriftPush {
        pub width: u32,
        pub height: u32,
        pub pad0: u32,
        pub pad1: u32,
    }
}

gpu_block! {
    /// `WrlsAtrousPush` in wrls_atrous.comp.
    pub struct WrlsAtrousPush {
        pub width: u32,
        pub height: u32,
        pub step: i32,
        pub kappa: f32,
        pub last: u32,
        pub keep: f32,
        pub pad1: u32,
        pub pad2: u32,
    }
}

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

/// What the update writes for the spatial filter and the pooled lag test, and the lag
/// estimate that next frame's update reads.
#[derive(Clone, Copy, Debug)]
pub(super) struct LagImages {
    /// Each pixel's prediction (rgb) and its variance (a).
    pub prediction: ImageHandle,
    /// Each pixel's a-posteriori residual (rgb) and its variance (a, < 0 where none).
    pub residual: History,
    /// The pooled residual: rgb mean, a its variance.
    pub drift: History,
}

impl Wrls {
    /// The pooled lag test, when the variant has it.
    pub(super) fn add_drift<'f>(&'f self, frame: &mut Frame<'f>, size: Extent, lag: &LagImages) {
        let Some(pipeline) = &self.drift else {
            return;
        };
        let push = WrlsDriftPush {
            width: size.width,
            height: size.height,
            pad0: 0,
            pad1: 0,
        };
        let name = format!("{}.drift", self.name);
        frame.add_compute(name, pipeline, push, size, |b| {
            b.read("residual", lag.residual.cur)
                .write("drift", lag.drift.cur);
        });
    }

    /// Ours' à-trous filter from `prediction` into `out`: steps 1, 2, 4, … ping-ponging
    /// between `prediction` and a scratch image (one level without the variant's
    /// à-trous: the paper's 5×5 footprint).
    pub(super) fn add_atrous<'f>(
        &'f self,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        size: Extent,
        prediction: ImageHandle,
        out: ImageHandle,
    ) -> Result<()> {
        let ping = graph.image(
            ctx,
            &format!("{}.atrous", self.name),
            graph.image_desc(prediction),
        )?;
        let iterations = if self.variant.atrous {
            self.params.atrous_iterations.max(1)
        } else {
            1
        };
        let pipeline = &self.atrous;
        let mut src = prediction;
        for i in 0..iterations {
            let last = i + 1 == iterations;
            let dst = match (last, src == ping) {
                (true, _) => out,
                (false, true) => prediction,
                (false, false) => ping,
            };
            let push = WrlsAtrousPush {
                width: size.width,
                height: size.height,
                step: 1 << i,
                kappa: self.params.kappa,
                last: last as u32,
                // Ours' addition to the filter; the paper's one-level variants blend all.
                keep: if self.variant.atrous {
                    self.params.atrous_keep
                } else {
                    0.0
                },
                pad1: 0,
                pad2: 0,
            };
            let name = format!("{}.atrous{i}", self.name);
            frame.add_compute(name, pipeline, push, size, |b| {
                b.read("color_in", src).write("color_out", dst);
            });
            src = dst;
        }
        Ok(())
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
