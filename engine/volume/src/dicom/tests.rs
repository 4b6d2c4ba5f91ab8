//! Tests of `dicom.rs`.

use super::*;
use crate::write::{self, DicomSlice};
use crate::VolumeData;

fn slice(z: usize, pixels: Vec<i16>) -> DicomSlice {
    DicomSlice {
        rows: 3,
        cols: 4,
        pixels16: Some(pixels),
        pixels8: None,
        signed: true,
        bits_stored: 12,
        position: Some([-10.0, -20.0, 5.0 + 2.5 * z as f64]),
        orientation: Some([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
        instance: Some(z as i64 + 1),
        pixel_spacing: [0.7, 0.6],
        thickness: Some(3.0),
        rescale: (1.0, -1024.0),
        series: "1.2.3.4".into(),
        explicit: true,
    }
}

#[test]
fn three_slice_series_sorts_by_position_and_rescales() {
    let dir = tempfile::tempdir().expect("tempdir");
    // Files are named against position order, one slice is implicit VR and one has a
    // different rescale storing the same physical values.
    let mut s0 = slice(0, vec![0; 12]);
    s0.pixels16 = Some((0..12).map(|i| i * 50).collect()); // physical -1024..-474
    let mut s1 = slice(1, vec![1024; 12]); // physical 0
    s1.explicit = false;
    let mut s2 = slice(2, vec![812; 12]);
    s2.rescale = (2.0, -1024.0); // physical 600
    write::dicom(&dir.path().join("c.dcm"), &s0);
    write::dicom(&dir.path().join("a.dcm"), &s1);
    write::dicom(&dir.path().join("b.dcm"), &s2);
    write::bytes(&dir.path().join(".DS_Store"), b"junk");
    let v = Volume::load(dir.path(), None).expect("series");
    assert_eq!(v.dims, [4, 3, 3]);
    // x along columns = second PixelSpacing value.
    assert_eq!(v.spacing, [0.6, 0.7, 2.5]);
    // -1024..600 is under a quarter of the 12-bit range in physical units: windowed.
    assert_eq!(v.window, [-1024.0, 600.0]);
    let VolumeData::U16(d) = &v.data else {
        panic!("16-bit DICOM must load as U16")
    };
    let unit = |p: f64| (((p + 1024.0) / 1624.0) * 65535.0).round() as u16;
    // z=0 is the ramp (file c.dcm), z=1 physical 0 (a.dcm), z=2 physical 600 (b.dcm).
    // The series is axial in LPS, so in RAS order x and y run backwards: the ramp's
    // last pixel comes first.
    assert_eq!(d[0], unit(-474.0));
    assert_eq!(d[11], 0);
    assert_eq!(d[12], unit(0.0));
    assert_eq!(d[24], 65535);
    // The first voxel in RAS order is the file's last column and row of the first
    // slice: LPS (-10 + 3 * 0.6, -20 + 2 * 0.7, 5), negated in x and y.
    let o = v.to_patient.origin;
    for (got, want) in o.iter().zip([8.2, 18.6, 5.0]) {
        assert!((got - want).abs() < 1e-6, "{o:?}");
    }
}

#[test]
fn zeroed_orientation_and_uneven_spacing_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let zeroed = dir.path().join("zeroed");
    std::fs::create_dir(&zeroed).expect("mkdir");
    for z in 0..3 {
        let mut s = slice(z, vec![0; 12]);
        s.orientation = Some([0.0; 6]);
        write::dicom(&zeroed.join(format!("s{z}.dcm")), &s);
    }
    // Used to say the slices "lie at the same position".
    let msg = Volume::load(&zeroed, None).unwrap_err().to_string();
    assert!(
        msg.contains("ImageOrientationPatient") && msg.contains("orthogonal unit vectors"),
        "{msg}"
    );

    // A missing slice (gaps 2.5, 5.0) used to be stacked at the mean with a warning
    // nobody saw: the geometry was wrong.
    let gap = dir.path().join("gap");
    std::fs::create_dir(&gap).expect("mkdir");
    for (i, z) in [0, 1, 3].into_iter().enumerate() {
        write::dicom(&gap.join(format!("s{i}.dcm")), &slice(z, vec![0; 12]));
    }
    let msg = Volume::load(&gap, None).unwrap_err().to_string();
    assert!(
        msg.contains("uneven slice spacing") && msg.contains("5.000 mm"),
        "{msg}"
    );
}

#[test]
fn instance_number_fallback_and_8_bit() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (file, inst) in [("x1.dcm", 3), ("x2.dcm", 1), ("x3.dcm", 2)] {
        let s = DicomSlice {
            pixels16: None,
            pixels8: Some(vec![inst as u8 * 80; 12]),
            signed: false,
            bits_stored: 8,
            position: None,
            orientation: None,
            instance: Some(inst),
            rescale: (1.0, 0.0),
            ..slice(0, vec![])
        };
        write::dicom(&dir.path().join(file), &s);
    }
    let v = Volume::load(dir.path(), None).expect("series");
    assert_eq!(v.dims, [4, 3, 3]);
    assert_eq!(v.spacing[2], 3.0, "SliceThickness is the fallback distance");
    let VolumeData::U8(d) = &v.data else {
        panic!("8-bit DICOM must load as U8")
    };
    assert_eq!((d[0], d[12], d[24]), (80, 160, 240));
}

#[test]
fn bad_series_are_rejected_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    write::dicom(&dir.path().join("a.dcm"), &slice(0, vec![0; 12]));
    let mut other = slice(1, vec![0; 12]);
    other.series = "9.9".into();
    write::dicom(&dir.path().join("b.dcm"), &other);
    let err = Volume::load(dir.path(), None).unwrap_err();
    assert!(
        matches!(err, VolumeError::InconsistentSeries { .. }),
        "{err}"
    );
    assert!(err.to_string().contains("2 series"));

    let dir = tempfile::tempdir().expect("tempdir");
    write::dicom(&dir.path().join("a.dcm"), &slice(0, vec![0; 12]));
    write::dicom(&dir.path().join("b.dcm"), &slice(0, vec![0; 12]));
    let err = Volume::load(dir.path(), None).unwrap_err();
    assert!(err.to_string().contains("same position"), "{err}");

    // A truncated slice names the slice file.
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("cut.dcm");
    write::dicom(&p, &slice(0, vec![0; 12]));
    let b = std::fs::read(&p).expect("read");
    write::bytes(&p, &b[..b.len() - 4]);
    let err = Volume::load(dir.path(), None).unwrap_err();
    assert!(
        matches!(
            err,
            VolumeError::Truncated {
                expected: 24,
                found: 20,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cut.dcm"));

    // Rows that do not match the pixel data.
    let p = dir.path().join("cut.dcm");
    let mut s = slice(0, vec![0; 24]);
    s.rows = 3;
    write::dicom(&p, &s);
    let err = Volume::load(&p, None).unwrap_err();
    assert!(matches!(err, VolumeError::SizeMismatch { .. }), "{err}");

    // A compressed transfer syntax.
    let p = dir.path().join("jpeg.dcm");
    write::dicom(&p, &slice(0, vec![0; 12]));
    let mut b = std::fs::read(&p).expect("read");
    let at = b
        .windows(EXPLICIT_LE.len())
        .position(|w| w == EXPLICIT_LE.as_bytes())
        .expect("syntax uid");
    b[at..at + 19].copy_from_slice(b"1.2.840.10008.1.2.4");
    write::bytes(&p, &b);
    let err = Volume::load(&p, None).unwrap_err();
    assert!(matches!(err, VolumeError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("jpeg.dcm") && err.to_string().contains("compressed"));

    // Malformed: a PixelSpacing that is not numbers.
    let p = dir.path().join("ps.dcm");
    let mut s = slice(0, vec![0; 12]);
    s.pixel_spacing = [f64::NAN, 1.0];
    write::dicom(&p, &s);
    let err = Volume::load(&p, None).unwrap_err();
    assert!(matches!(err, VolumeError::MalformedHeader { .. }), "{err}");
    assert!(err.to_string().contains("ps.dcm") && err.to_string().contains("PixelSpacing"));

    // Empty folder.
    let empty = tempfile::tempdir().expect("tempdir");
    let err = Volume::load(empty.path(), None).unwrap_err();
    assert!(matches!(err, VolumeError::Unsupported { .. }), "{err}");
}

#[test]
fn stored_bits_are_masked_and_sign_extended() {
    let s = mask_bits(Samples::I16(vec![0x0FFF, 0x7800]), 12);
    assert_eq!(s, Samples::I16(vec![-1, -2048]));
    let u = mask_bits(Samples::U16(vec![0xF123]), 12);
    assert_eq!(u, Samples::U16(vec![0x0123]));
}
