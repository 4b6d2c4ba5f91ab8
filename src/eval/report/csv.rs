//! The tables of an eval: `metrics.csv` (per frame), `summary.csv` (per scene and
//! method, from [`crate::eval::scores`]), `baseline.csv` (the accumulation curve), and
//! the text table printed at the end.

use crate::eval::results::{MetricRow, SceneResult};
use crate::eval::scores::{overall_recovery_text, scene_summary, Overall};
use crate::output::{opt, write_text as write};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

pub const METRICS_HEADER: &str = "scene,method,frame,psnr,ssim,flip,temporal_error,gpu_ms";
pub const SUMMARY_HEADER: &str =
    "scene,method,psnr,ssim,flip,temporal_error,gpu_ms,frames_to_recover";
pub const BASELINE_HEADER: &str = "scene,frame,spp,gpu_ms,psnr";

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
    use super::*;
    use crate::eval::plan::scenes::dir_name;
    use crate::eval::results::BaselinePoint;
    use crate::eval::scores::{overall_summary, Recovery};

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
            dir: dir_name(name),
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
