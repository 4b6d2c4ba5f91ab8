//! PNGs of an eval's frames: tone-mapped frames and FLIP error maps.

use crate::output::write_rgb8_png;
use anyhow::Result;
use dvr_engine::metrics::{flip_colormap, Rgb32Image};
use std::path::Path;

/// Writes display values (already tone-mapped) as an 8-bit sRGB PNG.
pub fn write_display_png(path: &Path, display: &Rgb32Image) -> Result<()> {
    write_rgb8_png(path, display.width, display.height, &display.to_srgb8())
}

/// Writes a FLIP error map through the magma colour map.
pub fn write_flip_png(path: &Path, width: u32, height: u32, map: &[f32]) -> Result<()> {
    let bytes: Vec<u8> = flip_colormap(map).into_iter().flatten().collect();
    write_rgb8_png(path, width, height, &bytes)
}
