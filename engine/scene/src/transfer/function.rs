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
    /// What the points' `density` means: the normalised density, or the volume's data
    /// units (Hounsfield for CT), converted when the TF meets a volume
    /// ([`Self::in_density`]).
    pub units: TfUnits,
}

/// The units of a TF's densities (`units = "density"` or `"data"` in its file).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TfUnits {
    /// The volume's normalised density, `[0, 1]` over its window.
    #[default]
    Density,
    /// The volume's physical values: Hounsfield units for CT (from the rescale slope
    /// and intercept), the stored values otherwise.
    Data,
}

/// The TOML layout of one TF file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TfFile {
    name: Option<String>,
    #[serde(default)]
    units: TfUnits,
    #[serde(default, rename = "point")]
    points: Vec<ControlPoint>,
}

impl TransferFunction {
    /// Reads and checks a TF file; its name defaults to the file stem.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, TransferError> {
        let path = path.as_ref();
        let text = dvr_volume::files::read_text(path, dvr_volume::files::MAX_TEXT_FILE_BYTES)
            .map_err(|source| TransferError::Io {
                path: path.to_path_buf(),
                source,
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
            check_point(origin, index, p, file.units)?;
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
            units: file.units,
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
            check_point(origin, index, p, self.units)?;
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
            units: a.units,
        }
    }

    /// The TF over normalised density for a volume whose `window` (physical values at
    /// density 0 and 1) is given: a data-unit TF's points are mapped through the window
    /// and cut to `[0, 1]` (the TF's values at the cuts become end points); a density TF
    /// is returned as it is.
    pub fn in_density(&self, window: [f32; 2]) -> Self {
        if self.units == TfUnits::Density {
            return self.clone();
        }
        let [lo, hi] = window;
        let span = if hi > lo { hi - lo } else { 1.0 };
        let to_data = |d: f32| lo + d * span;
        let mut points: Vec<ControlPoint> = self
            .points
            .iter()
            .map(|p| ControlPoint {
                density: (p.density - lo) / span,
                ..*p
            })
            .filter(|p| p.density > 0.0 && p.density < 1.0)
            .collect();
        for (end, at) in [(0.0f32, 0usize), (1.0, usize::MAX)] {
            let mut p = self.sample(to_data(end));
            p.density = end;
            if at == 0 {
                points.insert(0, p);
            } else {
                points.push(p);
            }
        }
        Self {
            name: self.name.clone(),
            points,
            units: TfUnits::Density,
        }
    }

    /// The TF as a TOML file in the format [`Self::from_toml_str`] reads (what the
    /// explorer's editor saves). Numbers are written in their shortest exact form.
    pub fn to_toml(&self) -> String {
        let mut s = String::new();
        let v3 = |c: [f32; 3]| format!("[{:?}, {:?}, {:?}]", c[0], c[1], c[2]);
        // `write!` to a String cannot fail.
        let _ = writeln!(s, "name = {}", toml_string(&self.name));
        if self.units == TfUnits::Data {
            let _ = writeln!(s, "units = \"data\"");
        }
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

fn check_point(
    origin: &str,
    index: usize,
    p: &ControlPoint,
    units: TfUnits,
) -> Result<(), TransferError> {
    let checked = match units {
        TfUnits::Density => p.check(),
        // Data units may be any finite value (HU run from -1024 to several thousand).
        TfUnits::Data if !p.density.is_finite() => Err((
            "density",
            format!("{} is not a finite data value", p.density),
        )),
        TfUnits::Data => ControlPoint { density: 0.5, ..*p }.check(),
    };
    checked.map_err(|(field, message)| TransferError::InvalidPoint {
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
