//! Series: up to 4 **channels** on one grid at T ≥ 1 **time points**, read one time
//! point at a time.
//!
//! [`Series::open`] reads the headers (grid, spacing, orientation, channel count, names
//! and colours, time count) and then time point 0 of each selected channel once, which
//! fixes each channel's **window** (see below) and the series' RAS grid. [`Series::read`]
//! then reads one time point: one normalised [`Volume`] per selected channel, on the
//! series' grid, in RAS order like every loaded volume. Nothing is cached: each read
//! opens the files again, so a caller keeps resident only the time points it uses and
//! may read the next one on another thread (a `Series` is `Send + Sync`); reading a time
//! point twice gives identical volumes.
//!
//! # The window of a channel
//!
//! Each channel's window is the one the normalisation rule (`normalise.rs`) gives its
//! **first time point**, and every later time point is mapped through that same window
//! (values outside it are clamped), so a time series does not flicker as its range
//! changes. A one-channel, one-time-point file therefore loads exactly as
//! [`Volume::load`] loads it. An OME-Zarr `omero` window is not used for normalisation
//! (it is a display range); it is checked (finite, start ≤ end) and reported as
//! [`ChannelInfo::display_window`].
//!
//! # Sources
//!
//! | source | channels | time points |
//! | --- | --- | --- |
//! | NIfTI-1 | `dim[5]` (e.g. intent vector) | `dim[4]` |
//! | NRRD | axes of `kinds` `vector`, `list`, `RGB-color`, `point`, … | the axis of kind `time` |
//! | OME-Zarr | the axis of type `channel` (or named `c`); `omero.channels` labels, colours, windows | the axis of type `time` (or named `t`) |
//! | OME-TIFF | `SizeC`; `Channel` `Name`/`Color` | `SizeT`, pages in any `DimensionOrder` |
//! | a list of files | one per file ([`Series::open_channels`]), named by file stem | one per file ([`Series::open_times`], [`Series::open_glob`]) |
//! | DICOM, raw | one | one |
//!
//! NRRD without `kinds`: a size-1 axis is dropped; otherwise the non-spatial axis is the
//! one whose `space directions` entry is `none`, else the last; it holds channels when it
//! has at most 4 entries and time points when it has more. A 5D NRRD needs `kinds`.
//!
//! A selection (`channels = [0, 2]`) picks channels in the order given; without one a
//! source of more than 4 channels is an error saying how to pick.
//!
//! # Grids
//!
//! Channels from several files are placed on the **first file's grid**: a file on
//! another grid is resampled (trilinear, in patient space) by its patient transform; a
//! file without one (no sform/qform, an OME file, raw) is an error naming it, unless it
//! has the first file's shape, when the two are taken as aligned. The time points of one
//! series must share one grid; files that do not are an error naming both shapes.

mod arrays;
mod glob;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::orientation::resample_onto;
use crate::{formats, PatientTransform, SampleKind, Volume, VolumeError};

pub use glob::expand as expand_glob;

/// Most channels one series holds: one RGBA volume texture.
pub const MAX_CHANNELS: usize = 4;

/// A series' metadata: what [`Series::open`] read.
#[derive(Clone, Debug, PartialEq)]
pub struct SeriesInfo {
    /// The first file's (or folder's) name, as [`Volume::name`].
    pub name: String,
    /// Voxels along x, y, z (RAS order).
    pub dims: [u32; 3],
    /// Voxel size in mm along x, y, z.
    pub spacing: [f32; 3],
    /// Where the voxels lie in patient space (RAS+, mm).
    pub to_patient: PatientTransform,
    /// The selected channels, in the order read returns them.
    pub channels: Vec<ChannelInfo>,
    /// Number of time points (at least 1).
    pub times: usize,
}

/// One channel of a series.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelInfo {
    /// The channel's name: the file's label (omero `label`, OME-XML `Name`), the file
    /// stem for a channel read from a file of its own, else `channel <index>`.
    pub name: String,
    /// Its index in the source (the file's channel axis, or the list of files).
    pub index: usize,
    /// The file it is read from.
    pub file: PathBuf,
    /// Its display colour (RGB) where the file states one.
    pub colour: Option<[u8; 3]>,
    /// The physical values (data units, after rescale) that map to density 0 and 1,
    /// fixed over all time points.
    pub window: [f32; 2],
    /// The file's display range (OME-Zarr omero `window` start/end), not used for
    /// normalisation.
    pub display_window: Option<[f64; 2]>,
    /// The type the samples were stored as.
    pub sample_kind: SampleKind,
    /// Whether it was resampled onto the first file's grid.
    pub resampled: bool,
}

/// What a source file states about one of its channels.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct SourceChannel {
    pub name: Option<String>,
    pub colour: Option<[u8; 3]>,
    pub display_window: Option<[f64; 2]>,
}

/// Most channels a file may state: far more than any image has, and a bound on what a
/// header's channel count makes us allocate before its data is read.
pub(crate) const MAX_SOURCE_CHANNELS: u64 = 1 << 16;

/// `n` channels with `meta` for the first ones (and none for the rest), refused past
/// [`MAX_SOURCE_CHANNELS`].
pub(crate) fn channel_list(
    path: &Path,
    n: u64,
    mut meta: Vec<SourceChannel>,
) -> Result<Vec<SourceChannel>, VolumeError> {
    if n > MAX_SOURCE_CHANNELS {
        return Err(VolumeError::TooManyChannels {
            path: path.to_path_buf(),
            count: usize::try_from(n).unwrap_or(usize::MAX),
        });
    }
    meta.resize(n as usize, SourceChannel::default());
    Ok(meta)
}

/// A file's series layout, from its header alone.
#[derive(Clone, Debug)]
pub(crate) struct SourceInfo {
    pub path: PathBuf,
    /// What [`Volume::load`] names its volume.
    pub name: String,
    /// Voxels along the file's index axes (before RAS ordering).
    pub dims: [u32; 3],
    /// The patient transform the file states, if any.
    pub orientation: Option<PatientTransform>,
    /// One entry per channel (at least one).
    pub channels: Vec<SourceChannel>,
    /// Time points (at least one).
    pub times: usize,
}

/// A window: the physical values that map to density 0 and 1.
pub(crate) type Window = (f64, f64);

/// A volume read through a window, with the window used (its own where none was given).
pub(crate) type Windowed = Result<(Volume, Window), VolumeError>;

/// A file read channel by channel, time point by time point. Each read opens the file
/// again (no state between reads), so a source is shared across threads as it is.
pub(crate) trait Source: Send + Sync {
    fn info(&self) -> &SourceInfo;
    /// One channel at one time point in RAS order, normalised through `window` where
    /// given, else its own; with the window used.
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed;
}

/// A source of one channel at one time point read whole by [`Volume::load`]'s loader:
/// DICOM series and raw files, which hold no channel or time axes.
pub(crate) struct WholeFile {
    info: SourceInfo,
    volume: Arc<Volume>,
}

impl WholeFile {
    /// Loads `path` once (its only time point): `has_affine` says whether its format
    /// states an orientation (DICOM does; raw does not).
    pub(crate) fn open(
        path: &Path,
        volume: Volume,
        has_affine: bool,
    ) -> Result<Box<dyn Source>, VolumeError> {
        let info = SourceInfo {
            path: path.to_path_buf(),
            name: volume.name.clone(),
            dims: volume.dims,
            orientation: has_affine.then_some(volume.to_patient),
            channels: vec![SourceChannel::default()],
            times: 1,
        };
        Ok(Box::new(WholeFile {
            info,
            volume: Arc::new(volume),
        }))
    }
}

impl Source for WholeFile {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, _channel: usize, _time: usize, _window: Option<Window>) -> Windowed {
        // One channel, one time point: its own window is the series' window.
        let v = (*self.volume).clone();
        let w = (f64::from(v.window[0]), f64::from(v.window[1]));
        Ok((v, w))
    }
}

/// How the files of a series make it up.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Arrangement {
    /// One file holds every channel and time point.
    OneFile,
    /// One file per channel, each with the series' time points.
    ChannelFiles,
    /// One file per time point, each with the series' channels.
    TimeFiles,
}

/// How a channel's volume is put on the series' grid.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Placement {
    /// It is on the grid as read.
    AsRead,
    /// Same shape, no affine on one side: taken as aligned with the first file.
    Aligned,
    /// Resampled by its patient transform.
    Resampled,
}

/// One selected channel: where it is read from and how it is placed.
struct Slot {
    source: usize,
    channel: usize,
    window: (f64, f64),
    placement: Placement,
}

/// A series of channels and time points (see the module docs).
pub struct Series {
    info: SeriesInfo,
    arrangement: Arrangement,
    sources: Vec<Box<dyn Source>>,
    slots: Vec<Slot>,
}

impl std::fmt::Debug for Series {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Series").field("info", &self.info).finish()
    }
}

fn shape(d: [u32; 3]) -> String {
    format!("{}x{}x{}", d[0], d[1], d[2])
}

impl Series {
    /// Opens one file or folder (any format [`Volume::load`] reads) as a series; with
    /// `channels`, only those channels, in that order.
    pub fn open(path: &Path, channels: Option<&[usize]>) -> Result<Series, VolumeError> {
        let source = formats::open_series(path)?;
        Self::build(Arrangement::OneFile, vec![source], channels)
    }

    /// Several files as channels, one per file (named by file stem), on the first
    /// file's grid; `channels` selects among the files.
    pub fn open_channels(
        paths: &[PathBuf],
        channels: Option<&[usize]>,
    ) -> Result<Series, VolumeError> {
        let sources = Self::open_all(paths)?;
        Self::build(Arrangement::ChannelFiles, sources, channels)
    }

    /// Several files as the time points of one series, in the order given.
    pub fn open_times(
        paths: &[PathBuf],
        channels: Option<&[usize]>,
    ) -> Result<Series, VolumeError> {
        let sources = Self::open_all(paths)?;
        Self::build(Arrangement::TimeFiles, sources, channels)
    }

    /// The files a glob names (`*` and `?` in the file name, sorted by name) as the
    /// time points of one series.
    pub fn open_glob(pattern: &Path, channels: Option<&[usize]>) -> Result<Series, VolumeError> {
        let paths = expand_glob(pattern)?;
        Self::open_times(&paths, channels)
    }

    fn open_all(paths: &[PathBuf]) -> Result<Vec<Box<dyn Source>>, VolumeError> {
        if paths.is_empty() {
            return Err(VolumeError::MalformedHeader {
                path: PathBuf::from("(no files)"),
                field: "files".into(),
                problem: "a series needs at least one file".into(),
            });
        }
        paths.iter().map(|p| formats::open_series(p)).collect()
    }

    fn build(
        arrangement: Arrangement,
        sources: Vec<Box<dyn Source>>,
        selection: Option<&[usize]>,
    ) -> Result<Series, VolumeError> {
        let first = sources[0].info().clone();
        // The channels there are to pick from: (source, channel in it, its name).
        let available: Vec<(usize, usize, String)> = match arrangement {
            Arrangement::ChannelFiles => {
                for s in &sources {
                    let i = s.info();
                    if i.channels.len() != 1 {
                        return Err(VolumeError::ChannelSelection {
                            path: i.path.clone(),
                            selection: Vec::new(),
                            problem: format!(
                                "a file of a list of channels holds one channel; this one \
                                 holds {}",
                                i.channels.len()
                            ),
                        });
                    }
                    if i.times != first.times {
                        return Err(VolumeError::GridMismatch {
                            path: first.path.clone(),
                            what: "channels with different numbers of time points",
                            shape: format!("{} time points", first.times),
                            other: i.path.clone(),
                            other_shape: format!("{} time points", i.times),
                        });
                    }
                }
                sources
                    .iter()
                    .enumerate()
                    .map(|(k, s)| (k, 0, s.info().name.clone()))
                    .collect()
            }
            Arrangement::OneFile | Arrangement::TimeFiles => {
                if arrangement == Arrangement::TimeFiles {
                    check_time_files(&sources)?;
                }
                let one = first.channels.len() == 1;
                first
                    .channels
                    .iter()
                    .enumerate()
                    .map(|(c, ch)| {
                        let name = ch.name.clone().unwrap_or_else(|| {
                            if one {
                                first.name.clone()
                            } else {
                                format!("channel {c}")
                            }
                        });
                        (0, c, name)
                    })
                    .collect()
            }
        };
        let picked = select(&first.path, available.len(), selection)?;
        let times = match arrangement {
            Arrangement::TimeFiles => sources.len(),
            _ => first.times,
        };
        if times == 0 {
            return Err(VolumeError::MalformedHeader {
                path: first.path.clone(),
                field: "time".into(),
                problem: "the time axis is empty (no time points)".into(),
            });
        }
        // Time point 0 of each channel: its window, and the grid of the first.
        let mut slots = Vec::new();
        let mut channels = Vec::new();
        let mut grid: Option<Volume> = None;
        for &a in &picked {
            let (source, channel, ref name) = available[a];
            let src = &sources[source];
            let (v, window) = src.read(channel, 0, None)?;
            let placement = match &grid {
                None => Placement::AsRead,
                Some(g) => placement(g, &first, &v, src.info())?,
            };
            let meta = &src.info().channels[channel];
            channels.push(ChannelInfo {
                name: name.clone(),
                index: if arrangement == Arrangement::ChannelFiles {
                    source
                } else {
                    channel
                },
                file: src.info().path.clone(),
                colour: meta.colour,
                window: v.window,
                display_window: meta.display_window,
                sample_kind: v.sample_kind,
                resampled: placement == Placement::Resampled,
            });
            slots.push(Slot {
                source,
                channel,
                window,
                placement,
            });
            if grid.is_none() {
                grid = Some(v);
            }
        }
        let Some(g) = grid else {
            return Err(VolumeError::ChannelSelection {
                path: first.path.clone(),
                selection: Vec::new(),
                problem: "selects no channel".into(),
            });
        };
        let info = SeriesInfo {
            name: first.name.clone(),
            dims: g.dims,
            spacing: g.spacing,
            to_patient: g.to_patient,
            channels,
            times,
        };
        Ok(Series {
            info,
            arrangement,
            sources,
            slots,
        })
    }

    /// The series' metadata.
    pub fn info(&self) -> &SeriesInfo {
        &self.info
    }

    /// Time point `t`: one volume per selected channel (in the selection's order), each
    /// normalised through its channel's window, all on the series' grid.
    pub fn read(&self, t: usize) -> Result<Vec<Volume>, VolumeError> {
        if t >= self.info.times {
            return Err(VolumeError::TimeOutOfRange {
                path: self.sources[0].info().path.clone(),
                time: t,
                times: self.info.times,
            });
        }
        let mut out = Vec::with_capacity(self.slots.len());
        for slot in &self.slots {
            let (source, time) = match self.arrangement {
                Arrangement::TimeFiles => (t, 0),
                _ => (slot.source, t),
            };
            let src = &self.sources[source];
            let (mut v, _) = src.read(slot.channel, time, Some(slot.window))?;
            match slot.placement {
                Placement::AsRead => {}
                Placement::Aligned => {
                    v.spacing = self.info.spacing;
                    v.to_patient = self.info.to_patient;
                }
                Placement::Resampled => {
                    v = resample_onto(&v, self.info.dims, &self.info.to_patient);
                }
            }
            if v.dims != self.info.dims {
                // A time file whose header agreed but whose RAS grid does not.
                return Err(VolumeError::GridMismatch {
                    path: self.sources[0].info().path.clone(),
                    what: "time points of one series",
                    shape: shape(self.info.dims),
                    other: src.info().path.clone(),
                    other_shape: shape(v.dims),
                });
            }
            out.push(v);
        }
        Ok(out)
    }
}

/// The files of a time series must hold one time point each, the same channels, on one
/// grid (their headers' shapes and orientations).
fn check_time_files(sources: &[Box<dyn Source>]) -> Result<(), VolumeError> {
    let first = sources[0].info();
    for s in sources {
        let i = s.info();
        if i.times != 1 {
            return Err(VolumeError::GridMismatch {
                path: first.path.clone(),
                what: "a list of time points holds one per file; files",
                shape: format!("{} time point(s)", first.times),
                other: i.path.clone(),
                other_shape: format!("{} time points", i.times),
            });
        }
        let same_place = match (i.orientation, first.orientation) {
            (Some(a), Some(b)) => close(&a, &b),
            (None, None) => true,
            _ => false,
        };
        if i.dims != first.dims || !same_place {
            return Err(VolumeError::GridMismatch {
                path: first.path.clone(),
                what: "time points of one series",
                shape: shape(first.dims),
                other: i.path.clone(),
                other_shape: if i.dims != first.dims {
                    shape(i.dims)
                } else {
                    format!("{} placed elsewhere (another affine)", shape(i.dims))
                },
            });
        }
        if i.channels.len() != first.channels.len() {
            return Err(VolumeError::GridMismatch {
                path: first.path.clone(),
                what: "time points of one series",
                shape: format!("{} channel(s)", first.channels.len()),
                other: i.path.clone(),
                other_shape: format!("{} channel(s)", i.channels.len()),
            });
        }
    }
    Ok(())
}

/// Whether two transforms place voxels within a thousandth of a voxel of each other.
fn close(a: &PatientTransform, b: &PatientTransform) -> bool {
    let tol = 1e-3 * a.spacing().iter().fold(f64::MAX, |m, &s| m.min(s));
    let axes = a
        .axes
        .iter()
        .flatten()
        .zip(b.axes.iter().flatten())
        .all(|(x, y)| (x - y).abs() <= tol);
    let origin = a
        .origin
        .iter()
        .zip(&b.origin)
        .all(|(x, y)| (x - y).abs() <= tol);
    axes && origin
}

/// How channel volume `v` (from `src`) goes on the grid of `g` (from `first`).
fn placement(
    g: &Volume,
    first: &SourceInfo,
    v: &Volume,
    src: &SourceInfo,
) -> Result<Placement, VolumeError> {
    let both = first.orientation.is_some() && src.orientation.is_some();
    if both {
        if v.dims == g.dims && close(&v.to_patient, &g.to_patient) {
            return Ok(Placement::AsRead);
        }
        return Ok(Placement::Resampled);
    }
    if v.dims == g.dims {
        return Ok(Placement::Aligned);
    }
    // Name the file that lacks the affine.
    let (path, sh, other, other_sh) = if src.orientation.is_none() {
        (&src.path, v.dims, &first.path, g.dims)
    } else {
        (&first.path, g.dims, &src.path, v.dims)
    };
    Err(VolumeError::NoAffine {
        path: path.clone(),
        shape: shape(sh),
        first: other.clone(),
        first_shape: shape(other_sh),
    })
}

/// The indices of `available` channels a selection picks: all of them (at most
/// [`MAX_CHANNELS`]) without one; each index in range and at most once.
fn select(
    path: &Path,
    available: usize,
    selection: Option<&[usize]>,
) -> Result<Vec<usize>, VolumeError> {
    let Some(sel) = selection else {
        if available > MAX_CHANNELS {
            return Err(VolumeError::TooManyChannels {
                path: path.to_path_buf(),
                count: available,
            });
        }
        return Ok((0..available).collect());
    };
    let bad = |problem: String| VolumeError::ChannelSelection {
        path: path.to_path_buf(),
        selection: sel.to_vec(),
        problem,
    };
    if sel.is_empty() {
        return Err(bad("selects no channel".into()));
    }
    for (i, &c) in sel.iter().enumerate() {
        if c >= available {
            return Err(bad(format!(
                "channel {c} is out of range: there are {available} (0..{available})"
            )));
        }
        if sel[..i].contains(&c) {
            return Err(bad(format!("channel {c} is selected twice")));
        }
    }
    if sel.len() > MAX_CHANNELS {
        return Err(VolumeError::TooManyChannels {
            path: path.to_path_buf(),
            count: sel.len(),
        });
    }
    Ok(sel.to_vec())
}

#[cfg(test)]
mod tests;
