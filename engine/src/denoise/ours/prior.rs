//! `<name>.guide`, `<name>.prior_fit`, `<name>.prior` (ours_guide.comp,
//! ours_prior_fit.comp, ours_prior.comp): the spatial prior. Where an estimate is young,
//! a local linear model of its neighbours' estimates on the guide albedo predicts it, and
//! the two are combined by their variances before the à-trous filter, which then carries
//! each neighbour by the model's prediction (`CARRY` in variance_atrous.comp).

use super::Ours;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle, RenderGraph};

/// Pixels between two fits' centres: the grid's size here, and the shaders' specialisation
/// constant `PRIOR_STRIDE` (include/ours_prior.glsl).
pub const PRIOR_STRIDE: u32 = 4;

/// The fits' images, as both shaders name them: β₀ with the residuals' mean square V,
/// then the coefficients of the albedo's r, g, b and of the position's x, y (rgb each).
const FITS: [&str; 6] = ["fit0", "fit_r", "fit_g", "fit_b", "fit_x", "fit_y"];

gpu_block! {
    /// `OursGuidePush` in ours_guide.comp.
    pub struct OursGuidePush {
        pub width: u32,
        pub height: u32,
        pub pad0: u32,
        pub pad1: u32,
    }
}

gpu_block! {
    /// `OursPriorFitPush` in ours_prior_fit.comp.
    pub struct OursPriorFitPush {
        pub width: u32,
        pub height: u32,
        pub cells_x: u32,
        pub cells_y: u32,
    }
}

gpu_block! {
    /// `OursPriorPush` in ours_prior.comp.
    pub struct OursPriorPush {
        pub width: u32,
        pub height: u32,
        pub keep: f32,
        pub pad: f32,
    }
}

/// The prior's three pipelines.
pub(super) struct PriorPipelines {
    pub guide: Pipeline<OursGuidePush>,
    pub fit: Pipeline<OursPriorFitPush>,
    pub combine: Pipeline<OursPriorPush>,
}

impl PriorPipelines {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let stride = [("PRIOR_STRIDE", SpecValue::I32(PRIOR_STRIDE as i32))];
        Ok(Self {
            guide: ctx.pipeline("ours_guide", &[])?,
            fit: ctx.pipeline("ours_prior_fit", &stride)?,
            combine: ctx.pipeline("ours_prior", &stride)?,
        })
    }
}

impl Ours {
    /// Adds the prior over `estimate` (rgb, a variance; the frame's size) guided by `guide`
    /// (the composited albedo); returns the combined estimate with its variance, and every
    /// pixel's prediction (rgb, a 1 where there is a fit) for the à-trous to carry by.
    pub(super) fn add_prior<'f>(
        &'f self,
        pipelines: &'f PriorPipelines,
        ctx: &GpuContext,
        graph: &mut RenderGraph,
        frame: &mut Frame<'f>,
        estimate: ImageHandle,
        guide: ImageHandle,
    ) -> Result<(ImageHandle, ImageHandle)> {
        let n = &self.name;
        let desc = graph.image_desc(estimate);
        let [width, height, _] = desc.extent;
        let size = Extent { width, height };
        let footprint = graph.image(ctx, &format!("{n}.footprint"), desc)?;
        let cells = Extent {
            width: size.width.div_ceil(PRIOR_STRIDE),
            height: size.height.div_ceil(PRIOR_STRIDE),
        };
        let cell_desc = ImageDesc::d2(cells.width, cells.height, desc.format);
        let mut fits = Vec::with_capacity(FITS.len());
        for name in FITS {
            fits.push((name, graph.image(ctx, &format!("{n}.{name}"), cell_desc)?));
        }
        let combined = graph.image(ctx, &format!("{n}.prior"), desc)?;
        let pred = graph.image(ctx, &format!("{n}.prior_pred"), desc)?;
        let push = OursGuidePush {
            width: size.width,
            height: size.height,
            pad0: 0,
            pad1: 0,
        };
        frame.add_compute(format!("{n}.guide"), &pipelines.guide, push, size, |b| {
            b.read("guide", guide).write("footprint", footprint);
        });
        let push = OursPriorFitPush {
            width: size.width,
            height: size.height,
            cells_x: cells.width,
            cells_y: cells.height,
        };
        frame.add_compute(format!("{n}.prior_fit"), &pipelines.fit, push, cells, |b| {
            b.read("estimate", estimate).read("footprint", footprint);
            for &(name, fit) in &fits {
                b.write(name, fit);
            }
        });
        let push = OursPriorPush {
            width: size.width,
            height: size.height,
            keep: self.params.keep,
            pad: 0.0,
        };
        frame.add_compute(format!("{n}.prior"), &pipelines.combine, push, size, |b| {
            b.read("estimate", estimate).read("footprint", footprint);
            for &(name, fit) in &fits {
                b.sampled(name, fit);
            }
            b.write("combined", combined).write("prediction", pred);
        });
        Ok((combined, pred))
    }
}
