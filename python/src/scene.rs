//! Scenes and transfer functions cross the boundary as the dicts their TOML files hold
//! (`dvr.Scene` and `dvr.TransferFunction` edit those dicts in Python); the engine
//! parses and checks them with the same code, and so the same messages, as the CLI.

use crate::convert::{from_toml, to_toml, value_error};
use dvr_engine::scene::Scene;
use dvr_engine::transfer::TransferFunction;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A scene dict as the engine's checked scene; `origin` names it in errors.
pub fn scene_from_dict(d: &Bound<'_, PyDict>, origin: &str) -> PyResult<Scene> {
    let value = to_toml(d.as_any(), "scene")?;
    let text = toml::to_string(&value).map_err(value_error)?;
    Scene::from_toml_str(&text, origin).map_err(value_error)
}

/// Control points (the `point` list of a TF file) as the engine's checked TF.
pub fn tf_from_dict(d: &Bound<'_, PyDict>) -> PyResult<TransferFunction> {
    let value = to_toml(d.as_any(), "transfer function")?;
    let text = toml::to_string(&value).map_err(value_error)?;
    TransferFunction::from_toml_str(&text, "transfer function").map_err(value_error)
}

pub fn toml_dict<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    let value: toml::Value = toml::from_str(text).map_err(value_error)?;
    from_toml(py, &value)
}

/// The dict of a built-in scene (`"phantom/orbit"`) or a scene file, paths in it made
/// relative to the working directory.
#[pyfunction]
pub fn scene_dict<'py>(py: Python<'py>, name_or_path: &str) -> PyResult<Bound<'py, PyAny>> {
    let scene = Scene::open(name_or_path).map_err(value_error)?;
    toml_dict(py, &scene.to_toml().map_err(value_error)?)
}

/// The built-in scene names, `<dataset>/<animation>`.
#[pyfunction]
pub fn builtin_scene_names() -> Vec<String> {
    Scene::builtin_names()
}

/// Checks a scene dict as a scene file is checked; returns it as the engine writes it
/// back (defaults filled in).
#[pyfunction]
pub fn check_scene<'py>(
    py: Python<'py>,
    scene: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyAny>> {
    let scene = scene_from_dict(scene, "scene")?;
    toml_dict(py, &scene.to_toml().map_err(value_error)?)
}

/// A shipped TF preset, by name, as its dict.
#[pyfunction]
pub fn tf_preset<'py>(py: Python<'py>, name: &str) -> PyResult<Bound<'py, PyAny>> {
    let tf = TransferFunction::preset(name).map_err(value_error)?;
    toml_dict(py, &tf.to_toml())
}

/// A TF file as its dict.
#[pyfunction]
pub fn tf_file<'py>(py: Python<'py>, path: std::path::PathBuf) -> PyResult<Bound<'py, PyAny>> {
    let tf = TransferFunction::load(&path).map_err(value_error)?;
    toml_dict(py, &tf.to_toml())
}

/// The names of the shipped TF presets.
#[pyfunction]
pub fn tf_preset_names() -> PyResult<Vec<String>> {
    TransferFunction::preset_names().map_err(value_error)
}

/// Checks a TF dict (`{"name": ..., "point": [...]}`) as a TF file is checked.
#[pyfunction]
pub fn check_tf(tf: &Bound<'_, PyDict>) -> PyResult<()> {
    tf_from_dict(tf).map(|_| ())
}
