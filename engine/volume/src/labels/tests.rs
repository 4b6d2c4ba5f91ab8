use super::*;
use crate::write::{self, NiftiData};

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().expect("tempdir")
}

#[test]
fn integer_label_maps_keep_their_values_in_every_type() {
    let d = dir();
    let dims = [5, 4, 3];
    let n = 60;
    let wide: Vec<u16> = (0..n).map(|i| [0, 1, 7, 300, 40000][i % 5]).collect();
    let cases = [
        (
            "u8.nii",
            NiftiData::U8((0..n).map(|i| (i % 6) as u8).collect()),
            (0..n).map(|i| (i % 6) as u16).collect::<Vec<_>>(),
        ),
        (
            "i16.nii",
            NiftiData::I16((0..n).map(|i| (i % 3) as i16 * 1000).collect()),
            (0..n).map(|i| (i % 3) as u16 * 1000).collect(),
        ),
        ("u16.nii.gz", NiftiData::U16(wide.clone()), wide),
    ];
    for (name, data, want) in cases {
        let path = d.path().join(name);
        write::nifti(&path, dims, [1.0; 3], &data, None);
        let map = LabelMap::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(map.dims, dims);
        assert_eq!(map.values, want, "{name}");
    }
}

#[test]
fn float_and_negative_label_maps_are_refused_naming_the_file() {
    let d = dir();
    let f = d.path().join("prob.nii");
    write::nifti(&f, [2, 2, 2], [1.0; 3], &NiftiData::F32(vec![0.5; 8]), None);
    let msg = LabelMap::load(&f).unwrap_err().to_string();
    assert!(
        msg.contains("prob.nii") && msg.contains("integers"),
        "{msg}"
    );
    let neg = d.path().join("neg.nii");
    write::nifti(
        &neg,
        [2, 2, 2],
        [1.0; 3],
        &NiftiData::I16(vec![-3, 0, 1, 2, 0, 0, 0, 1]),
        None,
    );
    let msg = LabelMap::load(&neg).unwrap_err().to_string();
    assert!(msg.contains("neg.nii") && msg.contains("-3"), "{msg}");
}

#[test]
fn nearest_neighbour_puts_labels_on_a_finer_grid_without_new_values() {
    // 2 mm labels onto a 1 mm grid over the same box: every fine voxel takes the label of
    // the coarse voxel its centre falls in, and no value appears that was not there.
    let coarse = LabelMap {
        name: "seg".into(),
        path: "seg.nii".into(),
        dims: [2, 2, 2],
        to_patient: PatientTransform::aligned([2.0; 3]),
        values: vec![0, 1, 2, 3, 4, 5, 6, 7],
    };
    let fine = PatientTransform {
        origin: [-0.5; 3],
        ..PatientTransform::aligned([1.0; 3])
    };
    let m = coarse.onto([4, 4, 4], &fine);
    assert_eq!(m.present(), vec![1, 2, 3, 4, 5, 6, 7]);
    // Fine voxel (i, j, k) lies at i - 0.5 mm: coarse index (i - 0.5) / 2, rounded.
    for (i, j, k) in [(0, 0, 0), (3, 0, 0), (0, 3, 3), (2, 2, 2), (1, 1, 1)] {
        let c = |x: i64| ((x as f64 - 0.5) / 2.0).round() as i64;
        assert_eq!(
            m.at(i, j, k),
            coarse.at(c(i), c(j), c(k)),
            "({i}, {j}, {k})"
        );
    }
    // Outside the labelled box: no label.
    let far = PatientTransform {
        origin: [100.0; 3],
        ..PatientTransform::aligned([1.0; 3])
    };
    assert!(coarse.onto([2, 2, 2], &far).values.iter().all(|&v| v == 0));
}

#[test]
fn itksnap_and_slicer_tables_read_as_their_tools_write_them() {
    let itk = r#"################################################
# ITK-SnAP Label Description File
# Columns = IDX -R- -G- -B- -A-- VIS MSH LABEL
################################################
    0     0    0    0        0  0  0    "Clear Label"
    1   255    0    0        1  1  1    "White Matter"
    2     0  255    0      0.5  0  1    "Grey matter, cortical"
"#;
    let t = LabelTable::parse_itksnap(itk, Path::new("seg.label")).expect("itk-snap");
    assert_eq!(t.labels.len(), 3);
    let wm = t.get(1).expect("label 1");
    assert_eq!(
        (wm.name.as_str(), wm.colour, wm.opacity, wm.visible),
        ("White Matter", [1.0, 0.0, 0.0], 1.0, true)
    );
    let gm = t.get(2).expect("label 2");
    assert_eq!(
        (gm.name.as_str(), gm.opacity, gm.visible),
        ("Grey matter, cortical", 0.5, false)
    );

    let ctbl = "# Color table file seg.ctbl\n# 2 values\n0 Background 0 0 0 0\n5 liver 221 130 101 255\n17 kidney 185 102 83 128\n";
    let t = LabelTable::parse_slicer(ctbl, Path::new("seg.ctbl")).expect("slicer");
    assert_eq!(
        t.labels.iter().map(|l| l.value).collect::<Vec<_>>(),
        vec![0, 5, 17]
    );
    let k = t.get(17).expect("kidney");
    assert_eq!(k.name, "kidney");
    assert!((k.opacity - 128.0 / 255.0).abs() < 1e-6 && (k.colour[0] - 185.0 / 255.0).abs() < 1e-6);
}

#[test]
fn table_mistakes_name_the_file_and_line() {
    let cases = [
        (
            "a.label",
            "# c\n 1 255 0 0 1 1 1 \"ok\"\n 2 256 0 0 1 1 1 \"bad\"\n",
            "line 3",
            "R \"256\"",
        ),
        ("b.label", " 1 255 0 0 1.5 1 1 \"x\"\n", "line 1", "opacity"),
        ("c.label", " 1 255 0 0 1 1 \"x\"\n", "line 1", "6 numbers"),
        ("d.label", " 1 255 0 0 1 1 1 x\n", "line 1", "LABEL"),
        ("e.ctbl", "1 liver 1 2 3\n", "line 1", "5 fields"),
        ("f.ctbl", "x liver 1 2 3 4\n", "line 1", "label value"),
        (
            "g.ctbl",
            "1 a 1 2 3 4\n1 b 1 2 3 4\n",
            "label table",
            "given twice",
        ),
    ];
    let d = dir();
    for (name, text, at, what) in cases {
        let path = d.path().join(name);
        write::text(&path, text);
        let msg = LabelTable::load(&path).unwrap_err().to_string();
        assert!(
            msg.contains(name) && msg.contains(at) && msg.contains(what),
            "{name}: {msg}"
        );
    }
}

#[test]
fn labels_a_table_lacks_take_palette_colours_and_are_listed() {
    let mut t =
        LabelTable::parse_slicer("3 skull 200 200 180 255\n", Path::new("t.ctbl")).expect("table");
    let added = t.complete(&[0, 2, 3, 14]);
    assert_eq!(added, vec![2, 14]);
    assert_eq!(t.get(2).map(|l| l.colour), Some(PALETTE[2]));
    assert_eq!(t.get(14).map(|l| l.name.as_str()), Some("label 14"));
    assert_eq!(t.get(3).map(|l| l.name.as_str()), Some("skull"));
    assert!(t.get(0).is_none(), "0 is no label");
}

#[test]
fn the_mni_segmentation_and_its_itksnap_table_load_on_the_t1_grid() {
    let volumes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/volumes");
    let map = LabelMap::load(&volumes.join("mni152_labels.nii.gz")).expect("label map");
    let t1 = Volume::load(&volumes.join("mni152_t1.nii.gz"), None).expect("t1");
    assert_eq!((map.dims, map.to_patient), (t1.dims, t1.to_patient));
    assert_eq!(map.present(), vec![1, 2, 3]);
    let mut table = LabelTable::load(&volumes.join("mni152_labels.label")).expect("table");
    assert!(
        table.complete(&map.present()).is_empty(),
        "the table names every label"
    );
    let names: Vec<&str> = table.labels.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(
        names,
        vec![
            "Clear Label",
            "White matter",
            "Grey matter",
            "Rest of the brain"
        ]
    );
    // The rest of the brain is hidden until shown.
    let shown: Vec<bool> = table.labels.iter().map(|l| l.visible).collect();
    assert_eq!(shown, vec![false, true, true, false]);
    // White matter is brighter than grey matter in the T1 it was made from.
    let mean = |label: u16| {
        let (sum, n) = map
            .values
            .iter()
            .zip(0..)
            .filter(|(&v, _)| v == label)
            .fold((0.0, 0u32), |(s, n), (_, i)| {
                (s + f64::from(t1.data.get(i).unwrap_or(0.0)), n + 1)
            });
        sum / f64::from(n.max(1))
    };
    assert!(
        mean(1) > mean(2) + 0.05,
        "white {} grey {}",
        mean(1),
        mean(2)
    );
}

#[test]
fn an_oblique_label_map_is_refused_rather_than_interpolated() {
    let d = dir();
    let path = d.path().join("tilted.nii");
    // An sform rotated 30° about x: the loaders would resample it trilinearly.
    let (c, s) = (30f32.to_radians().cos(), 30f32.to_radians().sin());
    let sform = [[1.0, 0.0, 0.0, 0.0], [0.0, c, -s, 0.0], [0.0, s, c, 0.0]];
    let data = NiftiData::U8((0..27).map(|i| (i % 3) as u8).collect());
    write::nifti_series(&path, [3, 3, 3], [1, 1], [1.0; 3], &data, None, Some(sform));
    let msg = LabelMap::load(&path).unwrap_err().to_string();
    assert!(
        msg.contains("tilted.nii") && msg.contains("oblique"),
        "{msg}"
    );
}

/// Empty voxels take the lowest mask among their non-empty 26 neighbours (0 with none),
/// from the border list made once: checked against each neighbourhood read directly,
/// on a map of three labels with empty space in and around them, as labels hide and
/// fade.
#[test]
fn empty_voxels_take_their_tissue_neighbours_lowest_mask() {
    let dims = [13u32, 11, 9];
    let n = (dims[0] * dims[1] * dims[2]) as usize;
    // A fixed pseudo-random map: labels 0–3, a third of the voxels empty.
    let mut state = 0x9e37_79b9u32;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state
    };
    let values: Vec<u16> = (0..n).map(|_| (next() % 4) as u16).collect();
    let empty: Vec<bool> = (0..n).map(|_| next() % 3 == 0).collect();
    let map = LabelMap {
        name: "random".into(),
        path: "random.nii".into(),
        dims,
        to_patient: crate::orientation::PatientTransform::aligned([1.0; 3]),
        values,
    };
    let space = EmptySpace::new(&map, empty.clone()).expect("same length");
    let [nx, ny, nz] = dims.map(|d| d as usize);
    for (hidden, fade) in [(None, 1.0), (Some(2u16), 1.0), (Some(1), 0.4), (None, 0.0)] {
        let look = |v: u16| Look {
            colour: [0.5, 0.25, 1.0],
            opacity: if v == 3 { fade } else { 0.8 },
            visible: Some(v) != hidden,
        };
        let mask = |v: u16| {
            let l = look(v);
            ((if l.visible { l.opacity } else { 0.0 }) * 255.0).round() as u8
        };
        let shape = LabelLook::shape_of(&map, look);
        let got = LabelLook::with_shape(&map, look, 4, [4, 3, 3], shape, Some(&space));
        for z in 0..nz {
            for y in 0..ny {
                for x in 0..nx {
                    let i = (z * ny + y) * nx + x;
                    let want = if !empty[i] {
                        mask(map.values[i])
                    } else {
                        let mut lowest: Option<u8> = None;
                        for zz in z.saturating_sub(1)..(z + 2).min(nz) {
                            for yy in y.saturating_sub(1)..(y + 2).min(ny) {
                                for xx in x.saturating_sub(1)..(x + 2).min(nx) {
                                    let j = (zz * ny + yy) * nx + xx;
                                    if !empty[j] {
                                        let m = mask(map.values[j]);
                                        lowest = Some(lowest.map_or(m, |l| l.min(m)));
                                    }
                                }
                            }
                        }
                        lowest.unwrap_or(0)
                    };
                    assert_eq!(
                        got.rgba[i][3], want,
                        "voxel {x},{y},{z} (empty {}), hidden {hidden:?}, fade {fade}",
                        empty[i]
                    );
                }
            }
        }
    }
    assert!(
        EmptySpace::new(&map, vec![true; 3]).is_none(),
        "a mis-sized mask"
    );
}

#[test]
fn the_shown_opacity_is_the_one_every_shown_label_of_the_map_has() {
    // Labels 1–3 on a small grid; label 4 is in no voxel, so its look does not count.
    let dims = [6u32, 1, 1];
    let map = LabelMap {
        name: "row".into(),
        path: "row.nii".into(),
        dims,
        to_patient: crate::orientation::PatientTransform::aligned([1.0; 3]),
        values: vec![1, 1, 2, 2, 3, 3],
    };
    let shown_opacity =
        |look: &dyn Fn(u16) -> Look| LabelLook::new(&map, look, 4, [2, 1, 1]).shown_opacity;
    let look = |opacity: [f32; 5], visible: [bool; 5]| {
        move |v: u16| Look {
            colour: [1.0; 3],
            opacity: opacity[usize::from(v)],
            visible: visible[usize::from(v)],
        }
    };
    let all = [true; 5];
    assert_eq!(shown_opacity(&look([1.0; 5], all)), 1.0);
    // A label the map does not hold may differ.
    assert_eq!(shown_opacity(&look([1.0, 1.0, 1.0, 1.0, 0.2], all)), 1.0);
    // Hidden labels do not count; the opacity is the mask's 8 bits.
    let hide_2 = [true, true, false, true, true];
    assert_eq!(
        shown_opacity(&look([1.0, 0.6, 0.1, 0.6, 1.0], hide_2)),
        153.0 / 255.0
    );
    // Two shown opacities, or none shown: 0, the mask read as it is.
    assert_eq!(shown_opacity(&look([1.0, 1.0, 0.5, 1.0, 1.0], all)), 0.0);
    assert_eq!(shown_opacity(&look([1.0; 5], [false; 5])), 0.0);
    // A shown label of opacity 0 is empty, as a hidden one.
    assert_eq!(
        shown_opacity(&look([1.0, 0.7, 0.0, 0.7, 1.0], all)),
        unorm_f(0.7)
    );
}

fn unorm_f(x: f32) -> f32 {
    f32::from((x * 255.0).round() as u8) / 255.0
}
