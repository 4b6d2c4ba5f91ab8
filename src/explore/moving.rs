//! Fewer pixels while the view moves: when a still frame costs more GPU time than
//! `--moving-ms`, a camera, light or TF change is rendered at 1/k of the view's size per
//! side, k the smallest divisor whose k² fewer pixels fit the target (a frame's cost is
//! mostly per pixel: path trace, features march, denoisers), at most [`MAX_DIVISOR`]. The
//! present pass upsamples the smaller frame into the view. The divisor is chosen when a
//! motion starts and held until the view has been still for [`SETTLE_FRAMES`] frames with
//! no drag held, so the denoisers' histories restart twice per motion (at its start and
//! its end), not every frame.

/// The most pixels per side one rendered pixel stands for while moving.
pub const MAX_DIVISOR: u32 = 8;

/// Still frames (no change, no drag held) before the full size returns: one frame of
/// slack so a drag's gaps between pointer events do not flip the size.
pub const SETTLE_FRAMES: u32 = 2;

/// The smallest side a reduced frame may have (the explorer's smallest view).
pub const MIN_SIDE: u32 = 16;

/// The moving-view state (see the module docs).
#[derive(Clone, Debug)]
pub struct MovingScale {
    /// GPU time to aim for while moving, ms; 0 renders every frame at full size.
    target_ms: f32,
    /// GPU span of the newest finished full-size frame, ms.
    still_ms: Option<f64>,
    /// The divisor in use (1 = full size).
    divisor: u32,
    /// Frames since the view last changed.
    quiet: u32,
}

impl MovingScale {
    pub fn new(target_ms: f32) -> Self {
        Self {
            target_ms,
            still_ms: None,
            divisor: 1,
            quiet: SETTLE_FRAMES,
        }
    }

    /// The divisor for this frame: `changed` when the camera, lights or TF differ from
    /// the last frame's, `held` while a drag is under way.
    pub fn next(&mut self, changed: bool, held: bool) -> u32 {
        if changed || held {
            self.quiet = 0;
            if self.divisor == 1 {
                self.divisor = self.choose();
            }
        } else {
            self.quiet = self.quiet.saturating_add(1);
            if self.quiet >= SETTLE_FRAMES {
                self.divisor = 1;
            }
        }
        self.divisor
    }

    /// A finished frame rendered with `divisor`, whose passes spanned `gpu_ms`.
    pub fn finished(&mut self, divisor: u32, gpu_ms: f64) {
        if divisor == 1 && gpu_ms > 0.0 {
            self.still_ms = Some(gpu_ms);
        }
    }

    /// The smallest k with still_ms / k² ≤ target, within [1, MAX_DIVISOR]; 1 when off or
    /// before any full-size frame has been timed.
    fn choose(&self) -> u32 {
        match self.still_ms {
            Some(ms) if self.target_ms > 0.0 && ms > f64::from(self.target_ms) => {
                let k = (ms / f64::from(self.target_ms)).sqrt().ceil() as u32;
                k.clamp(1, MAX_DIVISOR)
            }
            _ => 1,
        }
    }
}

/// The rendered size for a view of `view` pixels at `divisor`.
pub fn reduced(view: (u32, u32), divisor: u32) -> (u32, u32) {
    if divisor <= 1 {
        return view;
    }
    let side = |v: u32| (v / divisor).max(MIN_SIDE.min(v));
    (side(view.0), side(view.1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cheap_frame_never_shrinks() {
        let mut m = MovingScale::new(100.0);
        m.finished(1, 40.0);
        assert_eq!(m.next(true, false), 1);
        assert_eq!(m.next(false, true), 1);
    }

    #[test]
    fn off_or_untimed_renders_full_size() {
        let mut off = MovingScale::new(0.0);
        off.finished(1, 5000.0);
        assert_eq!(off.next(true, false), 1);
        let mut untimed = MovingScale::new(100.0);
        assert_eq!(untimed.next(true, false), 1);
    }

    #[test]
    fn the_divisor_fits_the_target_and_holds_until_the_view_settles() {
        let mut m = MovingScale::new(100.0);
        m.finished(1, 1000.0); // 10× over: k = ceil(sqrt(10)) = 4
        assert_eq!(m.next(true, false), 4);
        // Reduced frames finishing do not change the still frame's time.
        m.finished(4, 70.0);
        assert_eq!(m.next(false, true), 4, "a held drag keeps it");
        assert_eq!(m.next(false, false), 4, "one still frame is slack");
        assert_eq!(m.next(true, false), 4, "a change restarts the count");
        assert_eq!(m.next(false, false), 4);
        assert_eq!(
            m.next(false, false),
            1,
            "settled after {SETTLE_FRAMES} still frames"
        );
        // Far over the target: at most MAX_DIVISOR.
        m.finished(1, 1e6);
        assert_eq!(m.next(true, false), MAX_DIVISOR);
    }

    #[test]
    fn reduced_sizes_keep_a_smallest_side() {
        assert_eq!(reduced((512, 256), 1), (512, 256));
        assert_eq!(reduced((512, 256), 4), (128, 64));
        assert_eq!(reduced((256, 64), 8), (32, 16));
        assert_eq!(reduced((40, 12), 8), (16, 12));
    }
}
