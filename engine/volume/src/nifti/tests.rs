//! Tests of `nifti.rs`.

use super::*;
use crate::write::{self, NiftiData};
use crate::VolumeData;

/// Writes `data` as a 5×4×3 NIfTI at `path`, unit spacing, no scaling.
fn nifti_5x4x3(path: &Path, data: NiftiData) {
    write::nifti(path, [5, 4, 3], [1.0; 3], &data, None);
}

/// A 5×4×3 NIfTI of uint8 sevens written at `path`, and its bytes: the file the header
/// tests edit.
fn sevens(path: &Path) -> Vec<u8> {
    nifti_5x4x3(path, NiftiData::U8(vec![7; 60]));
    std::fs::read(path).expect("read")
}

#[test]
fn nii_and_nii_gz_round_trip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let u8s: Vec<u8> = (0..60).map(|i| (i * 4) as u8).collect();
    for name in ["a.nii", "a.nii.gz"] {
        let path = dir.path().join(name);
        write::nifti(
            &path,
            [5, 4, 3],
            [0.8, 0.9, 1.5],
            &NiftiData::U8(u8s.clone()),
            None,
        );
        let v = Volume::load(&path, None).expect(name);
        assert_eq!(v.name, "a");
        assert_eq!(v.dims, [5, 4, 3]);
        assert_eq!(v.spacing, [0.8, 0.9, 1.5]);
        assert_eq!(v.data, VolumeData::U8(u8s.clone()), "{name}");
    }
}

#[test]
fn scaling_int16_uint16_and_float() {
    let dir = tempfile::tempdir().expect("tempdir");
    // int16 with scl_slope 2, scl_inter -1000: physical -1000..-1000+2*59*10.
    let path = dir.path().join("s.nii.gz");
    let i: Vec<i16> = (0..60).map(|x| x * 10).collect();
    write::nifti(
        &path,
        [5, 4, 3],
        [1.0; 3],
        &NiftiData::I16(i),
        Some((2.0, -1000.0)),
    );
    let v = Volume::load(&path, None).expect("int16");
    assert_eq!(v.window, [-1000.0, 180.0]);
    let VolumeData::U16(d) = &v.data else {
        panic!("int16 must load as U16")
    };
    assert_eq!((d[0], d[59]), (0, 65535));

    let path = dir.path().join("u.nii");
    let u: Vec<u16> = (0..60).map(|x| x * 1000).collect();
    nifti_5x4x3(&path, NiftiData::U16(u.clone()));
    assert_eq!(
        Volume::load(&path, None).expect("u16").data,
        VolumeData::U16(u)
    );

    let path = dir.path().join("f.nii");
    let fl: Vec<f32> = (0..60).map(|x| x as f32 / 59.0).collect();
    nifti_5x4x3(&path, NiftiData::F32(fl.clone()));
    assert_eq!(
        Volume::load(&path, None).expect("f32").data,
        VolumeData::F32(fl)
    );
}

#[test]
fn bad_files_are_rejected_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let good = dir.path().join("good.nii");
    let bytes = sevens(&good);
    let variant = |name: &str, edit: &dyn Fn(&mut Vec<u8>)| {
        let mut b = bytes.clone();
        edit(&mut b);
        let p = dir.path().join(name);
        write::bytes(&p, &b);
        let err = Volume::load(&p, None).unwrap_err();
        assert!(err.to_string().contains(name), "{err}");
        err
    };
    let err = variant("cut.nii", &|b| b.truncate(b.len() - 5));
    assert!(
        matches!(
            err,
            VolumeError::Truncated {
                expected: 60,
                found: 55,
                ..
            }
        ),
        "{err}"
    );
    let err = variant("long.nii", &|b| b.extend_from_slice(&[0; 3]));
    assert!(matches!(err, VolumeError::SizeMismatch { .. }), "{err}");
    let err = variant("zero.nii", &|b| {
        b[42..44].copy_from_slice(&0i16.to_le_bytes())
    });
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    let err = variant("big.nii", &|b| {
        b[42..44].copy_from_slice(&5000i16.to_le_bytes())
    });
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    let err = variant("dt.nii", &|b| {
        b[70..72].copy_from_slice(&8i16.to_le_bytes())
    });
    assert!(matches!(err, VolumeError::UnsupportedType { .. }), "{err}");
    assert!(err.to_string().contains("int32") && err.to_string().contains("float64"));
    let err = variant("magic.nii", &|b| b[344..348].copy_from_slice(b"xyz\0"));
    assert!(
        matches!(&err, VolumeError::MalformedHeader { field, .. } if field == "magic"),
        "{err}"
    );
    let err = variant("hdr.nii", &|b| {
        b[0..4].copy_from_slice(&100i32.to_le_bytes())
    });
    assert!(
        matches!(&err, VolumeError::MalformedHeader { field, .. } if field == "sizeof_hdr"),
        "{err}"
    );
    let err = variant("tiny.nii", &|b| b.truncate(100));
    assert!(matches!(err, VolumeError::MalformedHeader { .. }), "{err}");
    let err = variant("t4.nii", &|b| {
        b[40..42].copy_from_slice(&4i16.to_le_bytes());
        b[48..50].copy_from_slice(&2i16.to_le_bytes());
    });
    assert!(matches!(err, VolumeError::Unsupported { .. }), "{err}");
}

#[test]
fn header_is_checked_before_the_data_is_read() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("t4.nii");
    let mut b = sevens(&path);
    b[40..42].copy_from_slice(&4i16.to_le_bytes());
    b[48..50].copy_from_slice(&20i16.to_le_bytes());
    write::bytes(&path, &b);
    // An 8 GiB (sparse) 4-D file: the loader used to read all of it first.
    let f = std::fs::OpenOptions::new()
        .write(true)
        .open(&path)
        .expect("open");
    f.set_len(8 << 30).expect("sparse file");
    let err = crate::load_within_seconds(&path, 5).unwrap_err();
    assert!(matches!(err, VolumeError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("4D NIfTI"), "{err}");
}

#[test]
fn clear_messages_for_vox_offset_pixdim_and_trailing_gzip_bytes() {
    let dir = tempfile::tempdir().expect("tempdir");
    for name in ["off.nii", "off.nii.gz"] {
        let path = dir.path().join(name);
        let plain = dir.path().join("plain.nii");
        let mut b = sevens(&plain);
        b[108..112].copy_from_slice(&1000f32.to_le_bytes());
        if name.ends_with(".gz") {
            let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
            std::io::Write::write_all(&mut e, &b).expect("gzip");
            b = e.finish().expect("gzip");
        }
        write::bytes(&path, &b);
        // Used to say "truncated: expected 60 bytes of voxel data, found 0".
        let err = Volume::load(&path, None).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains(name) && msg.contains("vox_offset") && msg.contains("1000"),
            "{msg}"
        );
    }

    // pixdim 3e38 used to load (and render black).
    let path = dir.path().join("px.nii");
    write::nifti(
        &path,
        [5, 4, 3],
        [1.0, 3e38, 1.0],
        &NiftiData::U8(vec![7; 60]),
        None,
    );
    let msg = Volume::load(&path, None).unwrap_err().to_string();
    assert!(msg.contains("pixdim") && msg.contains("1e6"), "{msg}");

    // Valid gzip followed by other bytes used to fail with "invalid gzip header".
    let path = dir.path().join("tail.nii.gz");
    let mut b = sevens(&path);
    b.extend_from_slice(&[0; 100]);
    write::bytes(&path, &b);
    let v = Volume::load(&path, None).expect("complete data with trailing zeros");
    assert_eq!(v.data, VolumeData::U8(vec![7; 60]));
}

#[test]
fn nan_in_float_nifti_is_rejected() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("nan.nii.gz");
    let mut f = vec![0.5f32; 60];
    f[17] = f32::NAN;
    nifti_5x4x3(&path, NiftiData::F32(f));
    let err = Volume::load(&path, None).unwrap_err();
    // voxel 17 = (2, 3, 0) in a 5x4 slice.
    assert!(
        matches!(
            err,
            VolumeError::NonFinite {
                count: 1,
                first: [2, 3, 0],
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("nan.nii.gz"));
}

#[test]
fn float64_loads_as_float32_and_reports_its_type() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("f64.nii");
    write::nifti(
        &path,
        [2, 1, 1],
        [1.0; 3],
        &NiftiData::F32(vec![0.0, 0.0]),
        None,
    );
    let mut b = std::fs::read(&path).expect("read back");
    b[70..72].copy_from_slice(&64i16.to_le_bytes());
    b[72..74].copy_from_slice(&64i16.to_le_bytes());
    b.truncate(352);
    for x in [0.25f64, 0.75] {
        b.extend_from_slice(&x.to_le_bytes());
    }
    std::fs::write(&path, b).expect("rewrite");
    let v = Volume::load(&path, None).expect("float64");
    assert_eq!(v.data, VolumeData::F32(vec![0.25, 0.75]));
    assert_eq!(v.sample_kind, crate::SampleKind::F32);
}
