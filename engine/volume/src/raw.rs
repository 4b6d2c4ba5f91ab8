//! Raw voxel files: no header, the layout comes from [`RawParams`] or a sidecar.
//!
//! Raw dumps are what many tools and public datasets (e.g. the Stanford and Klacansky
//! volume collections) ship. Their dims are easy to get wrong, so the file size must
//! match the dims exactly: short is "truncated", long is "dims do not match".
//!
//! A sidecar sits next to the data as `<file>.json` or `<file>.toml`, e.g.
//! `head.raw.toml`:
//!
//! ```toml
//! dims = [256, 256, 113]
//! format = "u16"        # u8 | u16 | i16 | f32 (also uint8, uint16, int16, float32)
//! spacing = [1.0, 1.0, 2.0]   # mm, optional, default 1
//! ```

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::error::VolumeError;
use super::samples::{SampleKind, Samples, Stored};
use super::{io, name_of, validate_dims, validate_spacing, Volume};

/// Sample type of a raw file (always little endian).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum RawFormat {
    #[serde(rename = "u8", alias = "uint8")]
    U8,
    #[serde(rename = "u16", alias = "uint16")]
    U16,
    /// Signed 16-bit, e.g. CT in Hounsfield units.
    #[serde(rename = "i16", alias = "int16")]
    I16,
    #[serde(rename = "f32", alias = "float32", alias = "float")]
    F32,
}

impl RawFormat {
    pub(crate) fn kind(self) -> SampleKind {
        match self {
            RawFormat::U8 => SampleKind::U8,
            RawFormat::U16 => SampleKind::U16,
            RawFormat::I16 => SampleKind::I16,
            RawFormat::F32 => SampleKind::F32,
        }
    }
}

/// Layout of a raw volume file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawParams {
    /// Voxels along x, y, z (x fastest in the file).
    pub dims: [u32; 3],
    pub format: RawFormat,
    /// Voxel size in mm.
    #[serde(default = "unit_spacing")]
    pub spacing: [f32; 3],
}

fn unit_spacing() -> [f32; 3] {
    [1.0; 3]
}

/// Largest sidecar read: a few lines of TOML or JSON.
const MAX_SIDECAR_BYTES: u64 = 64 << 10;

/// The sidecar paths tried for `path`, in order.
fn sidecar_paths(path: &Path) -> [PathBuf; 2] {
    ["json", "toml"].map(|ext| {
        let mut s = path.as_os_str().to_os_string();
        s.push(".");
        s.push(ext);
        PathBuf::from(s)
    })
}

/// Reads `<path>.json` or `<path>.toml` if one exists.
pub(crate) fn read_sidecar(path: &Path) -> Result<Option<RawParams>, VolumeError> {
    for side in sidecar_paths(path) {
        if !side.is_file() {
            continue;
        }
        let bytes = io::read_small(&side, MAX_SIDECAR_BYTES, "a sidecar")?;
        let text = String::from_utf8_lossy(&bytes);
        let parsed = if side.extension().is_some_and(|e| e == "json") {
            serde_json::from_str::<RawParams>(&text).map_err(|e| e.to_string())
        } else {
            toml::from_str::<RawParams>(&text).map_err(|e| e.to_string())
        };
        return parsed
            .map(Some)
            .map_err(|problem| VolumeError::MalformedHeader {
                path: side.clone(),
                field: "dims/format/spacing".into(),
                problem,
            });
    }
    Ok(None)
}

/// Loads `path` as raw little-endian voxels laid out as `params` says.
pub(crate) fn load(path: &Path, params: &RawParams) -> Result<Volume, VolumeError> {
    let dims = validate_dims(path, params.dims.map(i64::from))?;
    let spacing = validate_spacing(path, "spacing", params.spacing.map(f64::from))?;
    let kind = params.format.kind();
    // Check the size before reading, so wrong dims on a huge file fail fast.
    let (file, len) = io::open_regular(path)?;
    io::check_len(path, dims, kind, len)?;
    let expected = io::expected_bytes(dims, kind);
    let bytes = io::read_bounded(path, file, 0, expected, &|found| VolumeError::Truncated {
        path: path.to_path_buf(),
        expected,
        found,
    })?;
    io::check_len(path, dims, kind, bytes.len() as u64)?;
    let stored = Stored::plain(Samples::decode(kind, bytes, false));
    Volume::from_stored(path, name_of(path), dims, spacing, stored)
}

#[cfg(test)]
mod tests;
