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
mod tests {
    use super::*;

    const TWO: &str = r#"
        name = "two"
        [[point]]
        density = 1.0
        opacity = 0.5
        diffuse = [0.0, 0.0, 1.0]
        [[point]]
        density = 0.2
        opacity = 1.0
        diffuse = [0.0, 1.0, 0.0]
        [[point]]
        density = 0.0
        opacity = 0.0
        diffuse = [1.0, 0.0, 0.0]
        roughness = 0.1
    "#;

    fn two() -> TransferFunction {
        TransferFunction::from_toml_str(TWO, "two.toml").expect("valid TF")
    }

    #[test]
    fn parsing_sorts_by_density() {
        let tf = two();
        assert_eq!(tf.name, "two");
        let d: Vec<f32> = tf.points.iter().map(|p| p.density).collect();
        assert_eq!(d, [0.0, 0.2, 1.0]);
        assert!(tf.validate().is_ok());
    }

    #[test]
    fn name_defaults_to_file_stem() {
        let text = TWO.replace("name = \"two\"", "");
        let tf =
            TransferFunction::from_toml_str(&text, "/some/dir/bone-white.toml").expect("valid");
        assert_eq!(tf.name, "bone-white");
    }

    #[test]
    fn lut_is_exact_at_control_points_and_linear_between() {
        let lut = two().lut();
        assert_eq!(lut.len(), LUT_SIZE);
        // Endpoints: exactly the first and last control points.
        assert_eq!(lut.diffuse_opacity[0], [1.0, 0.0, 0.0, 0.0]);
        assert_eq!(lut.specular_roughness[0], [0.0, 0.0, 0.0, 0.1]);
        assert_eq!(lut.diffuse_opacity[LUT_SIZE - 1], [0.0, 0.0, 1.0, 0.5]);
        // Density 0.2 is entry 51 (51/255): exactly the middle control point.
        assert_eq!(TfLut::density_of(51), 0.2);
        assert_eq!(lut.diffuse_opacity[51], [0.0, 1.0, 0.0, 1.0]);
        // Halfway between 0.2 and 1.0 is 0.6 = entry 153.
        let mid = lut.diffuse_opacity[153];
        let want = [0.0, 0.5, 0.5, 0.75];
        for (m, w) in mid.iter().zip(want) {
            assert!((m - w).abs() < 1e-6, "{mid:?} != {want:?}");
        }
        // A quarter of the way from 0 to 0.2 (not a LUT entry): sample directly.
        let q = two().sample(0.05);
        assert!((q.opacity - 0.25).abs() < 1e-6 && (q.roughness - 0.2).abs() < 1e-6);
    }

    #[test]
    fn values_are_clamped_outside_the_points() {
        let text = r#"
            [[point]]
            density = 0.25
            opacity = 0.2
            diffuse = [0.5, 0.5, 0.5]
            [[point]]
            density = 0.75
            opacity = 0.6
            diffuse = [1.0, 1.0, 1.0]
        "#;
        let tf = TransferFunction::from_toml_str(text, "inner.toml").expect("valid");
        let lut = tf.lut();
        assert_eq!(lut.diffuse_opacity[0], [0.5, 0.5, 0.5, 0.2]);
        assert_eq!(lut.diffuse_opacity[10], [0.5, 0.5, 0.5, 0.2]);
        assert_eq!(lut.diffuse_opacity[LUT_SIZE - 1], [1.0, 1.0, 1.0, 0.6]);
        assert_eq!(tf.sample(-3.0).opacity, 0.2);
        assert_eq!(tf.sample(7.0).opacity, 0.6);
    }

    #[test]
    fn lerp_blends_the_functions() {
        let a = two();
        let b = TransferFunction {
            name: "b".into(),
            points: vec![
                ControlPoint::new(0.0, 1.0, [1.0, 1.0, 1.0]),
                ControlPoint::new(0.5, 0.0, [0.0, 0.0, 0.0]),
                ControlPoint::new(0.9, 0.3, [0.2, 0.4, 0.6]),
            ],
        };
        b.validate().expect("b valid");
        let (la, lb) = (a.lut(), b.lut());
        let close = |x: &TfLut, y: &TfLut| x.max_abs_diff(y) < 1e-5;
        assert!(close(&TransferFunction::lerp(&a, &b, 0.0).lut(), &la));
        assert!(close(&TransferFunction::lerp(&a, &b, 1.0).lut(), &lb));
        for t in [0.25, 0.5, 0.8] {
            let tf = TransferFunction::lerp(&a, &b, t);
            tf.validate().expect("blend valid");
            assert!(close(&tf.lut(), &TfLut::lerp(&la, &lb, t)), "t = {t}");
        }
        // The blend is of functions: at density 0.5, a is 1 − 0.3/0.8·0.5, b is 0.
        let mid = TransferFunction::lerp(&a, &b, 0.5).sample(0.5).opacity;
        let want = 0.5 * (1.0 - 0.5 * (0.3 / 0.8));
        assert!((mid - want).abs() < 1e-6, "{mid} vs {want}");
    }

    fn err(text: &str) -> String {
        match TransferFunction::from_toml_str(text, "bad.toml") {
            Ok(_) => panic!("accepted: {text}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn errors_name_file_point_and_field() {
        let e = err(&TWO.replace("opacity = 0.5", "opacity = 1.5"));
        assert!(e.starts_with("bad.toml: point[0].opacity:"), "{e}");

        let e = err(&TWO.replace("diffuse = [0.0, 1.0, 0.0]", "diffuse = [0.0, -1.0, 0.0]"));
        assert!(e.starts_with("bad.toml: point[1].diffuse:"), "{e}");

        let e = err(&TWO.replace("density = 1.0", "density = 1.2"));
        assert!(e.starts_with("bad.toml: point[0].density:"), "{e}");

        let e = err(&TWO.replace("density = 1.0", "density = 0.0"));
        assert!(
            e.starts_with("bad.toml: point[2].density:") && e.contains("point[0]"),
            "{e}"
        );

        let e = err("[[point]]\ndensity = 0.0\nopacity = 0.0\ndiffuse = [1,1,1]\n");
        assert!(
            e.starts_with("bad.toml: point:") && e.contains("at least 2"),
            "{e}"
        );

        let e = err(&TWO.replace("roughness = 0.1", "roughnes = 0.1"));
        assert!(
            e.starts_with("bad.toml:") && e.contains("roughnes") && e.contains("line"),
            "{e}"
        );

        let e = err("name = \"x\"\n[[point]\n");
        assert!(e.starts_with("bad.toml:") && e.contains("line 2"), "{e}");
    }

    #[test]
    fn validate_rejects_unsorted_points() {
        let mut tf = two();
        tf.points.swap(0, 1);
        let e = tf.validate().map_err(|e| e.to_string());
        assert!(
            matches!(&e, Err(m) if m.starts_with("two: point[1].density")),
            "{e:?}"
        );
    }

    #[test]
    fn to_toml_round_trips() {
        let mut tf = two();
        tf.name = "quote \" and \\ backslash".into();
        tf.points[1].emissive = [0.1, 2.5, 1e-7];
        tf.points[2].specular = [0.3, 0.3, 0.3];
        let back = TransferFunction::from_toml_str(&tf.to_toml(), "rt.toml").expect("round trip");
        assert_eq!(back, tf);
    }
}
