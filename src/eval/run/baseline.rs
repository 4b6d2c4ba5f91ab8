//! The speed-vs-accuracy baseline: plain accumulation of n spp (n = 1, 2, 4, …) on a
//! few frames of a scene, scored against the reference. Its GPU time is the measured
//! path-trace time per sample of the evaluated frames times n, so it sits on the same
//! axis as the denoisers (which pay path tracing at `--spp` plus their own passes).

use super::overlap::Overlap;
use super::timing::Timing;
use crate::eval::references::ReferenceCache;
use crate::eval::results::BaselinePoint;
use crate::progress::Progress;
use crate::setup::Setup;
use anyhow::Result;
use dvr_engine::image_io::to_rgb;
use dvr_engine::metrics::{score, FrameReference};
use dvr_engine::session::{Edit, Session};
use std::sync::Arc;

/// Largest sample count of the baseline curve.
pub const MAX_SPP: u32 = 256;

/// Seed offset of the baseline's sample stream, so it is independent of the
/// references' (which would otherwise share its first n samples and flatter it).
const SEED_OFFSET: u32 = 0x5eed_0b11;

/// Sample counts of the curve: powers of two up to min([`MAX_SPP`], ref_spp / 2), so
/// the baseline always has at most half the reference's samples.
pub fn levels(ref_spp: u32) -> Vec<u32> {
    let top = MAX_SPP.min(ref_spp / 2);
    std::iter::successors(Some(1u32), |n| n.checked_mul(2))
        .take_while(|&n| n <= top)
        .collect()
}

/// Frames the baseline is measured on: the first and the middle one (the cost stays
/// bounded whatever the animation length).
pub fn frames(frames: u32) -> Vec<u32> {
    let mut f = vec![0, frames / 2];
    f.dedup();
    f
}

/// Work units of the baseline of one scene (see [`Progress`]).
pub fn units(frame_count: u32, ref_spp: u32) -> f64 {
    let per_frame: u32 = levels(ref_spp).iter().sum();
    (frames(frame_count).len() as u32 * per_frame) as f64
}

/// Measures the curve with `renderer` (after the evaluated frames: it changes the
/// renderer's seed).
#[allow(clippy::too_many_arguments)]
pub fn measure(
    session: &mut Session,
    setup: &Setup,
    references: &ReferenceCache,
    path_trace_ms_per_spp: f64,
    ref_spp: u32,
    progress: &mut Progress,
    label: &str,
    timing: &Arc<Timing>,
) -> Result<Vec<BaselinePoint>> {
    let mut settings = *session.settings();
    settings.set_seed(settings.seed().wrapping_add(SEED_OFFSET));
    session.edit(Edit::Settings(settings))?;
    // Each level is scored on the pool while the GPU renders the next.
    let mut jobs = Overlap::new(timing);
    let (w, h) = (setup.width(), setup.height());
    for f in frames(setup.frames) {
        let hdr = references.load(f)?;
        let reference = Arc::new(timing.metrics.time(|| FrameReference::new(&hdr)));
        for n in levels(ref_spp) {
            let batch = session.renderer()?.samples_per_dispatch();
            let pixels = session.reference_at(f, n, batch)?;
            let (reference, job_timing) = (Arc::clone(&reference), Arc::clone(timing));
            jobs.spawn(move || {
                let s = job_timing
                    .metrics
                    .time(|| score(&reference, &to_rgb(w, h, &pixels), None));
                Ok(BaselinePoint {
                    frame: f,
                    spp: n,
                    gpu_ms: path_trace_ms_per_spp * f64::from(n),
                    psnr: s.psnr,
                })
            })?;
            progress.advance(
                f64::from(n),
                &format!("{label} | baseline frame {f}, {n} spp"),
            );
        }
    }
    jobs.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_stop_at_half_the_reference_and_256() {
        assert_eq!(levels(16), vec![1, 2, 4, 8]);
        assert_eq!(levels(17), vec![1, 2, 4, 8]);
        assert_eq!(levels(1), Vec::<u32>::new());
        assert_eq!(levels(4096).last(), Some(&256));
        assert_eq!(levels(4096).len(), 9);
    }

    #[test]
    fn first_and_middle_frame() {
        assert_eq!(frames(16), vec![0, 8]);
        assert_eq!(frames(3), vec![0, 1]);
        assert_eq!(frames(1), vec![0]);
        assert_eq!(units(16, 16), 2.0 * 15.0);
    }
}
