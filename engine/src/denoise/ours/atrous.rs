//! `<name>.atrous0..2` (variance_atrous.comp): the à-trous spatial filter over the
//! filters' estimates, edge-stopped by their variances: steps 1, 2 and 4 (`ATROUS_LEVELS`),
//! ping-ponging between scratch images (never into the input, which is the filter's state
//! where the prior did not run), the last level into the denoiser's output. Where the spatial prior ran, each neighbour is carried to the pixel
//! by the prior's prediction first (`CARRY` in variance_atrous.comp).

use super::Ours;
use crate::denoise::variance_atrous::{add_level, Level};
use crate::denoise::DenoiseFrame;
use crate::error::Result;
use crate::graph::ImageHandle;

impl Ours {
    pub(super) fn add_atrous<'f>(
        &'f self,
        f: &mut DenoiseFrame<'_, 'f>,
        estimate: ImageHandle,
        prediction: Option<ImageHandle>,
        state: super::feedback::State,
    ) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
        let size = input.size;
        // The carrying variant where there is a prediction to carry by.
        let pipeline = match (prediction, &self.atrous_carry, &self.atrous) {
            (Some(_), Some(carry), _) => carry,
            (_, _, Some(plain)) => plain,
            _ => return Ok(estimate),
        };
        let n = &self.name;
        let desc = graph.image_desc(estimate);
        let out = graph.image(ctx, &format!("{n}.out"), desc)?;
        // Scratch images of their own: without the prior the input is the filter's state
        // (a history), and no level may write into it.
        let ping = graph.image(ctx, &format!("{n}.atrous"), desc)?;
        let levels = super::ATROUS_LEVELS;
        let mut src = estimate;
        for i in 0..levels {
            let last = i + 1 == levels;
            let dst = match (last, src == ping) {
                (true, _) => out,
                (false, true) => graph.image(ctx, &format!("{n}.atrous_b"), desc)?,
                (false, false) => ping,
            };
            let level = Level {
                step: 1 << i,
                kappa: self.params.kappa,
                keep: self.params.keep,
                last,
            };
            add_level(
                frame,
                pipeline,
                format!("{n}.atrous{i}"),
                size,
                level,
                src,
                dst,
                prediction,
            );
            if i == 0 && !last && self.variant.feedback {
                self.add_feedback(frame, size, dst, state);
            }
            src = dst;
        }
        Ok(out)
    }
}
