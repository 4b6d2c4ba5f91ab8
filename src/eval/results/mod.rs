//! What an evaluated scene produced: per frame and method its scores ([`MetricRow`]),
//! the accumulation baseline's points ([`BaselinePoint`]), all of it with the scene's
//! settings as one [`SceneResult`], kept in `<scene>/result.json` ([`record`]). The run
//! makes these; the scores and the reports read them.
//!
//! A layer just above the plan: it imports `super::plan` (the result's key) and nothing
//! else of the eval.

pub mod float;
pub mod record;

use serde::{Deserialize, Serialize};

/// Per-frame scores of one method.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct MetricRow {
    pub scene: String,
    pub method: String,
    pub frame: u32,
    #[serde(with = "float")]
    pub psnr: f64,
    #[serde(with = "float")]
    pub ssim: f64,
    #[serde(with = "float")]
    pub flip: f64,
    #[serde(with = "float::option")]
    pub temporal_error: Option<f64>,
    #[serde(with = "float")]
    pub gpu_ms: f64,
}

/// Everything the reports need about one evaluated scene (kept in
/// `<scene>/result.json`, see [`record`]).
#[derive(Clone, Serialize, Deserialize)]
pub struct SceneResult {
    pub name: String,
    /// Folder name inside the eval folder.
    pub dir: String,
    pub frames: u32,
    pub spp: u32,
    pub methods: Vec<String>,
    /// Frame of the sudden change, for scenes that have one.
    pub event_frame: Option<u32>,
    pub rows: Vec<MetricRow>,
    pub baseline: Vec<BaselinePoint>,
    #[serde(with = "float")]
    pub path_trace_ms_per_spp: f64,
    pub device: String,
    /// How the volume was held: "dense volume", or the brick pool's residency at the
    /// scene's last frame (the page shows it); empty in results written before it.
    #[serde(default)]
    pub volume: String,
}

impl SceneResult {
    /// A method's rows in frame order.
    pub fn series(&self, method: &str) -> Vec<&MetricRow> {
        let mut rows: Vec<&MetricRow> = self.rows.iter().filter(|r| r.method == method).collect();
        rows.sort_by_key(|r| r.frame);
        rows
    }
}

/// One level of the accumulation baseline on one frame: its GPU time (path tracing
/// only) and PSNR.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct BaselinePoint {
    pub frame: u32,
    pub spp: u32,
    #[serde(with = "float")]
    pub gpu_ms: f64,
    #[serde(with = "float")]
    pub psnr: f64,
}
