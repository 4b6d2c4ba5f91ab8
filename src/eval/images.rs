//! PNGs of an eval: tone-mapped frames and FLIP error maps.

use anyhow::{Context, Result};
use dvr_engine::metrics::{flip_colormap, Rgb32Image};
use std::path::Path;

/// Writes display values (already tone-mapped) as an 8-bit sRGB PNG.
pub fn write_display_png(path: &Path, display: &Rgb32Image) -> Result<()> {
    save_rgb8(path, display.width, display.height, &display.to_srgb8())
}

/// Writes a FLIP error map through the magma colour map.
pub fn write_flip_png(path: &Path, width: u32, height: u32, map: &[f32]) -> Result<()> {
    let bytes: Vec<u8> = flip_colormap(map).into_iter().flatten().collect();
    save_rgb8(path, width, height, &bytes)
}

/// Writes 8-bit sRGB pixels as a PNG, atomically.
pub fn save_rgb8(path: &Path, width: u32, height: u32, bytes: &[u8]) -> Result<()> {
    let png = dvr_engine::image_io::encode_srgb8_png(path, width, height, bytes)?;
    dvr_engine::image_io::write_file(path, &png, dvr_engine::files::Durability::Renamed)
        .with_context(|| format!("writing {}", path.display()))
}
