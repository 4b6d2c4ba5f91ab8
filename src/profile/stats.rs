//! Streaming per-pass statistics: a profile of any length keeps a fixed amount of state
//! per pass (count, sums, extremes and a log-spaced histogram for the median and p95)
//! instead of every frame's timings, so a 10,000-frame or overnight run stays flat in
//! memory.

use dvr_engine::gpu::timestamps::{gb_per_s, PassTiming};
use serde::Serialize;
use std::collections::{BTreeMap, HashMap};

/// Frames left out of the statistics: the first dispatch of each pipeline includes
/// driver compilation (150–200 ms on lavapipe) and one-off uploads.
pub const WARMUP_FRAMES: usize = 2;

/// Width of a histogram bin as a ratio: a median or p95 read from the histogram is the
/// centre of its bin, within ±0.25% of the exact value.
const BIN_RATIO: f64 = 1.005;
/// Smallest time the histogram resolves (1 ns); shorter ones land in its lowest bin.
const MIN_MS: f64 = 1e-6;

/// What the reports show of one pass (or of the whole frame, `total`).
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PassStats {
    pub pass: String,
    pub frames: usize,
    pub mean_ms: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
    /// Mean bytes per frame the pass's declared accesses touch (a lower bound on its
    /// memory traffic for passes that touch all they declare).
    pub bytes: f64,
    /// Declared bytes over GPU time.
    pub gb_per_s: f64,
    /// `gb_per_s` as a share of the device's peak bandwidth, when it was measured.
    pub percent_of_peak: Option<f64>,
}

/// Times in a log-spaced histogram (bounded by the range of times, not their number).
#[derive(Clone, Debug, Default)]
struct Series {
    count: usize,
    sum_ms: f64,
    sum_bytes: f64,
    min_ms: f64,
    max_ms: f64,
    bins: BTreeMap<i32, u64>,
}

fn bin_of(ms: f64) -> i32 {
    ((ms.max(MIN_MS) / MIN_MS).ln() / BIN_RATIO.ln()).floor() as i32
}

fn bin_centre(bin: i32) -> f64 {
    MIN_MS * BIN_RATIO.powf(f64::from(bin) + 0.5)
}

impl Series {
    fn add(&mut self, ms: f64, bytes: u64) {
        if self.count == 0 {
            self.min_ms = ms;
            self.max_ms = ms;
        }
        self.count += 1;
        self.sum_ms += ms;
        self.sum_bytes += bytes as f64;
        self.min_ms = self.min_ms.min(ms);
        self.max_ms = self.max_ms.max(ms);
        *self.bins.entry(bin_of(ms)).or_default() += 1;
    }

    /// The value of rank round(q (n − 1)) in sorted order: exact at the extremes, else
    /// the centre of its bin (clamped to the observed range).
    fn percentile(&self, q: f64) -> f64 {
        if self.count == 0 {
            return 0.0;
        }
        let rank = (q * (self.count - 1) as f64).round() as u64;
        if rank == 0 {
            return self.min_ms;
        }
        if rank as usize >= self.count - 1 {
            return self.max_ms;
        }
        let mut seen = 0;
        for (&bin, &n) in &self.bins {
            seen += n;
            if seen > rank {
                return bin_centre(bin).clamp(self.min_ms, self.max_ms);
            }
        }
        self.max_ms
    }

    fn stats(&self, pass: &str, peak_gb_per_s: Option<f64>) -> PassStats {
        let n = self.count.max(1) as f64;
        let rate = gb_per_s(self.sum_bytes, self.sum_ms);
        PassStats {
            pass: pass.to_string(),
            frames: self.count,
            mean_ms: self.sum_ms / n,
            median_ms: self.percentile(0.5),
            p95_ms: self.percentile(0.95),
            bytes: self.sum_bytes / n,
            gb_per_s: rate,
            percent_of_peak: peak_gb_per_s.filter(|&p| p > 0.0).map(|p| 100.0 * rate / p),
        }
    }
}

/// Per-pass statistics fed one frame at a time, warm-up frames left out (unless the
/// run has no other frames).
#[derive(Clone, Debug, Default)]
pub struct Stats {
    order: Vec<String>,
    by_pass: HashMap<String, Series>,
    total: Series,
    /// The warm-up frames, kept until a measured frame arrives.
    warmup: Vec<Vec<PassTiming>>,
    frames_seen: usize,
}

impl Stats {
    pub fn new() -> Self {
        Self::default()
    }

    /// Frames fed so far, warm-up included.
    pub fn frames_seen(&self) -> usize {
        self.frames_seen
    }

    pub fn add_frame(&mut self, frame: &[PassTiming]) {
        self.frames_seen += 1;
        if self.frames_seen <= WARMUP_FRAMES {
            self.warmup.push(frame.to_vec());
            return;
        }
        self.warmup.clear();
        self.measure(frame);
    }

    fn measure(&mut self, frame: &[PassTiming]) {
        let (mut ms, mut bytes) = (0.0, 0);
        for t in frame {
            if !self.by_pass.contains_key(&t.pass) {
                self.order.push(t.pass.clone());
            }
            self.by_pass
                .entry(t.pass.clone())
                .or_default()
                .add(t.ms, t.bytes);
            ms += t.ms;
            bytes += t.bytes;
        }
        self.total.add(ms, bytes);
    }

    /// Per pass in first-seen order, and the whole frame; `peak_gb_per_s` (when known)
    /// gives each its share of the peak.
    pub fn summary(&self, peak_gb_per_s: Option<f64>) -> (Vec<PassStats>, PassStats) {
        if self.total.count == 0 && !self.warmup.is_empty() {
            // A run no longer than the warm-up: its frames are all there is.
            let mut all = Stats::new();
            for f in &self.warmup {
                all.measure(f);
            }
            return all.summary(peak_gb_per_s);
        }
        let passes = self
            .order
            .iter()
            .map(|p| self.by_pass[p].stats(p, peak_gb_per_s))
            .collect();
        (passes, self.total.stats("total", peak_gb_per_s))
    }
}

/// Statistics of a whole sequence of frames (warm-up left out).
pub fn aggregate(frames: &[Vec<PassTiming>]) -> (Vec<PassStats>, PassStats) {
    let mut s = Stats::new();
    for f in frames {
        s.add_frame(f);
    }
    s.summary(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(pass: &str, ms: f64, bytes: u64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            start_ms: 0.0,
            ms,
            bytes,
        }
    }

    #[test]
    fn aggregate_skips_warmup_and_orders_passes() {
        let mut frames = vec![vec![t("a", 100.0, 0)]; WARMUP_FRAMES];
        for i in 0..10 {
            frames.push(vec![t("b", 1.0, 1000), t("a", i as f64, 0)]);
        }
        let (passes, total) = aggregate(&frames);
        assert_eq!(passes[0].pass, "b");
        assert_eq!(passes[1].pass, "a");
        assert!((passes[1].mean_ms - 4.5).abs() < 1e-9);
        assert_eq!(passes[1].frames, 10);
        assert!((total.mean_ms - 5.5).abs() < 1e-9);
        assert_eq!(passes[0].bytes, 1000.0);
        // 1000 bytes in 1 ms = 10^6 B/s.
        assert!((passes[0].gb_per_s - 1e-3).abs() < 1e-12);
        assert_eq!(passes[0].percent_of_peak, None);
        let (passes, _) = {
            let mut s = Stats::new();
            frames.iter().for_each(|f| s.add_frame(f));
            s.summary(Some(0.01))
        };
        assert!((passes[0].percent_of_peak.unwrap() - 10.0).abs() < 1e-9);
    }

    #[test]
    fn a_run_within_the_warmup_uses_its_frames() {
        let (passes, total) = aggregate(&[vec![t("a", 3.0, 0)]]);
        assert_eq!(passes[0].frames, 1);
        assert_eq!(total.mean_ms, 3.0);
    }

    #[test]
    fn percentiles_are_within_a_bin_of_the_exact_ones() {
        let mut s = Series::default();
        for v in [1.0, 2.0, 3.0] {
            s.add(v, 0);
        }
        assert!((s.percentile(0.5) - 2.0).abs() < 2.0 * 0.0025);
        assert_eq!(s.percentile(0.0), 1.0);
        assert_eq!(s.percentile(1.0), 3.0);
        // 1..=1000 ms, shuffled: the exact median (rank 500) is 501, the p95 (rank 949)
        // 950.
        let mut s = Series::default();
        for i in 0..1000u64 {
            s.add(((i * 7919) % 1000 + 1) as f64, 0);
        }
        assert!((s.percentile(0.5) / 501.0 - 1.0).abs() < 0.0025);
        assert!((s.percentile(0.95) / 950.0 - 1.0).abs() < 0.0025);
        assert_eq!(s.percentile(0.5), s.percentile(0.5000001));
    }

    #[test]
    fn memory_does_not_grow_with_frames() {
        let mut s = Stats::new();
        for i in 0..100_000 {
            s.add_frame(&[t("a", 1.0 + (i % 10) as f64 * 0.01, 8), t("b", 2.0, 8)]);
        }
        assert!(s.by_pass["a"].bins.len() <= 10);
        assert_eq!(s.by_pass["b"].bins.len(), 1);
        assert_eq!(s.frames_seen(), 100_000);
        assert_eq!(s.summary(None).1.frames, 100_000 - WARMUP_FRAMES);
    }
}
