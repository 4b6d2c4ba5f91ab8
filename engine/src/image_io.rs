//! Frame files: linear float EXR (what the metrics, references and environment maps
//! use) and tone-mapped sRGB PNG (what people look at), through the one tone map in
//! `metrics::tonemap`.

use crate::files::Durability;
use crate::metrics::{tonemap_srgb, Rgb32Image};
use std::path::{Path, PathBuf};
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ImageIoError {
    #[error("{}: {message}", path.display())]
    Exr { path: PathBuf, message: String },
    #[error("{}: {message}", path.display())]
    Png { path: PathBuf, message: String },
    #[error("{}: cannot write: {message}", path.display())]
    Write { path: PathBuf, message: String },
}

pub type Result<T> = std::result::Result<T, ImageIoError>;

/// Largest EXR read (pixels of one layer): the largest frame `dvr` renders.
pub const MAX_EXR_PIXELS: usize = 8192 * 8192;

/// Exposure applied before the tone map for PNGs (the metrics score what they show).
pub const PNG_EXPOSURE: f32 = crate::metrics::DISPLAY_EXPOSURE;

pub fn to_rgb(width: u32, height: u32, rgba: &[[f32; 4]]) -> Rgb32Image {
    Rgb32Image {
        width,
        height,
        data: rgba.iter().map(|p| [p[0], p[1], p[2]]).collect(),
    }
}

/// The image as an EXR file (linear float RGB), in memory.
pub fn encode_exr(path: &Path, img: &Rgb32Image) -> Result<Vec<u8>> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    check_size(path, img)?;
    let w = img.width as usize;
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_channels(
        (w, img.height as usize),
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let c = img.data[p.y() * w + p.x()];
            (c[0], c[1], c[2])
        }),
    )
    .write()
    .to_buffered(&mut bytes)
    .map_err(|e| ImageIoError::Exr {
        path: path.to_path_buf(),
        message: format!("cannot write EXR: {e}"),
    })?;
    Ok(bytes.into_inner())
}

/// Writes an EXR atomically (see [`crate::files::write_atomic`]).
pub fn write_exr(path: &Path, img: &Rgb32Image) -> Result<()> {
    write_file(path, &encode_exr(path, img)?, Durability::Renamed)
}

/// Reads the first RGB(A) layer of an EXR file. Only regular files are opened.
pub fn read_exr(path: &Path) -> Result<Rgb32Image> {
    use exr::prelude::*;
    let err = |message: String| ImageIoError::Exr {
        path: path.to_path_buf(),
        message,
    };
    let (file, _) =
        crate::files::open_regular(path).map_err(|e| err(format!("cannot read EXR: {e}")))?;
    let mut reader = std::io::BufReader::new(file);
    // The header first: a corrupt one could ask for any size, and the pixels are
    // allocated from it.
    let meta = exr::meta::MetaData::read_from_buffered(&mut reader, false)
        .map_err(|e| err(format!("cannot read EXR: {e}")))?;
    for h in &meta.headers {
        let (w, hgt) = (h.layer_size.width(), h.layer_size.height());
        if w.saturating_mul(hgt) > MAX_EXR_PIXELS {
            return Err(err(format!(
                "a {w}x{hgt} layer; at most {MAX_EXR_PIXELS} pixels (8192x8192) are read"
            )));
        }
    }
    std::io::Seek::rewind(&mut reader).map_err(|e| err(format!("cannot read EXR: {e}")))?;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _| {
                let w = res.width();
                (w, vec![[0f32; 3]; w * res.height()])
            },
            |(w, data), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                data[pos.y() * *w + pos.x()] = [r, g, b];
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(reader)
        .map_err(|e| err(format!("cannot read EXR: {e}")))?;
    let size = image.layer_data.size;
    Ok(Rgb32Image {
        width: size.width() as u32,
        height: size.height() as u32,
        data: image.layer_data.channel_data.pixels.1,
    })
}

/// The image tone-mapped to sRGB (the one tone map, [`PNG_EXPOSURE`]) as a PNG file, in
/// memory.
pub fn encode_png(path: &Path, img: &Rgb32Image) -> Result<Vec<u8>> {
    check_size(path, img)?;
    let bytes = tonemap_srgb(img, PNG_EXPOSURE).to_srgb8();
    encode_srgb8_png(path, img.width, img.height, &bytes)
}

/// 8-bit sRGB pixels (`width × height × 3` bytes) as a PNG file, in memory.
pub fn encode_srgb8_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(
        &mut out,
        rgb,
        width,
        height,
        image::ExtendedColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(|e| ImageIoError::Png {
        path: path.to_path_buf(),
        message: format!("cannot write PNG: {e}"),
    })?;
    Ok(out.into_inner())
}

/// Writes a tone-mapped PNG atomically (see [`crate::files::write_atomic`]).
pub fn write_png(path: &Path, img: &Rgb32Image) -> Result<()> {
    write_file(path, &encode_png(path, img)?, Durability::Renamed)
}

/// Writes encoded image bytes through [`crate::files::write_atomic`].
pub fn write_file(path: &Path, bytes: &[u8], durability: Durability) -> Result<()> {
    crate::files::write_atomic(path, bytes, durability).map_err(|e| ImageIoError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

/// An image whose pixel count does not match its size would write a header-only file
/// (or index out of bounds): refuse it by name.
fn check_size(path: &Path, img: &Rgb32Image) -> Result<()> {
    let pixels = img.width as usize * img.height as usize;
    if img.width == 0 || img.height == 0 || img.data.len() != pixels {
        return Err(ImageIoError::Write {
            path: path.to_path_buf(),
            message: format!(
                "{} pixels for a {}x{} image",
                img.data.len(),
                img.width,
                img.height
            ),
        });
    }
    Ok(())
}
