//! `dvr profile`: per-pass GPU time over many frames, as a table, JSON and a Chrome
//! trace-event file (open it in Perfetto or chrome://tracing).

use anyhow::{Context, Result};
use dvr_engine::gpu::timestamps::PassTiming;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

/// Frames left out of the statistics: the first dispatch of each pipeline includes
/// driver compilation (150–200 ms on lavapipe) and one-off uploads.
pub const WARMUP_FRAMES: usize = 2;

#[derive(Clone, Debug, Serialize)]
pub struct PassStats {
    pub pass: String,
    pub frames: usize,
    pub mean_ms: f64,
    pub median_ms: f64,
    pub p95_ms: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Profile {
    pub device: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub denoisers: Vec<String>,
    pub warmup_frames: usize,
    pub passes: Vec<PassStats>,
    pub total: PassStats,
    pub frames: Vec<Vec<PassTiming>>,
}

fn percentile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return 0.0;
    }
    let rank = (q * (sorted.len() - 1) as f64).round() as usize;
    sorted[rank.min(sorted.len() - 1)]
}

pub fn stats(name: &str, mut values: Vec<f64>) -> PassStats {
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    PassStats {
        pass: name.to_string(),
        frames: n,
        mean_ms: if n == 0 {
            0.0
        } else {
            values.iter().sum::<f64>() / n as f64
        },
        median_ms: percentile(&values, 0.5),
        p95_ms: percentile(&values, 0.95),
    }
}

/// Aggregates per-pass timings over frames (after the warm-up), in first-seen pass order.
pub fn aggregate(frames: &[Vec<PassTiming>]) -> (Vec<PassStats>, PassStats) {
    let measured = if frames.len() > WARMUP_FRAMES {
        &frames[WARMUP_FRAMES..]
    } else {
        frames
    };
    let mut order = Vec::new();
    let mut by_pass: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    let mut totals = Vec::new();
    for f in measured {
        let mut total = 0.0;
        for t in f {
            if !by_pass.contains_key(&t.pass) {
                order.push(t.pass.clone());
            }
            by_pass.entry(t.pass.clone()).or_default().push(t.ms);
            total += t.ms;
        }
        totals.push(total);
    }
    let passes = order
        .iter()
        .map(|p| stats(p, by_pass.remove(p).unwrap_or_default()))
        .collect();
    (passes, stats("total", totals))
}

pub fn table(p: &Profile) -> String {
    let mut s = format!(
        "{} | {} | {}x{} | {} spp | denoisers: {}\n",
        p.device,
        p.scene,
        p.width,
        p.height,
        p.spp,
        p.denoisers.join(",")
    );
    s.push_str(&format!(
        "{:<28} {:>10} {:>10} {:>10}\n",
        "pass", "mean ms", "median ms", "p95 ms"
    ));
    for r in p.passes.iter().chain(std::iter::once(&p.total)) {
        s.push_str(&format!(
            "{:<28} {:>10.3} {:>10.3} {:>10.3}\n",
            r.pass, r.mean_ms, r.median_ms, r.p95_ms
        ));
    }
    s
}

/// Chrome trace-event JSON: one complete ("X") event per pass per frame, frames laid end
/// to end on one GPU track, times in microseconds.
pub fn chrome_trace(frames: &[Vec<PassTiming>]) -> serde_json::Value {
    let mut events = Vec::new();
    let mut offset_us = 0.0;
    for (i, f) in frames.iter().enumerate() {
        let mut frame_end: f64 = 0.0;
        for t in f {
            events.push(serde_json::json!({
                "name": t.pass,
                "cat": "gpu",
                "ph": "X",
                "ts": offset_us + t.start_ms * 1000.0,
                "dur": t.ms * 1000.0,
                "pid": 1,
                "tid": 1,
                "args": { "frame": i },
            }));
            frame_end = frame_end.max(t.start_ms + t.ms);
        }
        offset_us += frame_end * 1000.0 + 10.0;
    }
    serde_json::json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "metadata": { "process": "dvr GPU" },
    })
}

pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let text = serde_json::to_string_pretty(value)?;
    dvr_engine::files::write_atomic(
        path,
        text.as_bytes(),
        dvr_engine::files::Durability::Renamed,
    )
    .with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(pass: &str, start: f64, ms: f64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            start_ms: start,
            ms,
        }
    }

    #[test]
    fn aggregate_skips_warmup_and_orders_passes() {
        let mut frames = vec![vec![t("a", 0.0, 100.0)]; WARMUP_FRAMES];
        for i in 0..10 {
            frames.push(vec![t("b", 0.0, 1.0), t("a", 1.0, i as f64)]);
        }
        let (passes, total) = aggregate(&frames);
        assert_eq!(passes[0].pass, "b");
        assert_eq!(passes[1].pass, "a");
        assert!((passes[1].mean_ms - 4.5).abs() < 1e-9);
        assert_eq!(passes[1].frames, 10);
        assert!((total.mean_ms - 5.5).abs() < 1e-9);
        assert_eq!(percentile(&[1.0, 2.0, 3.0], 0.5), 2.0);
    }

    #[test]
    fn trace_events_are_sequential() {
        let frames = vec![vec![t("a", 0.0, 1.0)], vec![t("a", 0.0, 2.0)]];
        let v = chrome_trace(&frames);
        let ev = v["traceEvents"].as_array().expect("events");
        assert_eq!(ev.len(), 2);
        assert!(ev[1]["ts"].as_f64() > ev[0]["ts"].as_f64());
        assert_eq!(ev[0]["ph"], "X");
    }
}
