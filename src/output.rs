//! The commands' text outputs (CSV, JSON, HTML, SVG): written through a temporary name
//! and a rename, so a reader or an interruption never sees half a file, with errors that
//! name the file.

use anyhow::{Context, Result};
use dvr_engine::files::{write_atomic, Durability};
use std::path::Path;

pub fn write_text(path: &Path, text: &str) -> Result<()> {
    write_atomic(path, text.as_bytes(), Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}

/// `v` with `digits` decimals, or an empty cell when there is none.
pub fn opt(v: Option<f64>, digits: usize) -> String {
    v.map(|v| format!("{v:.digits$}")).unwrap_or_default()
}
