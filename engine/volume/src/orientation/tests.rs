//! Tests of `orientation.rs`: exact reordering for flips and permutations, the LPS
//! conversion, and resampling of oblique grids checked on a linear field (which
//! trilinear interpolation reproduces exactly).

use super::*;
use crate::samples::{Samples, Stored};
use crate::write::{self, NiftiData};

/// A volume whose voxel (x, y, z) holds `x + 10 y + 100 z` (as f32 density / 1000).
fn indexed(dims: [u32; 3]) -> Volume {
    let mut v = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                v.push((x + 10 * y + 100 * z) as f32 / 1000.0);
            }
        }
    }
    Volume::new("t", dims, [1.0; 3], VolumeData::F32(v)).expect("valid")
}

fn at(v: &Volume, x: u32, y: u32, z: u32) -> f32 {
    (v.value(x, y, z).expect("inside") * 1000.0).round()
}

#[test]
fn an_aligned_transform_changes_nothing_but_the_origin() {
    let v = indexed([3, 4, 5]);
    let mut t = PatientTransform::aligned([1.0, 2.0, 3.0]);
    t.origin = [-5.0, 6.0, 7.0];
    let r = to_ras(Path::new("t"), v.clone(), t).expect("aligned");
    assert_eq!(r.data, v.data);
    assert_eq!(r.spacing, [1.0, 2.0, 3.0]);
    assert_eq!(r.to_patient.origin, [-5.0, 6.0, 7.0]);
}

#[test]
fn a_flipped_x_axis_reverses_x_and_moves_the_origin() {
    let v = indexed([3, 2, 2]);
    let t = PatientTransform {
        axes: [[-2.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        origin: [10.0, 0.0, 0.0],
    };
    let r = to_ras(Path::new("t"), v, t).expect("flip");
    assert_eq!(r.dims, [3, 2, 2]);
    // New x = 0 is old x = 2, the leftmost point: R grows with the new x.
    assert_eq!(at(&r, 0, 1, 1), 2.0 + 10.0 + 100.0);
    assert_eq!(at(&r, 2, 0, 0), 0.0);
    assert_eq!(r.to_patient.origin, [6.0, 0.0, 0.0]);
    assert_eq!(r.spacing, [2.0, 1.0, 1.0]);
}

#[test]
fn permuted_axes_are_reordered_with_their_spacing() {
    // Index x runs along S, y along R, z along -A.
    let v = indexed([2, 3, 4]);
    let t = PatientTransform {
        axes: [[0.0, 0.0, 1.5], [0.5, 0.0, 0.0], [0.0, -2.0, 0.0]],
        origin: [0.0; 3],
    };
    let r = to_ras(Path::new("t"), v, t).expect("permute");
    assert_eq!(r.dims, [3, 4, 2]);
    assert_eq!(r.spacing, [0.5, 2.0, 1.5]);
    for (i, j, k) in [(0, 0, 0), (2, 1, 1), (1, 3, 0)] {
        // RAS (i, j, k) is old (x = k, y = i, z = 3 - j).
        let want = (k + 10 * i + 100 * (3 - j)) as f32;
        assert_eq!(at(&r, i, j, k), want, "({i},{j},{k})");
    }
    let p = r.to_patient.apply([0.0; 3]);
    assert_eq!(p, [0.0, -6.0, 0.0]);
}

#[test]
fn lps_axes_become_ras_by_negating_x_and_y() {
    let t = PatientTransform::from_lps(
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [1.0, 2.0, 3.0],
    );
    assert_eq!(t.axes[0], [-1.0, 0.0, 0.0]);
    assert_eq!(t.axes[1], [0.0, -1.0, 0.0]);
    assert_eq!(t.origin, [-1.0, -2.0, 3.0]);
    let r = to_ras(Path::new("t"), indexed([2, 2, 1]), t).expect("lps");
    assert_eq!(at(&r, 0, 0, 0), 11.0);
    assert_eq!(at(&r, 1, 1, 0), 0.0);
}

#[test]
fn an_oblique_grid_is_resampled_where_its_voxels_lie() {
    // A field linear in patient space, f = 0.01 * (R + 2 A + 3 S) + 0.5, sampled on a
    // grid rotated 30° about S: trilinear interpolation reproduces it exactly inside.
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let t = PatientTransform {
        axes: [[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]],
        origin: [0.0, 0.0, 0.0],
    };
    assert!(t.is_oblique());
    let dims = [12u32, 10, 4];
    let f = |p: [f64; 3]| 0.01 * (p[0] + 2.0 * p[1] + 3.0 * p[2]) + 0.5;
    let mut data = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                data.push(f(t.apply([x as f64, y as f64, z as f64])) as f32);
            }
        }
    }
    let v = Volume::new("o", dims, [1.0; 3], VolumeData::F32(data)).expect("valid");
    let r = to_ras(Path::new("o"), v, t).expect("oblique");
    assert_eq!(r.spacing, [1.0; 3]);
    let inverse = invert(t);
    let mut inside = 0;
    for k in 0..r.dims[2] {
        for j in 0..r.dims[1] {
            for i in 0..r.dims[0] {
                let p = r.to_patient.apply([i, j, k].map(f64::from));
                let q = inverse(p);
                let got = r.value(i, j, k).expect("inside");
                let within = (0..3).all(|a| q[a] >= 0.0 && q[a] <= f64::from(dims[a] - 1));
                if within {
                    inside += 1;
                    assert!(
                        (f64::from(got) - f(p)).abs() < 1e-5,
                        "{p:?}: {got} vs {}",
                        f(p)
                    );
                } else if (0..3).any(|a| q[a] < -0.01 || q[a] > f64::from(dims[a] - 1) + 0.01) {
                    assert_eq!(got, 0.0, "outside at {p:?}");
                }
            }
        }
    }
    assert!(inside > 200, "{inside} voxels inside");
}

#[test]
fn degenerate_axes_are_an_error_naming_the_orientation() {
    let t = PatientTransform {
        axes: [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        origin: [0.0; 3],
    };
    let err = to_ras(Path::new("bad.nii"), indexed([2, 2, 2]), t).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("bad.nii") && msg.contains("orientation"),
        "{msg}"
    );
}

#[test]
fn stored_samples_with_an_orientation_load_in_ras_order() {
    let samples = Samples::U8(vec![10, 20, 30]);
    let load = |orientation| {
        let stored = Stored {
            orientation,
            ..Stored::plain(samples.clone())
        };
        Volume::from_stored(Path::new("s"), "s".into(), [3, 1, 1], [1.0; 3], stored).expect("load")
    };
    let plain = load(None);
    let flipped = load(Some(PatientTransform {
        axes: [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        origin: [0.0; 3],
    }));
    let VolumeData::U8(p) = plain.data else {
        panic!("u8 stays u8")
    };
    let reversed: Vec<u8> = p.iter().rev().copied().collect();
    assert_eq!(flipped.data, VolumeData::U8(reversed));
    assert_eq!(flipped.window, plain.window);
}

/// Writes a NIfTI whose sform (code 2) holds `rows`.
fn nifti_with_sform(path: &Path, dims: [u32; 3], data: Vec<f32>, rows: [[f32; 4]; 3]) {
    write::nifti(path, dims, [1.0; 3], &NiftiData::F32(data), None);
    let mut b = std::fs::read(path).expect("read back");
    b[254..256].copy_from_slice(&2i16.to_le_bytes());
    for (r, row) in rows.iter().enumerate() {
        for (c, x) in row.iter().enumerate() {
            let at = 280 + 16 * r + 4 * c;
            b[at..at + 4].copy_from_slice(&x.to_le_bytes());
        }
    }
    std::fs::write(path, b).expect("rewrite");
}

#[test]
fn a_nifti_whose_sform_flips_x_loads_mirrored() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data: Vec<f32> = (0..8).map(|i| i as f32 / 8.0).collect();
    let plain = dir.path().join("plain.nii");
    let flipped = dir.path().join("flipped.nii");
    let ident = [
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
    ];
    let mut flip = ident;
    flip[0][0] = -1.0;
    nifti_with_sform(&plain, [2, 2, 2], data.clone(), ident);
    nifti_with_sform(&flipped, [2, 2, 2], data, flip);
    let a = Volume::load(&plain, None).expect("plain");
    let b = Volume::load(&flipped, None).expect("flipped");
    for z in 0..2 {
        for y in 0..2 {
            for x in 0..2 {
                assert_eq!(a.value(x, y, z), b.value(1 - x, y, z), "({x},{y},{z})");
            }
        }
    }
    assert_ne!(a.data, b.data);
    assert_eq!(b.to_patient.origin, [-1.0, 0.0, 0.0]);
}
