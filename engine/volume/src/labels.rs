//! Label maps: an integer volume (a segmentation: organs, a tumour, a parcellation) beside
//! a density volume, read by the volume loaders (NIfTI, NRRD, OME-Zarr, raw) and put on
//! the volume's grid by nearest neighbour through the patient transforms (interpolating
//! label values makes labels that are not there). Its label table is `labels/table.rs`.

mod look;
mod ome;
mod table;

pub use look::{EmptySpace, LabelLook, Look, SMOOTHING_SIGMA};
pub use ome::{first_label_image, image_label_table};
pub use table::{Label, LabelTable, PALETTE};

use crate::orientation::invert;
use crate::{PatientTransform, SampleKind, Volume, VolumeError};
use std::path::{Path, PathBuf};

/// Whether the file at `path` states where its voxels lie in patient space (an affine,
/// DICOM's position and orientation); raw files do not. Header-only for the formats with
/// headers (raw and DICOM are read whole).
pub fn states_orientation(path: &Path) -> Result<bool, VolumeError> {
    Ok(crate::formats::open_series(path)?
        .info()
        .orientation
        .is_some())
}

/// Largest label value: labels are held as u16.
pub const MAX_LABEL: u32 = u16::MAX as u32;

/// A label map on a grid: one label value per voxel, x fastest (RAS order, as volumes).
#[derive(Clone, Debug, PartialEq)]
pub struct LabelMap {
    pub name: String,
    /// The file it was read from (errors name it).
    pub path: PathBuf,
    pub dims: [u32; 3],
    pub to_patient: PatientTransform,
    pub values: Vec<u16>,
}

impl LabelMap {
    /// Reads an integer volume file as a label map. A float file, negative values,
    /// values past [`MAX_LABEL`] or an oblique grid are errors naming the file.
    pub fn load(path: &Path) -> Result<Self, VolumeError> {
        // The loaders put an oblique grid on RAS axes by trilinear resampling, which
        // would mix label values: refused until a nearest-neighbour path exists.
        let oblique = crate::formats::open_series(path)?
            .info()
            .orientation
            .is_some_and(|t| t.is_oblique());
        if oblique {
            return Err(VolumeError::Unsupported {
                path: path.to_path_buf(),
                reason: "an oblique label map (its axes are tilted from R, A, S): putting it \
                         on RAS axes would interpolate label values"
                    .into(),
            });
        }
        let v = Volume::load(path, None)?;
        Self::from_volume(path, &v)
    }

    /// A built-in dataset's segmentation on the grid of `dims` voxels placed by
    /// `to_patient` (the dataset's own volume), with its table: `phantom` (scalp, skull,
    /// brain, ventricles, vessels; made at the volume's size) or `mri` (white matter, grey
    /// matter and the rest of the brain of the MNI152 head, read from the assets).
    pub fn builtin(
        name: &str,
        dims: [u32; 3],
        to_patient: &PatientTransform,
    ) -> Result<(Self, LabelTable), VolumeError> {
        match name {
            "phantom" => {
                let [n, ny, nz] = dims;
                if ny != n || nz != n {
                    return Err(VolumeError::Unsupported {
                        path: PathBuf::from(name),
                        reason: format!(
                            "the phantom's labels are made on its own cubic grid, not {dims:?} voxels (use them with `builtin = \"phantom\"`)"
                        ),
                    });
                }
                let map = Self {
                    name: "phantom labels".into(),
                    path: PathBuf::from("phantom"),
                    dims,
                    to_patient: *to_patient,
                    values: crate::phantom::labels(n),
                };
                let labels = crate::phantom::LABELS
                    .iter()
                    .map(|&(value, name, colour)| Label {
                        value,
                        name: name.into(),
                        colour,
                        opacity: 1.0,
                        visible: true,
                    })
                    .collect();
                Ok((map, LabelTable { labels }))
            }
            "mri" => {
                let (file, table) = crate::assets::mri_labels();
                let map = Self::load(&file)?.onto(dims, to_patient);
                Ok((map, LabelTable::load(&table)?))
            }
            _ => Err(VolumeError::UnknownBuiltin {
                name: name.into(),
                valid: "phantom, mri".into(),
            }),
        }
    }

    /// The label map a file gives, and the table its own metadata holds: an OME-Zarr
    /// label image's `image-label`, and for an OME-Zarr image with a `labels/` group the
    /// first label image it lists; any other file as [`LabelMap::load`], no table.
    pub fn load_with_table(path: &Path) -> Result<(Self, Option<LabelTable>), VolumeError> {
        let own = image_label_table(path)?;
        if own.is_none() {
            if let Some(first) = first_label_image(path)? {
                log::info!(
                    "{}: its first label image, {}",
                    path.display(),
                    first.display()
                );
                let table = image_label_table(&first)?;
                return Ok((Self::load(&first)?, table));
            }
        }
        Ok((Self::load(path)?, own))
    }

    /// The label values of a loaded integer volume: its densities brought back through
    /// its window (exact for integer samples: a window spans at most 65535 steps of the
    /// 16-bit density, or the 8-bit values themselves).
    pub fn from_volume(path: &Path, v: &Volume) -> Result<Self, VolumeError> {
        let bad = |problem: String| VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: "label values".into(),
            problem,
        };
        if matches!(v.sample_kind, SampleKind::F32 | SampleKind::F64) {
            return Err(bad(format!(
                "{} samples: a label map holds integers (uint8, uint16, int16)",
                v.sample_kind.name()
            )));
        }
        let [lo, hi] = v.window.map(f64::from);
        let mut values = Vec::with_capacity(v.data.len());
        for i in 0..v.data.len() {
            let d = f64::from(v.data.get(i).unwrap_or(0.0));
            let label = (lo + d * (hi - lo)).round();
            if !(0.0..=f64::from(MAX_LABEL)).contains(&label) {
                return Err(bad(format!(
                    "voxel {i} holds {label}; labels are 0 to {MAX_LABEL} (0 is no label)"
                )));
            }
            values.push(label as u16);
        }
        Ok(Self {
            name: v.name.clone(),
            path: path.to_path_buf(),
            dims: v.dims,
            to_patient: v.to_patient,
            values,
        })
    }

    /// The label at voxel (x, y, z); 0 outside.
    pub fn at(&self, x: i64, y: i64, z: i64) -> u16 {
        let [nx, ny, nz] = self.dims.map(i64::from);
        if x < 0 || y < 0 || z < 0 || x >= nx || y >= ny || z >= nz {
            return 0;
        }
        self.values[((z * ny + y) * nx + x) as usize]
    }

    /// The label map on the grid of `dims` voxels placed by `onto`, by nearest
    /// neighbour: each voxel takes the label of the voxel its centre falls in (0 outside).
    /// The same grid is returned as it is.
    pub fn onto(&self, dims: [u32; 3], onto: &PatientTransform) -> Self {
        if dims == self.dims && *onto == self.to_patient {
            return self.clone();
        }
        let inverse = invert(self.to_patient);
        let mut values = Vec::with_capacity(crate::voxel_count(dims) as usize);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let p = onto.apply([f64::from(i), f64::from(j), f64::from(k)]);
                    let q = inverse(p).map(|c| c.round() as i64);
                    values.push(self.at(q[0], q[1], q[2]));
                }
            }
        }
        Self {
            values,
            dims,
            to_patient: *onto,
            ..self.clone()
        }
    }

    /// The label values present (0, no label, left out), ascending.
    pub fn present(&self) -> Vec<u16> {
        let mut seen = vec![false; MAX_LABEL as usize + 1];
        for &v in &self.values {
            seen[usize::from(v)] = true;
        }
        (1..=MAX_LABEL as usize)
            .filter(|&v| seen[v])
            .map(|v| v as u16)
            .collect()
    }
}

#[cfg(test)]
mod tests;
