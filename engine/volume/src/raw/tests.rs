//! Tests of `raw.rs`.

use super::*;
use crate::write;
use crate::VolumeData;
use crate::{MAX_SPACING_MM, MIN_SPACING_MM};

#[test]
fn round_trips_with_params_and_sidecars() {
    let dir = tempfile::tempdir().expect("tempdir");
    let values: Vec<u16> = (0..24).map(|i| i * 2000).collect();
    let path = dir.path().join("ramp.raw");
    write::raw_u16(&path, &values);
    let params = RawParams {
        dims: [2, 3, 4],
        format: RawFormat::U16,
        spacing: [0.5, 0.5, 2.0],
    };
    let v = Volume::load(&path, Some(&params)).expect("load with params");
    assert_eq!(v.name, "ramp");
    assert_eq!(v.dims, [2, 3, 4]);
    assert_eq!(v.spacing, [0.5, 0.5, 2.0]);
    // 0..46000 spans most of u16: the type window is kept.
    assert_eq!(v.data, VolumeData::U16(values.clone()));

    // The same file found through a TOML sidecar, then a JSON one (JSON is tried first).
    write::text(
        &dir.path().join("ramp.raw.toml"),
        "dims = [2, 3, 4]\nformat = \"uint16\"\nspacing = [0.5, 0.5, 2.0]\n",
    );
    assert_eq!(Volume::load(&path, None).expect("toml sidecar"), v);
    write::text(
        &dir.path().join("ramp.raw.json"),
        r#"{"dims": [4, 3, 2], "format": "u16"}"#,
    );
    let j = Volume::load(&path, None).expect("json sidecar");
    assert_eq!((j.dims, j.spacing), ([4, 3, 2], [1.0; 3]));
}

#[test]
fn f32_raw_round_trips() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("f.raw");
    write::raw_f32(&path, &[0.0, 0.25, 0.5, 1.0]);
    let p = RawParams {
        dims: [4, 1, 1],
        format: RawFormat::F32,
        spacing: [1.0; 3],
    };
    let v = Volume::load(&path, Some(&p)).expect("load");
    assert_eq!(v.data, VolumeData::F32(vec![0.0, 0.25, 0.5, 1.0]));
}

#[test]
fn wrong_sizes_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("short.raw");
    write::raw_u16(&path, &[1, 2, 3]);
    let mut p = RawParams {
        dims: [2, 2, 1],
        format: RawFormat::U16,
        spacing: [1.0; 3],
    };
    let err = Volume::load(&path, Some(&p)).unwrap_err();
    assert!(
        matches!(
            err,
            VolumeError::Truncated {
                expected: 8,
                found: 6,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("short.raw"));
    assert!(err.to_string().contains("expected 8 bytes"));

    p.dims = [1, 1, 1];
    let err = Volume::load(&path, Some(&p)).unwrap_err();
    assert!(matches!(err, VolumeError::SizeMismatch { .. }), "{err}");
    assert!(err.to_string().contains("short.raw"));
    assert!(err.to_string().contains("do not match"));

    p.dims = [0, 1, 3];
    let err = Volume::load(&path, Some(&p)).unwrap_err();
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    assert!(err.to_string().contains("short.raw"));

    p.dims = [8192, 1, 1];
    let err = Volume::load(&path, Some(&p)).unwrap_err();
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    assert!(err.to_string().contains("8192"));
}

#[test]
fn nan_in_float_raw_is_rejected_with_location() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("nan.raw");
    write::raw_f32(&path, &[0.0, 0.1, 0.2, f32::NAN, 0.3, f32::NEG_INFINITY]);
    let p = RawParams {
        dims: [2, 3, 1],
        format: RawFormat::F32,
        spacing: [1.0; 3],
    };
    let err = Volume::load(&path, Some(&p)).unwrap_err();
    assert!(matches!(
        err,
        VolumeError::NonFinite {
            count: 2,
            first: [1, 1, 0],
            ..
        }
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("nan.raw") && msg.contains("2 non-finite"),
        "{msg}"
    );
}

#[test]
fn malformed_sidecar_names_the_sidecar() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("v.raw");
    write::raw_u16(&path, &[0; 8]);
    write::text(
        &dir.path().join("v.raw.toml"),
        "dims = [2, 2]\nformat = \"u16\"\n",
    );
    let err = Volume::load(&path, None).unwrap_err();
    assert!(matches!(err, VolumeError::MalformedHeader { .. }), "{err}");
    assert!(err.to_string().contains("v.raw.toml"), "{err}");
}

#[test]
fn spacing_bounds_hold_after_rounding_to_f32() {
    // The inclusive bounds, as written in a file: 1e-6 rounds to 9.99999997e-7 in f32.
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("one.raw");
    write::raw_u16(&path, &[7]);
    for s in [MIN_SPACING_MM, MAX_SPACING_MM] {
        let spacing = [s as f32; 3];
        let params = RawParams {
            dims: [1, 1, 1],
            format: RawFormat::U16,
            spacing,
        };
        let v = Volume::load(&path, Some(&params)).unwrap_or_else(|e| panic!("{s:e}: {e}"));
        assert_eq!(v.spacing, spacing);
    }
    // Past them still fails.
    let params = RawParams {
        dims: [1, 1, 1],
        format: RawFormat::U16,
        spacing: [(MIN_SPACING_MM * 0.99) as f32; 3],
    };
    assert!(Volume::load(&path, Some(&params)).is_err());
}
