use super::*;
use crate::write::{self, NiftiData, NrrdData};
use crate::VolumeData;
use serde_json::json;

fn u8s(v: &Volume) -> Vec<u8> {
    match &v.data {
        VolumeData::U8(d) => d.clone(),
        other => panic!("expected u8 data, got {other:?}"),
    }
}

/// A 2×2×2 uint8 block whose voxel i holds `base + i * 30` (so 0 and 210 at base 0:
/// a wide range, whose window is the type's, 0..255).
fn block(base: u8) -> Vec<u8> {
    (0..8u8).map(|i| base + i * 30).collect()
}

/// Writes `data` as a NIfTI of 2×2×2 volumes, `extra = [time points, channels]` of them
/// (the data holds them time fastest, then channel), unit spacing, no scaling or sform.
fn nifti_2x2x2(path: &Path, extra: [u32; 2], data: NiftiData) {
    write::nifti_series(path, [2, 2, 2], extra, [1.0; 3], &data, None, None);
}

#[test]
fn a_series_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<Series>();
}

#[test]
fn one_channel_one_time_point_loads_as_volume_load_in_every_format() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let data: Vec<u16> = (0..24).map(|i| i * 1000).collect();
    let mut files = Vec::new();
    let nii = d.join("a.nii.gz");
    write::nifti(
        &nii,
        [2, 3, 4],
        [1.0, 2.0, 3.0],
        &NiftiData::U16(data.clone()),
        None,
    );
    files.push(nii);
    for (name, detached) in [("b.nrrd", false), ("c.nhdr", true)] {
        let p = d.join(name);
        let nd = NrrdData::U16(data.clone());
        write::nrrd(&p, [2, 3, 4], [1.0, 0.5, 2.0], &nd, false, false, detached);
        files.push(p);
    }
    let raw = d.join("e.raw");
    write::raw_u16(&raw, &data);
    write::text(
        &d.join("e.raw.json"),
        r#"{"dims": [2, 3, 4], "format": "u16"}"#,
    );
    files.push(raw);
    let pages: Vec<Vec<u8>> = (0..4).map(|z| vec![z * 60; 6]).collect();
    let tif = d.join("f.ome.tif");
    write::ome_tiff(
        &tif,
        2,
        3,
        &pages,
        r#"<OME><Image><Pixels DimensionOrder="XYZCT" SizeX="2" SizeY="3" SizeZ="4"/></Image></OME>"#,
    );
    files.push(tif);
    files.push(zarr_v3(
        d,
        "g.zarr",
        &[1, 1, 4, 3, 2],
        &(0..24).collect::<Vec<u8>>(),
        json!({}),
    ));
    for f in files {
        let want = Volume::load(&f, None).unwrap();
        let s = Series::open(&f, None).unwrap();
        assert_eq!(s.info().times, 1);
        assert_eq!(s.info().channels.len(), 1, "{}", f.display());
        assert_eq!(s.info().dims, want.dims);
        assert_eq!(s.info().to_patient, want.to_patient);
        assert_eq!(s.info().channels[0].window, want.window);
        let got = s.read(0).unwrap();
        assert_eq!(got, vec![want], "{}", f.display());
    }
}

#[test]
fn nifti_time_points_and_channels_are_read_one_time_point_at_a_time() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("fmri.nii");
    // 3 time points of 2 channels; the file runs x, y, z, then t, then channel.
    let mut data = Vec::new();
    for c in 0..2u8 {
        for t in 0..3u8 {
            data.extend(block(c * 3 + t));
        }
    }
    nifti_2x2x2(&p, [3, 2], NiftiData::U8(data));
    let s = Series::open(&p, None).unwrap();
    assert_eq!(s.info().times, 3);
    let names: Vec<&str> = s.info().channels.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["channel 0", "channel 1"]);
    for t in 0..3u8 {
        let v = s.read(t as usize).unwrap();
        assert_eq!(v.len(), 2);
        assert_eq!(u8s(&v[0]), block(t));
        assert_eq!(u8s(&v[1]), block(3 + t));
        // One window per channel over time (the type's range here).
        assert_eq!(v[0].window, [0.0, 255.0]);
    }
    assert_eq!(
        s.read(2).unwrap(),
        s.read(2).unwrap(),
        "reads are repeatable"
    );
    // A selection, in the order given.
    let s = Series::open(&p, Some(&[1, 0])).unwrap();
    let v = s.read(1).unwrap();
    assert_eq!((u8s(&v[0]), u8s(&v[1])), (block(4), block(1)));
    // Another thread reads the next time point.
    let s = Arc::new(s);
    let s2 = Arc::clone(&s);
    let next = std::thread::spawn(move || s2.read(2))
        .join()
        .unwrap()
        .unwrap();
    assert_eq!(u8s(&next[1]), block(2));
    // Volume::load still refuses the 4D file, saying how to read it.
    let e = Volume::load(&p, None).unwrap_err().to_string();
    assert!(e.contains("fmri.nii") && e.contains("series"), "{e}");
}

#[test]
fn later_time_points_keep_the_first_ones_window() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("grow.nii");
    // Float data: time 0 spans 0..2, time 1 spans 0..4, clamped by time 0's window.
    let t0: Vec<f32> = (0..8).map(|i| i as f32 * 2.0 / 7.0).collect();
    let t1: Vec<f32> = t0.iter().map(|x| x * 2.0).collect();
    let data = [t0, t1].concat();
    nifti_2x2x2(&p, [2, 1], NiftiData::F32(data));
    let s = Series::open(&p, None).unwrap();
    assert_eq!(s.info().channels[0].window, [0.0, 2.0]);
    let v = s.read(1).unwrap();
    assert_eq!(v[0].window, [0.0, 2.0]);
    let VolumeData::F32(d) = &v[0].data else {
        panic!("float data")
    };
    assert!((d[1] - 2.0 / 7.0).abs() < 1e-6 && d[7] == 1.0, "{d:?}");
}

/// A NRRD of uint8 `data` with `sizes` and `extra` header lines.
fn nrrd(path: &Path, sizes: &str, extra: &str, data: &[u8]) {
    let n = sizes.split_whitespace().count();
    let mut f =
        format!("NRRD0004\ntype: uint8\ndimension: {n}\nsizes: {sizes}\nencoding: raw\n{extra}\n")
            .into_bytes();
    f.extend_from_slice(data);
    write::bytes(path, &f);
}

#[test]
fn nrrd_axes_by_kinds_and_by_size() {
    let dir = tempfile::tempdir().unwrap();
    // Interleaved RGB: channels fastest.
    let p = dir.path().join("rgb.nrrd");
    let mut data = Vec::new();
    for i in 0..8 {
        data.extend([block(0)[i], block(1)[i], block(2)[i]]);
    }
    nrrd(
        &p,
        "3 2 2 2",
        "kinds: RGB-color domain domain domain\n",
        &data,
    );
    let s = Series::open(&p, None).unwrap();
    assert_eq!((s.info().channels.len(), s.info().times), (3, 1));
    let v = s.read(0).unwrap();
    assert_eq!(u8s(&v[2]), block(2));
    // Time last, by kinds, and without them (5 entries > 4: time).
    let data: Vec<u8> = (0..5).flat_map(block).collect();
    for (name, extra) in [
        ("t.nrrd", "kinds: domain domain domain time\n"),
        ("n.nrrd", ""),
    ] {
        let p = dir.path().join(name);
        nrrd(&p, "2 2 2 5", extra, &data);
        let s = Series::open(&p, None).unwrap();
        assert_eq!((s.info().channels.len(), s.info().times), (1, 5), "{name}");
        assert_eq!(u8s(&s.read(3).unwrap()[0]), block(3));
    }
    // Without kinds, 2 entries (≤ 4) are channels; the `none` direction says which axis.
    let p = dir.path().join("two.nrrd");
    let data: Vec<u8> = (0..2).flat_map(block).collect();
    nrrd(
        &p,
        "2 2 2 2",
        "space: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,1) none\n",
        &data,
    );
    let s = Series::open(&p, None).unwrap();
    assert_eq!((s.info().channels.len(), s.info().times), (2, 1));
    assert_eq!(u8s(&s.read(0).unwrap()[1]), block(1));
    // 5D: vector and time, by kinds.
    let p = dir.path().join("vt.nrrd");
    let mut data = Vec::new();
    for t in 0..3u8 {
        for i in 0..8 {
            data.extend([block(t)[i], block(t + 3)[i]]);
        }
    }
    nrrd(
        &p,
        "2 2 2 2 3",
        "kinds: vector domain domain domain time\n",
        &data,
    );
    let s = Series::open(&p, Some(&[1])).unwrap();
    assert_eq!(s.info().times, 3);
    assert_eq!(u8s(&s.read(2).unwrap()[0]), block(5));
    let e = Volume::load(&p, None).unwrap_err().to_string();
    assert!(e.contains("vt.nrrd") && e.contains("series"), "{e}");
}

/// An OME-Zarr 0.5 image `name` with axes t, c, z, y, x of `shape` in chunks of one
/// (t, c), uint8 `data` in C order, and `omero` attributes.
fn zarr_v3(
    dir: &Path,
    name: &str,
    shape: &[u64; 5],
    data: &[u8],
    omero: serde_json::Value,
) -> PathBuf {
    let root = dir.join(name);
    let axes = json!([{"name": "t", "type": "time"}, {"name": "c", "type": "channel"},
        {"name": "z", "type": "space", "unit": "millimeter"},
        {"name": "y", "type": "space", "unit": "millimeter"},
        {"name": "x", "type": "space", "unit": "millimeter"}]);
    let mut ome = json!({"version": "0.5", "multiscales": [{"axes": axes, "datasets": [{"path": "0",
        "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0, 2.0, 1.0, 1.0]}]}]}]});
    if omero != json!({}) {
        ome["omero"] = omero;
    }
    let group = json!({"zarr_format": 3, "node_type": "group", "attributes": {"ome": ome}});
    let chunk = [1, 1, shape[2], shape[3], shape[4]];
    let array = json!({"zarr_format": 3, "node_type": "array", "shape": shape, "data_type": "uint8",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": chunk}},
        "chunk_key_encoding": {"name": "default"}, "fill_value": 0, "codecs": [{"name": "bytes"}]});
    std::fs::create_dir_all(root.join("0")).unwrap();
    write::text(&root.join("zarr.json"), &group.to_string());
    write::text(&root.join("0/zarr.json"), &array.to_string());
    let vol = (shape[2] * shape[3] * shape[4]) as usize;
    for t in 0..shape[0] {
        for c in 0..shape[1] {
            let at = ((t * shape[1] + c) as usize) * vol;
            let key = root.join(format!("0/c/{t}/{c}/0/0/0"));
            std::fs::create_dir_all(key.parent().unwrap()).unwrap();
            write::bytes(&key, &data[at..at + vol]);
        }
    }
    root
}

#[test]
fn ome_zarr_channels_and_time_points_with_omero_metadata() {
    let dir = tempfile::tempdir().unwrap();
    // 2 time points × 3 channels of 2×2×2.
    let data: Vec<u8> = (0..6).flat_map(block).collect();
    let omero = json!({"channels": [
        {"label": "DAPI", "color": "0000FF", "window": {"start": 0, "end": 100, "min": 0, "max": 255}},
        {"label": "GFP", "color": "00FF00"}, {"label": "RFP", "color": "FF0000"}]});
    let p = zarr_v3(dir.path(), "cells.zarr", &[2, 3, 2, 2, 2], &data, omero);
    let s = Series::open(&p, Some(&[2, 0])).unwrap();
    let info = s.info();
    assert_eq!(info.times, 2);
    assert_eq!(info.spacing, [1.0, 1.0, 2.0]);
    assert_eq!(info.channels[0].name, "RFP");
    assert_eq!(info.channels[0].colour, Some([255, 0, 0]));
    assert_eq!(info.channels[1].display_window, Some([0.0, 100.0]));
    let v = s.read(1).unwrap();
    assert_eq!((u8s(&v[0]), u8s(&v[1])), (block(5), block(3)));
    // A NaN window is refused, naming the field.
    let bad = json!({"channels": [{"window": {"start": "NaN", "end": 1}}]});
    let p = zarr_v3(dir.path(), "nan.zarr", &[1, 1, 2, 2, 2], &block(0), bad);
    let e = Series::open(&p, None).unwrap_err().to_string();
    assert!(e.contains("nan.zarr") && e.contains("window.start"), "{e}");
}

#[test]
fn ome_zarr_0_4_channels() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("v2.zarr");
    std::fs::create_dir_all(root.join("0")).unwrap();
    let axes = json!([{"name": "c", "type": "channel"}, {"name": "z", "type": "space"},
        {"name": "y", "type": "space"}, {"name": "x", "type": "space"}]);
    write::text(&root.join(".zgroup"), r#"{"zarr_format": 2}"#);
    write::text(
        &root.join(".zattrs"),
        &json!({"multiscales": [{"version": "0.4", "axes": axes, "datasets": [{"path": "0",
            "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0, 1.0, 1.0]}]}]}],
            "omero": {"channels": [{"label": "a"}, {"label": "b"}]}})
        .to_string(),
    );
    write::text(
        &root.join("0/.zarray"),
        &json!({"zarr_format": 2, "shape": [2, 2, 2, 2], "chunks": [1, 2, 2, 2], "dtype": "|u1",
            "compressor": null, "fill_value": 0, "order": "C", "filters": null,
            "dimension_separator": "/"})
        .to_string(),
    );
    for c in 0..2u8 {
        let key = root.join(format!("0/{c}/0/0/0"));
        std::fs::create_dir_all(key.parent().unwrap()).unwrap();
        write::bytes(&key, &block(c * 5));
    }
    let s = Series::open(&root, None).unwrap();
    assert_eq!(s.info().channels[1].name, "b");
    assert_eq!(u8s(&s.read(0).unwrap()[1]), block(5));
}

#[test]
fn ome_tiff_channels_and_time_points_in_every_dimension_order() {
    let dir = tempfile::tempdir().unwrap();
    // Z = 2 slices of 2×2, C = 2, T = 3; page (z, c, t) holds 10z + 3c + 50t + index.
    let page =
        |z: u8, c: u8, t: u8| -> Vec<u8> { (0..4).map(|i| 10 * z + 3 * c + 50 * t + i).collect() };
    for order in ["XYZCT", "XYZTC", "XYCZT", "XYCTZ", "XYTZC", "XYTCZ"] {
        let mut pages = Vec::new();
        let dims: Vec<char> = order[2..].chars().collect();
        let size = |d: char| match d {
            'Z' => 2u8,
            'C' => 2,
            _ => 3,
        };
        for k in 0..size(dims[2]) {
            for j in 0..size(dims[1]) {
                for i in 0..size(dims[0]) {
                    let mut zct = [0u8; 3];
                    for (d, v) in dims.iter().zip([i, j, k]) {
                        zct["ZCT".find(*d).unwrap()] = v;
                    }
                    pages.push(page(zct[0], zct[1], zct[2]));
                }
            }
        }
        let xml = format!(
            r#"<OME><Image><Pixels DimensionOrder="{order}" SizeX="2" SizeY="2" SizeZ="2" SizeC="2" SizeT="3"><Channel ID="Channel:0:0" Name="nuclei" Color="-16776961"/><Channel ID="Channel:0:1" Name="membrane" Color="16711935"/></Pixels></Image></OME>"#
        );
        let p = dir.path().join(format!("{order}.ome.tif"));
        write::ome_tiff(&p, 2, 2, &pages, &xml);
        let s = Series::open(&p, None).unwrap();
        let info = s.info();
        assert_eq!((info.channels.len(), info.times), (2, 3), "{order}");
        assert_eq!(info.channels[0].name, "nuclei");
        assert_eq!(info.channels[0].colour, Some([255, 0, 0]));
        assert_eq!(info.channels[1].colour, Some([0, 255, 0]));
        let v = s.read(2).unwrap();
        // Stored uint8 in a narrow range: the window is time 0's data range.
        let lo = f64::from(v[1].window[0]);
        let hi = f64::from(v[1].window[1]);
        for z in 0..2u8 {
            for i in 0..4u8 {
                let want = f64::from(page(z, 1, 2)[i as usize]);
                let got = v[1]
                    .value(u32::from(i % 2), u32::from(i / 2), u32::from(z))
                    .unwrap();
                let expect = ((want - lo) / (hi - lo)).clamp(0.0, 1.0);
                assert!(
                    (f64::from(got) - expect).abs() < 1.0 / 255.0,
                    "{order} z{z} i{i}"
                );
            }
        }
        let _ = Volume::load(&p, None).unwrap();
    }
}

/// A float NIfTI `name` of `dims` voxels of `spacing` mm, its sform placing voxel 0 at
/// `origin`, holding the linear field 1 + x + 2y + 3z (patient mm).
fn linear_nifti(dir: &Path, name: &str, dims: [u32; 3], spacing: f32, origin: [f32; 3]) -> PathBuf {
    let p = dir.join(name);
    let mut data = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let x = origin[0] + i as f32 * spacing;
                let y = origin[1] + j as f32 * spacing;
                let z = origin[2] + k as f32 * spacing;
                data.push(1.0 + x + 2.0 * y + 3.0 * z);
            }
        }
    }
    let sform = [
        [spacing, 0.0, 0.0, origin[0]],
        [0.0, spacing, 0.0, origin[1]],
        [0.0, 0.0, spacing, origin[2]],
    ];
    write::nifti_series(
        &p,
        dims,
        [1, 1],
        [spacing; 3],
        &NiftiData::F32(data),
        None,
        Some(sform),
    );
    p
}

#[test]
fn channels_from_files_are_resampled_onto_the_first_grid() {
    let dir = tempfile::tempdir().unwrap();
    let t1 = linear_nifti(dir.path(), "t1.nii", [5, 5, 5], 1.0, [0.0; 3]);
    let stat = linear_nifti(dir.path(), "stat.nii", [3, 3, 3], 2.0, [0.0; 3]);
    let s = Series::open_channels(&[t1.clone(), stat], None).unwrap();
    let info = s.info();
    assert_eq!(info.dims, [5, 5, 5]);
    assert_eq!(info.channels[1].name, "stat");
    assert!(info.channels[1].resampled && !info.channels[0].resampled);
    let v = s.read(0).unwrap();
    assert_eq!(v[1].dims, [5, 5, 5]);
    assert_eq!(v[1].to_patient, v[0].to_patient);
    // Trilinear interpolation of a linear field is exact: both channels hold it.
    let [lo, hi] = v[1].window.map(f64::from);
    for (x, y, z) in [(0, 0, 0), (1, 2, 3), (3, 1, 4), (4, 4, 4)] {
        let f = 1.0 + f64::from(x) + 2.0 * f64::from(y) + 3.0 * f64::from(z);
        let got = f64::from(v[1].value(x, y, z).unwrap());
        assert!(
            (got - (f - lo) / (hi - lo)).abs() < 1e-5,
            "({x},{y},{z}) {got}"
        );
    }
    // A file without an affine on another grid cannot be placed.
    let raw = dir.path().join("noaffine.raw");
    write::raw_f32(&raw, &[0.5; 8]);
    write::text(
        &dir.path().join("noaffine.raw.json"),
        r#"{"dims": [2, 2, 2], "format": "f32"}"#,
    );
    let e = Series::open_channels(&[t1.clone(), raw], None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("noaffine.raw") && e.contains("no affine to resample by"),
        "{e}"
    );
    // The same shape without an affine is taken as aligned.
    let raw = dir.path().join("aligned.raw");
    write::raw_f32(&raw, &[0.25; 125]);
    write::text(
        &dir.path().join("aligned.raw.json"),
        r#"{"dims": [5, 5, 5], "format": "f32"}"#,
    );
    let s = Series::open_channels(&[t1, raw], None).unwrap();
    let v = s.read(0).unwrap();
    assert_eq!(v[1].to_patient, v[0].to_patient);
    assert_eq!(v[1].value(2, 2, 2), Some(0.25));
}

#[test]
fn time_points_from_a_list_or_a_glob() {
    let dir = tempfile::tempdir().unwrap();
    for t in 0..3u8 {
        let p = dir.path().join(format!("vol_{t:03}.nii"));
        nifti_2x2x2(&p, [1, 1], NiftiData::U8(block(t)));
    }
    let s = Series::open_glob(&dir.path().join("vol_*.nii"), None).unwrap();
    assert_eq!(s.info().times, 3);
    assert_eq!(u8s(&s.read(2).unwrap()[0]), block(2));
    // A time point on another grid: both shapes named.
    let odd = dir.path().join("vol_003.nii");
    write::nifti(&odd, [2, 2, 3], [1.0; 3], &NiftiData::U8(vec![0; 12]), None);
    let e = Series::open_glob(&dir.path().join("vol_*.nii"), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("2x2x2") && e.contains("2x2x3") && e.contains("vol_003.nii"),
        "{e}"
    );
    let e = Series::open_glob(&dir.path().join("none_*.nii"), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("matches no file"), "{e}");
}

#[test]
fn bad_selections_times_and_channel_counts_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("five.nii");
    let data: Vec<u8> = (0..5).flat_map(block).collect();
    nifti_2x2x2(&p, [1, 5], NiftiData::U8(data));
    let e = Series::open(&p, None).unwrap_err().to_string();
    assert!(
        e.contains("five.nii") && e.contains("5 channels") && e.contains("channels = [0, 2]"),
        "{e}"
    );
    let s = Series::open(&p, Some(&[4, 0])).unwrap();
    assert_eq!(u8s(&s.read(0).unwrap()[0]), block(4));
    for (sel, needle) in [
        (&[0usize, 5][..], "out of range"),
        (&[1, 1][..], "selected twice"),
        (&[][..], "no channel"),
    ] {
        let e = Series::open(&p, Some(sel)).unwrap_err().to_string();
        assert!(e.contains("five.nii") && e.contains(needle), "{e}");
    }
    let e = Series::open(&p, Some(&[0, 1, 2, 3, 4]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("at most 4"), "{e}");
    let e = s.read(1).unwrap_err().to_string();
    assert!(
        e.contains("five.nii") && e.contains("time point 1 is out of range"),
        "{e}"
    );
    // An empty T axis.
    let mut b = std::fs::read(&p).unwrap();
    b[40..42].copy_from_slice(&4i16.to_le_bytes());
    b[48..50].copy_from_slice(&0i16.to_le_bytes());
    write::bytes(&p, &b);
    let e = Series::open(&p, None).unwrap_err().to_string();
    assert!(
        e.contains("five.nii") && e.contains("dim[4]") && e.contains("empty"),
        "{e}"
    );
    // NaN data in a later time point.
    let p = dir.path().join("nan.nii");
    let mut data = vec![0.5f32; 16];
    data[9] = f32::NAN;
    nifti_2x2x2(&p, [2, 1], NiftiData::F32(data));
    let s = Series::open(&p, None).unwrap();
    let e = s.read(1).unwrap_err().to_string();
    assert!(e.contains("nan.nii") && e.contains("NaN"), "{e}");
    // A truncated 4D file: the read is bounded by the header and says so.
    let p = dir.path().join("short.nii");
    let data: Vec<u8> = (0..3).flat_map(block).collect();
    nifti_2x2x2(&p, [3, 1], NiftiData::U8(data));
    let b = std::fs::read(&p).unwrap();
    write::bytes(&p, &b[..b.len() - 4]);
    let e = Series::open(&p, None).unwrap_err().to_string();
    assert!(e.contains("short.nii") && e.contains("truncated"), "{e}");
}

#[test]
fn a_dicom_series_is_one_channel_at_one_time_point_with_its_orientation() {
    let dir = tempfile::tempdir().unwrap();
    for z in 0..3 {
        let s = write::DicomSlice {
            rows: 3,
            cols: 4,
            pixels16: Some((0..12).map(|i| i * 40 + z as i16).collect()),
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
        };
        write::dicom(&dir.path().join(format!("{z}.dcm")), &s);
    }
    let want = Volume::load(dir.path(), None).unwrap();
    let s = Series::open(dir.path(), None).unwrap();
    assert_eq!((s.info().channels.len(), s.info().times), (1, 1));
    assert_eq!(s.read(0).unwrap(), vec![want]);
}

#[test]
fn lists_of_channel_files_must_agree_on_time_points_and_hold_one_channel_each() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.nii");
    let b = dir.path().join("b.nii");
    let two = dir.path().join("two.nii");
    nifti_2x2x2(&a, [1, 1], NiftiData::U8(block(0)));
    let data: Vec<u8> = (0..2).flat_map(block).collect();
    nifti_2x2x2(&b, [2, 1], NiftiData::U8(data.clone()));
    nifti_2x2x2(&two, [1, 2], NiftiData::U8(data));
    let e = Series::open_channels(&[a.clone(), b.clone()], None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("a.nii") && e.contains("b.nii") && e.contains("2 time points"),
        "{e}"
    );
    let e = Series::open_channels(&[a.clone(), two], None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("two.nii") && e.contains("holds 2"), "{e}");
    // An explicit list of time points; a 2-time-point file in it is refused.
    let c = dir.path().join("c.nii");
    nifti_2x2x2(&c, [1, 1], NiftiData::U8(block(7)));
    let s = Series::open_times(&[a.clone(), c.clone()], None).unwrap();
    assert_eq!(u8s(&s.read(1).unwrap()[0]), block(7));
    let e = Series::open_times(&[a, b], None).unwrap_err().to_string();
    assert!(e.contains("b.nii") && e.contains("2 time points"), "{e}");
}
