//! `phantom`: a CT-like head for testing the renderer on thin, high-contrast structures.
//!
//! Layers from outside in, as signed distance functions evaluated at voxel centres:
//! air, scalp (soft), an ellipsoidal skull shell (bone), brain soft
//! tissue with a faint smooth texture, two ventricles (fluid, low density), and six
//! contrast-filled vessels: helical and sinusoidal tubes 1-2 voxels across at any
//! resolution, running through the soft tissue. The vessels are what a denoiser blurs
//! away first, which is why the phantom has them. Edges are box-filtered over one voxel;
//! vessels are not (their width is in voxels), so they stay crisp.

use super::procedural::{centre, coverage, ellipsoid, fill_slices, Waves};

/// Densities of the tissue classes (normalised).
pub(crate) const SCALP: f32 = 0.32;
pub(crate) const BONE: f32 = 0.80;
pub(crate) const TISSUE: f32 = 0.45;
pub(crate) const CSF: f32 = 0.14;
pub(crate) const VESSEL: f32 = 1.0;
/// Amplitude bound of the soft-tissue texture (sum of the wave amplitudes).
#[cfg(test)]
pub(crate) const TEXTURE: f32 = 0.031;

const SKIN_R: [f32; 3] = [0.78, 0.92, 0.84];
const BONE_R: [f32; 3] = [0.78 * 0.965, 0.92 * 0.965, 0.84 * 0.965];
const BRAIN_R: [f32; 3] = [0.78 * 0.9, 0.92 * 0.9, 0.84 * 0.9];

/// Ventricles: (centre, radii), a body and a lower horn per side.
const VENTRICLES: [([f32; 3], [f32; 3]); 4] = [
    ([0.11, 0.02, 0.12], [0.06, 0.26, 0.09]),
    ([-0.11, 0.02, 0.12], [0.06, 0.26, 0.09]),
    ([0.18, -0.22, -0.05], [0.05, 0.10, 0.14]),
    ([-0.18, -0.22, -0.05], [0.05, 0.10, 0.14]),
];

/// A tube along one axis whose cross-section centre moves as
/// `centre + amp * (sin(freq t + phase), cos(freq t + phase))`:
/// a helix when both amplitudes are set, a sinusoid when one is zero.
pub(crate) struct Vessel {
    pub axis: usize,
    pub centre: [f32; 2],
    pub amp: [f32; 2],
    pub freq: f32,
    pub phase: f32,
}

impl Vessel {
    /// The two axes across the tube.
    pub(crate) fn across(&self) -> [usize; 2] {
        match self.axis {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        }
    }

    /// Cross-section centre at coordinate `t` along the axis.
    pub(crate) fn at(&self, t: f32) -> [f32; 2] {
        let a = self.freq * t + self.phase;
        [
            self.centre[0] + self.amp[0] * a.sin(),
            self.centre[1] + self.amp[1] * a.cos(),
        ]
    }
}

pub(crate) const VESSELS: [Vessel; 6] = [
    Vessel {
        axis: 2,
        centre: [0.42, 0.30],
        amp: [0.06, 0.06],
        freq: 6.0,
        phase: 0.0,
    },
    Vessel {
        axis: 2,
        centre: [-0.42, 0.30],
        amp: [0.06, 0.06],
        freq: 6.0,
        phase: 1.5,
    },
    Vessel {
        axis: 2,
        centre: [0.0, -0.55],
        amp: [0.10, 0.0],
        freq: 5.0,
        phase: 0.7,
    },
    Vessel {
        axis: 1,
        centre: [0.25, -0.40],
        amp: [0.0, 0.08],
        freq: 5.0,
        phase: 0.2,
    },
    Vessel {
        axis: 1,
        centre: [-0.25, -0.40],
        amp: [0.06, 0.06],
        freq: 7.0,
        phase: 2.0,
    },
    Vessel {
        axis: 0,
        centre: [0.55, 0.35],
        amp: [0.05, 0.05],
        freq: 8.0,
        phase: 0.4,
    },
];

/// Vessel cross-section in voxels: full density within this in-plane distance of the
/// centre line (every slice has a voxel centre within 0.71 of it, so the tube never
/// breaks)...
pub(crate) const VESSEL_CORE: f32 = 0.75;
/// ...falling to none at this distance (under 2 - 0.71, so voxels two steps away are
/// tissue).
pub(crate) const VESSEL_EDGE: f32 = 1.25;

/// Generates the phantom at `n`³ voxels (U16 unorm).
pub(crate) fn generate(n: u32) -> Vec<u16> {
    let dims = [n; 3];
    let h = 2.0 / n as f32; // voxel size in [-1, 1] units
    let waves = Waves::new(
        dims,
        &[
            (0.012, [5.0, 3.0, -4.0], 0.3),
            (0.009, [-7.0, 9.0, 2.0], 1.7),
            (0.006, [13.0, -6.0, 11.0], 0.9),
            (0.004, [-17.0, 14.0, 19.0], 2.4),
        ],
    );
    // Centre line of every vessel at every index along its axis.
    let lines: Vec<Vec<[f32; 2]>> = VESSELS
        .iter()
        .map(|v| (0..n).map(|i| v.at(centre(i, n))).collect())
        .collect();
    let margin = 2.0 * h;
    fill_slices(dims, |z, slice| {
        let pz = centre(z, n);
        for y in 0..n {
            let py = centre(y, n);
            // Only the part of the row inside the (slightly grown) scalp can be non-zero.
            let t = 1.0 - (py / (SKIN_R[1] + margin)).powi(2) - (pz / (SKIN_R[2] + margin)).powi(2);
            if t <= 0.0 {
                continue;
            }
            let half = (SKIN_R[0] + margin) * t.sqrt();
            let x0 = (((1.0 - half) / h).floor().max(0.0)) as u32;
            let x1 = (((1.0 + half) / h).ceil() as u32).min(n);
            let row = &mut slice[(y * n) as usize..((y + 1) * n) as usize];
            let wrow = waves.row(y, z);
            for x in x0..x1 {
                let p = [centre(x, n), py, pz];
                let idx = [x, y, z];
                let d_skin = ellipsoid(p, [0.0; 3], SKIN_R) / h;
                if d_skin >= 0.5 {
                    continue;
                }
                let mut val = SCALP * coverage(d_skin);
                let d_bone = ellipsoid(p, [0.0; 3], BONE_R) / h;
                if d_bone < 0.5 {
                    val += (BONE - val) * coverage(d_bone);
                    let d_brain = ellipsoid(p, [0.0; 3], BRAIN_R) / h;
                    if d_brain < 0.5 {
                        let tissue = TISSUE + waves.at(&wrow, x);
                        val += (tissue - val) * coverage(d_brain);
                        let d_vent = VENTRICLES
                            .iter()
                            .map(|&(c, r)| ellipsoid(p, c, r))
                            .fold(f32::INFINITY, f32::min)
                            / h;
                        if d_vent < 0.5 {
                            val += (CSF - val) * coverage(d_vent);
                        }
                        // Vessels fade out three voxels inside the skull.
                        let inside = coverage(d_brain + 3.0);
                        if inside > 0.0 {
                            let mut cov: f32 = 0.0;
                            for (v, line) in VESSELS.iter().zip(&lines) {
                                let q = line[idx[v.axis] as usize];
                                let [a, b] = v.across();
                                let (du, dv) = ((p[a] - q[0]) / h, (p[b] - q[1]) / h);
                                let d2 = du * du + dv * dv;
                                if d2 < VESSEL_EDGE * VESSEL_EDGE {
                                    let d = d2.sqrt();
                                    let c = (VESSEL_EDGE - d) / (VESSEL_EDGE - VESSEL_CORE);
                                    cov = cov.max(c.clamp(0.0, 1.0));
                                }
                            }
                            val += (VESSEL - val) * cov * inside;
                        }
                    }
                }
                row[x as usize] = (val.clamp(0.0, 1.0) * 65535.0).round() as u16;
            }
        }
    })
}

/// The phantom's tissue classes as labels: what [`labels`] writes per voxel.
pub const LABELS: [(u16, &str, [f32; 3]); 5] = [
    (1, "scalp", [0.85, 0.66, 0.56]),
    (2, "skull", [0.95, 0.93, 0.84]),
    (3, "brain", [0.86, 0.58, 0.56]),
    (4, "ventricles", [0.40, 0.62, 0.95]),
    (5, "vessels", [0.92, 0.16, 0.14]),
];

/// The phantom's segmentation at `n`³ voxels: the class whose region holds each voxel's
/// centre (0 outside the scalp), from the same shapes [`generate`] fills. A vessel voxel
/// is one whose centre lies within a voxel of a centre line, where the vessels are
/// drawn (three voxels inside the skull on).
pub(crate) fn labels(n: u32) -> Vec<u16> {
    let dims = [n; 3];
    let h = 2.0 / n as f32;
    let lines: Vec<Vec<[f32; 2]>> = VESSELS
        .iter()
        .map(|v| (0..n).map(|i| v.at(centre(i, n))).collect())
        .collect();
    let vessel_r = 0.5 * (VESSEL_CORE + VESSEL_EDGE);
    fill_slices(dims, |z, slice| {
        for y in 0..n {
            for x in 0..n {
                let p = [centre(x, n), centre(y, n), centre(z, n)];
                let idx = [x, y, z];
                let label = if ellipsoid(p, [0.0; 3], SKIN_R) >= 0.0 {
                    0
                } else if ellipsoid(p, [0.0; 3], BONE_R) >= 0.0 {
                    1
                } else {
                    let d_brain = ellipsoid(p, [0.0; 3], BRAIN_R) / h;
                    let vessel = d_brain + 3.0 < 0.5
                        && VESSELS.iter().zip(&lines).any(|(v, line)| {
                            let q = line[idx[v.axis] as usize];
                            let [a, b] = v.across();
                            let (du, dv) = ((p[a] - q[0]) / h, (p[b] - q[1]) / h);
                            du * du + dv * dv < vessel_r * vessel_r
                        });
                    let ventricle = VENTRICLES.iter().any(|&(c, r)| ellipsoid(p, c, r) < 0.0);
                    match () {
                        _ if d_brain >= 0.0 => 2,
                        _ if vessel => 5,
                        _ if ventricle => 4,
                        _ => 3,
                    }
                };
                slice[(y * n + x) as usize] = label;
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Volume, VolumeData};

    #[test]
    fn phantom_is_deterministic_and_has_its_tissue_classes() {
        let a = Volume::builtin("phantom", 48).expect("phantom");
        let b = Volume::builtin("phantom", 48).expect("phantom");
        assert_eq!(a.data.as_bytes(), b.data.as_bytes(), "same bytes twice");
        assert!(matches!(a.data, VolumeData::U16(_)));
        assert_eq!((a.dims, a.spacing), ([48; 3], [1.0; 3]));
        assert_eq!(a.value(0, 0, 0), Some(0.0), "air in the corner");
        let c = a.value(24, 24, 24).expect("centre");
        assert!(
            (c - TISSUE).abs() <= TEXTURE + 1e-3,
            "soft tissue at the centre: {c}"
        );
        let max = (0..a.data.len())
            .filter_map(|i| a.data.get(i))
            .fold(0.0, f32::max);
        // Contrast-filled vessels are the densest class (above bone, as in CT angiography).
        assert!(
            (max - VESSEL).abs() < 1e-3 || (max - BONE).abs() < 1e-3,
            "the densest voxel is vessel or bone: {max}"
        );
        // A ventricle centre is fluid.
        let (vc, _) = VENTRICLES[0];
        let [x, y, z] = vc.map(|c| ((c + 1.0) / 2.0 * 48.0) as u32);
        let v = a.value(x, y, z).expect("ventricle");
        assert!((v - CSF).abs() < 0.01, "ventricle density {v}");
    }

    #[test]
    fn vessels_are_thin_chains_in_soft_tissue() {
        let n = 96;
        let vol = Volume::builtin("phantom", n).expect("phantom");
        let h = 2.0 / n as f32;
        let to_index = |c: f32| ((c + 1.0) / h - 0.5).round() as i64;
        for (vi, v) in VESSELS.iter().enumerate() {
            let [a, b] = v.across();
            let mut prev: Option<[i64; 3]> = None;
            let (mut chain, mut longest) = (0, 0);
            // Walk the middle third of the vessel's axis, one voxel at a time.
            for t in n / 3..2 * n / 3 {
                let q = v.at(centre(t, n));
                let mut idx = [0i64; 3];
                idx[v.axis] = i64::from(t);
                idx[a] = to_index(q[0]);
                idx[b] = to_index(q[1]);
                let get = |i: [i64; 3]| {
                    vol.value(i[0] as u32, i[1] as u32, i[2] as u32)
                        .unwrap_or(0.0)
                };
                let here = get(idx);
                if here < VESSEL - 0.01 {
                    prev = None; // e.g. where the vessel leaves the brain
                    chain = 0;
                    continue;
                }
                // Two voxels away across the tube: soft tissue.
                for (axis, step) in [(a, 2), (a, -2), (b, 2), (b, -2)] {
                    let mut j = idx;
                    j[axis] += step;
                    let s = get(j);
                    assert!(
                        (s - TISSUE).abs() <= TEXTURE + 0.01,
                        "vessel {vi} at {idx:?}: voxel {j:?} is {s}, not soft tissue"
                    );
                }
                if let Some(p) = prev {
                    assert!(
                        (0..3).all(|k| (p[k] - idx[k]).abs() <= 1),
                        "vessel {vi} breaks between {p:?} and {idx:?}"
                    );
                }
                prev = Some(idx);
                chain += 1;
                longest = longest.max(chain);
            }
            assert!(
                longest >= 10,
                "vessel {vi}: longest chain is {longest} voxels"
            );
        }
    }
}
