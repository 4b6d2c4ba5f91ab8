//! `dvr.Volume`: a density volume in the engine's form, from a numpy array, a file or a
//! built-in dataset. Arrays are indexed `[z, y, x]` (C order, x fastest in memory, as
//! nibabel's `get_fdata().T`, pydicom stacks and zarr arrays usually are), and
//! `spacing` is given in the same axis order as the array's shape.

use crate::convert::value_error;
use dvr_engine::renderer::scene_setup::DEFAULT_VOLUME_SIZE;
use dvr_engine::scene::parse_gpu_memory;
use dvr_engine::volume::{Volume as EngineVolume, VolumeData, Voxels};
use numpy::{PyArray3, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::prelude::*;
use std::path::PathBuf;

#[pyclass(module = "dvr._native", frozen)]
pub struct Volume {
    pub inner: EngineVolume,
}

/// `array`'s elements in C order (non-contiguous views are copied).
fn voxels_of<T: numpy::Element + Copy>(a: &Bound<'_, PyUntypedArray>) -> PyResult<Vec<T>> {
    let typed = a.cast::<PyArray3<T>>()?;
    let ro = typed.readonly();
    Ok(ro.as_array().iter().copied().collect())
}

#[pymethods]
impl Volume {
    /// A volume from a 3-D numpy array indexed `[z, y, x]` (uint8, uint16, int16 or
    /// float32) with `spacing` (mm) in the same order. Values are normalised to density
    /// by the rule the file loaders follow: float32 in [0, 1] is density as it is,
    /// anything else is windowed to its range.
    #[new]
    #[pyo3(signature = (array, spacing = (1.0, 1.0, 1.0), name = "array"))]
    fn new(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        spacing: (f64, f64, f64),
        name: &str,
    ) -> PyResult<Self> {
        let a = array.cast::<PyUntypedArray>().map_err(|_| {
            value_error(format!(
                "{name}: expected a numpy array, got {}",
                array
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            ))
        })?;
        if a.ndim() != 3 {
            return Err(value_error(format!(
                "{name}: expected a 3-D array indexed [z, y, x], got {} dimension(s) (shape {:?})",
                a.ndim(),
                a.shape()
            )));
        }
        let shape = a.shape();
        if shape.contains(&0) {
            return Err(value_error(format!(
                "{name}: the array is empty (shape {shape:?})"
            )));
        }
        let too_big = |n: usize| {
            u32::try_from(n)
                .map_err(|_| value_error(format!("{name}: shape {shape:?} is too large")))
        };
        let dims = [too_big(shape[2])?, too_big(shape[1])?, too_big(shape[0])?];
        let dtype = a.dtype();
        let voxels = if dtype.is_equiv_to(&numpy::dtype::<u8>(py)) {
            Voxels::U8(voxels_of::<u8>(a)?)
        } else if dtype.is_equiv_to(&numpy::dtype::<u16>(py)) {
            Voxels::U16(voxels_of::<u16>(a)?)
        } else if dtype.is_equiv_to(&numpy::dtype::<i16>(py)) {
            Voxels::I16(voxels_of::<i16>(a)?)
        } else if dtype.is_equiv_to(&numpy::dtype::<f32>(py)) {
            Voxels::F32(voxels_of::<f32>(a)?)
        } else {
            return Err(value_error(format!(
                "{name}: dtype {dtype} is not a volume type (uint8, uint16, int16 or float32; \
                 convert with .astype(numpy.float32))"
            )));
        };
        let spacing = [spacing.2 as f32, spacing.1 as f32, spacing.0 as f32];
        let inner = py
            .detach(|| EngineVolume::from_voxels(name, dims, spacing, voxels))
            .map_err(value_error)?;
        Ok(Self { inner })
    }

    /// Loads a volume file: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), DICOM (a folder or
    /// a .dcm file) or raw data with a `<file>.json`/`.toml` sidecar, as the CLI does.
    /// `gpu_memory` ("512M"): of an OME-Zarr image's levels, the finest that fits it.
    #[staticmethod]
    #[pyo3(signature = (path, gpu_memory = None))]
    fn load(py: Python<'_>, path: PathBuf, gpu_memory: Option<String>) -> PyResult<Self> {
        let budget = gpu_memory
            .map(|s| parse_gpu_memory(&s).map_err(|e| value_error(format!("gpu_memory: {e}"))))
            .transpose()?;
        let inner = py
            .detach(|| EngineVolume::load_within(&path, None, budget))
            .map_err(value_error)?;
        Ok(Self { inner })
    }

    /// A built-in dataset: `phantom` (CT-like head), `cloud` (a homogeneous medium),
    /// both `size`³, `sparse` (blobs and tubes, size×size×size/2, held dense here) or
    /// `mri` (the bundled MNI152 T1; `size` is ignored).
    #[staticmethod]
    #[pyo3(signature = (name, size = DEFAULT_VOLUME_SIZE))]
    fn builtin(py: Python<'_>, name: &str, size: u32) -> PyResult<Self> {
        let name = name.to_string();
        let inner = py
            .detach(|| EngineVolume::builtin(&name, size))
            .map_err(value_error)?;
        Ok(Self { inner })
    }

    /// The name errors and pages use (file stem, built-in name, or as given).
    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    /// The array shape, `(z, y, x)`.
    #[getter]
    fn shape(&self) -> (u32, u32, u32) {
        let d = self.inner.dims;
        (d[2], d[1], d[0])
    }

    /// Voxel size in mm, `(z, y, x)`.
    #[getter]
    fn spacing(&self) -> (f32, f32, f32) {
        let s = self.inner.spacing;
        (s[2], s[1], s[0])
    }

    /// The physical values that map to density 0 and 1.
    #[getter]
    fn window(&self) -> (f32, f32) {
        (self.inner.window[0], self.inner.window[1])
    }

    /// How the GPU stores it: `uint8`, `uint16` or `float32`.
    #[getter]
    fn dtype(&self) -> &'static str {
        match self.inner.data {
            VolumeData::U8(_) => "uint8",
            VolumeData::U16(_) => "uint16",
            VolumeData::F32(_) => "float32",
        }
    }

    /// The normalised densities in [0, 1] as a float32 array indexed `[z, y, x]`.
    fn to_numpy<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        let d = self.inner.dims.map(|n| n as usize);
        let data = &self.inner.data;
        let flat: Vec<f32> = (0..data.len())
            .map(|i| data.get(i).unwrap_or(0.0))
            .collect();
        let array = numpy::ndarray::Array3::from_shape_vec((d[2], d[1], d[0]), flat)
            .expect("a volume holds dims' product of voxels");
        PyArray3::from_owned_array(py, array)
    }

    fn __repr__(&self) -> String {
        let (z, y, x) = self.shape();
        let (sz, sy, sx) = self.spacing();
        format!(
            "Volume({:?}, shape=({z}, {y}, {x}), spacing=({sz}, {sy}, {sx}), dtype={})",
            self.inner.name,
            self.dtype()
        )
    }
}
