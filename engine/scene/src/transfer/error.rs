//! Errors from reading and checking transfer functions.
//!
//! `origin` is the file a TF came from (or its name when it was built in code), so a
//! message always says where to look; point errors add the index of the `[[point]]` in
//! the file (0-based, in file order) and the field.

use std::path::PathBuf;

/// Everything that can go wrong reading or checking a transfer function.
#[derive(Debug, thiserror::Error)]
pub enum TransferError {
    /// The file could not be read.
    #[error("{}: cannot read transfer function: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown field or a value of the wrong type (the message
    /// carries the line and column).
    #[error("{origin}: {source}")]
    Parse {
        origin: String,
        source: toml::de::Error,
    },
    /// Fewer than two control points: a TF needs a range to interpolate over.
    #[error("{origin}: point: a transfer function needs at least 2 control points, found {count}")]
    TooFewPoints { origin: String, count: usize },
    /// One field of one control point is out of range.
    #[error("{origin}: point[{index}].{field}: {message}")]
    InvalidPoint {
        origin: String,
        index: usize,
        field: &'static str,
        message: String,
    },
    /// Two control points share a density (the TF would be discontinuous there).
    #[error(
        "{origin}: point[{second}].density: {density} duplicates point[{first}].density \
         (densities must be strictly increasing)"
    )]
    DuplicateDensity {
        origin: String,
        first: usize,
        second: usize,
        density: f32,
    },
    /// Control points built in code are not sorted by density.
    #[error(
        "{origin}: point[{index}].density: {density} is not greater than the previous \
         point's density (points must be sorted and strictly increasing)"
    )]
    NotIncreasing {
        origin: String,
        index: usize,
        density: f32,
    },
    /// No preset of that name in the assets folder.
    #[error("unknown transfer-function preset `{name}` (looked in {}); available: {available}", dir.display())]
    UnknownPreset {
        name: String,
        dir: PathBuf,
        available: String,
    },
}
