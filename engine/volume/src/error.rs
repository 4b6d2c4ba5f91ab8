//! The one error type of the volume module.
//!
//! Every variant names the file (or, for built-ins, the dataset name) and says what is
//! wrong in terms a user can act on: the expected and found sizes, the header field, the
//! first bad voxel. The applications wrap it with `anyhow` context; nothing here panics on
//! bad input.

use std::path::PathBuf;

/// Why a volume could not be loaded or built.
#[derive(Debug, thiserror::Error)]
pub enum VolumeError {
    /// The file (or folder) could not be opened or read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// The path is a folder, FIFO, socket or device where a file was expected.
    #[error("{}: is {what}, not a file (volume data must be a regular file)", path.display())]
    NotAFile { path: PathBuf, what: &'static str },

    /// The voxel data ends early.
    #[error("{}: truncated: expected {expected} bytes of voxel data, found {found}", path.display())]
    Truncated {
        path: PathBuf,
        expected: u64,
        found: u64,
    },

    /// There is more voxel data than the dimensions account for: the dims are probably wrong.
    #[error(
        "{}: dims {}x{}x{} of {format} need {expected} bytes of voxel data, but the file holds {found}; \
         the dims do not match the data size",
        path.display(), dims[0], dims[1], dims[2]
    )]
    SizeMismatch {
        path: PathBuf,
        dims: [u32; 3],
        format: &'static str,
        expected: u64,
        found: u64,
    },

    /// Float data holds NaN or infinite values (never clamped silently).
    #[error(
        "{}: {count} non-finite (NaN/Inf) values; the first is at voxel ({}, {}, {})",
        path.display(), first[0], first[1], first[2]
    )]
    NonFinite {
        path: PathBuf,
        count: u64,
        first: [u32; 3],
    },

    /// Zero, negative or absurdly large dimensions.
    #[error("{}: invalid dims {dims:?}: {reason}", path.display())]
    BadDims {
        path: PathBuf,
        dims: Vec<i64>,
        reason: String,
    },

    /// A sample type the loaders do not read.
    #[error("{}: unsupported data type {datatype}; supported: {supported}", path.display())]
    UnsupportedType {
        path: PathBuf,
        datatype: String,
        supported: &'static str,
    },

    /// A header field is missing or cannot be parsed.
    #[error("{}: malformed header: field `{field}`: {problem}", path.display())]
    MalformedHeader {
        path: PathBuf,
        field: String,
        problem: String,
    },

    /// A valid file that uses a feature the loaders do not support (compression scheme,
    /// 4D data, unknown extension...).
    #[error("{}: unsupported: {reason}", path.display())]
    Unsupported { path: PathBuf, reason: String },

    /// Compressed voxel data could not be decompressed.
    #[error("{}: corrupt compressed data: {source}", path.display())]
    Decompress {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },

    /// A raw file without dims/format: neither parameters nor a sidecar were given.
    #[error(
        "{}: raw volume without parameters: pass dims, format and spacing, or write a sidecar \
         `{}.json` or `{}.toml` with fields dims, format, spacing",
        path.display(), path.display(), path.display()
    )]
    MissingRawParams { path: PathBuf },

    /// The slices of a DICOM series do not fit together.
    #[error("{}: inconsistent DICOM series: {problem}", path.display())]
    InconsistentSeries { path: PathBuf, problem: String },

    /// `Volume::builtin` was given a name it does not know.
    #[error("unknown builtin volume `{name}`; valid names: {valid}")]
    UnknownBuiltin { name: String, valid: String },

    /// More channels than one volume texture packs (4), with no selection.
    #[error(
        "{}: {count} channels; dvr renders at most 4 at once: pick some by index, e.g. \
         `channels = [0, 2]` (`--channels 0,2` on the command line)",
        path.display()
    )]
    TooManyChannels { path: PathBuf, count: usize },

    /// A channel selection names a channel that is not there, or one twice.
    #[error("{}: channel selection {selection:?}: {problem}", path.display())]
    ChannelSelection {
        path: PathBuf,
        selection: Vec<usize>,
        problem: String,
    },

    /// A time point past the series' last.
    #[error("{}: time point {time} is out of range: the series has {times} (0..{times})", path.display())]
    TimeOutOfRange {
        path: PathBuf,
        time: usize,
        times: usize,
    },

    /// Two files of one series that must share a grid do not.
    #[error(
        "{}: {what} on different grids: {} is {}, {} is {}",
        path.display(), path.display(), shape, other.display(), other_shape
    )]
    GridMismatch {
        path: PathBuf,
        what: &'static str,
        shape: String,
        other: PathBuf,
        other_shape: String,
    },

    /// A channel on another grid than the first file's, with no orientation to place it.
    #[error(
        "{}: its grid ({shape}) differs from {}'s ({first_shape}) and it has no affine to \
         resample by (no sform/qform, space directions or DICOM orientation); give it the \
         first file's grid, or an orientation",
        path.display(), first.display()
    )]
    NoAffine {
        path: PathBuf,
        shape: String,
        first: PathBuf,
        first_shape: String,
    },
}
