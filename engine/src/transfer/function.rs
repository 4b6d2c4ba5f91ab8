//! [`TransferFunction`]: control points read from TOML, checked, evaluated and blended.
//!
//! Parsing sorts the points by density, so a file may list them in any order; field
//! errors still cite the point's position in the file, which is what a person editing
//! it can find.

use std::fmt::Write as _;
use std::path::Path;

use serde::Deserialize;

use super::{ControlPoint, TfLut, TransferError, LUT_SIZE};

/// A transfer function: control points sorted by strictly increasing density.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    /// Shown in the UI and in reports; presets use their file name.
    pub name: String,
    /// Sorted by density, at least two, densities strictly increasing.
    pub points: Vec<ControlPoint>,
}

/// The TOML layout of one TF file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TfFile {
    name: Option<String>,
    #[serde(default, rename = "point")]
    points: Vec<ControlPoint>,
}

impl TransferFunction {
    /// Reads and checks a TF file; its name defaults to the file stem.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, TransferError> {
        let path = path.as_ref();
        let text =
            crate::files::read_text(path, crate::files::MAX_TEXT_FILE_BYTES).map_err(|source| {
                TransferError::Io {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Self::from_toml_str(&text, &path.display().to_string())
    }

    /// Parses and checks TF text. `origin` names the text in error messages (a file path
    /// or a label) and, through its file stem, gives the default name.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, TransferError> {
        let file: TfFile = toml::from_str(text).map_err(|source| TransferError::Parse {
            origin: origin.to_string(),
            source,
        })?;
        let name = file.name.unwrap_or_else(|| {
            Path::new(origin)
                .file_stem()
                .map_or_else(|| origin.to_string(), |s| s.to_string_lossy().into_owned())
        });
        if file.points.len() < 2 {
            return Err(TransferError::TooFewPoints {
                origin: origin.to_string(),
                count: file.points.len(),
            });
        }
        for (index, p) in file.points.iter().enumerate() {
            check_point(origin, index, p)?;
        }
        // Sort, remembering each point's index in the file for the duplicate message.
        let mut indexed: Vec<(usize, ControlPoint)> = file.points.into_iter().enumerate().collect();
        indexed.sort_by(|a, b| a.1.density.total_cmp(&b.1.density));
        for w in indexed.windows(2) {
            if w[0].1.density == w[1].1.density {
                let (first, second) = (w[0].0.min(w[1].0), w[0].0.max(w[1].0));
                return Err(TransferError::DuplicateDensity {
                    origin: origin.to_string(),
                    first,
                    second,
                    density: w[0].1.density,
                });
            }
        }
        Ok(Self {
            name,
            points: indexed.into_iter().map(|(_, p)| p).collect(),
        })
    }

    /// Checks a TF built or edited in code: at least two points, every field in range,
    /// densities strictly increasing. Errors name the TF by its `name`.
    pub fn validate(&self) -> Result<(), TransferError> {
        let origin = &self.name;
        if self.points.len() < 2 {
            return Err(TransferError::TooFewPoints {
                origin: origin.clone(),
                count: self.points.len(),
            });
        }
        for (index, p) in self.points.iter().enumerate() {
            check_point(origin, index, p)?;
        }
        for (index, w) in self.points.windows(2).enumerate() {
            // `!(a < b)` rather than `a >= b`: also rejects NaN (already caught above).
            if w[0].density.partial_cmp(&w[1].density) != Some(std::cmp::Ordering::Less) {
                return Err(TransferError::NotIncreasing {
                    origin: origin.clone(),
                    index: index + 1,
                    density: w[1].density,
                });
            }
        }
        Ok(())
    }

    /// The TF's value at `density`: linear between the two surrounding control points,
    /// the end point's value outside their range. Exactly a control point's values at
    /// its density. The returned point's `density` is `density`.
    pub fn sample(&self, density: f32) -> ControlPoint {
        let (Some(first), Some(last)) = (self.points.first(), self.points.last()) else {
            // Only reachable for an unvalidated, empty TF: transparent black.
            return ControlPoint::new(density, 0.0, [0.0; 3]);
        };
        let k = self.points.partition_point(|p| p.density <= density);
        let mut out = if k == 0 {
            *first
        } else if k == self.points.len() {
            *last
        } else {
            let (a, b) = (&self.points[k - 1], &self.points[k]);
            let t = (density - a.density) / (b.density - a.density);
            ControlPoint::lerp(a, b, t)
        };
        out.density = density;
        out
    }

    /// Samples the TF at the [`LUT_SIZE`] densities `i / (LUT_SIZE − 1)`.
    pub fn lut(&self) -> TfLut {
        let mut lut = TfLut::with_capacity(LUT_SIZE);
        for i in 0..LUT_SIZE {
            lut.push(&self.sample(TfLut::density_of(i)));
        }
        lut
    }

    /// The TF whose every property is `a·(1−t) + b·t` at every density, `t` clamped to
    /// `[0, 1]`: the functions are blended, not the point lists. Because both are
    /// piecewise linear, the blend is piecewise linear with breakpoints at the union of
    /// both TFs' densities, so it is represented exactly (up to rounding). Its LUT equals
    /// [`TfLut::lerp`] of the two LUTs.
    pub fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let mut densities: Vec<f32> = a
            .points
            .iter()
            .chain(&b.points)
            .map(|p| p.density)
            .collect();
        densities.sort_by(f32::total_cmp);
        densities.dedup();
        let points = densities
            .into_iter()
            .map(|d| {
                let mut p = ControlPoint::lerp(&a.sample(d), &b.sample(d), t);
                p.density = d;
                p
            })
            .collect();
        Self {
            name: format!("{}..{}@{t}", a.name, b.name),
            points,
        }
    }

    /// The TF as a TOML file in the format [`Self::from_toml_str`] reads (what the
    /// explorer's editor saves). Numbers are written in their shortest exact form.
    pub fn to_toml(&self) -> String {
        let mut s = String::new();
        let v3 = |c: [f32; 3]| format!("[{:?}, {:?}, {:?}]", c[0], c[1], c[2]);
        // `write!` to a String cannot fail.
        let _ = writeln!(s, "name = {}", toml_string(&self.name));
        for p in &self.points {
            let _ = writeln!(s, "\n[[point]]");
            let _ = writeln!(s, "density = {:?}", p.density);
            let _ = writeln!(s, "opacity = {:?}", p.opacity);
            let _ = writeln!(s, "diffuse = {}", v3(p.diffuse));
            let _ = writeln!(s, "specular = {}", v3(p.specular));
            let _ = writeln!(s, "emissive = {}", v3(p.emissive));
            let _ = writeln!(s, "roughness = {:?}", p.roughness);
        }
        s
    }
}

fn check_point(origin: &str, index: usize, p: &ControlPoint) -> Result<(), TransferError> {
    p.check()
        .map_err(|(field, message)| TransferError::InvalidPoint {
            origin: origin.to_string(),
            index,
            field,
            message,
        })
}

/// A TOML basic string (quotes and escapes) for any text.
fn toml_string(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

#[cfg(test)]
mod tests;
