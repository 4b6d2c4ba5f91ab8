//! A label map beside the volume on the device: a map that changes nothing renders the
//! frames no map renders, a hidden label is empty medium (Beer–Lambert through a hidden
//! slab), a label's surface is smooth (a voxelised sphere's first-hit normals follow the
//! sphere), and picking names the label under a pixel.

mod common;

use common::*;
use dvr_engine::renderer::scene_setup::SceneSetup;
use dvr_engine::renderer::{FrameRequest, LabelLookRef, FEATURE_IMAGES};
use dvr_engine::scene::{Estimator, LabelMode};
use dvr_engine::volume::labels::{EmptySpace, LabelLook, LabelMap, Look, SMOOTHING_SIGMA};
use dvr_engine::volume::PatientTransform;
use std::sync::Arc;

fn map(dims: [u32; 3], label: impl Fn(u32, u32, u32) -> u16) -> LabelMap {
    let mut values = Vec::new();
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                values.push(label(x, y, z));
            }
        }
    }
    LabelMap {
        name: "test".into(),
        path: "test.nii".into(),
        dims,
        to_patient: PatientTransform::aligned([1.0; 3]),
        values,
    }
}

fn look(m: &LabelMap, brick: u32, grid: [u32; 3], f: impl Fn(u16) -> Look) -> LabelLookRef {
    LabelLookRef(Arc::new(LabelLook::new(m, f, brick, grid)))
}

const SHOWN: Look = Look {
    colour: [1.0; 3],
    opacity: 1.0,
    visible: true,
};
const HIDDEN: Look = Look {
    colour: [1.0; 3],
    opacity: 1.0,
    visible: false,
};

/// Camera rays along z through an absorbing unit cube whose voxels z in [8, 16) of 32
/// are a hidden label: T = exp(−μt · 0.75).
fn hidden_slab_transmittance(estimator: Estimator) -> f64 {
    let n = 32;
    let mut s = settings(8, 1);
    s.settings.set_estimator(estimator);
    s.config.density_scale = 1.5;
    s.config.labels = Some(LabelMode::Tint);
    s.settings.set_step_size(0.25).expect("step");
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    let volume = constant_volume(n, 1.0);
    let slab = map([n; 3], |_, _, z| if (8..16).contains(&z) { 2 } else { 1 });
    let labels = look(&slab, n, [1; 3], |v| if v == 2 { HIDDEN } else { SHOWN });
    let mut r = renderer(context(), s, &volume, &["none"]);
    let i = dvr_engine::renderer::FrameInputs {
        labels: Some(labels),
        ..inputs(
            front_camera(3.0, 2.0),
            vec![environment(1.0)],
            constant_lut(1.0, 0.0),
        )
    };
    let img = r.reference(&i, 4096, 512).expect("reference render");
    mean_rgb(&img)[0]
}

/// A ball of density 1 (radius 10 voxels of 32) in empty space, its voxels one hidden
/// label, the empty space unlabelled and shown: with the empty voxels taking their
/// tissue neighbours' mask nothing is left to see, every camera ray reaches the
/// environment; without, the product of the density's and the mask's ramps leaves a
/// skin at the ball's outline. Returns (the darkest pixel, its count below 1).
fn hidden_ball(fit_to_medium: bool) -> (f32, usize) {
    let n = 32u32;
    let inside = |x: u32, y: u32, z: u32| {
        let c = |i: u32| i as f32 + 0.5 - n as f32 / 2.0;
        c(x).powi(2) + c(y).powi(2) + c(z).powi(2) <= 100.0
    };
    let mut volume = constant_volume(n, 1.0);
    let ball = map([n; 3], |x, y, z| u16::from(inside(x, y, z)));
    volume.bytes = ball
        .values
        .iter()
        .map(|&v| if v == 1 { 255 } else { 0 })
        .collect();
    volume.bricks.min = vec![0.0];
    let mut s = settings(32, 1);
    s.config.density_scale = 40.0;
    s.config.labels = Some(LabelMode::Tint);
    s.settings.set_filter_sigma(0.0).expect("pinhole");
    let of = |v: u16| if v == 1 { HIDDEN } else { SHOWN };
    let zero = EmptySpace::new(&ball, volume.zero_voxels().expect("dense")).expect("one grid");
    let shape = LabelLook::shape_of(&ball, of);
    let empty = fit_to_medium.then_some(&zero);
    let labels = LabelLookRef(Arc::new(LabelLook::with_shape(
        &ball, of, n, [1; 3], shape, empty,
    )));
    let mut r = renderer(context(), s, &volume, &["none"]);
    let i = dvr_engine::renderer::FrameInputs {
        labels: Some(labels),
        ..inputs(
            front_camera(3.0, 25.0),
            vec![environment(1.0)],
            constant_lut(1.0, 0.0),
        )
    };
    let img = r.reference(&i, 64, 64).expect("reference render");
    let darkest = img.iter().map(|p| p[0]).fold(f32::INFINITY, f32::min);
    (darkest, img.iter().filter(|p| p[0] < 1.0).count())
}

#[test]
fn hiding_every_tissue_label_leaves_no_skin_where_tissue_meets_empty_space() {
    let (darkest, dimmed) = hidden_ball(true);
    assert_eq!(
        (darkest, dimmed),
        (1.0, 0),
        "the hidden ball left medium in front of the environment"
    );
    // The same look without fitting the empty voxels' masks does leave a skin: the test
    // sees the difference it is named for.
    let (darkest, dimmed) = hidden_ball(false);
    assert!(
        darkest < 0.99 && dimmed > 20,
        "no skin without the fit: darkest {darkest}, {dimmed} pixels below 1"
    );
    assert_validation_clean();
}

#[test]
fn a_hidden_label_is_empty_medium_to_delta_tracking_and_ray_marching() {
    let expected = (-1.5f64 * 0.75).exp();
    for estimator in [Estimator::Delta, Estimator::RayMarch] {
        let t = hidden_slab_transmittance(estimator);
        assert!(
            ((t - expected) / expected).abs() < 0.01,
            "{estimator:?}: T = {t}, exp(-1.125) = {expected}"
        );
    }
    assert_validation_clean();
}

/// The phantom's frames with the renderer's inputs changed by `edit`, read back for
/// `ours` and the noisy input.
fn phantom_frames(
    labels: Option<LabelMode>,
    look_of: impl Fn(&SceneSetup) -> Option<LabelLookRef>,
) -> Vec<Vec<(String, Vec<[f32; 4]>)>> {
    let mut setup = builtin_setup("phantom/orbit", 3, 24);
    setup.config.labels = labels;
    let look = look_of(&setup);
    let mut r = setup
        .renderer(context(), &["ours", "svgf"])
        .expect("renderer");
    let frames = (0..3).map(|f| dvr_engine::renderer::FrameInputs {
        labels: look.clone(),
        ..setup.frame_inputs(f)
    });
    let out = render_frames(&mut r, frames, &readback());
    out.into_iter().map(|f| f.images).collect()
}

#[test]
fn a_map_of_one_visible_label_with_a_unit_tint_renders_the_frames_of_no_map() {
    let none = phantom_frames(None, |_| None);
    let one = phantom_frames(Some(LabelMode::Tint), |s| {
        let v = &s.volume;
        let m = map(v.dims, |_, _, _| 7);
        Some(look(&m, v.bricks.brick, v.bricks.grid, |_| SHOWN))
    });
    // The same with the empty voxels' masks fitted to their neighbours' (as a scene's
    // look under a TF transparent at 0 is): the air next to tissue keeps the mask 1.
    let fitted = phantom_frames(Some(LabelMode::Tint), |s| {
        let v = &s.volume;
        let m = map(v.dims, |_, _, _| 7);
        let zero = EmptySpace::new(&m, v.zero_voxels().expect("dense")).expect("one grid");
        let shape = LabelLook::shape_of(&m, |_| SHOWN);
        let l = LabelLook::with_shape(
            &m,
            |_| SHOWN,
            v.bricks.brick,
            v.bricks.grid,
            shape,
            Some(&zero),
        );
        Some(LabelLookRef(Arc::new(l)))
    });
    assert_eq!(none.len(), 3);
    for (f, (a, b)) in none
        .iter()
        .zip(&one)
        .chain(none.iter().zip(&fitted))
        .enumerate()
    {
        for ((name, x), (_, y)) in a.iter().zip(b) {
            let same = x
                .iter()
                .zip(y)
                .all(|(p, q)| p.map(f32::to_bits) == q.map(f32::to_bits));
            assert!(
                same,
                "frame {f}, {name}: a map that changes nothing changed the image"
            );
        }
    }
    assert_validation_clean();
}

/// Angles (degrees) between the first-hit normals and a sphere's own, over the surface
/// pixels of a `size`² view of a sphere of radius 20 voxels in a 64³ label map, shown
/// as solid tissue.
fn sphere_normal_errors(size: u32, sigma: f32) -> Vec<(glam::Vec3, f64)> {
    let n = SPHERE_GRID;
    let mut s = settings(size, 1);
    s.config.density_scale = 150.0;
    s.config.labels = Some(LabelMode::Solid);
    let volume = constant_volume(n, 0.5);
    let sphere = map([n; 3], |x, y, z| sphere_label([x, y, z].map(|i| i as i64)));
    let shown = |v| if v == 1 { SHOWN } else { HIDDEN };
    let labels = LabelLookRef(Arc::new(LabelLook::filtered(
        &sphere, shown, n, [1; 3], sigma,
    )));
    let mut r = renderer(context(), s, &volume, &["none"]);
    let i = dvr_engine::renderer::FrameInputs {
        labels: Some(labels),
        ..inputs(
            front_camera(2.0, 25.0),
            vec![environment(1.0)],
            constant_lut(1.0, 0.8),
        )
    };
    let request = FrameRequest {
        readback: true,
        features: true,
        ..Default::default()
    };
    let mut done: Vec<_> = r.frame(&i, &request).expect("frame").into_iter().collect();
    done.extend(r.flush().expect("flush"));
    let image = |name: &str| {
        done[0]
            .images
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, i)| i.clone())
            .expect("features read back")
    };
    let (pos, nrm, alb) = (
        image(FEATURE_IMAGES[0]),
        image(FEATURE_IMAGES[1]),
        image(FEATURE_IMAGES[2]),
    );
    drop(r);
    assert_validation_clean();
    let mut errors = Vec::new();
    for ((p, nm), a) in pos.iter().zip(&nrm).zip(&alb) {
        if a[3] < 0.5 {
            continue; // not on the threshold surface
        }
        // The sphere's normal at the hit, facing the camera as feature normals do (a
        // grazing ray may cross the threshold just past the silhouette).
        let p = glam::Vec3::new(p[0], p[1], p[2]);
        let d = p - glam::Vec3::new(0.0, 0.0, 2.0);
        let own = if p.dot(d) > 0.0 { -p } else { p }.normalize();
        let nm = glam::Vec3::new(nm[0], nm[1], nm[2]).normalize();
        errors.push((p, angle(own, nm)));
    }
    errors
}

#[test]
fn a_label_surface_is_smooth_its_normals_follow_the_sphere() {
    let hits = sphere_normal_errors(256, SMOOTHING_SIGMA);
    let errors: Vec<f64> = hits.iter().map(|h| h.1).collect();
    // The sphere (radius 0.3125 of the unit box at distance 2, 25° field) covers about a
    // third of the image.
    assert!(
        errors.len() > 256 * 256 / 5,
        "{} surface pixels",
        errors.len()
    );
    let within = errors.iter().filter(|&&e| e < 10.0).count() as f64 / errors.len() as f64;
    println!(
        "labelled sphere at 256²: {:.1}% of {} surface pixels within 10° of the sphere's normal",
        within * 100.0,
        errors.len()
    );
    assert!(within >= 0.95, "{:.1}% within 10°", within * 100.0);
    // The same without the filter: trilinear reads of the raw indicator leave the voxel
    // facets in the normals.
    let raw = sphere_normal_errors(256, 0.0);
    let raw_within = raw.iter().filter(|h| h.1 < 10.0).count() as f64 / raw.len() as f64;
    // And a nearest-neighbour look-up of the labels (central differences of the label
    // indicator at the same surface points): normals along the voxel axes.
    let nearest = |p: glam::Vec3| {
        let v = (p + 0.5) * SPHERE_GRID as f32;
        let at = |o: glam::Vec3| {
            let q = (v + o).floor();
            f32::from(sphere_label([q.x as i64, q.y as i64, q.z as i64]))
        };
        let g = glam::Vec3::new(
            at(glam::Vec3::X) - at(-glam::Vec3::X),
            at(glam::Vec3::Y) - at(-glam::Vec3::Y),
            at(glam::Vec3::Z) - at(-glam::Vec3::Z),
        );
        let d = p - glam::Vec3::new(0.0, 0.0, 2.0);
        let own = if p.dot(d) > 0.0 { -p } else { p }.normalize();
        // The normal along the indicator's gradient, turned to face the camera.
        let n = if g.dot(d) < 0.0 { g } else { -g };
        if g == glam::Vec3::ZERO {
            90.0
        } else {
            angle(own, n)
        }
    };
    let near_within =
        hits.iter().filter(|h| nearest(h.0) < 10.0).count() as f64 / hits.len() as f64;
    println!(
        "unfiltered (trilinear reads of the indicator): {:.1}% within 10°; nearest-neighbour look-up: {:.1}%",
        raw_within * 100.0,
        near_within * 100.0
    );
    assert!(
        raw_within < within && near_within < within,
        "the filter is what smooths the surface"
    );
}

const SPHERE_GRID: u32 = 64;

/// Label 1 inside a sphere of radius 20 voxels at the centre of a 64³ grid, 0 outside.
fn sphere_label(v: [i64; 3]) -> u16 {
    let n = i64::from(SPHERE_GRID);
    if v.iter().any(|&c| c < 0 || c >= n) {
        return 0;
    }
    let d = v.map(|i| i as f32 + 0.5 - n as f32 / 2.0);
    u16::from(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= 400.0)
}

fn angle(a: glam::Vec3, b: glam::Vec3) -> f64 {
    f64::from(a.normalize().dot(b.normalize()).clamp(-1.0, 1.0))
        .acos()
        .to_degrees()
}

/// Picking through a session on the phantom with its built-in labels, shown as solid
/// tissue one label at a time: looking straight at a voxel of each label near the
/// label's centroid, the pick names that label.
#[test]
fn picking_names_the_label_at_the_centre_of_each_label_of_the_phantom() {
    use dvr_engine::scene::{CameraSpec, Scene};
    use dvr_engine::session::{Edit, LabelEdit, Session};
    let scene = Scene::from_toml_str(
        r#"
        [volume]
        builtin = "phantom"
        size = 48
        [transfer]
        a = "ct-bone"
        [labels]
        builtin = "phantom"
        mode = "solid"
        [[light]]
        kind = "environment"
        intensity = 1.0
        "#,
        "pick.toml",
    )
    .expect("scene");
    let extent = dvr_engine::graph::Extent {
        width: 33,
        height: 33,
    };
    let setup = SceneSetup::new(scene, extent, Some(1), 48).expect("setup");
    let labels = setup.labels.clone().expect("built-in labels");
    let (dims, world) = (setup.volume.dims, setup.volume.world_size);
    let mut s = Session::new(setup, context(), &["none"]).expect("session");
    let values: Vec<u16> = s.view().labels.iter().map(|l| l.value).collect();
    assert_eq!(
        values,
        [1, 2, 3, 4, 5],
        "scalp, skull, brain, ventricles, vessels"
    );
    for value in values {
        // The label's voxel nearest its centroid, in world units.
        let voxels: Vec<glam::Vec3> = (0..labels.map.values.len())
            .filter(|&i| labels.map.values[i] == value)
            .map(|i| {
                let [nx, ny, _] = dims.map(|d| d as usize);
                let v = [i % nx, (i / nx) % ny, i / (nx * ny)];
                glam::Vec3::from(v.map(|c| c as f32 + 0.5))
                    / glam::Vec3::from(dims.map(|d| d as f32))
                    * glam::Vec3::from(world)
                    - glam::Vec3::from(world) * 0.5
            })
            .collect();
        let centroid = voxels.iter().sum::<glam::Vec3>() / voxels.len() as f32;
        let target = *voxels
            .iter()
            .min_by(|a, b| a.distance(centroid).total_cmp(&b.distance(centroid)))
            .expect("the label has voxels");
        s.edit(Edit::Label(LabelEdit {
            value: None,
            visible: Some(false),
            ..Default::default()
        }))
        .expect("hide all");
        s.edit(Edit::Label(LabelEdit {
            value: Some(value),
            visible: Some(true),
            ..Default::default()
        }))
        .expect("show one");
        s.edit(Edit::Camera(CameraSpec {
            position: (target + glam::Vec3::new(0.3, 1.4, 0.4)).as_dvec3(),
            target: target.as_dvec3(),
            up: glam::DVec3::Z,
            fov_y_degrees: 20.0,
        }))
        .expect("camera");
        let pick = s
            .pick(16, 16)
            .expect("pick")
            .unwrap_or_else(|| panic!("the ray meets label {value} at {target}"));
        assert_eq!(
            (pick.label, pick.label_name.as_deref().is_some()),
            (value, true),
            "looking at label {value} at {target}: {pick:?}"
        );
    }
    let err = s.pick(33, 0).unwrap_err().to_string();
    assert!(err.contains("outside the 33x33 image"), "{err}");
    drop(s);
    assert_validation_clean();
}

/// What a scene's `[labels]` gets wrong is an error naming the field or the file.
#[test]
fn bad_label_sections_and_maps_are_errors_naming_them() {
    use dvr_engine::scene::Scene;
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = |labels: &str| {
        format!(
            "[volume]\nbuiltin = \"phantom\"\nsize = 16\n[transfer]\na = \"ct-bone\"\n[[light]]\nkind = \"environment\"\nintensity = 1.0\n{labels}"
        )
    };
    let parse_err = |labels: &str| {
        Scene::from_toml_str(&scene(labels), "bad.toml")
            .unwrap_err()
            .to_string()
    };
    let e = parse_err(
        "[labels]\nbuiltin = \"phantom\"\n[[label]]\nvalue = 2\ncolour = [2.0, 0.0, 0.0]\n",
    );
    assert!(e.contains("label[0].colour") && e.contains("[0, 1]"), "{e}");
    let e = parse_err("[labels]\nbuiltin = \"phantom\"\n[[label]]\nvalue = 2\nopacity = 1.5\n");
    assert!(e.contains("label[0].opacity"), "{e}");
    let e = parse_err("[[label]]\nvalue = 2\nvisible = false\n");
    assert!(e.contains("without a [labels]"), "{e}");
    let e = parse_err("[labels]\nbuiltin = \"cloud\"\n");
    assert!(
        e.contains("labels.builtin") && e.contains("no built-in labels"),
        "{e}"
    );
    let e = parse_err("[labels]\n");
    assert!(e.contains("labels") && e.contains("give one of"), "{e}");
    let e = parse_err("[labels]\nbuiltin = \"phantom\"\nmode = \"wire\"\n");
    assert!(e.contains("wire"), "{e}");

    let setup_err = |labels: &str| {
        let s = Scene::from_toml_str(&scene(labels), "bad.toml").expect("parses");
        let size = dvr_engine::graph::Extent {
            width: 8,
            height: 8,
        };
        match SceneSetup::new(s, size, Some(1), 16) {
            Ok(_) => panic!("{labels}: set up"),
            Err(e) => e.to_string(),
        }
    };
    let e = setup_err("[labels]\nbuiltin = \"phantom\"\n[[label]]\nvalue = 9\nvisible = false\n");
    assert!(
        e.contains("label[0].value = 9") && e.contains("1, 2, 3, 4, 5"),
        "{e}"
    );
    // An NRRD label map with no space directions, on another grid than the built-in
    // phantom's: nothing says how the grids meet.
    let nrrd = dir.path().join("seg.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nencoding: raw\n\n".to_vec();
    bytes.extend(vec![1u8; 512]);
    std::fs::write(&nrrd, bytes).expect("write");
    let e = setup_err(&format!(
        "[labels]\nfile = {:?}\n",
        nrrd.display().to_string()
    ));
    assert!(
        e.contains("seg.nrrd")
            && e.contains("[8, 8, 8]")
            && e.contains("nothing says how the grids meet"),
        "{e}"
    );
    // A float map is not a label map.
    let float = dir.path().join("prob.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: float\ndimension: 3\nsizes: 16 16 16\nendian: little\nencoding: raw\n\n"
            .to_vec();
    bytes.extend((0..4096).flat_map(|_| 0.5f32.to_le_bytes()));
    std::fs::write(&float, bytes).expect("write");
    let e = setup_err(&format!(
        "[labels]\nfile = {:?}\n",
        float.display().to_string()
    ));
    assert!(
        e.contains("prob.nrrd") && e.contains("label values") && e.contains("integers"),
        "{e}"
    );
    // A table line that does not parse names its line.
    let table = dir.path().join("seg.label");
    std::fs::write(
        &table,
        "# ITK-SNAP\n0 0 0 0 0 0 0 \"Clear\"\n1 300 0 0 1 1 1 \"bad\"\n",
    )
    .expect("write");
    let same_grid = dir.path().join("same.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 16 16 16\nencoding: raw\n\n".to_vec();
    bytes.extend(vec![1u8; 4096]);
    std::fs::write(&same_grid, bytes).expect("write");
    let e = setup_err(&format!(
        "[labels]\nfile = {:?}\ntable = {:?}\n",
        same_grid.display().to_string(),
        table.display().to_string()
    ));
    assert!(
        e.contains("seg.label") && e.contains("line 3") && e.contains("300"),
        "{e}"
    );
}

/// A label map whose file runs along −x (its affine flips the axis) lands on the volume's
/// grid the right way round: what lies on the patient's left in the file lies there on
/// the volume's grid.
#[test]
fn a_flipped_label_map_is_placed_by_its_affine() {
    use dvr_engine::scene::Scene;
    let dir = tempfile::tempdir().expect("tempdir");
    let nrrd = |name: &str, directions: &str, origin: &str, bytes: Vec<u8>| {
        let path = dir.path().join(name);
        let mut b = format!(
            "NRRD0004\ntype: uint8\ndimension: 3\nspace: right-anterior-superior\nsizes: 8 8 8\n\
             space directions: {directions}\nspace origin: {origin}\nencoding: raw\n\n"
        )
        .into_bytes();
        b.extend(bytes);
        std::fs::write(&path, b).expect("write");
        path
    };
    let volume = nrrd(
        "vol.nrrd",
        "(1,0,0) (0,1,0) (0,0,1)",
        "(0,0,0)",
        vec![100; 512],
    );
    // Label 1 in the file's first four x indices, which its flipped x axis puts at
    // patient x 7..4: the volume's x indices 4..7.
    let seg: Vec<u8> = (0..512).map(|i| u8::from(i % 8 < 4)).collect();
    let labels = nrrd("seg.nrrd", "(-1,0,0) (0,1,0) (0,0,1)", "(7,0,0)", seg);
    let text = format!(
        "[volume]\nfile = {:?}\n[transfer]\na = \"ct-bone\"\n[labels]\nfile = {:?}\n\
         [[light]]\nkind = \"environment\"\nintensity = 1.0\n",
        volume.display().to_string(),
        labels.display().to_string()
    );
    let scene = Scene::from_toml_str(&text, "flip.toml").expect("scene");
    let size = dvr_engine::graph::Extent {
        width: 8,
        height: 8,
    };
    let setup = SceneSetup::new(scene, size, Some(1), 8).expect("setup");
    let map = &setup.labels.as_ref().expect("labels").map;
    for x in 0..8 {
        assert_eq!(map.at(x, 3, 3), u16::from(x >= 4), "volume x index {x}");
    }
}

/// A colour or opacity edit keeps the filtered shape (only visibility changes it): the
/// look made from the last one's shape equals one made from scratch.
#[test]
fn an_opacity_edit_reuses_the_shape_and_looks_as_one_made_afresh() {
    let setup = {
        let scene = dvr_engine::scene::Scene::from_toml_str(
            "[volume]\nbuiltin = \"phantom\"\nsize = 24\n[transfer]\na = \"ct-bone\"\n[labels]\n\
             builtin = \"phantom\"\n[[light]]\nkind = \"environment\"\nintensity = 1.0\n",
            "reuse.toml",
        )
        .expect("scene");
        let size = dvr_engine::graph::Extent {
            width: 8,
            height: 8,
        };
        SceneSetup::new(scene, size, Some(1), 24).expect("setup")
    };
    let labels = setup.labels.clone().expect("labels");
    let mut views = setup.scene.label_views.clone();
    let lut = setup.scene.tf_a.lut();
    let first = labels.look(&views, &lut);
    views[2].opacity = 0.3;
    views[4].colour = [0.0, 1.0, 0.0];
    let edited = labels.look(&views, &lut);
    assert!(
        Arc::ptr_eq(&first.shape, &edited.shape),
        "the shape is kept"
    );
    let mode = labels.mode;
    let v = views.clone();
    let of = |value| dvr_engine::scene::labels::look_of(&v, mode, value);
    // ct-bone is transparent at 0, so the phantom's empty voxels are fitted.
    assert!(lut.transparent_at_zero(1));
    let zero =
        EmptySpace::new(&labels.map, setup.volume.zero_voxels().expect("dense")).expect("one grid");
    let afresh = LabelLook::with_shape(
        &labels.map,
        of,
        setup.volume.bricks.brick,
        setup.volume.bricks.grid,
        LabelLook::shape_of(&labels.map, of),
        Some(&zero),
    );
    assert_eq!(*edited, afresh);
    views[1].visible = false;
    let hidden = labels.look(&views, &lut);
    assert!(!Arc::ptr_eq(&edited.shape, &hidden.shape) && edited.shape != hidden.shape);
}
