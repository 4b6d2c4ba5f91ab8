//! [`TfLut`]: a transfer function sampled into the tables the GPU reads.
//!
//! Three RGBA32F rows of [`LUT_SIZE`] texels, indexed by density. 256 entries match the
//! precision of 8-bit volumes and are finer than any hand-edited TF; with linear
//! filtering the shader sees the piecewise-linear TF up to one texel of smoothing.

use super::ControlPoint;

/// Entries per LUT row. Entry `i` holds the TF at density `i / (LUT_SIZE − 1)`, so the
/// first and last entries are the TF at exactly 0 and 1.
pub const LUT_SIZE: usize = 256;

/// A TF sampled at [`LUT_SIZE`] densities, three RGBA rows (the layout the GPU uploads).
#[derive(Debug, Clone, PartialEq)]
pub struct TfLut {
    /// `[diffuse.r, diffuse.g, diffuse.b, opacity]`.
    pub diffuse_opacity: Vec<[f32; 4]>,
    /// `[specular.r, specular.g, specular.b, roughness]`.
    pub specular_roughness: Vec<[f32; 4]>,
    /// `[emissive.r, emissive.g, emissive.b, 0]`.
    pub emissive: Vec<[f32; 4]>,
}

impl TfLut {
    /// The density of entry `i`: `i / (LUT_SIZE − 1)`.
    pub fn density_of(i: usize) -> f32 {
        i as f32 / (LUT_SIZE - 1) as f32
    }

    pub(crate) fn with_capacity(n: usize) -> Self {
        Self {
            diffuse_opacity: Vec::with_capacity(n),
            specular_roughness: Vec::with_capacity(n),
            emissive: Vec::with_capacity(n),
        }
    }

    pub(crate) fn push(&mut self, p: &ControlPoint) {
        let [r, g, b] = p.diffuse;
        self.diffuse_opacity.push([r, g, b, p.opacity]);
        let [r, g, b] = p.specular;
        self.specular_roughness.push([r, g, b, p.roughness]);
        let [r, g, b] = p.emissive;
        self.emissive.push([r, g, b, 0.0]);
    }

    /// Entries per row ([`LUT_SIZE`] for LUTs made by [`super::TransferFunction::lut`]).
    pub fn len(&self) -> usize {
        self.diffuse_opacity.len()
    }

    /// True when the rows are empty.
    pub fn is_empty(&self) -> bool {
        self.diffuse_opacity.is_empty()
    }

    /// The three rows in upload order: 0 = diffuse/opacity, 1 = specular/roughness,
    /// 2 = emissive (e.g. the layers of a 1D array image, or rows of a 2D one).
    pub fn rows(&self) -> [&[[f32; 4]]; 3] {
        [
            &self.diffuse_opacity,
            &self.specular_roughness,
            &self.emissive,
        ]
    }

    /// Whether density 0 is empty medium in every one of `channels` rows laid end to end
    /// (the first entry of each has opacity 0): then a voxel whose fields are all 0 holds
    /// nothing, whatever mask a label map gives it.
    pub fn transparent_at_zero(&self, channels: usize) -> bool {
        let n = self.len() / channels.max(1);
        n > 0
            && (0..channels.max(1))
                .all(|c| self.diffuse_opacity.get(c * n).is_some_and(|e| e[3] == 0.0))
    }

    /// The largest opacity in the table (what a majorant must bound).
    pub fn max_opacity(&self) -> f32 {
        self.diffuse_opacity
            .iter()
            .map(|e| e[3])
            .fold(0.0, f32::max)
    }

    /// Entry-wise `a·(1−t) + b·t`, `t` clamped to `[0, 1]`: exactly `a` at 0 and `b` at 1.
    /// This is how a TF edit is animated (the functions are blended, not their control
    /// points). If the lengths differ, the result has the shorter length.
    pub fn lerp(a: &Self, b: &Self, t: f32) -> Self {
        let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
        let row = |x: &[[f32; 4]], y: &[[f32; 4]]| -> Vec<[f32; 4]> {
            x.iter()
                .zip(y)
                .map(|(p, q)| std::array::from_fn(|c| p[c] * (1.0 - t) + q[c] * t))
                .collect()
        };
        Self {
            diffuse_opacity: row(&a.diffuse_opacity, &b.diffuse_opacity),
            specular_roughness: row(&a.specular_roughness, &b.specular_roughness),
            emissive: row(&a.emissive, &b.emissive),
        }
    }

    /// The same table slid along the density axis by `shift` (a fraction of the density
    /// range): entry `d` holds this table at `d − shift`, linearly interpolated and held
    /// at the ends, so a positive shift moves every feature to higher densities (a
    /// window sliding up). This is how a window sweep is animated.
    pub fn shifted(&self, shift: f32) -> Self {
        let n = self.len();
        if n < 2 || shift == 0.0 || !shift.is_finite() {
            return self.clone();
        }
        let last = (n - 1) as f32;
        let row = |x: &[[f32; 4]]| -> Vec<[f32; 4]> {
            (0..n)
                .map(|i| {
                    let at = ((i as f32 / last - shift) * last).clamp(0.0, last);
                    let k = (at.floor() as usize).min(n - 2);
                    let t = at - k as f32;
                    std::array::from_fn(|c| x[k][c] * (1.0 - t) + x[k + 1][c] * t)
                })
                .collect()
        };
        Self {
            diffuse_opacity: row(&self.diffuse_opacity),
            specular_roughness: row(&self.specular_roughness),
            emissive: row(&self.emissive),
        }
    }

    /// The largest absolute difference between corresponding entries (infinite if the
    /// lengths differ). For tests and tolerances.
    pub fn max_abs_diff(&self, other: &Self) -> f32 {
        if self.len() != other.len() {
            return f32::INFINITY;
        }
        self.rows()
            .into_iter()
            .zip(other.rows())
            .flat_map(|(x, y)| x.iter().zip(y))
            .flat_map(|(p, q)| p.iter().zip(q).map(|(a, b)| (a - b).abs()))
            .fold(0.0, f32::max)
    }
}

#[cfg(test)]
mod tests {
    use super::super::TransferFunction;
    use super::*;

    fn tf(opacity_at_1: f32, colour: [f32; 3]) -> TransferFunction {
        TransferFunction {
            name: "t".into(),
            units: Default::default(),
            points: vec![
                ControlPoint::new(0.0, 0.0, colour),
                ControlPoint::new(1.0, opacity_at_1, colour),
            ],
        }
    }

    #[test]
    fn lerp_at_0_and_1_is_exactly_a_and_b() {
        let a = tf(1.0, [0.3, 0.6, 0.9]).lut();
        let b = tf(0.4, [0.9, 0.1, 0.2]).lut();
        assert_eq!(TfLut::lerp(&a, &b, 0.0), a);
        assert_eq!(TfLut::lerp(&a, &b, 1.0), b);
        assert_eq!(TfLut::lerp(&a, &b, -2.0), a);
        assert_eq!(TfLut::lerp(&a, &b, 9.0), b);
        let h = TfLut::lerp(&a, &b, 0.5);
        assert!((h.diffuse_opacity[LUT_SIZE - 1][3] - 0.7).abs() < 1e-6);
        assert!((h.diffuse_opacity[7][0] - 0.6).abs() < 1e-6);
    }

    #[test]
    fn shifting_slides_the_table_along_density() {
        let ramp = TransferFunction {
            name: "ramp".into(),
            units: Default::default(),
            points: vec![
                ControlPoint::new(0.0, 0.0, [1.0; 3]),
                ControlPoint::new(0.5, 0.0, [1.0; 3]),
                ControlPoint::new(0.6, 1.0, [1.0; 3]),
                ControlPoint::new(1.0, 1.0, [1.0; 3]),
            ],
        }
        .lut();
        assert_eq!(ramp.shifted(0.0), ramp);
        let up = ramp.shifted(0.2);
        let opacity_at = |l: &TfLut, d: f32| l.diffuse_opacity[(d * 255.0).round() as usize][3];
        // The edge moves from 0.5–0.6 to 0.7–0.8; the ends are held.
        assert!(opacity_at(&up, 0.69) < 1e-3, "{}", opacity_at(&up, 0.69));
        assert!(
            (opacity_at(&up, 0.75) - 0.5).abs() < 0.02,
            "{}",
            opacity_at(&up, 0.75)
        );
        assert!((opacity_at(&up, 0.81) - 1.0).abs() < 1e-3);
        assert_eq!(opacity_at(&up, 1.0), 1.0);
        let down = ramp.shifted(-0.2);
        assert!(
            (opacity_at(&down, 0.35) - 0.5).abs() < 0.02,
            "{}",
            opacity_at(&down, 0.35)
        );
        assert_eq!(opacity_at(&down, 0.0), 0.0);
    }

    #[test]
    fn layout_and_helpers() {
        let l = tf(0.8, [1.0, 1.0, 1.0]).lut();
        assert_eq!(l.len(), LUT_SIZE);
        assert!(!l.is_empty());
        assert_eq!(l.rows().map(<[_]>::len), [LUT_SIZE; 3]);
        assert_eq!(l.max_opacity(), 0.8);
        assert_eq!(l.max_abs_diff(&l), 0.0);
        assert_eq!(TfLut::density_of(0), 0.0);
        assert_eq!(TfLut::density_of(LUT_SIZE - 1), 1.0);
    }
}
