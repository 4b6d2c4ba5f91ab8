//! `<name>.atrous0..2` (variance_atrous.comp): the à-trous spatial filter over the
//! filters' estimates, edge-stopped by their variances: steps 1, 2 and 4 (`ATROUS_LEVELS`),
//! ping-ponging between scratch images (never into the input, which is the filter's state
//! where the prior did not run), the last level into the denoiser's output. Where the spatial prior ran, each neighbour is carried to the pixel
//! by the prior's prediction first (`CARRY` in variance_atrous.comp).

use super::Ours;
use crate::denoise::variance_atrous::{add_guided_level_state, add_level, Level};
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
        let guided = match (&self.atrous_guided, prediction) {
            (Some(g), Some(_)) if self.params.guided > 0.0 => Some(g),
            _ => None,
        };
        let feedback_pass = if guided.is_some() && self.params.guided > 1.5 {
            1
        } else {
            0
        };
        let passes = if guided.is_some() { 2 } else { 1 };
        let mut guide_img = None;
        for pass in 0..passes {
            let mut src = estimate;
            let final_pass = pass + 1 == passes;
            let levels = if pass == 1 && self.params.glevels > 0.0 {
                self.params.glevels as u32
            } else {
                levels
            };
            for i in 0..levels {
                let last = i + 1 == levels;
                let dst = if last && final_pass {
                    out
                } else if last {
                    graph.image(ctx, &format!("{n}.guide{pass}"), desc)?
                } else {
                    graph.image(ctx, &format!("{n}.atrous_p{pass}l{i}"), desc)?
                };
                let level = Level {
                    step: 1 << i,
                    kappa: self.params.kappa,
                    keep: self.params.keep,
                    last: last && final_pass,
                    own_variance: pass == 1 && self.params.guided > 2.5,
                    guide_scale: self.params.gscale,
                    select_fresh: pass == 1 && self.params.gselect > 0.0,
                };
                let pipe = if pass == 1 { guided.unwrap() } else { pipeline };
                add_guided_level_state(
                    frame,
                    pipe,
                    format!("{n}.atrous{}", i + pass * super::ATROUS_LEVELS),
                    size,
                    level,
                    src,
                    dst,
                    prediction,
                    if pass == 1 { guide_img } else { None },
                    Some((state.model, state.noise)),
                );
                if i == 0 && !last && self.variant.feedback && pass == feedback_pass {
                    self.add_feedback(frame, size, dst, state);
                }
                src = dst;
            }
            guide_img = Some(src);
        }
        let _ = (ping, add_level);
        Ok(out)
    }
}
