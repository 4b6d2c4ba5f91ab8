//! Density volumes on the CPU: loading, procedural datasets, normalisation and the
//! majorant grid. No GPU: this crate builds and tests without a Vulkan loader, and the
//! engine re-exports it as `dvr_engine::volume` (with `files`, `bytes` and `assets`, the
//! input/output rules and the shipped files every layer above uses).
//!
//! The path tracer samples one scalar density per voxel from a 3D texture (R8/R16 unorm or
//! R32F) and indexes its transfer functions by that value. This module produces exactly
//! that data and nothing GPU-side: a [`Volume`] is a flat array (x fastest, then y, then
//! z) of densities with `[0, 1]` meaning, its dimensions and its voxel spacing in mm. The
//! GPU layer uploads [`VolumeData::as_bytes`] as is.
//!
//! # Sources
//!
//! Formats are rows of one table (`formats.rs`: name endings, magic bytes, folder probes).
//!
//! | source | how | file |
//! | --- | --- | --- |
//! | raw | dims/format/spacing from [`RawParams`] or a sidecar `<file>.json` / `<file>.toml` | `raw.rs` |
//! | NRRD | `.nrrd` (attached) and `.nhdr` (detached); raw/gzip; uint8/uint16/int16/float | `nrrd.rs` |
//! | NIfTI-1 | `.nii`, `.nii.gz`; uint8/int16/uint16/float32; `scl_slope/inter` | `nifti.rs` |
//! | DICOM | a folder of slices (uncompressed little endian, 8/16 bit) | `dicom.rs` |
//! | OME-TIFF | `.ome.tif(f)` z-stacks (channel 0, time 0 here, all of them as a series; spacing from the OME-XML), plain `.tif` page stacks; uint8/uint16/int16/float32 | `ome_tiff.rs` |
//! | OME-Zarr | an image group (0.4 on Zarr v2, 0.5 on Zarr v3; the finest level that fits) or one level's array; uint8/uint16/int16/float32; blosc, gzip, zstd | `zarr.rs` |
//! | a series | up to 4 channels on one grid at T time points, read one time point at a time ([`Series`]): NIfTI `dim[4]`/`dim[5]`, NRRD `kinds`, OME-Zarr `c`/`t` axes and `omero`, OME-TIFF `SizeC`/`SizeT`, lists and globs of files | `series.rs` |
//! | built-in | `phantom` (CT-like head, thin vessels), `cloud` (homogeneous), `mri` (MNI152) | `builtin.rs` |
//!
//! Loaders keep the file's index order (no reorientation to RAS/LPS): the renderer
//! places the volume by its dims and spacing only.
//!
//! # Normalisation (the window)
//!
//! Stored values are rescaled to physical units (`slope * v + intercept`), then a window
//! `[lo, hi]` maps to `[0, 1]`; [`Volume::window`] records it so transfer functions can
//! be written in physical units (e.g. Hounsfield) and converted. The exact rule:
//!
//! - **integer data**: the window is the data's `[min, max]` when `max > min` and
//!   `max - min` is less than a quarter of the type's range (DICOM: the `BitsStored`
//!   range), e.g. 12-bit CT in a 16-bit NRRD or NIfTI; otherwise the type's full range,
//!   so files of one type stay comparable. 8-bit data stays [`VolumeData::U8`], 16-bit data (signed or
//!   not) becomes [`VolumeData::U16`] rescaled into `0..=65535`.
//! - **float data**: NaN/Inf is an error ([`VolumeError::NonFinite`]), never clamped
//!   silently. Data already inside `[0, 1]` is kept (window `[0, 1]`); otherwise the
//!   window is `[min, max]`. The result is [`VolumeData::F32`] clamped to `[0, 1]`.
//!
//! # Limits
//!
//! Each dimension must be in `1..=4096` and the voxel count at most 2^31, so linear
//! indices fit in 32 bits on the GPU. 4096 is the upper bound of one 3D texture on the
//! GPUs this engine targets; Vulkan itself guarantees only 256 (`maxImageDimension3D`),
//! so the GPU layer still checks the device's limit before uploading.

pub mod assets;
pub mod blocks;
mod builtin;
pub mod bytes;
mod cloud;
mod dicom;
mod error;
pub mod files;
mod formats;
mod io;
pub mod labels;
mod majorant;
mod nifti;
mod normalise;
mod nrrd;
mod ome_tiff;
mod orientation;
mod phantom;
mod procedural;
mod raw;
mod samples;
mod series;
pub mod sparse;
#[cfg(test)]
mod write;
mod zarr;

use std::path::Path;

pub use builtin::BUILTIN_NAMES;
pub use error::VolumeError;
pub use majorant::MajorantGrid;
pub use orientation::PatientTransform;
pub use raw::{RawFormat, RawParams};
pub use samples::SampleKind;
pub use series::{expand_glob, ChannelInfo, Series, SeriesInfo, MAX_CHANNELS};

use samples::{Samples, Stored};

/// Largest accepted dimension along any axis.
pub const MAX_DIM: u32 = 4096;
/// Largest accepted voxel count.
pub const MAX_VOXELS: u64 = 1 << 31;

/// A scalar density volume, normalised to `[0, 1]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Volume {
    /// Short name: the file stem, the folder name of a DICOM series, or the built-in name.
    pub name: String,
    /// Voxels along x, y, z.
    pub dims: [u32; 3],
    /// Voxel size in mm along x, y, z.
    pub spacing: [f32; 3],
    /// Where the voxels lie in patient space (RAS+, mm). The voxels are stored in RAS
    /// order (x along +R, y along +A, z along +S: see `orientation.rs`), so its axes are
    /// the spacings along the diagonal; its origin is the first voxel's position.
    pub to_patient: PatientTransform,
    /// The physical values (after rescale) that map to density 0 and 1.
    pub window: [f32; 2],
    /// The type the samples were stored as (in the file or the array) before
    /// normalisation: what a user's `dtype` was.
    pub sample_kind: SampleKind,
    /// The densities, x fastest, then y, then z.
    pub data: VolumeData,
}

/// Stored voxels as an application hands them over (x fastest), before normalisation:
/// see [`Volume::from_voxels`].
#[derive(Clone, Debug, PartialEq)]
pub enum Voxels {
    U8(Vec<u8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    F32(Vec<f32>),
}

/// Normalised voxel data: unorm integers or floats in `[0, 1]`, x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub enum VolumeData {
    /// `v / 255` is the density (uploads as R8 unorm).
    U8(Vec<u8>),
    /// `v / 65535` is the density (uploads as R16 unorm).
    U16(Vec<u16>),
    /// The density itself, in `[0, 1]` (uploads as R32 float).
    F32(Vec<f32>),
}

impl VolumeData {
    /// Number of voxels.
    pub fn len(&self) -> usize {
        match self {
            VolumeData::U8(v) => v.len(),
            VolumeData::U16(v) => v.len(),
            VolumeData::F32(v) => v.len(),
        }
    }

    /// True when there are no voxels.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Bytes per voxel.
    pub fn bytes_per_voxel(&self) -> usize {
        match self {
            VolumeData::U8(_) => 1,
            VolumeData::U16(_) => 2,
            VolumeData::F32(_) => 4,
        }
    }

    /// The normalised density of voxel `i` (`None` past the end).
    pub fn get(&self, i: usize) -> Option<f32> {
        match self {
            VolumeData::U8(v) => v.get(i).map(|&x| f32::from(x) / 255.0),
            VolumeData::U16(v) => v.get(i).map(|&x| f32::from(x) / 65535.0),
            VolumeData::F32(v) => v.get(i).copied(),
        }
    }

    /// The voxels as bytes in native (little-endian on every supported GPU host) order,
    /// ready to copy into a staging buffer.
    pub fn as_bytes(&self) -> &[u8] {
        match self {
            VolumeData::U8(v) => v,
            VolumeData::U16(v) => bytemuck::cast_slice(v),
            VolumeData::F32(v) => bytemuck::cast_slice(v),
        }
    }
}

impl Volume {
    /// Builds a volume from data already normalised to `[0, 1]` (window `[0, 1]`),
    /// checking dims, spacing and data length. `name` stands in for a path in errors.
    pub fn new(
        name: &str,
        dims: [u32; 3],
        spacing: [f32; 3],
        data: VolumeData,
    ) -> Result<Volume, VolumeError> {
        let path = Path::new(name);
        let dims = validate_dims(path, dims.map(i64::from))?;
        let spacing = validate_spacing(path, "spacing", spacing.map(f64::from))?;
        let voxels = voxel_count(dims);
        if data.len() as u64 != voxels {
            let b = data.bytes_per_voxel() as u64;
            return Err(VolumeError::SizeMismatch {
                path: path.to_path_buf(),
                dims,
                format: format_name(&data),
                expected: voxels * b,
                found: data.len() as u64 * b,
            });
        }
        Ok(Volume {
            name: name.to_string(),
            dims,
            spacing,
            to_patient: PatientTransform::aligned(spacing),
            window: [0.0, 1.0],
            sample_kind: match data {
                VolumeData::U8(_) => SampleKind::U8,
                VolumeData::U16(_) => SampleKind::U16,
                VolumeData::F32(_) => SampleKind::F32,
            },
            data,
        })
    }

    /// Loads a volume from a file or a DICOM folder.
    ///
    /// With `raw` given the file is read as raw voxels whatever its extension. Otherwise
    /// the table in `formats.rs` picks the loader: a folder by its probe (Zarr metadata
    /// -> OME-Zarr, any other folder -> a DICOM series), a file by its name's ending,
    /// then by its magic bytes; last, any file with a sidecar `<file>.json`/`<file>.toml`
    /// is raw.
    pub fn load(path: &Path, raw: Option<&RawParams>) -> Result<Volume, VolumeError> {
        Self::load_within(path, raw, None)
    }

    /// [`Volume::load`] for a renderer with `budget` bytes for its volume: of an OME-Zarr
    /// image's levels, the finest whose voxels fit it is read (see `zarr.rs`).
    pub fn load_within(
        path: &Path,
        raw: Option<&RawParams>,
        budget: Option<u64>,
    ) -> Result<Volume, VolumeError> {
        if let Some(params) = raw {
            return raw::load(path, params);
        }
        formats::load(path, formats::Request { budget })
    }

    /// A built-in dataset: `phantom` (CT-like head with thin vessels, U16), `cloud`
    /// (homogeneous non-convex medium, U8), both `size`³ voxels of 1 mm, or `mri` (the
    /// MNI152 T1 template from the assets; `size` is ignored).
    pub fn builtin(name: &str, size: u32) -> Result<Volume, VolumeError> {
        builtin::build(name, size)
    }

    /// Physical size in mm: dims × spacing.
    pub fn extent(&self) -> [f32; 3] {
        [0, 1, 2].map(|i| self.dims[i] as f32 * self.spacing[i])
    }

    /// Size of the voxel data in bytes.
    pub fn byte_size(&self) -> u64 {
        self.data.len() as u64 * self.data.bytes_per_voxel() as u64
    }

    /// Number of voxels.
    pub fn voxel_count(&self) -> u64 {
        voxel_count(self.dims)
    }

    /// Linear index of voxel (x, y, z).
    pub fn index(&self, x: u32, y: u32, z: u32) -> usize {
        (z as usize * self.dims[1] as usize + y as usize) * self.dims[0] as usize + x as usize
    }

    /// Normalised density at voxel (x, y, z), `None` outside.
    pub fn value(&self, x: u32, y: u32, z: u32) -> Option<f32> {
        if x >= self.dims[0] || y >= self.dims[1] || z >= self.dims[2] {
            return None;
        }
        self.data.get(self.index(x, y, z))
    }

    /// Histogram of the normalised densities over `bins` equal bins of `[0, 1]` (the last
    /// bin includes 1.0). Empty for `bins == 0`.
    pub fn histogram(&self, bins: usize) -> Vec<u32> {
        let mut out = vec![0u32; bins];
        if bins == 0 {
            return out;
        }
        let bin = |d: f32| ((d as f64 * bins as f64) as usize).min(bins - 1);
        // Integer data: count each stored value once, then map the counts to bins.
        let mut add_counts = |counts: &[u32], scale: f32| {
            for (v, &c) in counts.iter().enumerate() {
                if c > 0 {
                    let b = bin(v as f32 / scale);
                    out[b] = out[b].saturating_add(c);
                }
            }
        };
        match &self.data {
            VolumeData::U8(v) => {
                let mut counts = vec![0u32; 256];
                v.iter().for_each(|&x| counts[x as usize] += 1);
                add_counts(&counts, 255.0);
            }
            VolumeData::U16(v) => {
                let mut counts = vec![0u32; 65536];
                v.iter().for_each(|&x| counts[x as usize] += 1);
                add_counts(&counts, 65535.0);
            }
            VolumeData::F32(v) => {
                for &x in v {
                    let b = bin(x.clamp(0.0, 1.0));
                    out[b] = out[b].saturating_add(1);
                }
            }
        }
        out
    }

    /// The constant density when every non-zero voxel holds the same value (a
    /// homogeneous medium inside a boundary), so the path tracer can use closed-form free
    /// paths. `None` when values differ or every voxel is zero. Scans all voxels.
    pub fn is_homogeneous(&self) -> Option<f32> {
        fn constant<T: Copy + PartialEq + Default>(v: &[T]) -> Option<T> {
            let zero = T::default();
            let mut nz = v.iter().copied().filter(|&x| x != zero);
            let first = nz.next()?;
            nz.all(|x| x == first).then_some(first)
        }
        match &self.data {
            VolumeData::U8(v) => constant(v).map(|x| f32::from(x) / 255.0),
            VolumeData::U16(v) => constant(v).map(|x| f32::from(x) / 65535.0),
            VolumeData::F32(v) => constant(v),
        }
    }

    /// A volume from stored voxels an application holds (the Python package's numpy
    /// arrays), x fastest, normalised by the rule every file loader follows (see the
    /// module docs): a float array already in `[0, 1]` is density as it is, anything
    /// else is windowed. `name` stands in for a path in errors.
    pub fn from_voxels(
        name: &str,
        dims: [u32; 3],
        spacing: [f32; 3],
        voxels: Voxels,
    ) -> Result<Volume, VolumeError> {
        let path = Path::new(name);
        let dims = validate_dims(path, dims.map(i64::from))?;
        let spacing = validate_spacing(path, "spacing", spacing.map(f64::from))?;
        let samples = match voxels {
            Voxels::U8(v) => Samples::U8(v),
            Voxels::U16(v) => Samples::U16(v),
            Voxels::I16(v) => Samples::I16(v),
            Voxels::F32(v) => Samples::F32(v),
        };
        Volume::from_stored(
            path,
            name.to_string(),
            dims,
            spacing,
            Stored::plain(samples),
        )
    }

    /// Normalises decoded samples, puts them in RAS order by the file's orientation
    /// (when it states one) and wraps them: the shared tail of every loader.
    pub(crate) fn from_stored(
        path: &Path,
        name: String,
        dims: [u32; 3],
        spacing: [f32; 3],
        stored: Stored,
    ) -> Result<Volume, VolumeError> {
        Self::from_stored_in(path, name, dims, spacing, stored, None).map(|(v, _)| v)
    }

    /// [`Volume::from_stored`] through the window `fixed` where given (a series' later
    /// time points), else its own; returns the window used, unrounded.
    pub(crate) fn from_stored_in(
        path: &Path,
        name: String,
        dims: [u32; 3],
        spacing: [f32; 3],
        stored: Stored,
        fixed: Option<(f64, f64)>,
    ) -> Result<(Volume, (f64, f64)), VolumeError> {
        let orientation = stored.orientation;
        let sample_kind = stored.samples.kind();
        let n = normalise::normalise(path, dims, stored, fixed)?;
        let v = Volume {
            name,
            dims,
            spacing,
            to_patient: PatientTransform::aligned(spacing),
            window: n.window,
            sample_kind,
            data: n.data,
        };
        let v = match orientation {
            Some(t) => orientation::to_ras(path, v, t)?,
            None => v,
        };
        Ok((v, n.exact_window))
    }
}

fn format_name(d: &VolumeData) -> &'static str {
    match d {
        VolumeData::U8(_) => "uint8",
        VolumeData::U16(_) => "uint16",
        VolumeData::F32(_) => "float32",
    }
}

pub(crate) fn voxel_count(dims: [u32; 3]) -> u64 {
    dims.iter().map(|&d| u64::from(d)).product()
}

/// Checks dims against the limits of this module (see the module docs).
pub(crate) fn validate_dims(path: &Path, dims: [i64; 3]) -> Result<[u32; 3], VolumeError> {
    let bad = |reason: String| VolumeError::BadDims {
        path: path.to_path_buf(),
        dims: dims.to_vec(),
        reason,
    };
    if dims.iter().any(|&d| d <= 0) {
        return Err(bad("every dimension must be at least 1".into()));
    }
    if let Some(&d) = dims.iter().find(|&&d| d > i64::from(MAX_DIM)) {
        return Err(bad(format!(
            "dimension {d} exceeds {MAX_DIM}, the largest 3D texture this engine uploads"
        )));
    }
    let voxels: u64 = dims.iter().map(|&d| d as u64).product();
    if voxels > MAX_VOXELS {
        return Err(bad(format!(
            "{voxels} voxels exceed the limit of 2^31 = {MAX_VOXELS}"
        )));
    }
    Ok(dims.map(|d| d as u32))
}

/// Smallest voxel spacing accepted, in mm (1 nm: past electron microscopy).
pub const MIN_SPACING_MM: f64 = 1e-6;
/// Largest voxel spacing accepted, in mm (1 km).
pub const MAX_SPACING_MM: f64 = 1e6;
/// Largest ratio between the largest and smallest spacing: anisotropic MRI is about
/// 1:10; past 1:1000 the volume renders as a sheet (and usually a header is wrong).
pub const MAX_ANISOTROPY: f64 = 1e3;

/// Checks that voxel spacings are finite, in `[MIN_SPACING_MM, MAX_SPACING_MM]` and
/// within [`MAX_ANISOTROPY`] of each other; `field` names the header field. Outside
/// those the volume's world size overflows f32 or collapses to a sheet: a black image.
pub(crate) fn validate_spacing(
    path: &Path,
    field: &str,
    spacing: [f64; 3],
) -> Result<[f32; 3], VolumeError> {
    let bad = |problem: String| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.to_string(),
        problem,
    };
    // The bounds are checked as the volume stores spacing, in f32: `1e-6` written in a
    // file is 9.99999997e-7 once rounded, and must still count as the bound it names.
    let in_range = |s: f64| (MIN_SPACING_MM as f32..=MAX_SPACING_MM as f32).contains(&(s as f32));
    if !spacing.iter().all(|&s| s.is_finite() && in_range(s)) {
        return Err(bad(format!(
            "voxel spacing {spacing:?} must be finite and in [{MIN_SPACING_MM:e}, \
             {MAX_SPACING_MM:e}] mm"
        )));
    }
    let (lo, hi) = spacing
        .iter()
        .fold((f64::MAX, 0f64), |(lo, hi), &s| (lo.min(s), hi.max(s)));
    if hi / lo > MAX_ANISOTROPY {
        return Err(bad(format!(
            "voxel spacing {spacing:?}: the largest is {:.0} times the smallest (at most \
             {MAX_ANISOTROPY:.0}); the volume would render as a sheet",
            hi / lo
        )));
    }
    Ok(spacing.map(|s| s as f32))
}

/// [`Volume::load`] on another thread, failing if it does not return within `secs`
/// seconds: what tests of endless or blocking inputs use, so a regression fails the test
/// instead of hanging it (the stuck thread is left behind; the test process ends).
#[cfg(test)]
pub(crate) fn load_within_seconds(path: &Path, secs: u64) -> Result<Volume, VolumeError> {
    let (tx, rx) = std::sync::mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        let _ = tx.send(Volume::load(&p, None));
    });
    rx.recv_timeout(std::time::Duration::from_secs(secs))
        .unwrap_or_else(|_| panic!("loading {} took over {secs} s", path.display()))
}

/// Makes a FIFO at `path` (with `mkfifo`); false where that is not possible, and the
/// test that wants one skips that part.
#[cfg(test)]
pub(crate) fn make_fifo(path: &Path) -> bool {
    std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .is_ok_and(|s| s.success())
}

/// The volume name for a file: its name without the (double) extension.
pub(crate) fn name_of(path: &Path) -> String {
    let file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string());
    let lower = file.to_ascii_lowercase();
    let cut = if lower.ends_with(".nii.gz") {
        file.len() - 7
    } else {
        file.rfind('.').filter(|&i| i > 0).unwrap_or(file.len())
    };
    file[..cut].to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dims_limits_are_enforced_with_clear_messages() {
        let p = Path::new("vol.raw");
        assert_eq!(validate_dims(p, [4, 5, 6]).ok(), Some([4, 5, 6]));
        for (dims, needle) in [
            ([0, 5, 6], "at least 1"),
            ([-3, 5, 6], "at least 1"),
            ([5000, 5, 6], "exceeds 4096"),
            ([4096, 4096, 4096], "2^31"),
        ] {
            let err = validate_dims(p, dims).unwrap_err();
            assert!(matches!(err, VolumeError::BadDims { .. }));
            let msg = err.to_string();
            assert!(msg.contains("vol.raw") && msg.contains(needle), "{msg}");
        }
    }

    #[test]
    fn new_checks_length_and_queries_work() {
        let v = Volume::new(
            "t",
            [2, 2, 1],
            [0.5, 1.0, 2.0],
            VolumeData::U8(vec![0, 255, 51, 0]),
        )
        .expect("valid");
        assert_eq!(v.extent(), [1.0, 2.0, 2.0]);
        assert_eq!(v.byte_size(), 4);
        assert_eq!(v.value(1, 0, 0), Some(1.0));
        assert_eq!(v.value(0, 1, 0), Some(0.2));
        assert_eq!(v.value(2, 0, 0), None);
        assert_eq!(v.histogram(5), vec![2, 1, 0, 0, 1]);
        assert_eq!(v.histogram(0), Vec::<u32>::new());
        assert_eq!(v.is_homogeneous(), None);
        let err =
            Volume::new("short", [2, 2, 2], [1.0; 3], VolumeData::U8(vec![0; 7])).unwrap_err();
        assert!(matches!(err, VolumeError::SizeMismatch { .. }));
        let err = Volume::new(
            "flat",
            [2, 1, 1],
            [1.0, 0.0, 1.0],
            VolumeData::U8(vec![0; 2]),
        )
        .unwrap_err();
        assert!(matches!(err, VolumeError::MalformedHeader { .. }));
    }

    #[test]
    fn histogram_of_u16_and_f32_and_homogeneity() {
        let v = Volume::new(
            "h",
            [4, 1, 1],
            [1.0; 3],
            VolumeData::U16(vec![0, 65535, 30000, 30000]),
        )
        .expect("valid");
        assert_eq!(v.histogram(2), vec![3, 1]);
        assert_eq!(v.as_bytes_len(), 8);
        let f = Volume::new(
            "f",
            [4, 1, 1],
            [1.0; 3],
            VolumeData::F32(vec![0.0, 0.5, 0.5, 0.0]),
        )
        .expect("valid");
        assert_eq!(f.histogram(4), vec![2, 0, 2, 0]);
        assert_eq!(f.is_homogeneous(), Some(0.5));
        let z = Volume::new("z", [2, 1, 1], [1.0; 3], VolumeData::U8(vec![0, 0])).expect("valid");
        assert_eq!(z.is_homogeneous(), None);
    }

    #[test]
    fn names_drop_extensions() {
        assert_eq!(name_of(Path::new("/a/head.nii.gz")), "head");
        assert_eq!(name_of(Path::new("/a/head.NII.GZ")), "head");
        assert_eq!(name_of(Path::new("b/ct.nrrd")), "ct");
        assert_eq!(name_of(Path::new("series")), "series");
    }

    #[test]
    fn unknown_extension_is_rejected_by_name() {
        let err = Volume::load(Path::new("/nonexistent/picture.png"), None).unwrap_err();
        assert!(matches!(err, VolumeError::Unsupported { .. }));
        assert!(err.to_string().contains("picture.png"));
        let err = Volume::load(Path::new("/nonexistent/blob.raw"), None).unwrap_err();
        assert!(matches!(err, VolumeError::MissingRawParams { .. }));
        assert!(err.to_string().contains("blob.raw.json"));
    }

    impl Volume {
        fn as_bytes_len(&self) -> usize {
            self.data.as_bytes().len()
        }
    }
}
