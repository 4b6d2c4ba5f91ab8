//! Frame files: linear float EXR (what the metrics, references and environment maps
//! use) and tone-mapped sRGB PNG (what people look at), through the one tone map in
//! `metrics::tonemap`.

use crate::metrics::{tonemap_srgb, Rgb32Image};
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ImageIoError {
    #[error("{}: {message}", path.display())]
    Exr { path: PathBuf, message: String },
    #[error("{}: {message}", path.display())]
    Png { path: PathBuf, message: String },
}

pub type Result<T> = std::result::Result<T, ImageIoError>;

/// Exposure applied before the tone map for PNGs.
pub const PNG_EXPOSURE: f32 = 1.0;

pub fn to_rgb(width: u32, height: u32, rgba: &[[f32; 4]]) -> Rgb32Image {
    Rgb32Image {
        width,
        height,
        data: rgba.iter().map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

pub fn write_exr(path: &Path, img: &Rgb32Image) -> Result<()> {
    let w = img.width as usize;
    exr::prelude::write_rgb_file(path, w, img.height as usize, |x, y| {
        let p = img.data[y * w + x];
        (p[0], p[1], p[2])
    })
    .map_err(|e| ImageIoError::Exr {
        path: path.to_path_buf(),
        message: format!("cannot write EXR: {e}"),
    })
}

pub fn read_exr(path: &Path) -> Result<Rgb32Image> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| {
            let w = res.width();
            (w, vec![[0f32; 3]; w * res.height()])
        },
        |(w, data), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            data[pos.y() * *w + pos.x()] = [r, g, b];
        },
    )
    .map_err(|e| ImageIoError::Exr {
        path: path.to_path_buf(),
        message: format!("cannot read EXR: {e}"),
    })?;
    let size = image.layer_data.size;
    Ok(Rgb32Image {
        width: size.width() as u32,
        height: size.height() as u32,
        data: image.layer_data.channel_data.pixels.1,
    })
}

pub fn write_png(path: &Path, img: &Rgb32Image) -> Result<()> {
    let bytes = tonemap_srgb(img, PNG_EXPOSURE).to_srgb8();
    image::save_buffer(
        path,
        &bytes,
        img.width,
        img.height,
        image::ExtendedColorType::Rgb8,
    )
    .map_err(|e| ImageIoError::Png {
        path: path.to_path_buf(),
        message: format!("cannot write PNG: {e}"),
    })
}
