//! The tables of an eval: `metrics.csv` (per frame), `summary.csv` (per scene and
//! method), `baseline.csv` (the accumulation curve), and the text table printed at the
//! end. Means are plain means over frames, except the temporal error (frames 1.., as
//! frame 0 has no previous frame) and GPU time (frames after the warm-up).

use super::run::{MetricRow, SceneResult};
use super::{GPU_WARMUP_FRAMES, RECOVERY_TOLERANCE_DB};
use crate::output::{opt, write_text as write};
use anyhow::Result;
use dvr_engine::metrics::frames_to_recover;
use std::fmt::Write as _;
use std::path::Path;

pub const METRICS_HEADER: &str = "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms";
pub const SUMMARY_HEADER: &str =
    "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover";
pub const BASELINE_HEADER: &str = "scene,frame,spp,gpu_ms,psnr";

/// Frames a method needs after a sudden change to be back within
/// [`RECOVERY_TOLERANCE_DB`] of its PSNR before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Recovery {
    /// The scene has no sudden change (written as an empty field).
    NotApplicable,
    Frames(usize),
    /// Still degraded at the last frame (written as `never`).
    Never,
}

impl Recovery {
    pub fn csv(&self) -> String {
        match self {
            Recovery::NotApplicable => String::new(),
            Recovery::Frames(n) => n.to_string(),
            Recovery::Never => "never".into(),
        }
    }
}

/// Means of one method on one scene.
#[derive(Clone, Debug)]
pub struct Summary {
    pub scene: String,
    pub method: String,
    pub psnr: f64,
    pub ssim: f64,
    pub flip: f64,
    pub temporal_error: Option<f64>,
    pub gpu_ms: f64,
    pub recovery: Recovery,
}

/// Means of one method over all scenes (each scene weighs the same).
#[derive(Clone, Debug)]
pub struct Overall {
    pub method: String,
    pub scenes: usize,
    pub psnr: f64,
    pub ssim: f64,
    pub flip: f64,
    pub temporal_error: Option<f64>,
    pub gpu_ms: f64,
    /// Mean frames to recover over the scenes with a sudden change that recovered,
    /// and how many never did; `None` without such scenes.
    pub recovery: Option<(Option<f64>, usize)>,
}

fn mean(values: impl IntoIterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values
        .into_iter()
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

pub fn scene_summary(r: &SceneResult) -> Vec<Summary> {
    r.methods
        .iter()
        .map(|m| {
            let rows = r.series(m);
            let timed = if rows.len() > GPU_WARMUP_FRAMES {
                &rows[GPU_WARMUP_FRAMES..]
            } else {
                &rows[..]
            };
            let recovery = match r.event_frame {
                None => Recovery::NotApplicable,
                Some(e) => {
                    let psnr: Vec<f64> = rows.iter().map(|x| x.psnr).collect();
                    match frames_to_recover(&psnr, e as usize, RECOVERY_TOLERANCE_DB) {
                        Some(n) => Recovery::Frames(n),
                        None => Recovery::Never,
                    }
                }
            };
            Summary {
                scene: r.name.clone(),
                method: m.clone(),
                psnr: mean(rows.iter().map(|x| x.psnr)).unwrap_or(f64::NAN),
                ssim: mean(rows.iter().map(|x| x.ssim)).unwrap_or(f64::NAN),
                flip: mean(rows.iter().map(|x| x.flip)).unwrap_or(f64::NAN),
                temporal_error: mean(rows.iter().filter_map(|x| x.temporal_error)),
                gpu_ms: mean(timed.iter().map(|x| x.gpu_ms)).unwrap_or(f64::NAN),
                recovery,
            }
        })
        .collect()
}

pub fn overall_summary(results: &[SceneResult], methods: &[String]) -> Vec<Overall> {
    let all: Vec<Summary> = results.iter().flat_map(scene_summary).collect();
    methods
        .iter()
        .map(|m| {
            let s: Vec<&Summary> = all.iter().filter(|x| &x.method == m).collect();
            let sudden: Vec<Recovery> = s
                .iter()
                .map(|x| x.recovery)
                .filter(|r| *r != Recovery::NotApplicable)
                .collect();
            let recovery = (!sudden.is_empty()).then(|| {
                let frames = sudden.iter().filter_map(|r| match r {
                    Recovery::Frames(n) => Some(*n as f64),
                    _ => None,
                });
                let never = sudden.iter().filter(|r| **r == Recovery::Never).count();
                (mean(frames), never)
            });
            Overall {
                method: m.clone(),
                scenes: s.len(),
                psnr: mean(s.iter().map(|x| x.psnr)).unwrap_or(f64::NAN),
                ssim: mean(s.iter().map(|x| x.ssim)).unwrap_or(f64::NAN),
                flip: mean(s.iter().map(|x| x.flip)).unwrap_or(f64::NAN),
                temporal_error: mean(s.iter().filter_map(|x| x.temporal_error)),
                gpu_ms: mean(s.iter().map(|x| x.gpu_ms)).unwrap_or(f64::NAN),
                recovery,
            }
        })
        .collect()
}

/// A CSV field: quoted when it holds a comma, quote or line break.
fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

pub fn metrics_csv(results: &[SceneResult]) -> String {
    let mut s = format!("{METRICS_HEADER}\n");
    for r in results {
        for m in &r.methods {
            for x in r.series(m) {
                let MetricRow {
                    scene,
                    method,
                    frame,
                    psnr,
                    ssim,
                    flip,
                    temporal_error,
                    gpu_ms,
                } = x;
                let _ = writeln!(
                    s,
                    "{},{},{frame},{psnr:.6},{ssim:.6},{flip:.6},{},{gpu_ms:.4}",
                    field(scene),
                    field(method),
                    opt(*temporal_error, 6)
                );
            }
        }
    }
    s
}

pub fn summary_csv(results: &[SceneResult]) -> String {
    let mut s = format!("{SUMMARY_HEADER}\n");
    for x in results.iter().flat_map(scene_summary) {
        let _ = writeln!(
            s,
            "{},{},{:.4},{:.6},{:.6},{},{:.4},{}",
            field(&x.scene),
            field(&x.method),
            x.psnr,
            x.ssim,
            x.flip,
            opt(x.temporal_error, 6),
            x.gpu_ms,
            x.recovery.csv()
        );
    }
    s
}

pub fn baseline_csv(results: &[SceneResult]) -> String {
    let mut s = format!("{BASELINE_HEADER}\n");
    for r in results {
        for p in &r.baseline {
            let _ = writeln!(
                s,
                "{},{},{},{:.4},{:.4}",
                field(&r.name),
                p.frame,
                p.spp,
                p.gpu_ms,
                p.psnr
            );
        }
    }
    s
}

pub fn write_metrics(path: &Path, results: &[SceneResult]) -> Result<()> {
    write(path, &metrics_csv(results))
}

pub fn write_summary(path: &Path, results: &[SceneResult]) -> Result<()> {
    write(path, &summary_csv(results))
}

pub fn write_baseline(path: &Path, results: &[SceneResult]) -> Result<()> {
    write(path, &baseline_csv(results))
}

/// Frames to recover over all scenes, as text: `2.5`, `3.0 (1 never)`, `never (2)`.
pub fn overall_recovery_text(r: Option<(Option<f64>, usize)>) -> String {
    match r {
        None => String::new(),
        Some((Some(m), 0)) => format!("{m:.1}"),
        Some((Some(m), n)) => format!("{m:.1} ({n} never)"),
        Some((None, n)) => format!("never ({n})"),
    }
}

/// The summary as a fixed-width text table: every scene, then the means over scenes.
pub fn summary_table(results: &[SceneResult], overall: &[Overall]) -> String {
    let mut s = String::new();
    let all_label = |n: usize| format!("all ({n} scenes)");
    let width = results
        .iter()
        .map(|r| r.name.len())
        .chain(overall.iter().map(|o| all_label(o.scenes).len()))
        .max()
        .unwrap_or(0)
        .max(5);
    let _ = writeln!(
        s,
        "{:<width$} {:<8} {:>8} {:>7} {:>7} {:>9} {:>9} {:>8}",
        "scene", "method", "PSNR dB", "SSIM", "FLIP", "temporal", "GPU ms", "recover"
    );
    for x in results.iter().flat_map(scene_summary) {
        let _ = writeln!(
            s,
            "{:<width$} {:<8} {:>8.2} {:>7.4} {:>7.4} {:>9} {:>9.3} {:>8}",
            x.scene,
            x.method,
            x.psnr,
            x.ssim,
            x.flip,
            opt(x.temporal_error, 5),
            x.gpu_ms,
            x.recovery.csv()
        );
    }
    for o in overall {
        let _ = writeln!(
            s,
            "{:<width$} {:<8} {:>8.2} {:>7.4} {:>7.4} {:>9} {:>9.3} {:>8}",
            all_label(o.scenes),
            o.method,
            o.psnr,
            o.ssim,
            o.flip,
            opt(o.temporal_error, 5),
            o.gpu_ms,
            overall_recovery_text(o.recovery)
        );
    }
    s
}

#[cfg(test)]
pub(crate) mod tests {
    use super::super::baseline::BaselinePoint;
    use super::*;

    /// A small synthetic result: 2 methods × `frames` frames; `ours` dips after the
    /// event and recovers two frames later.
    pub(crate) fn result(name: &str, frames: u32, event: Option<u32>) -> SceneResult {
        let methods = vec!["none".to_string(), "ours".to_string()];
        let mut rows = Vec::new();
        for m in &methods {
            for f in 0..frames {
                let base = if m == "none" { 20.0 } else { 30.0 };
                let dip = match event {
                    Some(e) if m == "ours" && f >= e && f < e + 2 => 5.0,
                    _ => 0.0,
                };
                rows.push(MetricRow {
                    scene: name.into(),
                    method: m.clone(),
                    frame: f,
                    psnr: base - dip,
                    ssim: 0.5,
                    flip: 0.25,
                    temporal_error: (f > 0).then_some(0.01),
                    gpu_ms: if f < 2 { 100.0 } else { 2.0 },
                });
            }
        }
        SceneResult {
            name: name.into(),
            dir: super::super::scenes::dir_name(name),
            frames,
            spp: 2,
            methods,
            event_frame: event,
            rows,
            baseline: vec![BaselinePoint {
                frame: 0,
                spp: 1,
                gpu_ms: 0.5,
                psnr: 18.0,
            }],
            path_trace_ms_per_spp: 0.5,
            volume: "dense volume".into(),
            device: "test".into(),
        }
    }

    #[test]
    fn metrics_csv_has_the_schema_and_one_row_per_frame() {
        let r = [result("cloud/orbit", 4, None), result("a,b", 4, None)];
        let csv = metrics_csv(&r);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], METRICS_HEADER);
        assert_eq!(lines.len(), 1 + 2 * 2 * 4);
        assert_eq!(
            lines[1],
            "cloud/orbit,none,0,20.000000,0.500000,0.250000,,100.0000"
        );
        assert_eq!(
            lines[2],
            "cloud/orbit,none,1,20.000000,0.500000,0.250000,0.010000,100.0000"
        );
        assert!(lines[9].starts_with("\"a,b\",none,0,"), "{}", lines[9]);
    }

    #[test]
    fn summary_means_skip_warmup_and_measure_recovery() {
        let r = result("cloud/tf-jump", 10, Some(5));
        let s = scene_summary(&r);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].recovery, Recovery::Frames(0));
        assert_eq!(s[1].recovery, Recovery::Frames(2));
        assert_eq!(s[1].gpu_ms, 2.0);
        assert!((s[1].psnr - 29.0).abs() < 1e-12);
        assert_eq!(s[0].temporal_error, Some(0.01));
        let orbit = scene_summary(&result("cloud/orbit", 10, None));
        assert_eq!(orbit[1].recovery, Recovery::NotApplicable);
        let csv = summary_csv(&[result("cloud/orbit", 10, None), r]);
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], SUMMARY_HEADER);
        assert_eq!(lines.len(), 5);
        assert!(lines[1].ends_with(",2.0000,"), "{}", lines[1]);
        assert!(lines[4].ends_with(",2.0000,2"), "{}", lines[4]);
    }

    #[test]
    fn never_recovering_is_written_as_never() {
        let mut r = result("cloud/light-jump", 6, Some(3));
        for row in r
            .rows
            .iter_mut()
            .filter(|x| x.method == "ours" && x.frame >= 3)
        {
            row.psnr = 10.0;
        }
        let s = scene_summary(&r);
        assert_eq!(s[1].recovery, Recovery::Never);
        assert!(summary_csv(&[r])
            .lines()
            .nth(2)
            .unwrap()
            .ends_with(",never"));
    }

    #[test]
    fn overall_weighs_scenes_equally() {
        let r = [result("x/orbit", 4, None), result("x/tf-jump", 10, Some(5))];
        let methods = r[0].methods.clone();
        let o = overall_summary(&r, &methods);
        assert_eq!(o.len(), 2);
        assert_eq!(o[0].scenes, 2);
        assert!((o[1].psnr - 0.5 * (30.0 + 29.0)).abs() < 1e-12);
        assert_eq!(o[1].recovery, Some((Some(2.0), 0)));
        assert_eq!(overall_recovery_text(o[1].recovery), "2.0");
        let table = summary_table(&r, &o);
        assert!(table.contains("all (2 scenes)"), "{table}");
        assert_eq!(baseline_csv(&r).lines().count(), 3);
    }
}
