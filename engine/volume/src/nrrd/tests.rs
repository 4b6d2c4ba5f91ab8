//! Tests of `nrrd.rs`.

use super::*;
use crate::write::{self, NrrdData};
use crate::VolumeData;

fn ramp_i16() -> Vec<i16> {
    (0..60).map(|i| i as i16 * 50 - 1000).collect()
}

#[test]
fn attached_raw_and_gzip_round_trip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = NrrdData::I16(ramp_i16());
    for (name, gzip, big) in [
        ("a.nrrd", false, false),
        ("b.nrrd", true, false),
        ("c.nrrd", false, true),
    ] {
        let path = dir.path().join(name);
        write::nrrd(&path, [3, 4, 5], [0.5, 0.75, 2.0], &data, gzip, big, false);
        let v = Volume::load(&path, None).expect(name);
        assert_eq!(v.dims, [3, 4, 5], "{name}");
        assert_eq!(v.spacing, [0.5, 0.75, 2.0], "{name}");
        // -1000..1950 is a small part of i16: windowed to the data.
        assert_eq!(v.window, [-1000.0, 1950.0], "{name}");
        let VolumeData::U16(d) = &v.data else {
            panic!("int16 must load as U16")
        };
        assert_eq!(d[0], 0);
        assert_eq!(d[59], 65535);
        assert!(
            d.windows(2).all(|w| w[0] < w[1]),
            "{name}: ramp must stay monotone"
        );
    }
}

#[test]
fn detached_header_round_trips_with_space_directions() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("d.nhdr");
    let values: Vec<u8> = (0..24).map(|i| i * 10).collect();
    write::nrrd(
        &path,
        [2, 3, 4],
        [1.0, 2.0, 3.0],
        &NrrdData::U8(values.clone()),
        true,
        false,
        true,
    );
    assert!(dir.path().join("d.raw.gz").is_file());
    let v = Volume::load(&path, None).expect("nhdr");
    assert_eq!(v.dims, [2, 3, 4]);
    assert_eq!(v.spacing, [1.0, 2.0, 3.0]);
    // 0..230 is most of u8: untouched, but the header's space is LPS, so in RAS order
    // x and y run backwards.
    let ras: Vec<u8> = (0..4)
        .flat_map(|z| {
            (0..3)
                .rev()
                .flat_map(move |y| (0..2).rev().map(move |x| x + 2 * y + 6 * z))
        })
        .map(|i| values[i])
        .collect();
    assert_eq!(v.data, VolumeData::U8(ras));
}

#[test]
fn float_and_u16_round_trip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("f.nrrd");
    let f = vec![0.0, 0.5, 1.0, 0.25];
    write::nrrd(
        &path,
        [2, 2, 1],
        [1.0; 3],
        &NrrdData::F32(f.clone()),
        false,
        false,
        false,
    );
    assert_eq!(
        Volume::load(&path, None).expect("f32").data,
        VolumeData::F32(f)
    );
    let path = dir.path().join("u.nrrd");
    let u = vec![0, 65535, 1, 30000];
    write::nrrd(
        &path,
        [2, 2, 1],
        [1.0; 3],
        &NrrdData::U16(u.clone()),
        true,
        true,
        false,
    );
    assert_eq!(
        Volume::load(&path, None).expect("u16").data,
        VolumeData::U16(u)
    );
}

#[test]
fn hand_written_header_variants() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("h.nrrd");
    // 4D with a leading size-1 axis, spacings with nan, a comment and a key/value.
    let mut file = b"NRRD0004\n# comment\ntype: unsigned char\ndimension: 4\n\
sizes: 1 2 2 1\nspacings: nan 0.5 0.5 3\nencoding: raw\nmodality:=CT\n\n"
        .to_vec();
    file.extend_from_slice(&[0, 255, 10, 20]);
    write::bytes(&path, &file);
    let v = Volume::load(&path, None).expect("4D size-1");
    assert_eq!(v.dims, [2, 2, 1]);
    assert_eq!(v.spacing, [0.5, 0.5, 3.0]);
    assert_eq!(v.data, VolumeData::U8(vec![0, 255, 10, 20]));
}

#[test]
fn bad_files_are_rejected_by_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let data = NrrdData::I16(ramp_i16());
    let good = dir.path().join("good.nrrd");
    write::nrrd(&good, [3, 4, 5], [1.0; 3], &data, false, false, false);
    let bytes = std::fs::read(&good).expect("read");

    let cut = dir.path().join("cut.nrrd");
    write::bytes(&cut, &bytes[..bytes.len() - 10]);
    let err = Volume::load(&cut, None).unwrap_err();
    assert!(
        matches!(
            err,
            VolumeError::Truncated {
                expected: 120,
                found: 110,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("cut.nrrd"));

    let long = dir.path().join("long.nrrd");
    let mut b = bytes.clone();
    b.extend_from_slice(&[0; 4]);
    write::bytes(&long, &b);
    let err = Volume::load(&long, None).unwrap_err();
    assert!(matches!(err, VolumeError::SizeMismatch { .. }), "{err}");
    assert!(err.to_string().contains("long.nrrd"));

    let text = String::from_utf8_lossy(&bytes[..bytes.len() - 120]).to_string();
    let header_only = |name: &str, h: String, data: &[u8]| {
        let p = dir.path().join(name);
        let mut f = h.into_bytes();
        f.extend_from_slice(data);
        write::bytes(&p, &f);
        Volume::load(&p, None).unwrap_err()
    };
    let err = header_only(
        "zero.nrrd",
        text.replace("sizes: 3 4 5", "sizes: 3 0 5"),
        &[],
    );
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    assert!(err.to_string().contains("zero.nrrd"));

    let err = header_only(
        "huge.nrrd",
        text.replace("sizes: 3 4 5", "sizes: 3 4 100000"),
        &[],
    );
    assert!(matches!(err, VolumeError::BadDims { .. }), "{err}");
    assert!(err.to_string().contains("huge.nrrd"));

    let err = header_only("dbl.nrrd", text.replace("type: int16", "type: double"), &[]);
    assert!(matches!(err, VolumeError::UnsupportedType { .. }), "{err}");
    assert!(err.to_string().contains("dbl.nrrd") && err.to_string().contains("double"));

    let err = header_only("nosizes.nrrd", text.replace("sizes: 3 4 5\n", ""), &[]);
    assert!(
        matches!(&err, VolumeError::MalformedHeader { field, .. } if field == "sizes"),
        "{err}"
    );
    assert!(err.to_string().contains("nosizes.nrrd"));

    let err = header_only(
        "sz.nrrd",
        text.replace("sizes: 3 4 5", "sizes: 3 four 5"),
        &[],
    );
    assert!(matches!(err, VolumeError::MalformedHeader { .. }), "{err}");
    assert!(err.to_string().contains("`sizes`"));

    let err = header_only("magic.nrrd", text.replace("NRRD0004", "NRRX0004"), &[]);
    assert!(
        matches!(&err, VolumeError::MalformedHeader { field, .. } if field == "magic"),
        "{err}"
    );
    assert!(err.to_string().contains("magic.nrrd"));

    let err = header_only(
        "bz.nrrd",
        text.replace("encoding: raw", "encoding: bzip2"),
        &[],
    );
    assert!(matches!(err, VolumeError::Unsupported { .. }), "{err}");
    assert!(err.to_string().contains("bz.nrrd") && err.to_string().contains("bzip2"));

    let gz = dir.path().join("corrupt.nrrd");
    let mut f = text.replace("encoding: raw", "encoding: gzip").into_bytes();
    f.extend_from_slice(&[0x1f, 0x8b, 8, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9]);
    write::bytes(&gz, &f);
    let err = Volume::load(&gz, None).unwrap_err();
    assert!(
        matches!(
            err,
            VolumeError::Decompress { .. } | VolumeError::Truncated { .. }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("corrupt.nrrd"));
}

#[test]
fn detached_data_that_is_a_device_fifo_or_missing_is_refused_at_once() {
    let dir = tempfile::tempdir().expect("tempdir");
    let header = |name: &str, data_file: Option<&str>| {
        let p = dir.path().join(name);
        let mut h =
            "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 64 64 64\nencoding: raw\n".to_string();
        if let Some(f) = data_file {
            h += &format!("data file: {f}\n");
        }
        write::text(&p, &h);
        p
    };
    // Used to read /dev/zero until memory ran out (3 GB in 2.5 s).
    let p = header("zero.nhdr", Some("/dev/zero"));
    let err = crate::load_within_seconds(&p, 5).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("zero.nhdr") && msg.contains("/dev/zero is a character device"),
        "{msg}"
    );
    // Used to block forever opening the FIFO.
    let fifo = dir.path().join("pipe.raw");
    if crate::make_fifo(&fifo) {
        let p = header("fifo.nhdr", Some("pipe.raw"));
        let err = crate::load_within_seconds(&p, 5).unwrap_err();
        assert!(err.to_string().contains("FIFO"), "{err}");
    }
    // Used to say "truncated: ... found 0".
    let p = header("nodata.nhdr", None);
    let err = Volume::load(&p, None).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("nodata.nhdr") && msg.contains("data file") && msg.contains("detached"),
        "{msg}"
    );
}

#[test]
fn one_dimensional_nrrd_is_refused_with_the_dimensions_it_takes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let p = dir.path().join("line.nrrd");
    let mut f = b"NRRD0004\ntype: uint8\ndimension: 1\nsizes: 4\nencoding: raw\n\n".to_vec();
    f.extend_from_slice(&[0, 1, 2, 3]);
    write::bytes(&p, &f);
    let err = Volume::load(&p, None).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("line.nrrd") && msg.contains("dimension 1") && msg.contains("2 (one slice)"),
        "{msg}"
    );
}

#[test]
fn gzip_data_followed_by_other_bytes_loads_with_a_clear_note() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("t.nrrd");
    let values: Vec<u8> = (0..24).map(|i| i * 10).collect();
    write::nrrd(
        &path,
        [2, 3, 4],
        [1.0; 3],
        &NrrdData::U8(values.clone()),
        true,
        false,
        false,
    );
    let mut bytes = std::fs::read(&path).expect("read");
    bytes.extend_from_slice(b"\ntrailing text");
    write::bytes(&path, &bytes);
    // Used to fail with "invalid gzip header".
    let v = Volume::load(&path, None).expect("complete data with trailing bytes");
    assert_eq!(v.data, VolumeData::U8(values));
}

#[test]
fn directions_parse() {
    let v = parse_directions("none (1,0,0) (0, 2 ,0) (0,0,-3)").expect("parse");
    let lengths: Vec<Option<f64>> = v.iter().map(|d| d.as_deref().map(norm)).collect();
    assert_eq!(lengths, vec![None, Some(1.0), Some(2.0), Some(3.0)]);
    assert!(parse_directions("(1,0").is_none());
}

/// Reliability round 2: collinear `space directions` were accepted (only their lengths
/// were read), so a degenerate grid rendered as if it were rectangular.
#[test]
fn collinear_or_zero_directions_are_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (dirs, says) in [
        ("(1,0,0) (2,0,0) (0,0,1)", "axes 0 and 1 point the same way"),
        (
            "(1,0,0) (0,1,0) (0,-2,0.001)",
            "axes 1 and 2 point the same way",
        ),
        ("(0,0,0) (0,1,0) (0,0,1)", "axis 0's direction"),
    ] {
        let path = dir.path().join("v.nrrd");
        let mut bytes = format!(
            "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\
             space: left-posterior-superior\nspace directions: {dirs}\n\n"
        )
        .into_bytes();
        bytes.extend_from_slice(&[0u8; 8]);
        write::bytes(&path, &bytes);
        let e = Volume::load(&path, None).unwrap_err().to_string();
        assert!(
            e.contains("space directions") && e.contains(says),
            "{dirs}: {e}"
        );
        assert!(e.contains("v.nrrd"), "{e}");
    }
    // Oblique but spanning (a 10° shear) loads, with a warning.
    let path = dir.path().join("oblique.nrrd");
    let mut bytes = b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\
space directions: (1,0,0) (0,1,0) (0,0.17364818,0.98480775)\n\n"
        .to_vec();
    bytes.extend_from_slice(&[0u8; 8]);
    write::bytes(&path, &bytes);
    Volume::load(&path, None).expect("an oblique grid loads");
}
