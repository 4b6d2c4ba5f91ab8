//! `<name>.lag` (ours_lag.comp): the pooled lag test. The update's a-posteriori residuals
//! averaged over a 5×5 neighbourhood, with the variance of the mean; next frame's update
//! takes a significant mean as a shift of the state.

use super::Ours;
use crate::gpu_block;
use crate::graph::{Extent, Frame, History};

gpu_block! {
    /// `OursLagPush` in ours_lag.comp.
    pub struct OursLagPush {
        pub width: u32,
        pub height: u32,
        pub pad0: u32,
        pub pad1: u32,
    }
}

/// What the update writes for the lag test, and the pooled residual next frame reads.
#[derive(Clone, Copy, Debug)]
pub(super) struct LagImages {
    /// Each pixel's running a-posteriori residual (rgb) and its variance (a, < 0 where
    /// none).
    pub residual: History,
    /// The pooled residual: rgb mean, a its variance.
    pub pooled: History,
}

impl Ours {
    /// The pooled lag test (every variant runs it: the jump test reads it too; `ours-no-lag`
    /// only takes no shift from it).
    pub(super) fn add_lag<'f>(&'f self, frame: &mut Frame<'f>, size: Extent, lag: &LagImages) {
        let pipeline = &self.lag;
        let push = OursLagPush {
            width: size.width,
            height: size.height,
            pad0: 0,
            pad1: 0,
        };
        frame.add_compute(format!("{}.lag", self.name), pipeline, push, size, |b| {
            b.read("residual", lag.residual.cur)
                .write("lag", lag.pooled.cur);
        });
    }
}
