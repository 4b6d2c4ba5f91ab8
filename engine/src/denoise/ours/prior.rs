//! `<name>.guide`, `<name>.prior_sums`, `<name>.prior_fit`, `<name>.prior` (ours_guide.comp,
//! ours_prior_sums.comp, ours_prior_fit.comp, ours_prior.comp): the spatial prior. Where an
//! estimate is young, a local linear model of its neighbours' estimates on the guides (the
//! albedo, the gradient normal) predicts it, and
//! the two are combined by their variances before the à-trous filter, which then carries
//! each neighbour by the model's prediction (`CARRY` in variance_atrous.comp).

use super::Ours;
use crate::denoise::DenoiseFrame;
use crate::error::Result;
use crate::gpu::{GpuContext, ImageDesc, Pipeline, SpecValue};
use crate::gpu_block;
use crate::graph::{Extent, ImageHandle};
use ash::vk;

/// Pixels between two fits' centres: the grid's size here, and the shaders' specialisation
/// constant `PRIOR_STRIDE` (include/ours_prior.glsl).
pub const PRIOR_STRIDE: u32 = 4;

/// The fits' images, as both shaders name them: per colour channel the coefficients of
/// the first four features (1, the albedo's r, g, b), and of the normal's three with the
/// residuals' mean square V.
const FITS: [&str; 6] = [
    "fit_r_lo", "fit_r_hi", "fit_g_lo", "fit_g_hi", "fit_b_lo", "fit_b_hi",
];

/// The prior's include, whose `PRIOR_FEATURES` is the one home of the feature count.
const PRIOR_GLSL: &str = include_str!("../../../../shaders/glsl/include/ours_prior.glsl");

/// The fit's features (`PRIOR_FEATURES` in include/ours_prior.glsl, read from its text):
/// 1, the albedo's r, g, b, the normal's x, y, z.
const PRIOR_FEATURES: u32 = glsl_int(PRIOR_GLSL, "const int PRIOR_FEATURES = ");

/// The decimal integer that follows `prefix` in `src` (a GLSL declaration), at compile
/// time: a missing declaration fails the build.
const fn glsl_int(src: &str, prefix: &str) -> u32 {
    let (s, p) = (src.as_bytes(), prefix.as_bytes());
    let mut i = 0;
    while i + p.len() <= s.len() {
        let mut k = 0;
        while k < p.len() && s[i + k] == p[k] {
            k += 1;
        }
        if k == p.len() {
            let (mut j, mut v) = (i + k, 0u32);
            while j < s.len() && s[j].is_ascii_digit() {
                v = v * 10 + (s[j] - b'0') as u32;
                j += 1;
            }
            assert!(j > i + k, "no integer after the prefix");
            return v;
        }
        i += 1;
    }
    panic!("the prefix is not in the source")
}

/// Texels (rgba32f) of one block's sums, `PRIOR_SUM_TEXELS` in include/ours_prior.glsl:
/// the lower triangle of Σ f fᵀ, Σ f x per channel and Σ x² per channel, four to a texel.
const SUM_TEXELS: u32 =
    (PRIOR_FEATURES * (PRIOR_FEATURES + 1) / 2 + 3 * PRIOR_FEATURES + 3).div_ceil(4);

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
        /// 1: young estimates are combined with the prediction (0 in `ours-no-prior`,
        /// which keeps the prediction for the à-trous to carry by).
        pub combine: u32,
    }
}

/// What the prior's fit is guided by: the albedo composited along each ray (rgb, a
/// opacity) and the surface's gradient normal (xyz; zero where the ray finds none).
#[derive(Clone, Copy, Debug)]
pub(super) struct PriorGuides {
    pub albedo: ImageHandle,
    pub normal: ImageHandle,
}

/// The prior's pipelines.
pub(super) struct PriorPipelines {
    pub guide: Pipeline<OursGuidePush>,
    pub sums: Pipeline<OursPriorFitPush>,
    pub fit: Pipeline<OursPriorFitPush>,
    pub combine: Pipeline<OursPriorPush>,
}

impl PriorPipelines {
    pub fn new(ctx: &GpuContext) -> Result<Self> {
        let stride = [("PRIOR_STRIDE", SpecValue::I32(PRIOR_STRIDE as i32))];
        Ok(Self {
            guide: ctx.pipeline("ours_guide", &[])?,
            sums: ctx.pipeline("ours_prior_sums", &stride)?,
            fit: ctx.pipeline("ours_prior_fit", &[])?,
            combine: ctx.pipeline("ours_prior", &stride)?,
        })
    }
}

impl Ours {
    /// Adds the prior over `estimate` (rgb, a variance; the frame's size) guided by
    /// `guides`; returns the combined estimate with its variance, and every
    /// pixel's prediction (rgb, a 1 where there is a fit) for the à-trous to carry by.
    pub(super) fn add_prior<'f>(
        &'f self,
        f: &mut DenoiseFrame<'_, 'f>,
        estimate: ImageHandle,
        guides: PriorGuides,
    ) -> Result<(ImageHandle, ImageHandle)> {
        let (ctx, graph, frame, _) = f.parts();
        let PriorGuides { albedo, normal } = guides;
        let n = &self.name;
        let desc = graph.image_desc(estimate);
        let [width, height, _] = desc.extent;
        let size = Extent { width, height };
        // The guides in half precision: plenty for a fit's features, half the bandwidth.
        let half = ImageDesc::d2(width, height, vk::Format::R16G16B16A16_SFLOAT);
        let footprint = graph.image(ctx, &format!("{n}.footprint"), half)?;
        let footprint_normal = graph.image(ctx, &format!("{n}.footprint_normal"), half)?;
        let cells = Extent {
            width: size.width.div_ceil(PRIOR_STRIDE),
            height: size.height.div_ceil(PRIOR_STRIDE),
        };
        let cell_desc = ImageDesc::d2(cells.width, cells.height, desc.format);
        let sum_desc = ImageDesc::d2(cells.width * SUM_TEXELS, cells.height, desc.format);
        let sums = graph.image(ctx, &format!("{n}.prior_sums"), sum_desc)?;
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
        frame.add_compute(format!("{n}.guide"), &self.prior.guide, push, size, |b| {
            b.read("guide", albedo).read("normal", normal);
            b.write("footprint", footprint)
                .write("footprint_normal", footprint_normal);
        });
        let push = OursPriorFitPush {
            width: size.width,
            height: size.height,
            cells_x: cells.width,
            cells_y: cells.height,
        };
        frame.add_compute(
            format!("{n}.prior_sums"),
            &self.prior.sums,
            push,
            cells,
            |b| {
                b.read("estimate", estimate).read("footprint", footprint);
                b.read("footprint_normal", footprint_normal)
                    .write("sums", sums);
            },
        );
        frame.add_compute(
            format!("{n}.prior_fit"),
            &self.prior.fit,
            push,
            cells,
            |b| {
                b.read("sums", sums);
                for &(name, fit) in &fits {
                    b.write(name, fit);
                }
            },
        );
        let push = OursPriorPush {
            width: size.width,
            height: size.height,
            keep: self.params.keep,
            combine: self.variant.prior as u32,
        };
        frame.add_compute(format!("{n}.prior"), &self.prior.combine, push, size, |b| {
            b.read("estimate", estimate).read("footprint", footprint);
            b.read("footprint_normal", footprint_normal);
            for &(name, fit) in &fits {
                b.sampled(name, fit);
            }
            b.write("combined", combined).write("prediction", pred);
        });
        Ok((combined, pred))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shader_constants_match() {
        let glsl = PRIOR_GLSL;
        assert_eq!(
            PRIOR_FEATURES, 7,
            "1, the albedo's r, g, b, the normal's x, y, z"
        );
        assert!(glsl.contains("const int PRIOR_SUM_TEXELS = (SUM_XX + 3 + 3) / 4;"));
        assert!(glsl.contains("const int SUM_B = PRIOR_FEATURES * (PRIOR_FEATURES + 1) / 2;"));
        assert!(glsl.contains("const int SUM_XX = SUM_B + 3 * PRIOR_FEATURES;"));
        assert_eq!(SUM_TEXELS, 13);
    }
}
