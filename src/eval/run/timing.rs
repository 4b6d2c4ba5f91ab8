//! Where an eval's wall time goes: references, the evaluated frames, the accumulation
//! baseline and the reports, plus the CPU time the metrics took and how much of it the
//! main thread (the one that drives the GPU) spent waiting for them. Printed at the end
//! of `dvr eval`, so the effect of overlapping GPU and CPU work can be read off.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Nanoseconds added up from any thread.
#[derive(Debug, Default)]
pub struct Counter(AtomicU64);

impl Counter {
    pub fn add(&self, d: Duration) {
        self.0.fetch_add(d.as_nanos() as u64, Ordering::Relaxed);
    }

    pub fn secs(&self) -> f64 {
        self.0.load(Ordering::Relaxed) as f64 * 1e-9
    }

    /// Runs `f`, adding its duration.
    pub fn time<T>(&self, f: impl FnOnce() -> T) -> T {
        let started = Instant::now();
        let out = f();
        self.add(started.elapsed());
        out
    }
}

/// Where a finished eval's time went, in seconds (see [`Timing`]).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Outcome {
    pub wall_s: f64,
    pub gpu_s: f64,
    pub references_s: f64,
    pub frames_s: f64,
    pub baseline_s: f64,
    pub reports_s: f64,
    pub metrics_cpu_s: f64,
    pub metrics_wait_s: f64,
}

/// The phases of an eval (wall time on the main thread) and the metrics' CPU time.
#[derive(Debug, Default)]
pub struct Timing {
    pub references: Counter,
    pub frames: Counter,
    pub baseline: Counter,
    pub reports: Counter,
    /// CPU time in scoring (tone map, PSNR, SSIM, FLIP, temporal error), summed over
    /// every thread that scored.
    pub metrics: Counter,
    /// Wall time the main thread spent scoring and writing frames, or waiting for that
    /// work to finish, instead of rendering.
    pub metrics_wait: Counter,
    /// GPU time of every pass the eval's renderers ran (references, frames, baseline).
    pub gpu: Counter,
}

impl Timing {
    pub fn shared() -> Arc<Self> {
        Arc::new(Self::default())
    }

    /// Adds GPU time reported in milliseconds.
    pub fn add_gpu_ms(&self, ms: f64) {
        self.gpu.add(Duration::from_secs_f64(ms.max(0.0) * 1e-3));
    }

    /// The figures of a finished eval that took `wall`, for a benchmark's record.
    pub fn outcome(&self, wall: Duration) -> Outcome {
        Outcome {
            wall_s: wall.as_secs_f64(),
            gpu_s: self.gpu.secs(),
            references_s: self.references.secs(),
            frames_s: self.frames.secs(),
            baseline_s: self.baseline.secs(),
            reports_s: self.reports.secs(),
            metrics_cpu_s: self.metrics.secs(),
            metrics_wait_s: self.metrics_wait.secs(),
        }
    }

    /// One line: the wall time and where it went.
    pub fn summary(&self, wall: Duration) -> String {
        let wall = wall.as_secs_f64();
        let share = |s: f64| 100.0 * s / wall.max(1e-9);
        format!(
            "eval timing: wall {wall:.1} s | references {:.1} s | frames {:.1} s | baseline \
             {:.1} s | reports {:.1} s | metrics {:.1} s CPU | main thread on metrics and frame \
             writes {:.1} s ({:.1}% of wall) | GPU busy {:.1} s (wall = {:.2}x GPU time)",
            self.references.secs(),
            self.frames.secs(),
            self.baseline.secs(),
            self.reports.secs(),
            self.metrics.secs(),
            self.metrics_wait.secs(),
            share(self.metrics_wait.secs()),
            self.gpu.secs(),
            wall / self.gpu.secs().max(1e-9)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counters_add_durations() {
        let t = Timing::default();
        t.metrics.add(Duration::from_millis(1500));
        t.metrics.add(Duration::from_millis(500));
        assert!((t.metrics.secs() - 2.0).abs() < 1e-9);
        assert_eq!(t.references.time(|| 7), 7);
        let line = t.summary(Duration::from_secs(4));
        assert!(line.contains("metrics 2.0 s CPU"), "{line}");
        t.add_gpu_ms(500.0);
        let line = t.summary(Duration::from_secs(4));
        assert!(
            line.contains("GPU busy 0.5 s (wall = 8.00x GPU time)"),
            "{line}"
        );
    }
}
