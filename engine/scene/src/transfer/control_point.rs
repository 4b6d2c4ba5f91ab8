//! One control point of a transfer function: the optical properties at one density.

use serde::{Deserialize, Serialize};

/// Roughness used when a control point does not give one: a middle-of-the-road lobe.
pub const DEFAULT_ROUGHNESS: f32 = 0.5;

fn default_roughness() -> f32 {
    DEFAULT_ROUGHNESS
}

/// The optical properties at one density. `specular`, `emissive` and `roughness` may be
/// omitted in a file (0, 0 and [`DEFAULT_ROUGHNESS`]): most TFs are diffuse-only.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlPoint {
    /// Normalised density in `[0, 1]`.
    pub density: f32,
    /// In `[0, 1]`; extinction is `opacity × density_scale`.
    pub opacity: f32,
    /// Scattering albedo / diffuse colour, each channel in `[0, 1]`.
    pub diffuse: [f32; 3],
    /// Specular colour of the hybrid BRDF, each channel in `[0, 1]`.
    #[serde(default)]
    pub specular: [f32; 3],
    /// Emitted radiance, each channel finite and `>= 0`.
    #[serde(default)]
    pub emissive: [f32; 3],
    /// Roughness of the specular lobe in `[0, 1]`.
    #[serde(default = "default_roughness")]
    pub roughness: f32,
}

impl ControlPoint {
    /// A diffuse-only point (no specular, no emission, default roughness).
    pub fn new(density: f32, opacity: f32, diffuse: [f32; 3]) -> Self {
        Self {
            density,
            opacity,
            diffuse,
            specular: [0.0; 3],
            emissive: [0.0; 3],
            roughness: DEFAULT_ROUGHNESS,
        }
    }

    /// Every field blended as `a·(1−t) + b·t` (density included). The form is exact at
    /// both ends: `t = 0` gives `a` and `t = 1` gives `b` bit for bit.
    pub fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        let s = |x: f32, y: f32| x * (1.0 - t) + y * t;
        let v = |x: [f32; 3], y: [f32; 3]| [s(x[0], y[0]), s(x[1], y[1]), s(x[2], y[2])];
        Self {
            density: s(a.density, b.density),
            opacity: s(a.opacity, b.opacity),
            diffuse: v(a.diffuse, b.diffuse),
            specular: v(a.specular, b.specular),
            emissive: v(a.emissive, b.emissive),
            roughness: s(a.roughness, b.roughness),
        }
    }

    /// Checks every field's range; on failure returns the field name and what is wrong.
    pub(crate) fn check(&self) -> Result<(), (&'static str, String)> {
        unit("density", self.density)?;
        unit("opacity", self.opacity)?;
        for (field, c) in [("diffuse", self.diffuse), ("specular", self.specular)] {
            for (ch, x) in c.into_iter().enumerate() {
                if !(0.0..=1.0).contains(&x) {
                    return Err((field, format!("channel {ch} is {x}, must be in [0, 1]")));
                }
            }
        }
        for (ch, x) in self.emissive.into_iter().enumerate() {
            if !(x.is_finite() && (0.0..=MAX_EMISSIVE).contains(&x)) {
                return Err((
                    "emissive",
                    format!("channel {ch} is {x}, must be in [0, {MAX_EMISSIVE:e}]"),
                ));
            }
        }
        unit("roughness", self.roughness)
    }
}

/// Largest emitted radiance per channel: far brighter than any light a scene needs,
/// and far inside f32 when summed along a path.
pub const MAX_EMISSIVE: f32 = 1e6;

fn unit(field: &'static str, x: f32) -> Result<(), (&'static str, String)> {
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err((field, format!("{x} is outside [0, 1]")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn omitted_fields_take_defaults() {
        let p: ControlPoint =
            toml::from_str("density = 0.5\nopacity = 0.25\ndiffuse = [1, 0.5, 0]").expect("parses");
        assert_eq!(p, ControlPoint::new(0.5, 0.25, [1.0, 0.5, 0.0]));
        assert_eq!(p.roughness, 0.5);
        assert_eq!(p.specular, [0.0; 3]);
        assert_eq!(p.emissive, [0.0; 3]);
    }

    #[test]
    fn lerp_is_exact_at_the_ends() {
        let a = ControlPoint::new(0.1, 0.3, [0.1, 0.2, 0.3]);
        let mut b = ControlPoint::new(0.7, 0.9, [0.7, 0.6, 0.5]);
        b.emissive = [3.0, 2.0, 1.0];
        assert_eq!(ControlPoint::lerp(&a, &b, 0.0), a);
        assert_eq!(ControlPoint::lerp(&a, &b, 1.0), b);
    }

    #[test]
    fn check_names_the_field() {
        let mut p = ControlPoint::new(0.5, 0.5, [0.5; 3]);
        assert!(p.check().is_ok());
        p.diffuse[2] = 1.5;
        assert_eq!(p.check().map_err(|e| e.0), Err("diffuse"));
        p.diffuse[2] = 0.5;
        p.emissive[0] = f32::NAN;
        assert_eq!(p.check().map_err(|e| e.0), Err("emissive"));
        p.emissive[0] = 1e30;
        assert_eq!(p.check().map_err(|e| e.0), Err("emissive"));
        p.emissive[0] = 0.0;
        p.opacity = -0.1;
        assert_eq!(p.check().map_err(|e| e.0), Err("opacity"));
    }
}
