//! Frames to recover after a sudden change (light jump, transfer-function jump, ...).

/// Number of frames before the event whose mean PSNR is the baseline to recover to.
/// Five frames average out per-frame noise in the PSNR while staying close enough to
/// the event that a slow drift of the animation does not move the target.
pub const RECOVERY_BASELINE_FRAMES: usize = 5;

/// How many frames after a sudden change at `event_frame` a method needs until its
/// PSNR is back within `tolerance_db` of what it was before, and stays there.
///
/// * Baseline: the mean PSNR over the [`RECOVERY_BASELINE_FRAMES`] frames just before
///   `event_frame` (fewer if the series starts later than that).
/// * Recovered at frame `i >= event_frame` when `psnr[i] >= baseline - tolerance_db`
///   (doing *better* than before counts as recovered) and every later frame also is.
/// * Returns `Some(i - event_frame)` for the first such `i`: `Some(0)` means the
///   change did not hurt at all, `Some(k)` that frames `event_frame .. event_frame+k`
///   were degraded.
/// * `None` when it never recovers within the series (in particular when the last frame
///   is still degraded), when `event_frame` is 0 (no baseline) or is past the end.
///
/// Values are capped at [`PSNR_CAP`](super::PSNR_CAP) first, so infinite PSNRs of
/// identical frames keep the arithmetic finite. A NaN after the event counts as
/// degraded; a NaN in the baseline window makes the baseline undefined (`None`).
pub fn frames_to_recover(
    psnr_series: &[f64],
    event_frame: usize,
    tolerance_db: f64,
) -> Option<usize> {
    if event_frame == 0 || event_frame >= psnr_series.len() {
        return None;
    }
    // `f64::min` would turn NaN into the cap, so keep NaN explicitly.
    let cap = |v: f64| {
        if v.is_nan() {
            v
        } else {
            v.min(super::PSNR_CAP)
        }
    };
    let start = event_frame.saturating_sub(RECOVERY_BASELINE_FRAMES);
    let before = &psnr_series[start..event_frame];
    let baseline = before.iter().map(|&v| cap(v)).sum::<f64>() / before.len() as f64;
    if baseline.is_nan() {
        return None;
    }
    let threshold = baseline - tolerance_db;
    // NaN >= x is false, so NaN frames count as degraded.
    let ok = |v: f64| cap(v) >= threshold;
    // Walk back from the end: the recovery frame is one past the last degraded frame.
    let after = &psnr_series[event_frame..];
    match after.iter().rposition(|&v| !ok(v)) {
        None => Some(0),
        Some(last_bad) if last_bad + 1 < after.len() => Some(last_bad + 1),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dip_then_recovery() {
        // 10 frames at 30 dB, a jump at frame 10 dropping to 20 dB and climbing
        // 2 dB per frame: 20, 22, 24, 26, 28, 30, ...
        let mut s = vec![30.0; 10];
        s.extend((0..10).map(|i| (20.0 + 2.0 * i as f64).min(30.0)));
        // Within 1 dB: 30 - 1 = 29 is first met at 30 dB, 5 frames after the event.
        assert_eq!(frames_to_recover(&s, 10, 1.0), Some(5));
        // Within 3 dB: 28 dB is reached 4 frames after.
        assert_eq!(frames_to_recover(&s, 10, 3.0), Some(4));
        // A loose tolerance that the dip never violates.
        assert_eq!(frames_to_recover(&s, 10, 10.0), Some(0));
    }

    #[test]
    fn must_stay_recovered() {
        // Recovers at frame 6, relapses at 8, recovers for good at 10.
        let s = [
            30.0, 30.0, 30.0, 30.0, 30.0, 20.0, 30.0, 30.0, 20.0, 25.0, 30.0, 30.0,
        ];
        assert_eq!(frames_to_recover(&s, 5, 0.5), Some(5));
    }

    #[test]
    fn never_recovering_is_none() {
        let mut s = vec![30.0; 6];
        s.extend([20.0, 21.0, 22.0, 22.5, 23.0]);
        assert_eq!(frames_to_recover(&s, 6, 1.0), None);
        // No baseline / event outside the series.
        assert_eq!(frames_to_recover(&s, 0, 1.0), None);
        assert_eq!(frames_to_recover(&s, 11, 1.0), None);
        // NaN at the end is degraded.
        let s = [30.0, 30.0, 30.0, 30.0, f64::NAN];
        assert_eq!(frames_to_recover(&s, 3, 1.0), None);
        let s = [30.0, f64::NAN, 30.0, 30.0, 30.0];
        assert_eq!(frames_to_recover(&s, 3, 1.0), None);
    }

    #[test]
    fn baseline_uses_last_five_frames_and_caps_infinity() {
        // Early frames at 50 dB must not raise the target; only the last 5 (30 dB) count.
        let mut s = vec![50.0; 5];
        s.extend([30.0; 5]);
        s.extend([25.0, 29.5, 30.0]);
        assert_eq!(frames_to_recover(&s, 10, 1.0), Some(1));
        // Infinite (identical) frames are capped at PSNR_CAP.
        let s = [f64::INFINITY, f64::INFINITY, 40.0, 99.5, f64::INFINITY];
        assert_eq!(frames_to_recover(&s, 2, 1.0), Some(1));
    }
}
