//! `dvr._native`: the engine behind the `dvr` Python package. The Python layer
//! (`python/dvr/`) holds the classes users edit (scenes as dicts, cameras, lights,
//! transfer functions as control points); this module holds what touches the engine:
//! volumes, scene checking, the renderer and the metrics. Every engine error becomes a
//! Python exception carrying the CLI's message: `ValueError` for bad input (arrays,
//! scenes, settings), `RuntimeError` for the device.

mod convert;
mod image;
mod metrics;
mod renderer;
mod scene;
mod volume;
mod warnings;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    warnings::install();
    m.add(
        "DataDroppedWarning",
        m.py().get_type::<warnings::DataDroppedWarning>(),
    )?;
    m.add_class::<volume::Volume>()?;
    m.add_function(wrap_pyfunction!(set_assets_dir, m)?)?;
    m.add_function(wrap_pyfunction!(assets_dir, m)?)?;
    m.add_class::<renderer::Renderer>()?;
    m.add_function(wrap_pyfunction!(renderer::denoiser_names, m)?)?;
    m.add_function(wrap_pyfunction!(renderer::unused_overrides, m)?)?;
    m.add_function(wrap_pyfunction!(scene::scene_dict, m)?)?;
    m.add_function(wrap_pyfunction!(scene::builtin_scene_names, m)?)?;
    m.add_function(wrap_pyfunction!(scene::check_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene::tf_preset, m)?)?;
    m.add_function(wrap_pyfunction!(scene::tf_file, m)?)?;
    m.add_function(wrap_pyfunction!(scene::tf_preset_names, m)?)?;
    m.add_function(wrap_pyfunction!(scene::check_tf, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::psnr, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::ssim, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::flip, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::temporal_error, m)?)?;
    m.add_function(wrap_pyfunction!(metrics::tonemap, m)?)?;
    m.add_function(wrap_pyfunction!(image::encode_image, m)?)?;
    m.add_function(wrap_pyfunction!(validation_messages, m)?)?;
    Ok(())
}

/// Messages the Vulkan validation layer reported in this process (`DVR_VALIDATION=1`
/// turns it on): the tests require none, as the CLI's do.
#[pyfunction]
fn validation_messages() -> usize {
    dvr_engine::gpu::validation::message_count()
}

/// Makes `path` the assets folder (presets, the MRI, RAE networks) unless `$DVR_ASSETS`
/// is set: the package calls it at import with the copy its wheel carries.
#[pyfunction]
fn set_assets_dir(path: std::path::PathBuf) {
    dvr_engine::assets::set_assets_dir(path);
}

/// The assets folder in effect.
#[pyfunction]
fn assets_dir() -> std::path::PathBuf {
    dvr_engine::assets::assets_dir()
}
