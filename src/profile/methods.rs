//! Each profiled denoiser's cost: its own passes, the passes it needs that other methods
//! may need too (the surface features, the guide images), and the frame it would make
//! alone, with its dispatches and the bytes it moves per pixel.

use crate::profile::Profile;
use dvr_engine::gpu::timestamps::{gb_per_s, PassOwner, PassTiming};

/// GPU time of `method` in one frame: the passes every method shares (path trace,
/// motion) plus those it needs (the surface features and guide images, when it reads
/// them, however many other methods read them too) and its own; uploads and readbacks
/// are no method's cost. The graph records whom each pass works for.
pub fn method_gpu_ms(timings: &[PassTiming], method: &str) -> f64 {
    timings
        .iter()
        .filter(|t| t.owner.counts_for(method))
        .map(|t| t.ms)
        .sum()
}

/// One denoiser at one size (per-frame means after the warm-up).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MethodRow {
    pub method: String,
    /// GPU ms of the method's own passes.
    pub own_ms: f64,
    /// GPU ms of the passes it needs, however many other methods need them too (surface
    /// features, guide images): a method alone pays for them.
    pub needed_ms: f64,
    /// `own_ms + needed_ms`: what the method adds to the path-traced frame.
    pub cost_ms: f64,
    /// Compute dispatches of those passes per frame (a pass that runs only when the
    /// scene changed counts by the share of frames it ran in).
    pub dispatches: f64,
    /// Declared bytes of those passes per frame.
    pub bytes: f64,
    /// `bytes` per pixel of the frame.
    pub bytes_per_pixel: f64,
    /// Their bandwidth's share of the device's peak, when it was measured.
    pub percent_of_peak: Option<f64>,
    /// The shared passes (path trace, motion) plus `cost_ms`, as `dvr eval` counts a
    /// method's GPU time.
    pub frame_ms: f64,
}

/// The profile's mean frame: each pass's mean time and bytes per frame it ran in, scaled
/// by the share of the measured frames it ran in (the temporal gradients run only in
/// frames whose lights or transfer function changed), with that share.
fn mean_frame(p: &Profile) -> Vec<(PassTiming, f64)> {
    let frames = p.total.frames.max(1) as f64;
    p.passes
        .iter()
        .map(|r| {
            let share = (r.frames as f64 / frames).min(1.0);
            let t = PassTiming {
                pass: r.pass.clone(),
                owner: r.owner.clone(),
                start_ms: 0.0,
                ms: r.mean_ms * share,
                bytes: (r.bytes * share).round() as u64,
            };
            (t, share)
        })
        .collect()
}

/// GPU ms of the passes every method shares (path trace, motion).
pub fn shared_ms(p: &Profile) -> f64 {
    mean_frame(p)
        .iter()
        .filter(|(t, _)| t.owner == PassOwner::Shared)
        .map(|(t, _)| t.ms)
        .sum::<f64>()
        + 0.0
}

/// Each profiled denoiser's row.
pub fn method_rows(p: &Profile) -> Vec<MethodRow> {
    let mean = mean_frame(p);
    let frame: Vec<PassTiming> = mean.iter().map(|(t, _)| t.clone()).collect();
    let peak = p.peak_bandwidth.as_ref().map(|b| b.gb_per_s);
    let pixels = f64::from(p.run.width) * f64::from(p.run.height);
    p.run
        .denoisers
        .iter()
        .map(|m| {
            let serving: Vec<&(PassTiming, f64)> =
                mean.iter().filter(|(t, _)| t.owner.serves(m)).collect();
            // `+ 0.0`: an empty sum is -0.0, which would print as "-0.0000".
            let sum = |own: bool| {
                serving
                    .iter()
                    .filter(|(t, _)| matches!(t.owner, PassOwner::Method(_)) == own)
                    .map(|(t, _)| t.ms)
                    .sum::<f64>()
                    + 0.0
            };
            let (own_ms, needed_ms) = (sum(true), sum(false));
            let cost_ms = own_ms + needed_ms;
            let bytes = serving.iter().map(|(t, _)| t.bytes as f64).sum::<f64>() + 0.0;
            let rate = gb_per_s(bytes, cost_ms);
            MethodRow {
                method: m.clone(),
                own_ms,
                needed_ms,
                cost_ms,
                dispatches: serving.iter().map(|(_, share)| share).sum::<f64>() + 0.0,
                bytes,
                bytes_per_pixel: if pixels > 0.0 { bytes / pixels } else { 0.0 },
                percent_of_peak: peak
                    .filter(|&b| b > 0.0 && cost_ms > 0.0)
                    .map(|b| 100.0 * rate / b),
                frame_ms: method_gpu_ms(&frame, m),
            }
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::profile::{RunInfo, Stats, Window};
    use dvr_engine::passes::bandwidth::PeakBandwidth;

    fn t(pass: &str, owner: PassOwner, ms: f64, bytes: u64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            owner,
            start_ms: 0.0,
            ms,
            bytes,
        }
    }

    /// ours and svgf on an 8×8 frame: shared path trace and motion (4 ms), features both
    /// need (1 ms, 2 MB), ours' two passes (2 ms, 4 MB) and a gradient pass in every
    /// other frame (1 ms, 0 B), svgf's one (2 ms).
    pub(crate) fn two_method_profile() -> Profile {
        let both = || PassOwner::Methods(vec!["ours".into(), "svgf".into()]);
        let ours = || PassOwner::Method("ours".into());
        let mut stats = Stats::new();
        for i in 0..6 {
            let mut frame = vec![
                t("path_trace", PassOwner::Shared, 3.5, 0),
                t("motion", PassOwner::Shared, 0.5, 0),
                t("surface_features", both(), 1.0, 2_000_000),
                t("ours.update", ours(), 1.0, 3_000_000),
                t("ours.atrous", ours(), 1.0, 1_000_000),
                t("svgf.temporal", PassOwner::Method("svgf".into()), 2.0, 0),
            ];
            if i % 2 == 0 {
                frame.push(t("ours.gradient", ours(), 1.0, 0));
            }
            stats.add_frame(&frame);
        }
        let run = RunInfo {
            device: "d".into(),
            scene: "s".into(),
            width: 8,
            height: 8,
            spp: 2,
            denoisers: vec!["ours".into(), "svgf".into()],
            shared_tiles: true,
            volume: "dense volume".into(),
        };
        let peak = PeakBandwidth {
            gb_per_s: 4.0,
            buffer_bytes: 0,
            method: "m".into(),
        };
        Profile::new(run, &stats, &Window::new(1), Some(peak))
    }

    #[test]
    fn a_method_pays_for_what_it_needs() {
        let p = two_method_profile();
        assert_eq!(shared_ms(&p), 4.0);
        let rows = method_rows(&p);
        let ours = &rows[0];
        assert_eq!(ours.method, "ours");
        // Own: 2 ms every frame + 1 ms in half of them.
        assert_eq!((ours.own_ms, ours.needed_ms, ours.cost_ms), (2.5, 1.0, 3.5));
        assert_eq!(ours.dispatches, 3.5);
        // 6 MB per frame over 64 pixels.
        assert_eq!(ours.bytes_per_pixel, 6e6 / 64.0);
        // 6 MB in 3.5 ms against 4 GB/s.
        let rate = 6e6 / (3.5 * 1e6);
        assert!((ours.percent_of_peak.unwrap() - 100.0 * rate / 4.0).abs() < 1e-9);
        assert_eq!(ours.frame_ms, 7.5);
        let svgf = &rows[1];
        assert_eq!(
            (svgf.own_ms, svgf.needed_ms, svgf.frame_ms),
            (2.0, 1.0, 7.0)
        );
        assert_eq!(svgf.dispatches, 2.0);
    }
}
