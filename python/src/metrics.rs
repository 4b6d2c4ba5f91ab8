//! `dvr.metrics`: the scores `dvr eval` reports, on numpy images. Every function takes
//! linear radiance (what `Renderer.render` returns, `(h, w, 3)` float32) and tone-maps
//! it with the eval's tone map and exposure first, so a score here equals the eval's.

use crate::convert::{image_in, image_out, value_error};
use dvr_engine::metrics::{self, Rgb32Image, DEFAULT_PPD, PSNR_CAP};
use numpy::{PyArray3, PyReadonlyArray3};
use pyo3::prelude::*;

fn same_size(a: &Rgb32Image, b: &Rgb32Image, names: (&str, &str)) -> PyResult<()> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(value_error(format!(
            "{} is {}×{} but {} is {}×{} (width × height)",
            names.0, a.width, a.height, names.1, b.width, b.height
        )));
    }
    Ok(())
}

/// `score` of `test` against `reference`, both tone-mapped first, with the GIL released.
fn compare(
    py: Python<'_>,
    reference: &PyReadonlyArray3<'_, f32>,
    test: &PyReadonlyArray3<'_, f32>,
    score: impl Fn(&Rgb32Image, &Rgb32Image) -> f64 + Send + Sync,
) -> PyResult<f64> {
    let r = image_in(reference, "reference")?;
    let t = image_in(test, "test")?;
    same_size(&r, &t, ("reference", "test"))?;
    Ok(py.detach(|| score(&metrics::display(&r), &metrics::display(&t))))
}

/// PSNR in dB of `test` against `reference` on display values (capped as the eval caps
/// identical images).
#[pyfunction]
pub fn psnr(
    py: Python<'_>,
    reference: PyReadonlyArray3<'_, f32>,
    test: PyReadonlyArray3<'_, f32>,
) -> PyResult<f64> {
    compare(py, &reference, &test, |r, t| {
        metrics::psnr(r, t).min(PSNR_CAP)
    })
}

/// SSIM of `test` against `reference` on display values.
#[pyfunction]
pub fn ssim(
    py: Python<'_>,
    reference: PyReadonlyArray3<'_, f32>,
    test: PyReadonlyArray3<'_, f32>,
) -> PyResult<f64> {
    compare(py, &reference, &test, metrics::ssim)
}

/// Mean LDR-FLIP error of `test` against `reference` (the eval's viewing distance).
#[pyfunction]
pub fn flip(
    py: Python<'_>,
    reference: PyReadonlyArray3<'_, f32>,
    test: PyReadonlyArray3<'_, f32>,
) -> PyResult<f64> {
    compare(py, &reference, &test, |r, t| {
        metrics::flip(r, t, DEFAULT_PPD).mean
    })
}

/// Temporal error: the mean absolute difference between the method's change from
/// `prev_test` to `test` and the reference's from `prev_reference` to `reference`.
#[pyfunction]
pub fn temporal_error(
    py: Python<'_>,
    prev_test: PyReadonlyArray3<'_, f32>,
    test: PyReadonlyArray3<'_, f32>,
    prev_reference: PyReadonlyArray3<'_, f32>,
    reference: PyReadonlyArray3<'_, f32>,
) -> PyResult<f64> {
    let images = [
        image_in(&prev_test, "prev_test")?,
        image_in(&test, "test")?,
        image_in(&prev_reference, "prev_reference")?,
        image_in(&reference, "reference")?,
    ];
    for (img, name) in images
        .iter()
        .zip(["prev_test", "test", "prev_reference", "reference"])
    {
        same_size(&images[0], img, ("prev_test", name))?;
    }
    Ok(py.detach(|| {
        let d = images.each_ref().map(metrics::display);
        metrics::temporal_error(&d[0], &d[1], &d[2], &d[3])
    }))
}

/// The eval's tone map: linear radiance to sRGB-encoded display values in [0, 1] (what
/// its PNGs hold, what every score compares).
#[pyfunction]
pub fn tonemap<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<'_, f32>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let img = image_in(&image, "image")?;
    let d = metrics::display(&img);
    let rgba: Vec<[f32; 4]> = d.data.iter().map(|p| [p[0], p[1], p[2], 1.0]).collect();
    Ok(image_out(py, d.width, d.height, &rgba, 3))
}
