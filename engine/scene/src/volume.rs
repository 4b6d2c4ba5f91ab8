//! `[volume]`: which density volume a scene renders, and how dense it looks.
//!
//! World space is defined by the volume: it is centred at the origin and scaled
//! (uniformly, keeping its aspect and voxel spacing) so that its longest side is 1.0
//! world unit. Voxel index axes i, j, k map to world x, y, z without swapping; for
//! medical volumes in RAS order that makes +z superior, which is why the built-in scenes
//! use `up = [0, 0, 1]`.
//!
//! `density_scale` turns TF opacity into extinction: `μt = opacity × density_scale`
//! per world unit. At the default of 100, an opacity-1 voxel has a mean free path of
//! 0.01 world units, about one voxel of a 128³ volume.

use dvr_volume::RawFormat;
use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};

/// Extinction per world unit at opacity 1 when a scene does not say.
pub const DEFAULT_DENSITY_SCALE: f64 = 100.0;

/// Largest `density_scale`: an opacity-1 mean free path of 10⁻⁶ of the volume, far
/// denser than any tissue needs; past it f32 extinction sums overflow to a black image.
pub const MAX_DENSITY_SCALE: f64 = 1e6;

/// The procedural or bundled datasets every build has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BuiltinVolume {
    /// CT-like head phantom with thin vessels (procedural, U16).
    Phantom,
    /// The MNI152 T1 head MRI (bundled, uint8, brain-masked).
    Mri,
    /// A homogeneous semi-transparent shape (procedural, density 0.5 inside).
    Cloud,
    /// Blobs and tubes in a mostly empty N×N×N/2 box (procedural, U16, made brick by
    /// brick on demand): for the brick pool's large volumes. No built-in scene uses it.
    Sparse,
}

impl BuiltinVolume {
    /// Every built-in dataset, in the order scenes list them.
    pub const ALL: [Self; 3] = [Self::Phantom, Self::Mri, Self::Cloud];

    /// The name used in scene files and built-in scene names.
    pub fn name(self) -> &'static str {
        match self {
            Self::Phantom => "phantom",
            Self::Mri => "mri",
            Self::Cloud => "cloud",
            Self::Sparse => "sparse",
        }
    }
}

/// How to read a headerless raw file (`file = "x.raw"` plus `dims` and `format`).
#[derive(Debug, Clone, PartialEq)]
pub struct RawLayout {
    /// Voxels along x, y, z (x fastest in the file).
    pub dims: [u32; 3],
    pub format: RawFormat,
    /// Voxel size along x, y, z (any unit; only ratios matter). Default `[1, 1, 1]`.
    pub spacing: [f64; 3],
}

/// Where the density volume comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum VolumeSource {
    /// A built-in dataset; `size` is the procedural resolution (voxels along the
    /// longest side), `None` for the generator's default. Ignored by `mri`.
    Builtin {
        dataset: BuiltinVolume,
        size: Option<u32>,
    },
    /// A file: NRRD, NIfTI or a DICOM folder describe themselves (`raw: None`); a raw
    /// file needs its layout. The path is already joined to the scene file's folder.
    File {
        path: PathBuf,
        raw: Option<RawLayout>,
    },
    /// Several files, one channel each, resampled by their affines onto the first
    /// file's grid (`files = [..]`); paths already joined.
    Files { paths: Vec<PathBuf> },
}

/// The `[volume]` section, checked.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeSpec {
    pub source: VolumeSource,
    /// Extinction per world unit at opacity 1 (`μt = opacity × density_scale`).
    pub density_scale: f64,
    /// Which channels of the file (its C axis) or of `files`, in this order; `None`:
    /// all of them.
    pub channels: Option<Vec<usize>>,
}

impl VolumeSpec {
    pub(crate) fn check(&self, ctx: &Ctx) -> Result<(), SceneError> {
        ctx.positive_up_to(
            "volume.density_scale",
            self.density_scale,
            MAX_DENSITY_SCALE,
            " (extinction per world unit at opacity 1; the built-in scenes use 150)",
        )?;
        match &self.source {
            VolumeSource::Builtin {
                size: Some(size), ..
            } if !(8..=4096).contains(size) => {
                Err(ctx.invalid("volume.size", format!("{size} must be in 8..=4096")))
            }
            VolumeSource::Builtin { .. } => Ok(()),
            VolumeSource::File { path, .. } if !path.exists() => {
                Err(ctx.invalid("volume.file", format!("{} does not exist", path.display())))
            }
            VolumeSource::File { path, raw: Some(_) } if !path.is_file() => Err(ctx.invalid(
                "volume.file",
                format!(
                    "{} is not a file (a raw volume is one file)",
                    path.display()
                ),
            )),
            VolumeSource::File { raw: None, .. } => self.check_channels(ctx),
            VolumeSource::Files { paths } => {
                if paths.is_empty() {
                    return Err(ctx.invalid("volume.files", "is empty; list one file per channel"));
                }
                for p in paths {
                    if !p.exists() {
                        return Err(
                            ctx.invalid("volume.files", format!("{} does not exist", p.display()))
                        );
                    }
                }
                self.check_channels(ctx)
            }
            VolumeSource::File { raw: Some(r), .. } => {
                if r.dims.contains(&0) {
                    return Err(
                        ctx.invalid("volume.dims", format!("{:?} has a zero dimension", r.dims))
                    );
                }
                for s in r.spacing {
                    ctx.in_range(
                        "volume.spacing",
                        s,
                        dvr_volume::MIN_SPACING_MM,
                        dvr_volume::MAX_SPACING_MM,
                        " mm",
                    )?;
                }
                Ok(())
            }
        }
    }

    fn check_channels(&self, ctx: &Ctx) -> Result<(), SceneError> {
        match &self.channels {
            Some(c) if c.is_empty() => Err(ctx.invalid(
                "volume.channels",
                "is empty; list the channels to show, e.g. [0, 2]",
            )),
            Some(c) if c.len() > super::channel::MAX_CHANNELS => Err(ctx.invalid(
                "volume.channels",
                format!(
                    "{c:?} picks {} channels; a medium holds at most {}",
                    c.len(),
                    super::channel::MAX_CHANNELS
                ),
            )),
            _ => Ok(()),
        }
    }
}

/// `[volume]` as written: either `builtin` (+ `size`), `file` (+ raw layout) or `files`.
#[derive(Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct VolumeFile {
    #[serde(skip_serializing_if = "Option::is_none")]
    builtin: Option<BuiltinVolume>,
    #[serde(skip_serializing_if = "Option::is_none")]
    size: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    file: Option<PathBuf>,
    #[serde(skip_serializing_if = "Option::is_none")]
    files: Option<Vec<PathBuf>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    channels: Option<Vec<usize>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    dims: Option<[u32; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    format: Option<RawFormat>,
    #[serde(skip_serializing_if = "Option::is_none")]
    spacing: Option<[f64; 3]>,
    #[serde(default = "default_density_scale")]
    density_scale: f64,
}

fn default_density_scale() -> f64 {
    DEFAULT_DENSITY_SCALE
}

impl VolumeFile {
    /// Structure only (builtin xor file, raw layout complete); values are checked by
    /// [`VolumeSpec::check`].
    pub fn into_spec(self, ctx: &Ctx) -> Result<VolumeSpec, SceneError> {
        if let Some(paths) = self.files {
            if self.builtin.is_some() || self.file.is_some() {
                return Err(ctx.invalid(
                    "volume",
                    "give one of `builtin`, `file` or `files` (one channel per file)",
                ));
            }
            if self.dims.is_some() || self.format.is_some() || self.size.is_some() {
                return Err(ctx.invalid(
                    "volume.files",
                    "takes files that describe themselves (no raw layout, no size)",
                ));
            }
            return Ok(VolumeSpec {
                source: VolumeSource::Files {
                    paths: paths.iter().map(|p| ctx.resolve(p)).collect(),
                },
                density_scale: self.density_scale,
                channels: self.channels,
            });
        }
        if self.channels.is_some() && self.file.is_none() {
            return Err(ctx.invalid(
                "volume.channels",
                "picks channels of `file` or `files`; a built-in volume has one",
            ));
        }
        let source =
            match (self.builtin, self.file) {
                (Some(_), Some(_)) => {
                    return Err(ctx.invalid("volume", "give either `builtin` or `file`, not both"))
                }
                (None, None) => return Err(ctx.invalid(
                    "volume",
                    "missing `builtin = \"phantom\" | \"mri\" | \"cloud\" | \"sparse\"` or `file = \"path\"`",
                )),
                (Some(dataset), None) => {
                    for (field, given) in [
                        ("dims", self.dims.is_some()),
                        ("format", self.format.is_some()),
                        ("spacing", self.spacing.is_some()),
                    ] {
                        if given {
                            return Err(ctx.invalid(
                                format!("volume.{field}"),
                                "only for `file` volumes (a built-in volume knows its layout)",
                            ));
                        }
                    }
                    VolumeSource::Builtin {
                        dataset,
                        size: self.size,
                    }
                }
                (None, Some(path)) => {
                    if path.as_os_str().is_empty() {
                        return Err(ctx.invalid(
                            "volume.file",
                            "is empty; name a volume file (.nrrd, .nhdr, .nii, .nii.gz, .dcm, raw) \
                             or a DICOM folder",
                        ));
                    }
                    if self.size.is_some() {
                        return Err(ctx.invalid("volume.size", "only for `builtin` volumes"));
                    }
                    let raw = match (self.dims, self.format, self.spacing) {
                        (None, None, None) => None,
                        (Some(dims), Some(format), spacing) => Some(RawLayout {
                            dims,
                            format,
                            spacing: spacing.unwrap_or([1.0; 3]),
                        }),
                        (None, _, _) => {
                            return Err(ctx.invalid("volume.dims", "a raw volume needs `dims`"))
                        }
                        (_, None, _) => {
                            return Err(ctx.invalid(
                                "volume.format",
                                "a raw volume needs `format = \"u8\" | \"u16\" | \"f32\"`",
                            ))
                        }
                    };
                    VolumeSource::File {
                        path: ctx.resolve(&path),
                        raw,
                    }
                }
            };
        Ok(VolumeSpec {
            source,
            density_scale: self.density_scale,
            channels: self.channels,
        })
    }

    pub fn from_spec(v: &VolumeSpec) -> Self {
        let mut f = Self {
            density_scale: v.density_scale,
            channels: v.channels.clone(),
            ..Self::default()
        };
        match &v.source {
            VolumeSource::Builtin { dataset, size } => {
                f.builtin = Some(*dataset);
                f.size = *size;
            }
            VolumeSource::File { path, raw } => {
                f.file = Some(path.clone());
                if let Some(r) = raw {
                    f.dims = Some(r.dims);
                    f.format = Some(r.format);
                    f.spacing = Some(r.spacing);
                }
            }
            VolumeSource::Files { paths } => f.files = Some(paths.clone()),
        }
        f
    }
}
