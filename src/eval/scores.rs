//! The numbers the reports show, from the results: per scene and method the means over
//! frames and the frames to recover after a sudden change ([`scene_summary`]), the
//! means over all scenes ([`overall_summary`]), and the baseline's mean curve
//! ([`mean_curve`]). Means are plain means over frames, except the temporal error
//! (frames 1.., as frame 0 has no previous frame) and GPU time (frames after the
//! warm-up).
//!
//! The eval's scores layer: it imports the plan's constants and the results' types.

use super::plan::settings::{GPU_WARMUP_FRAMES, RECOVERY_TOLERANCE_DB};
use super::results::{BaselinePoint, SceneResult};
use dvr_engine::metrics::frames_to_recover;

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

/// Frames to recover over all scenes, as text: `2.5`, `3.0 (1 never)`, `never (2)`.
pub fn overall_recovery_text(r: Option<(Option<f64>, usize)>) -> String {
    match r {
        None => String::new(),
        Some((Some(m), 0)) => format!("{m:.1}"),
        Some((Some(m), n)) => format!("{m:.1} ({n} never)"),
        Some((None, n)) => format!("never ({n})"),
    }
}

/// The curve averaged over the measured frames: (spp, mean GPU ms, mean PSNR).
pub fn mean_curve(points: &[BaselinePoint]) -> Vec<(u32, f64, f64)> {
    let mut spps: Vec<u32> = points.iter().map(|p| p.spp).collect();
    spps.sort_unstable();
    spps.dedup();
    spps.into_iter()
        .map(|n| {
            let at: Vec<&BaselinePoint> = points.iter().filter(|p| p.spp == n).collect();
            let k = at.len() as f64;
            (
                n,
                at.iter().map(|p| p.gpu_ms).sum::<f64>() / k,
                at.iter().map(|p| p.psnr).sum::<f64>() / k,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_curve_averages_frames() {
        let p = |frame, spp, gpu_ms, psnr| BaselinePoint {
            frame,
            spp,
            gpu_ms,
            psnr,
        };
        let c = mean_curve(&[p(0, 1, 1.0, 20.0), p(8, 1, 1.0, 22.0), p(0, 2, 2.0, 25.0)]);
        assert_eq!(c, vec![(1, 1.0, 21.0), (2, 2.0, 25.0)]);
    }
}
