//! `cloud`: a homogeneous participating medium inside a smooth, non-convex boundary.
//!
//! One constant density inside, zero outside, no soft edge: the renderer detects this
//! with [`super::Volume::is_homogeneous`] and uses closed-form free-path sampling, and
//! analytic tests of the path tracer (transmittance through a known medium) have a
//! ground truth. The boundary is the smooth union of a torus and three spheres, so rays
//! enter and leave the medium several times (concave regions, a hole).

use super::procedural::{centre, fill_slices, length, smin, sphere};

/// The stored density inside the medium (128 / 255 ≈ 0.502).
pub(crate) const DENSITY: u8 = 128;

const SPHERES: [([f32; 3], f32); 3] = [
    ([0.0, 0.0, 0.25], 0.30),
    ([0.35, -0.25, 0.10], 0.22),
    ([-0.40, 0.30, -0.05], 0.20),
];
/// Torus in the xy plane: centre, major radius, minor radius.
const TORUS: ([f32; 3], f32, f32) = ([0.0, 0.0, -0.15], 0.52, 0.14);
/// Blend radius of the smooth union.
const BLEND: f32 = 0.12;

/// Signed distance to the boundary, in `[-1, 1]` units.
pub(crate) fn distance(p: [f32; 3]) -> f32 {
    let (c, major, minor) = TORUS;
    let q = [p[0] - c[0], p[1] - c[1], p[2] - c[2]];
    let ring = (q[0] * q[0] + q[1] * q[1]).sqrt() - major;
    let mut d = length([ring, q[2], 0.0]) - minor;
    for (c, r) in SPHERES {
        d = smin(d, sphere(p, c, r), BLEND);
    }
    d
}

/// Generates the cloud at `n`³ voxels (U8 unorm).
pub(crate) fn generate(n: u32) -> Vec<u8> {
    fill_slices([n; 3], |z, slice| {
        let pz = centre(z, n);
        for (i, v) in slice.iter_mut().enumerate() {
            let (x, y) = (i as u32 % n, i as u32 / n);
            let p = [centre(x, n), centre(y, n), pz];
            *v = if distance(p) < 0.0 { DENSITY } else { 0 };
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Volume, VolumeData};

    #[test]
    fn cloud_is_homogeneous_deterministic_and_non_convex() {
        let a = Volume::builtin("cloud", 64).expect("cloud");
        let b = Volume::builtin("cloud", 64).expect("cloud");
        assert_eq!(a.data, b.data, "same bytes twice");
        assert!(matches!(a.data, VolumeData::U8(_)));
        assert_eq!(a.is_homogeneous(), Some(f32::from(DENSITY) / 255.0));
        let filled = a.histogram(2)[1];
        assert!(
            filled > 64 * 64 * 64 / 50,
            "medium fills a fair part: {filled}"
        );
        assert_eq!(a.value(0, 0, 0), Some(0.0));
        // Non-convex: the segment between two points inside the torus ring, on opposite
        // sides of its hole, leaves the medium.
        let (c, major, _) = TORUS;
        let inside = |p: [f32; 3]| distance(p) < 0.0;
        let p0 = [c[0] - major, c[1], c[2]];
        let p1 = [c[0] + major, c[1], c[2]];
        assert!(inside(p0) && inside(p1));
        let mid_out = (1..20).any(|i| {
            let t = i as f32 / 20.0;
            !inside([0, 1, 2].map(|k| p0[k] + (p1[k] - p0[k]) * t))
        });
        assert!(
            mid_out,
            "the torus hole must be empty somewhere along the chord"
        );
    }
}
