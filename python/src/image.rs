//! Frames as the bytes of an image file, for a view that shows them (the notebook
//! viewer streams them to the browser): the eval's tone map, then JPEG or PNG, encoded
//! with the GIL released.

use crate::convert::{image_in, value_error};
use dvr_engine::image_io::{encode_srgb8_png, PNG_EXPOSURE};
use dvr_engine::metrics::tonemap_srgb;
use numpy::PyReadonlyArray3;
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use std::path::Path;

/// `image` ((h, w, 3) float32 linear radiance) tone-mapped as the eval's PNGs are
/// (`exposure` scales it first; default the eval's), encoded as `format` ("jpeg", with
/// `quality` 1 to 100, or "png").
#[pyfunction]
#[pyo3(signature = (image, format = "jpeg", quality = 90, exposure = None))]
pub fn encode_image<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<'_, f32>,
    format: &str,
    quality: i64,
    exposure: Option<f32>,
) -> PyResult<Bound<'py, PyBytes>> {
    let img = image_in(&image, "image")?;
    let exposure = exposure.unwrap_or(PNG_EXPOSURE);
    if !exposure.is_finite() || exposure <= 0.0 {
        return Err(value_error(format!(
            "exposure={exposure}: must be finite and > 0"
        )));
    }
    if !(1..=100).contains(&quality) {
        return Err(value_error(format!("quality={quality}: must be 1 to 100")));
    }
    let jpeg = match format {
        "jpeg" | "jpg" => true,
        "png" => false,
        other => {
            return Err(value_error(format!(
                "format={other:?}: must be \"jpeg\" or \"png\""
            )))
        }
    };
    let bytes = py.detach(|| -> Result<Vec<u8>, String> {
        let rgb = tonemap_srgb(&img, exposure).to_srgb8();
        if !jpeg {
            return encode_srgb8_png(Path::new("frame.png"), img.width, img.height, &rgb)
                .map_err(|e| e.to_string());
        }
        let mut out = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, quality as u8)
            .encode(&rgb, img.width, img.height, image::ExtendedColorType::Rgb8)
            .map_err(|e| format!("cannot encode JPEG: {e}"))?;
        Ok(out)
    });
    Ok(PyBytes::new(py, &bytes.map_err(value_error)?))
}
