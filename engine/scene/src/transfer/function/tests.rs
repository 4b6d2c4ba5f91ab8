//! Tests of `function.rs`.

use super::*;

const TWO: &str = r#"
        name = "two"
        [[point]]
        density = 1.0
        opacity = 0.5
        diffuse = [0.0, 0.0, 1.0]
        [[point]]
        density = 0.2
        opacity = 1.0
        diffuse = [0.0, 1.0, 0.0]
        [[point]]
        density = 0.0
        opacity = 0.0
        diffuse = [1.0, 0.0, 0.0]
        roughness = 0.1
    "#;

fn two() -> TransferFunction {
    TransferFunction::from_toml_str(TWO, "two.toml").expect("valid TF")
}

#[test]
fn parsing_sorts_by_density() {
    let tf = two();
    assert_eq!(tf.name, "two");
    let d: Vec<f32> = tf.points.iter().map(|p| p.density).collect();
    assert_eq!(d, [0.0, 0.2, 1.0]);
    assert!(tf.validate().is_ok());
}

#[test]
fn name_defaults_to_file_stem() {
    let text = TWO.replace("name = \"two\"", "");
    let tf = TransferFunction::from_toml_str(&text, "/some/dir/bone-white.toml").expect("valid");
    assert_eq!(tf.name, "bone-white");
}

#[test]
fn lut_is_exact_at_control_points_and_linear_between() {
    let lut = two().lut();
    assert_eq!(lut.len(), LUT_SIZE);
    // Endpoints: exactly the first and last control points.
    assert_eq!(lut.diffuse_opacity[0], [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(lut.specular_roughness[0], [0.0, 0.0, 0.0, 0.1]);
    assert_eq!(lut.diffuse_opacity[LUT_SIZE - 1], [0.0, 0.0, 1.0, 0.5]);
    // Density 0.2 is entry 51 (51/255): exactly the middle control point.
    assert_eq!(TfLut::density_of(51), 0.2);
    assert_eq!(lut.diffuse_opacity[51], [0.0, 1.0, 0.0, 1.0]);
    // Halfway between 0.2 and 1.0 is 0.6 = entry 153.
    let mid = lut.diffuse_opacity[153];
    let want = [0.0, 0.5, 0.5, 0.75];
    for (m, w) in mid.iter().zip(want) {
        assert!((m - w).abs() < 1e-6, "{mid:?} != {want:?}");
    }
    // A quarter of the way from 0 to 0.2 (not a LUT entry): sample directly.
    let q = two().sample(0.05);
    assert!((q.opacity - 0.25).abs() < 1e-6 && (q.roughness - 0.2).abs() < 1e-6);
}

#[test]
fn values_are_clamped_outside_the_points() {
    let text = r#"
            [[point]]
            density = 0.25
            opacity = 0.2
            diffuse = [0.5, 0.5, 0.5]
            [[point]]
            density = 0.75
            opacity = 0.6
            diffuse = [1.0, 1.0, 1.0]
        "#;
    let tf = TransferFunction::from_toml_str(text, "inner.toml").expect("valid");
    let lut = tf.lut();
    assert_eq!(lut.diffuse_opacity[0], [0.5, 0.5, 0.5, 0.2]);
    assert_eq!(lut.diffuse_opacity[10], [0.5, 0.5, 0.5, 0.2]);
    assert_eq!(lut.diffuse_opacity[LUT_SIZE - 1], [1.0, 1.0, 1.0, 0.6]);
    assert_eq!(tf.sample(-3.0).opacity, 0.2);
    assert_eq!(tf.sample(7.0).opacity, 0.6);
}

#[test]
fn lerp_blends_the_functions() {
    let a = two();
    let b = TransferFunction {
        name: "b".into(),
        units: Default::default(),
        points: vec![
            ControlPoint::new(0.0, 1.0, [1.0, 1.0, 1.0]),
            ControlPoint::new(0.5, 0.0, [0.0, 0.0, 0.0]),
            ControlPoint::new(0.9, 0.3, [0.2, 0.4, 0.6]),
        ],
    };
    b.validate().expect("b valid");
    let (la, lb) = (a.lut(), b.lut());
    let close = |x: &TfLut, y: &TfLut| x.max_abs_diff(y) < 1e-5;
    assert!(close(&TransferFunction::lerp(&a, &b, 0.0).lut(), &la));
    assert!(close(&TransferFunction::lerp(&a, &b, 1.0).lut(), &lb));
    for t in [0.25, 0.5, 0.8] {
        let tf = TransferFunction::lerp(&a, &b, t);
        tf.validate().expect("blend valid");
        assert!(close(&tf.lut(), &TfLut::lerp(&la, &lb, t)), "t = {t}");
    }
    // The blend is of functions: at density 0.5, a is 1 − 0.3/0.8·0.5, b is 0.
    let mid = TransferFunction::lerp(&a, &b, 0.5).sample(0.5).opacity;
    let want = 0.5 * (1.0 - 0.5 * (0.3 / 0.8));
    assert!((mid - want).abs() < 1e-6, "{mid} vs {want}");
}

fn err(text: &str) -> String {
    match TransferFunction::from_toml_str(text, "bad.toml") {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn errors_name_file_point_and_field() {
    let e = err(&TWO.replace("opacity = 0.5", "opacity = 1.5"));
    assert!(e.starts_with("bad.toml: point[0].opacity:"), "{e}");

    let e = err(&TWO.replace("diffuse = [0.0, 1.0, 0.0]", "diffuse = [0.0, -1.0, 0.0]"));
    assert!(e.starts_with("bad.toml: point[1].diffuse:"), "{e}");

    let e = err(&TWO.replace("density = 1.0", "density = 1.2"));
    assert!(e.starts_with("bad.toml: point[0].density:"), "{e}");

    let e = err(&TWO.replace("density = 1.0", "density = 0.0"));
    assert!(
        e.starts_with("bad.toml: point[2].density:") && e.contains("point[0]"),
        "{e}"
    );

    let e = err("[[point]]\ndensity = 0.0\nopacity = 0.0\ndiffuse = [1,1,1]\n");
    assert!(
        e.starts_with("bad.toml: point:") && e.contains("at least 2"),
        "{e}"
    );

    let e = err(&TWO.replace("roughness = 0.1", "roughnes = 0.1"));
    assert!(
        e.starts_with("bad.toml:") && e.contains("roughnes") && e.contains("line"),
        "{e}"
    );

    let e = err("name = \"x\"\n[[point]\n");
    assert!(e.starts_with("bad.toml:") && e.contains("line 2"), "{e}");
}

#[test]
fn validate_rejects_unsorted_points() {
    let mut tf = two();
    tf.points.swap(0, 1);
    let e = tf.validate().map_err(|e| e.to_string());
    assert!(
        matches!(&e, Err(m) if m.starts_with("two: point[1].density")),
        "{e:?}"
    );
}

#[test]
fn to_toml_round_trips() {
    let mut tf = two();
    tf.name = "quote \" and \\ backslash".into();
    tf.points[1].emissive = [0.1, 2.5, 1e-7];
    tf.points[2].specular = [0.3, 0.3, 0.3];
    let back = TransferFunction::from_toml_str(&tf.to_toml(), "rt.toml").expect("round trip");
    assert_eq!(back, tf);
}

#[test]
fn a_ct_preset_in_hounsfield_units_shows_bone_on_ct_windows_of_any_range() {
    let bone = TransferFunction::preset("ct-bone").expect("ct-bone preset");
    assert_eq!(bone.units, TfUnits::Data);
    // Two CTs: one windowed to its data [-1000, 1200] HU, one with metal to 3000 HU.
    for window in [[-1000.0f32, 1200.0], [-1024.0, 3000.0]] {
        let tf = bone.in_density(window);
        tf.validate().expect("converted TF is a density TF");
        assert_eq!(tf.units, TfUnits::Density);
        let at = |hu: f32| {
            tf.sample((hu - window[0]) / (window[1] - window[0]))
                .opacity
        };
        assert_eq!(at(1000.0), 1.0, "cortical bone opaque at window {window:?}");
        assert_eq!(at(40.0), 0.0, "soft tissue empty at window {window:?}");
        assert_eq!(at(-1000.0), 0.0, "air empty at window {window:?}");
        assert!((at(275.0) - 0.5).abs() < 1e-3, "half way up the ramp");
    }
    // The same preset read as a density TF would show nothing of that bone on the
    // wider window: the units are what make it fit.
    let naive = TransferFunction {
        units: TfUnits::Density,
        ..bone.clone()
    };
    assert!(
        naive.validate().is_err(),
        "HU densities are no normalised densities"
    );
}

#[test]
fn data_units_round_trip_through_toml_and_need_finite_values() {
    let text = "units = \"data\"\n[[point]]\ndensity = -1000\nopacity = 0\ndiffuse = [1, 1, 1]\n\
                [[point]]\ndensity = 2000\nopacity = 1\ndiffuse = [1, 1, 1]\n";
    let tf = TransferFunction::from_toml_str(text, "hu.toml").expect("data TF");
    assert_eq!(tf.units, TfUnits::Data);
    let back = TransferFunction::from_toml_str(&tf.to_toml(), "hu.toml").expect("round trip");
    assert_eq!(back, tf);
    let bad = text.replace("density = 2000", "density = nan");
    let err = TransferFunction::from_toml_str(&bad, "hu.toml").unwrap_err();
    assert!(err.to_string().contains("density"), "{err}");
    let err = TransferFunction::from_toml_str("units = \"hounsfield\"\n", "u.toml").unwrap_err();
    assert!(err.to_string().contains("u.toml"), "{err}");
    // Cut to the window: the ends take the TF's values there.
    let d = tf.in_density([0.0, 1000.0]);
    assert_eq!(d.points.first().map(|p| p.density), Some(0.0));
    let last = d.points.last().expect("points");
    assert_eq!(last.density, 1.0);
    assert!((last.opacity - 2.0 / 3.0).abs() < 1e-6, "{}", last.opacity);
}
