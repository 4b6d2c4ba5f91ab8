//! `<name>.feedback` (ours_feedback.comp): where the filter restarted this frame (an
//! effective history under `FEEDBACK_HISTORY` frames), the first à-trous level's estimate
//! replaces the state's mean (not its variance), so the next frame's update starts from a
//! denoised value.

use super::Ours;
use crate::gpu_block;
use crate::graph::{Extent, Frame, ImageHandle};

gpu_block! {
    /// `OursFeedbackPush` in ours_feedback.comp.
    pub struct OursFeedbackPush {
        pub width: u32,
        pub height: u32,
        pub pad0: u32,
        pub pad1: u32,
    }
}

/// The filter's state this frame: what the update wrote.
#[derive(Clone, Copy, Debug)]
pub(super) struct State {
    /// rgb the estimate, a its variance P.
    pub model: ImageHandle,
    /// R, and D, the part of P that process noise put there.
    pub noise: ImageHandle,
    /// Every state restarted: there was no history to predict from (the first frame,
    /// after a reset or a resize).
    pub fresh: bool,
}

impl Ours {
    /// Feeds `filtered` (an à-trous level's output: rgb, a variance) back into `state`
    /// where it restarted this frame.
    pub(super) fn add_feedback<'f>(
        &'f self,
        frame: &mut Frame<'f>,
        size: Extent,
        filtered: ImageHandle,
        state: State,
    ) {
        let push = OursFeedbackPush {
            width: size.width,
            height: size.height,
            pad0: 0,
            pad1: 0,
        };
        let name = format!("{}.feedback", self.name);
        frame.add_compute(name, &self.feedback, push, size, |b| {
            b.read("filtered", filtered)
                .read("noise", state.noise)
                .read_write("model", state.model);
        });
    }
}
