//! `dvr profile`: per-pass GPU time over many frames, as a table, JSON and a Chrome
//! trace-event file (open it in Perfetto or chrome://tracing), with each pass's declared
//! bytes, the bandwidth it achieved and its share of the device's measured peak.
//!
//! Statistics stream ([`stats`]): a run of any length keeps a fixed amount per pass. The
//! raw per-frame timings in the JSON and the trace are those of the last
//! [`WINDOW_FRAMES`] frames only ([`Window`]).

pub mod interrupt;
pub mod methods;
pub mod stats;

use dvr_engine::gpu::timestamps::PassTiming;
use dvr_engine::passes::bandwidth::PeakBandwidth;
pub use methods::method_gpu_ms;
use serde::Serialize;
pub use stats::{aggregate, PassStats, Stats, WARMUP_FRAMES};
use std::collections::VecDeque;

/// Frames whose raw timings a profile keeps for its JSON and trace: the most recent, so
/// a long run shows its steady state; older frames only count in the statistics.
pub const WINDOW_FRAMES: usize = 300;

/// The last `capacity` frames' raw timings, with the index of the first one kept.
#[derive(Clone, Debug)]
pub struct Window {
    capacity: usize,
    first: usize,
    frames: VecDeque<Vec<PassTiming>>,
}

impl Window {
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity: capacity.max(1),
            first: 0,
            frames: VecDeque::new(),
        }
    }

    pub fn push(&mut self, frame: Vec<PassTiming>) {
        if self.frames.len() == self.capacity {
            self.frames.pop_front();
            self.first += 1;
        }
        self.frames.push_back(frame);
    }

    /// Index of the first frame kept.
    pub fn first(&self) -> usize {
        self.first
    }

    pub fn frames(&self) -> impl Iterator<Item = &Vec<PassTiming>> {
        self.frames.iter()
    }

    pub fn len(&self) -> usize {
        self.frames.len()
    }
}

/// What `--json` writes.
#[derive(Clone, Debug, Serialize)]
pub struct Profile {
    #[serde(flatten)]
    pub run: RunInfo,
    pub warmup_frames: usize,
    /// Frames rendered (the statistics cover all of them after the warm-up).
    pub frames_rendered: usize,
    /// Set when a signal stopped the run early: which, and after how many frames.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub interrupted: Option<String>,
    /// The peak bandwidth each pass's `percent_of_peak` refers to.
    pub peak_bandwidth: Option<PeakBandwidth>,
    pub passes: Vec<PassStats>,
    pub total: PassStats,
    /// Each denoiser's cost: own passes, the passes it needs with others, dispatches and
    /// bytes per pixel per frame ([`methods`]).
    pub methods: Vec<methods::MethodRow>,
    /// Index of the first frame in `frames`.
    pub frames_first: usize,
    pub frames_note: String,
    /// Raw per-pass timings of the last frames (see `frames_note`).
    pub frames: Vec<Vec<PassTiming>>,
}

impl Profile {
    /// The report of a finished run: statistics of every frame, raw timings of the
    /// window.
    pub fn new(run: RunInfo, stats: &Stats, window: &Window, peak: Option<PeakBandwidth>) -> Self {
        let (passes, total) = stats.summary(peak.as_ref().map(|p| p.gb_per_s));
        let mut p = Self {
            run,
            warmup_frames: WARMUP_FRAMES,
            frames_rendered: stats.frames_seen(),
            interrupted: None,
            peak_bandwidth: peak,
            passes,
            total,
            methods: Vec::new(),
            frames_first: window.first(),
            frames_note: window_note(window, stats.frames_seen()),
            frames: window.frames().cloned().collect(),
        };
        p.methods = methods::method_rows(&p);
        p
    }
}

/// What a profile ran.
#[derive(Clone, Debug, Serialize)]
pub struct RunInfo {
    pub device: String,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    pub denoisers: Vec<String>,
    /// The à-trous levels read their window through shared memory (GpuContext::shared_tiles).
    pub shared_tiles: bool,
    /// How the volume reached the device: "dense volume", or the brick pool's residency
    /// at the end of the run.
    pub volume: String,
}

fn window_note(window: &Window, rendered: usize) -> String {
    if window.first() == 0 {
        format!("raw timings of all {} frames", window.len())
    } else {
        format!(
            "raw timings of the last {} of {rendered} frames (from frame {}); the statistics \
             cover every frame after the warm-up",
            window.len(),
            window.first()
        )
    }
}

pub fn table(p: &Profile) -> String {
    let r = &p.run;
    let mut s = format!(
        "{} | {} | {}x{} | {} spp | denoisers: {} | à-trous windows: {} | {}\n",
        r.device,
        r.scene,
        r.width,
        r.height,
        r.spp,
        r.denoisers.join(","),
        if r.shared_tiles {
            "shared-memory tiles"
        } else {
            "direct loads"
        },
        r.volume
    );
    match &p.peak_bandwidth {
        Some(b) => s.push_str(&format!(
            "peak bandwidth {:.1} GB/s ({})\n",
            b.gb_per_s, b.method
        )),
        None => s.push_str("peak bandwidth not measured\n"),
    }
    s.push_str(&format!(
        "{} frames, {} warm-up left out; median and p95 within 0.25% (streaming histogram); \
         MB = bytes the pass's declared accesses touch per frame\n",
        p.frames_rendered, p.warmup_frames
    ));
    // `ran`: the measured frames the pass ran in (the features march and ours' gradients
    // run only in frames whose inputs changed; times are per frame it ran in).
    s.push_str(&format!(
        "{:<28} {:>9} {:>10} {:>10} {:>10} {:>10} {:>9} {:>7}\n",
        "pass", "ran", "mean ms", "median ms", "p95 ms", "MB", "GB/s", "% peak"
    ));
    for r in p.passes.iter().chain(std::iter::once(&p.total)) {
        let peak = r
            .percent_of_peak
            .map(|v| format!("{v:.1}"))
            .unwrap_or_else(|| "-".into());
        s.push_str(&format!(
            "{:<28} {:>9} {:>10.3} {:>10.3} {:>10.3} {:>10.3} {:>9.2} {:>7}\n",
            r.pass,
            format!("{}/{}", r.frames, p.total.frames),
            r.mean_ms,
            r.median_ms,
            r.p95_ms,
            r.bytes / 1e6,
            r.gb_per_s,
            peak
        ));
    }
    s.push_str(&format!(
        "\nper denoiser: own passes, the passes it needs with others (features, guides), and \
         what it adds to the path-traced frame\n{:<28} {:>10} {:>10} {:>10} {:>10} {:>12}\n",
        "denoiser", "own ms", "needed ms", "cost ms", "dispatches", "bytes/pixel"
    ));
    for m in &p.methods {
        s.push_str(&format!(
            "{:<28} {:>10.3} {:>10.3} {:>10.3} {:>10.2} {:>12.1}\n",
            m.method, m.own_ms, m.needed_ms, m.cost_ms, m.dispatches, m.bytes_per_pixel
        ));
    }
    if p.frames_first > 0 {
        s.push_str(&format!("JSON and trace: {}\n", p.frames_note));
    }
    if let Some(why) = &p.interrupted {
        s.push_str(&format!("INTERRUPTED: {why}\n"));
    }
    s
}

/// Chrome trace-event JSON: one complete ("X") event per pass per frame, frames laid end
/// to end on one GPU track, times in microseconds; each event carries its frame index,
/// declared bytes and GB/s. `first` is the index of the first frame given.
pub fn chrome_trace<'a>(
    frames: impl IntoIterator<Item = &'a Vec<PassTiming>>,
    first: usize,
    note: &str,
) -> serde_json::Value {
    let mut events = Vec::new();
    let mut offset_us = 0.0;
    for (i, f) in frames.into_iter().enumerate() {
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
                "args": { "frame": first + i, "bytes": t.bytes, "gb_per_s": t.gb_per_s() },
            }));
            frame_end = frame_end.max(t.start_ms + t.ms);
        }
        offset_us += frame_end * 1000.0 + 10.0;
    }
    serde_json::json!({
        "traceEvents": events,
        "displayTimeUnit": "ms",
        "metadata": { "process": "dvr GPU", "frames": note },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn t(pass: &str, start: f64, ms: f64) -> PassTiming {
        PassTiming {
            pass: pass.into(),
            owner: Default::default(),
            start_ms: start,
            ms,
            bytes: 2_000_000,
        }
    }

    #[test]
    fn trace_events_are_sequential_and_carry_bytes() {
        let frames = [vec![t("a", 0.0, 1.0)], vec![t("a", 0.0, 2.0)]];
        let v = chrome_trace(&frames, 40, "note");
        let ev = v["traceEvents"].as_array().expect("events");
        assert_eq!(ev.len(), 2);
        assert!(ev[1]["ts"].as_f64() > ev[0]["ts"].as_f64());
        assert_eq!(ev[0]["ph"], "X");
        assert_eq!(ev[1]["args"]["frame"], 41);
        assert_eq!(ev[0]["args"]["bytes"], 2_000_000);
        assert_eq!(ev[0]["args"]["gb_per_s"], 2.0);
    }

    #[test]
    fn window_keeps_the_last_frames() {
        let mut w = Window::new(3);
        for i in 0..10 {
            w.push(vec![t("a", 0.0, i as f64)]);
        }
        assert_eq!(w.len(), 3);
        assert_eq!(w.first(), 7);
        let kept: Vec<f64> = w.frames().map(|f| f[0].ms).collect();
        assert_eq!(kept, vec![7.0, 8.0, 9.0]);
        assert!(window_note(&w, 10).contains("last 3 of 10 frames (from frame 7)"));
    }

    #[test]
    fn table_shows_bandwidth_columns() {
        let mut stats = Stats::new();
        let mut window = Window::new(WINDOW_FRAMES);
        for _ in 0..5 {
            stats.add_frame(&[t("a", 0.0, 1.0)]);
            window.push(vec![t("a", 0.0, 1.0)]);
        }
        let run = RunInfo {
            device: "dev".into(),
            scene: "s".into(),
            width: 4,
            height: 4,
            spp: 1,
            denoisers: vec!["none".into()],
            shared_tiles: false,
            volume: "dense volume".into(),
        };
        let peak = PeakBandwidth {
            gb_per_s: 8.0,
            buffer_bytes: 1,
            method: "measured".into(),
        };
        let p = Profile::new(run, &stats, &window, Some(peak));
        let text = table(&p);
        assert!(
            text.contains("peak bandwidth 8.0 GB/s (measured)"),
            "{text}"
        );
        assert!(text.contains("% peak"), "{text}");
        // 2 MB in 1 ms = 2 GB/s = 25% of 8 GB/s.
        let row = text.lines().find(|l| l.starts_with("a ")).expect("row a");
        assert!(row.contains("2.000") && row.ends_with("25.0"), "{row}");
        assert_eq!(p.frames_rendered, 5);
    }
}
