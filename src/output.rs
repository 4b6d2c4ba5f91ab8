//! Frame files: linear float EXR (what the metrics and references use) and tone-mapped
//! sRGB PNG (what people look at), both through the one tone map in `metrics::tonemap`.

use anyhow::{Context, Result};
use dvr_engine::metrics::{tonemap_srgb, Rgb32Image};
use std::path::Path;

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
    .with_context(|| format!("writing {}", path.display()))
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
    .with_context(|| format!("reading {}", path.display()))?;
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
    .with_context(|| format!("writing {}", path.display()))
}
