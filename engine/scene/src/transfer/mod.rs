//! Transfer functions: how a density sample becomes optical properties.
//!
//! A volume stores one scalar per voxel (density, normalised to `[0, 1]`). The path
//! tracer needs, for every density, an extinction coefficient and the colours that decide
//! what happens at a scattering event. A *transfer function* (TF) is that mapping. People
//! edit it as a handful of [`ControlPoint`]s (piecewise linear in density); the GPU reads
//! it as three 1D lookup tables of [`LUT_SIZE`] entries ([`TfLut`]), because a texture
//! fetch is cheaper and simpler in a shader than searching control points.
//!
//! - [`control_point`]: one control point and its field checks.
//! - [`function`]: [`TransferFunction`]: parsing (TOML), validation, evaluation,
//!   interpolation between two TFs.
//! - [`lut`]: [`TfLut`]: the sampled tables the GPU uploads, and their interpolation.
//! - [`preset`]: the named presets in `assets/transfer/*.toml` and where assets live.
//! - [`error`]: [`TransferError`]; every message names the file (or TF) and the point
//!   index and field at fault.
//!
//! Units: `opacity` is in `[0, 1]` and is turned into extinction by the scene's
//! `density_scale` (`μt = opacity × density_scale`, per world unit; see
//! [`crate`]). `diffuse` is the scattering albedo (and the diffuse colour of the
//! hybrid BRDF), `specular` and `roughness` parameterise the hybrid BRDF's specular lobe,
//! and `emissive` is radiance the medium emits at that density (added where a path
//! collides with the medium, as in Exposure Render; only used when the scene turns
//! emission on). These are the properties Exposure Render's TFs carry.
//!
//! # File format
//!
//! One TOML file per TF:
//!
//! ```toml
//! name = "example"          # optional; defaults to the file name without `.toml`
//!
//! [[point]]
//! density = 0.0             # in [0, 1]; points are sorted by density, duplicates are an error
//! opacity = 0.0             # in [0, 1]
//! diffuse = [1.0, 1.0, 1.0] # albedo, each channel in [0, 1]
//!
//! [[point]]
//! density = 1.0
//! opacity = 1.0
//! diffuse = [0.9, 0.8, 0.7]
//! specular = [0.2, 0.2, 0.2] # optional, in [0, 1], default 0
//! emissive = [0.0, 0.0, 0.0] # optional, >= 0, default 0
//! roughness = 0.5            # optional, in [0, 1], default 0.5
//! ```
//!
//! Between two control points every property is linear in density; below the first and
//! above the last point the TF holds the end point's values.

pub mod control_point;
pub mod error;
pub mod function;
pub mod lut;
pub mod preset;

pub use control_point::ControlPoint;
pub use error::TransferError;
pub use function::{TfUnits, TransferFunction};
pub use lut::{TfLut, LUT_SIZE};
