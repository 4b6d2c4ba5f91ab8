//! `dvr.Volume`: a density volume in the engine's form, from a numpy array, a file or a
//! built-in dataset. Arrays are indexed `[z, y, x]` (C order, x fastest in memory, as
//! nibabel's `get_fdata().T`, pydicom stacks and zarr arrays usually are), and
//! `spacing` is given in the same axis order as the array's shape.

use crate::convert::value_error;
use crate::warnings;
use dvr_engine::renderer::scene_setup::DEFAULT_VOLUME_SIZE;
use dvr_engine::scene::parse_gpu_memory;
use dvr_engine::volume::{SampleKind, Series, Volume as EngineVolume, VolumeData, Voxels};
use numpy::{
    PyArray2, PyArray3, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::IntoPyDict;
use std::path::PathBuf;
use std::sync::Arc;

/// The attributes a volume has (named when a mistyped one is asked for).
const FIELDS: &[&str] = &[
    "name",
    "channels",
    "times",
    "channel_names",
    "shape",
    "spacing",
    "window",
    "dtype",
    "stored_as",
    "to_patient",
    "data",
];

/// A density volume in the engine's form: from a numpy array, a file or a built-in
/// dataset, held in RAS order (see `to_patient`) with its data window and stored type.
#[pyclass(module = "dvr._native", frozen)]
pub struct Volume {
    /// Channel 0 at time point 0 (all of a plain volume).
    pub inner: EngineVolume,
    /// The channels and time points of a volume of more than one.
    pub series: Option<Arc<Series>>,
}

/// A 3-D array's voxels (x fastest) of a volume dtype, `dtype` named by `name` in errors.
fn voxels_any(
    py: Python<'_>,
    a: &Bound<'_, PyUntypedArray>,
    name: &str,
) -> PyResult<(Voxels, bool)> {
    let dtype = a.dtype();
    let voxels = if dtype.is_equiv_to(&numpy::dtype::<u8>(py)) {
        Voxels::U8(voxels_of::<u8>(a)?)
    } else if dtype.is_equiv_to(&numpy::dtype::<u16>(py)) {
        Voxels::U16(voxels_of::<u16>(a)?)
    } else if dtype.is_equiv_to(&numpy::dtype::<i16>(py)) {
        Voxels::I16(voxels_of::<i16>(a)?)
    } else if dtype.is_equiv_to(&numpy::dtype::<f32>(py)) {
        Voxels::F32(voxels_of::<f32>(a)?)
    } else if dtype.is_equiv_to(&numpy::dtype::<f64>(py)) {
        // The GPU holds float32 at most; float64 is what numpy computes in, so it is
        // common input and narrowing it is what a user would do by hand.
        let wide = voxels_of::<f64>(a)?;
        Voxels::F32(wide.into_iter().map(|x| x as f32).collect())
    } else {
        return Err(value_error(format!(
            "{name}: dtype {dtype} is not a volume type (uint8, uint16, int16, float32 or \
             float64; convert with .astype(numpy.float32))"
        )));
    };
    Ok((voxels, dtype.is_equiv_to(&numpy::dtype::<f64>(py))))
}

/// The grid (x, y, z voxels) of an array whose last three axes are z, y, x: an error
/// names an empty array or one too large.
fn grid_of(shape: &[usize], name: &str) -> PyResult<[u32; 3]> {
    if shape.contains(&0) {
        return Err(value_error(format!(
            "{name}: the array is empty (shape {shape:?})"
        )));
    }
    let too_big = |n: usize| {
        u32::try_from(n).map_err(|_| value_error(format!("{name}: shape {shape:?} is too large")))
    };
    let n = shape.len();
    Ok([
        too_big(shape[n - 1])?,
        too_big(shape[n - 2])?,
        too_big(shape[n - 3])?,
    ])
}

/// A volume of several channels or time points: `a` is `(C, Z, Y, X)` or
/// `(T, C, Z, Y, X)`; each channel is normalised through the window of its first time
/// point, as a file's series is.
fn from_series_array(
    py: Python<'_>,
    a: &Bound<'_, PyUntypedArray>,
    spacing: (f64, f64, f64),
    name: &str,
    channels: Option<Vec<usize>>,
) -> PyResult<Volume> {
    let shape = a.shape().to_vec();
    let (times, count) = if shape.len() == 4 {
        (1, shape[0])
    } else {
        (shape[0], shape[1])
    };
    let lead = shape.len() - 3;
    let (z, y, x) = (shape[lead], shape[lead + 1], shape[lead + 2]);
    let dims = grid_of(&shape, name)?;
    let flat = a.call_method1("reshape", ((times * count, z, y, x),))?;
    let mut blocks = Vec::with_capacity(times);
    let mut wide = false;
    for t in 0..times {
        let mut row = Vec::with_capacity(count);
        for c in 0..count {
            let block = flat.get_item(t * count + c)?;
            let block = block.cast::<PyUntypedArray>()?;
            let (v, w) = voxels_any(py, block, name)?;
            wide |= w;
            row.push(v);
        }
        blocks.push(row);
    }
    let spacing = [spacing.2 as f32, spacing.1 as f32, spacing.0 as f32];
    let series = py
        .detach(|| Series::from_arrays(name, dims, spacing, blocks, channels.as_deref()))
        .map_err(value_error)?;
    Volume::of_series(py, series, wide)
}

impl Volume {
    /// A volume of a series: channel 0 at time 0 as `inner`, the series beside it.
    fn of_series(py: Python<'_>, series: Series, wide: bool) -> PyResult<Self> {
        let mut first = py.detach(|| series.read(0)).map_err(value_error)?;
        let mut inner = first.swap_remove(0);
        if wide {
            inner.sample_kind = SampleKind::F64;
        }
        let info = series.info();
        let one = info.channels.len() == 1 && info.times == 1;
        Ok(Self {
            inner,
            series: (!one).then(|| Arc::new(series)),
        })
    }
}

/// `array`'s elements in C order (non-contiguous views are copied).
fn voxels_of<T: numpy::Element + Copy>(a: &Bound<'_, PyUntypedArray>) -> PyResult<Vec<T>> {
    let typed = a.cast::<PyArray3<T>>()?;
    let ro = typed.readonly();
    Ok(ro.as_array().iter().copied().collect())
}

#[pymethods]
impl Volume {
    /// A volume from a 3-D numpy array indexed `[z, y, x]` (uint8, uint16, int16,
    /// float32, or float64, held as float32) with `spacing` (mm) in the same order. Values are normalised to density
    /// by the rule the file loaders follow: float32 in [0, 1] is density as it is,
    /// anything else is windowed to its range.
    #[new]
    #[pyo3(signature = (array, spacing = (1.0, 1.0, 1.0), name = "array", channels = None))]
    fn new(
        py: Python<'_>,
        array: &Bound<'_, PyAny>,
        spacing: (f64, f64, f64),
        name: &str,
        channels: Option<Vec<usize>>,
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
        if a.ndim() == 4 || a.ndim() == 5 {
            return from_series_array(py, a, spacing, name, channels);
        }
        if a.ndim() != 3 {
            return Err(value_error(format!(
                "{name}: expected an array indexed [z, y, x], [c, z, y, x] (channels) or \
                 [t, c, z, y, x] (time points of channels), got {} dimension(s) (shape {:?})",
                a.ndim(),
                a.shape()
            )));
        }
        if channels.is_some() {
            return Err(value_error(format!(
                "{name}: channels= picks channels of a [c, z, y, x] or [t, c, z, y, x] array; this one is 3-D"
            )));
        }
        let dims = grid_of(a.shape(), name)?;
        let (voxels, wide) = voxels_any(py, a, name)?;
        let spacing = [spacing.2 as f32, spacing.1 as f32, spacing.0 as f32];
        let mut inner = py
            .detach(|| EngineVolume::from_voxels(name, dims, spacing, voxels))
            .map_err(value_error)?;
        if wide {
            // `dtype` reports what the user handed over, not the narrowed copy.
            inner.sample_kind = SampleKind::F64;
        }
        Ok(Self {
            inner,
            series: None,
        })
    }

    /// Loads a volume file: NIfTI (.nii, .nii.gz), NRRD (.nrrd, .nhdr), DICOM (a folder or
    /// a .dcm file), numpy's .npy (a 3-D array `[z, y, x]`, 1 mm voxels) or raw data with a `<file>.json`/`.toml` sidecar, as the CLI does.
    /// `gpu_memory` ("512M"): of an OME-Zarr image's levels, the finest that fits it.
    #[staticmethod]
    /// `_stacklevel`: whose line a dropped-data warning names (2 from `dvr.load_volume`,
    /// so it is the user's line there too).
    #[pyo3(signature = (path, gpu_memory = None, _stacklevel = 1))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        gpu_memory: Option<String>,
        _stacklevel: i32,
    ) -> PyResult<Self> {
        if path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("npy"))
        {
            // numpy's own format, read by numpy (no pickles: a .npy is data, not code);
            // it states no voxel size, so 1 mm as for an array.
            let array = py
                .import("numpy")?
                .getattr("load")?
                .call(
                    (path.as_os_str(),),
                    Some(&[("allow_pickle", false)].into_py_dict(py)?),
                )
                .map_err(|e| value_error(format!("{}: {e}", path.display())))?;
            let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned());
            return Self::new(
                py,
                &array,
                (1.0, 1.0, 1.0),
                stem.as_deref().unwrap_or("npy"),
                None,
            );
        }
        let budget = gpu_memory
            .map(|s| parse_gpu_memory(&s).map_err(|e| value_error(format!("gpu_memory: {e}"))))
            .transpose()?;
        // What the loader drops (extra channels, time points) it logs; the user sees it
        // as a DataDroppedWarning rather than a line on stderr.
        let (loaded, dropped) =
            py.detach(|| warnings::capture(|| EngineVolume::load_within(&path, None, budget)));
        let inner = loaded.map_err(value_error)?;
        warnings::issue(py, &dropped, _stacklevel)?;
        Ok(Self {
            inner,
            series: None,
        })
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
        Ok(Self {
            inner,
            series: None,
        })
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

    /// The type the samples had in the array or file: `uint8`, `uint16`, `int16`,
    /// `float32` or `float64`.
    #[getter]
    fn dtype(&self) -> &'static str {
        self.inner.sample_kind.name()
    }

    /// Index `[z, y, x]` to patient space (RAS+, mm) as a 4×4 affine: `p = A @ (z, y,
    /// x, 1)`. The voxels are stored in RAS order whatever the file's orientation (x
    /// along +Right, y +Anterior, z +Superior), so its 3×3 part is the spacings on the
    /// anti-diagonal: array axis 0 (z) steps along S, axis 2 (x) along R.
    #[getter]
    fn to_patient<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let t = &self.inner.to_patient;
        let mut m = [[0.0f64; 4]; 4];
        for (r, row) in m.iter_mut().take(3).enumerate() {
            for (c, cell) in row.iter_mut().take(3).enumerate() {
                // Array axis c is the engine's axis 2 - c.
                *cell = t.axes[2 - c][r];
            }
            row[3] = t.origin[r];
        }
        m[3][3] = 1.0;
        let array = numpy::ndarray::Array2::from_shape_fn((4, 4), |(r, c)| m[r][c]);
        PyArray2::from_owned_array(py, array)
    }

    /// The normalised densities in [0, 1] as a float32 array indexed `[z, y, x]` (a
    /// copy; the same as `to_numpy()`).
    #[getter]
    fn data<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray3<f32>> {
        self.to_numpy(py)
    }

    /// Opens a volume of several channels or time points: one file (its channel and
    /// time axes), a list of files (one channel each, resampled onto the first file's
    /// grid; with `times=True`, one time point each) or a glob (`scan_*.nii.gz`, time
    /// points sorted by name). `channels` picks some, in that order.
    #[staticmethod]
    #[pyo3(signature = (paths, channels = None, times = false))]
    fn load_series(
        py: Python<'_>,
        paths: &Bound<'_, PyAny>,
        channels: Option<Vec<usize>>,
        times: bool,
    ) -> PyResult<Self> {
        let picked = channels.as_deref();
        let series = if let Ok(one) = paths.extract::<PathBuf>() {
            let glob = one.to_string_lossy().contains(['*', '?']);
            py.detach(|| {
                if glob {
                    Series::open_glob(&one, picked)
                } else {
                    Series::open(&one, picked)
                }
            })
        } else {
            let list: Vec<PathBuf> = paths.extract()?;
            py.detach(|| {
                if times {
                    Series::open_times(&list, picked)
                } else {
                    Series::open_channels(&list, picked)
                }
            })
        }
        .map_err(value_error)?;
        Self::of_series(py, series, false)
    }

    /// How many channels the volume has.
    #[getter]
    fn channels(&self) -> usize {
        self.series.as_ref().map_or(1, |s| s.info().channels.len())
    }

    /// How many time points the volume has.
    #[getter]
    fn times(&self) -> usize {
        self.series.as_ref().map_or(1, |s| s.info().times)
    }

    /// The names of the channels (the file's labels, file stems, or `channel <i>`).
    #[getter]
    fn channel_names(&self) -> Vec<String> {
        match &self.series {
            Some(s) => s.info().channels.iter().map(|c| c.name.clone()).collect(),
            None => vec![self.inner.name.clone()],
        }
    }

    /// Channel `index` at time point `time` as a volume of its own (on the series' grid,
    /// with its own window).
    #[pyo3(signature = (index, time = 0))]
    fn channel(&self, py: Python<'_>, index: usize, time: usize) -> PyResult<Self> {
        let Some(series) = &self.series else {
            if index == 0 && time == 0 {
                return Ok(Self {
                    inner: self.inner.clone(),
                    series: None,
                });
            }
            return Err(value_error(format!(
                "channel {index} at time {time}: the volume has one channel and one time point"
            )));
        };
        let count = series.info().channels.len();
        if index >= count {
            return Err(value_error(format!(
                "channel {index} does not exist: the volume has {count} (0 to {})",
                count - 1
            )));
        }
        let mut all = py.detach(|| series.read(time)).map_err(value_error)?;
        Ok(Self {
            inner: all.swap_remove(index),
            series: None,
        })
    }

    /// A mistyped attribute names the ones that exist (as cameras, lights and scenes do).
    fn __getattr__(&self, name: &str) -> PyResult<()> {
        Err(pyo3::exceptions::PyAttributeError::new_err(format!(
            "Volume has no field '{name}' (fields: {})",
            FIELDS.join(", ")
        )))
    }

    fn __setattr__(&self, name: &str, _value: &Bound<'_, PyAny>) -> PyResult<()> {
        let what = if FIELDS.contains(&name) {
            format!("Volume.{name} cannot be assigned: a volume is immutable")
        } else {
            format!(
                "Volume has no field '{name}' (fields: {})",
                FIELDS.join(", ")
            )
        };
        Err(pyo3::exceptions::PyAttributeError::new_err(what))
    }

    /// How the GPU stores it: `uint8`, `uint16` (int16 is shifted into it) or `float32`.
    #[getter]
    fn stored_as(&self) -> &'static str {
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
