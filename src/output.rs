//! The commands' outputs (CSV, JSON, HTML, SVG, PNG): written through a temporary name
//! and a rename, so a reader or an interruption never sees half a file, with errors that
//! name the file.

use anyhow::{Context, Result};
use dvr_engine::files::{write_atomic, Durability};
use serde::Serialize;
use std::path::Path;

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, text.as_bytes(), Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}

/// `value` as pretty-printed JSON.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    write_text(path, &serde_json::to_string_pretty(value)?)
}

/// 8-bit sRGB pixels (`width` × `height`, RGB) as a PNG.
pub fn write_rgb8_png(path: &Path, width: u32, height: u32, bytes: &[u8]) -> Result<()> {
    let png = dvr_engine::image_io::encode_srgb8_png(path, width, height, bytes)?;
    dvr_engine::image_io::write_file(path, &png, Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}

/// `v` with `digits` decimals, or an empty cell when there is none.
pub fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|v| format!("{v:.digits$}")).unwrap_or_default()
}
