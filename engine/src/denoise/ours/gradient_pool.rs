//! `<name>.gradient_pool` (ours_gradient_pool.comp): ours' temporal gradients pooled over
//! 3×3, 5×5 and 9×9 strata and shrunk level by level (each towards the wider one's,
//! the widest towards no change), once per stratum, into the log luminance ratio and the
//! colour of the change that the update reads (one texel per pixel).

use super::gradient::Gradients;
use super::Ours;
use crate::gpu_block;
use crate::graph::Frame;

gpu_block! {
    /// `OursGradientPoolPush` in ours_gradient_pool.comp.
    pub struct OursGradientPoolPush {
        pub width: u32,
        pub height: u32,
        pub shrink: f32,
        pub pad0: u32,
    }
}

impl Ours {
    /// Pools this frame's temporal gradients (called once they are measured).
    pub(super) fn add_gradient_pool<'f>(&'f self, frame: &mut Frame<'f>, g: &Gradients) {
        let Some(pipeline) = &self.gradient_pool else {
            return;
        };
        let push = OursGradientPoolPush {
            width: g.strata[0],
            height: g.strata[1],
            shrink: self.params.shrink,
            pad0: 0,
        };
        let grid = [g.strata[0], g.strata[1], 1];
        frame.add_compute(
            format!("{}.gradient_pool", self.name),
            pipeline,
            push,
            grid,
            |b| {
                b.read("gradient_new", g.new)
                    .read("gradient_old", g.old)
                    .write("gradient_ratio", g.ratio);
            },
        );
    }
}
