//! Tests of `normalise.rs`.

use super::*;
use crate::samples::SampleKind;

fn run(samples: Samples, rescale: Rescale, dims: [u32; 3]) -> Normalised {
    let stored = Stored {
        type_range: samples.kind().full_range(),
        samples,
        rescale,
        orientation: None,
    };
    normalise(Path::new("t.raw"), dims, stored, None).expect("normalise")
}

#[test]
fn full_range_u8_is_untouched() {
    let n = run(
        Samples::U8(vec![0, 10, 255, 7]),
        Rescale::Uniform(Affine::IDENTITY),
        [4, 1, 1],
    );
    assert_eq!(n.data, VolumeData::U8(vec![0, 10, 255, 7]));
    assert_eq!(n.window, [0.0, 255.0]);
}

#[test]
fn twelve_bit_ct_is_windowed_to_its_data() {
    // i16 CT in Hounsfield units: -1024..3071 uses 1/16 of the type's range.
    let n = run(
        Samples::I16(vec![-1024, 0, 3071, 1000]),
        Rescale::Uniform(Affine::IDENTITY),
        [2, 2, 1],
    );
    assert_eq!(n.window, [-1024.0, 3071.0]);
    let VolumeData::U16(v) = n.data else {
        panic!("16-bit must stay 16-bit")
    };
    assert_eq!(v[0], 0);
    assert_eq!(v[2], 65535);
    assert_eq!(v[1], ((1024.0 / 4095.0) * 65535.0f64).round() as u16);
}

#[test]
fn wide_integer_data_keeps_the_type_window() {
    let n = run(
        Samples::U16(vec![0, 40000]),
        Rescale::Uniform(Affine::IDENTITY),
        [2, 1, 1],
    );
    assert_eq!(n.window, [0.0, 65535.0]);
    assert_eq!(n.data, VolumeData::U16(vec![0, 40000]));
}

#[test]
fn per_slice_rescale_lands_on_one_scale() {
    // Two slices storing the same physical values with different rescales.
    let slope2 = Affine {
        slope: 2.0,
        intercept: -100.0,
    };
    let n = run(
        Samples::U16(vec![100, 300, 100, 200]),
        Rescale::PerSlice(vec![Affine::IDENTITY, slope2]),
        [2, 1, 2],
    );
    // physical: slice 0 = 100, 300; slice 1 = 100, 300.
    assert_eq!(n.window, [100.0, 300.0]);
    assert_eq!(n.data, VolumeData::U16(vec![0, 65535, 0, 65535]));
}

#[test]
fn float_in_unit_range_is_kept_and_others_windowed() {
    let n = run(
        Samples::F32(vec![0.25, 0.5]),
        Rescale::Uniform(Affine::IDENTITY),
        [2, 1, 1],
    );
    assert_eq!(n.data, VolumeData::F32(vec![0.25, 0.5]));
    let n = run(
        Samples::F32(vec![-2.0, 2.0, 0.0]),
        Rescale::Uniform(Affine::IDENTITY),
        [3, 1, 1],
    );
    assert_eq!(n.window, [-2.0, 2.0]);
    assert_eq!(n.data, VolumeData::F32(vec![0.0, 1.0, 0.5]));
    let n = run(
        Samples::F32(vec![5.0, 5.0]),
        Rescale::Uniform(Affine::IDENTITY),
        [2, 1, 1],
    );
    assert_eq!(n.data, VolumeData::F32(vec![1.0, 1.0]));
}

/// Reliability round 2: two voxels at ±3.4e38 set the min–max window and flattened
/// every other voxel to 0.5 without a word. Now they are clamped (and a warning counts
/// them); the rest keep their spread.
#[test]
fn float_outliers_do_not_set_the_window() {
    let mut v: Vec<f32> = (0..1000).map(|i| 10.0 + 80.0 * i as f32 / 999.0).collect();
    v.push(3.4e38);
    v.push(-3.4e38);
    let n = run(
        Samples::F32(v),
        Rescale::Uniform(Affine::IDENTITY),
        [1002, 1, 1],
    );
    assert_eq!(n.window, [10.0, 90.0]);
    let VolumeData::F32(d) = n.data else {
        panic!("float data stays float")
    };
    assert_eq!((d[0], d[999], d[1000], d[1001]), (0.0, 1.0, 1.0, 0.0));
    assert!((d[500] - 0.5).abs() < 0.01);
    // A wide but honest range is left alone.
    let n = run(
        Samples::F32(vec![-1000.0, 0.0, 3000.0, 1.0]),
        Rescale::Uniform(Affine::IDENTITY),
        [4, 1, 1],
    );
    assert_eq!(n.window, [-1000.0, 3000.0]);
}

#[test]
fn nan_is_an_error_naming_the_first_voxel() {
    let stored = Stored::plain(Samples::F32(vec![
        0.0,
        0.0,
        0.0,
        f32::NAN,
        f32::INFINITY,
        0.0,
    ]));
    let err = normalise(Path::new("bad.raw"), [3, 1, 2], stored, None).unwrap_err();
    assert!(matches!(
        err,
        VolumeError::NonFinite {
            count: 2,
            first: [0, 0, 1],
            ..
        }
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("bad.raw") && msg.contains("(0, 0, 1)"),
        "{msg}"
    );
}

#[test]
fn dicom_bits_stored_range_is_the_type_range() {
    let stored = Stored {
        samples: Samples::U16(vec![0, 4095]),
        type_range: Some((0.0, 4095.0)),
        rescale: Rescale::Uniform(Affine::IDENTITY),
        orientation: None,
    };
    let n = normalise(Path::new("x.dcm"), [2, 1, 1], stored, None).expect("normalise");
    assert_eq!(n.window, [0.0, 4095.0]);
    assert_eq!(n.data, VolumeData::U16(vec![0, 65535]));
    assert_eq!(SampleKind::I16.full_range(), Some((-32768.0, 32767.0)));
}
