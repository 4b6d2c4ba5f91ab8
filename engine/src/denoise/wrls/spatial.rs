//! After the update: `<name>.drift` (wrls_drift.comp), the pooled lag test, and the
//! spatial filter: ours' à-trous over the models' predictions (`<name>.atrous0..k`,
//! wrls_atrous.comp) or the paper's 5×5 model blending (`<name>.spatial`,
//! wrls_spatial.comp).

use super::update::FeatureModels;
use super::Wrls;
use crate::denoise::DenoiseInputs;
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::graph::Extent;
use crate::graph::{Bind, Frame, History, ImageHandle, RenderGraph};
use crate::renderer::uniforms::{WrlsAtrousPush, WrlsDriftPush, WrlsSpatialPush};

/// What the update writes for the spatial filter and the pooled lag test, and the lag
/// estimate that next frame's update reads.
#[derive(Clone, Copy, Debug)]
pub(super) struct LagImages {
    /// Each pixel's prediction (rgb) and its variance (a).
    pub prediction: ImageHandle,
    /// Each pixel's a-posteriori residual (rgb) and its variance (a, < 0 where none).
    pub residual: ImageHandle,
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
            radius: self.params.drift_radius as i32,
            pad0: 0,
        };
        let lag = *lag;
        frame.add_pass(
            format!("{}.drift", self.name),
            |b| {
                b.read(lag.residual).write(lag.drift.cur);
            },
            move |pc| {
                let binds = [
                    ("residual", Bind::Image(lag.residual)),
                    ("drift", Bind::Image(lag.drift.cur)),
                ];
                let groups = pipeline.groups_2d(size.width, size.height);
                pc.dispatch(pipeline, &binds, &push, groups)
            },
        );
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
        let pipeline = &self.spatial;
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
                pad0: 0,
                pad1: 0,
                pad2: 0,
            };
            frame.add_pass(
                format!("{}.atrous{i}", self.name),
                |b| {
                    b.read(src).write(dst);
                },
                move |pc| {
                    let binds = [
                        ("color_in", Bind::Image(src)),
                        ("color_out", Bind::Image(dst)),
                    ];
                    let groups = pipeline.groups_2d(size.width, size.height);
                    pc.dispatch(pipeline, &binds, &push, groups)
                },
            );
            src = dst;
        }
        Ok(())
    }

    /// The paper's spatial pass: each pixel blends the predictions of the 25 models of
    /// its 5×5 window applied to its own predictor.
    pub(super) fn add_paper_spatial<'f>(
        &'f self,
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
        let (noisy, m) = (input.noisy, *m);
        frame.add_pass(
            format!("{}.spatial", self.name),
            |b| {
                b.read(m.z.cur)
                    .read(noisy)
                    .read(m.p[0].cur)
                    .read(m.p[2].cur)
                    .read(m.constant.cur)
                    .read(m.errors.cur)
                    .write(out);
                for h in &m.beta {
                    b.read(h.cur);
                }
            },
            move |pc| {
                let binds = [
                    ("z", Bind::Image(m.z.cur)),
                    ("beta_r", Bind::Image(m.beta[0].cur)),
                    ("beta_g", Bind::Image(m.beta[1].cur)),
                    ("beta_b", Bind::Image(m.beta[2].cur)),
                    ("noisy", Bind::Image(noisy)),
                    ("denoised", Bind::Image(out)),
                    ("p0", Bind::Image(m.p[0].cur)),
                    ("p2", Bind::Image(m.p[2].cur)),
                    ("constant", Bind::Image(m.constant.cur)),
                    ("errors", Bind::Image(m.errors.cur)),
                ];
                let groups = self.spatial.groups_2d(size.width, size.height);
                pc.dispatch(&self.spatial, &binds, &push, groups)
            },
        );
    }
}
