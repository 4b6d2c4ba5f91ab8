//! Tests of `flip.rs` (against fixtures from NVIDIA's flip-evaluator).

use super::super::test_rng::{add_noise, test_image};
use super::*;
use std::path::PathBuf;

#[test]
fn identical_is_zero() {
    let a = test_image(48, 40);
    let r = flip(&a, &a, DEFAULT_PPD);
    assert_eq!(r.mean, 0.0);
    assert!(r.error_map.iter().all(|&v| v == 0.0));
    assert_eq!(r.error_map.len(), 48 * 40);
}

#[test]
fn prepared_reference_gives_identical_results() {
    let a = test_image(40, 36);
    let prepared = FlipReference::new(&a, DEFAULT_PPD);
    for seed in 1..4 {
        let b = add_noise(&a, 0.03 * seed as f64, seed);
        assert_eq!(prepared.compare(&b), flip(&a, &b, DEFAULT_PPD));
    }
}

#[test]
fn more_noise_more_error() {
    let a = test_image(48, 40);
    let lo = flip(&a, &add_noise(&a, 0.02, 1), DEFAULT_PPD).mean;
    let hi = flip(&a, &add_noise(&a, 0.1, 1), DEFAULT_PPD).mean;
    assert!(0.0 < lo && lo < hi && hi < 1.0, "{lo} {hi}");
}

#[test]
fn default_filters_match_reference_sizes() {
    // At 67.02 ppd the reference uses a 21-tap CSF and 19-tap feature kernels.
    let ppd = DEFAULT_PPD as f32;
    assert!((DEFAULT_PPD - 67.0206).abs() < 1e-3);
    assert_eq!(SpatialFilters::new(ppd).y.len(), 21);
    let f = FeatureFilter::new(ppd);
    assert_eq!(f.g.len(), 19);
    let sum = |k: &[f32]| k.iter().sum::<f32>();
    assert!((sum(&f.g) - 1.0).abs() < 1e-5);
    assert!(sum(&f.dg).abs() < 1e-5 && sum(&f.ddg).abs() < 1e-5);
    let s = SpatialFilters::new(ppd);
    let (s1, s2) = (sum(&s.cz1), sum(&s.cz2));
    assert!((s1 * s1 + s2 * s2 - 1.0).abs() < 1e-5);
}

#[test]
fn colormap_endpoints() {
    let c = flip_colormap(&[0.0, 1.0, f32::NAN, 2.0, -1.0]);
    assert_eq!(c[0], [0, 0, 4]);
    assert_eq!(c[1], [252, 253, 191]);
    assert_eq!(c[2], c[0]);
    assert_eq!(c[3], c[1]);
    assert_eq!(c[4], c[0]);
}

fn fixture_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/flip")
}

fn load_png(path: &std::path::Path) -> Rgb32Image {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("open {}: {e}", path.display()))
        .to_rgb8();
    Rgb32Image::from_srgb8(img.width(), img.height(), img.as_raw())
}

/// Our port against NVIDIA's `flip-evaluator` on the pairs written by
/// `tools/check_flip.py` (noise, blur, shift, colour change, quantisation, faint
/// noise): the mean must agree within 1 % relative.
#[test]
fn agrees_with_flip_evaluator_on_fixtures() {
    let dir = fixture_dir();
    let json = std::fs::read_to_string(dir.join("expected.json"))
        .expect("tests/fixtures/flip/expected.json (run tools/check_flip.py)");
    let expected: serde_json::Value = serde_json::from_str(&json).expect("valid JSON");
    let ppd = expected["ppd"].as_f64().expect("ppd");
    let pairs = expected["pairs"].as_array().expect("pairs");
    assert!(pairs.len() >= 4);
    let mut report = String::new();
    let mut worst = 0.0f64;
    for p in pairs {
        let name = p["name"].as_str().unwrap();
        let a = load_png(&dir.join(p["reference"].as_str().unwrap()));
        let b = load_png(&dir.join(p["test"].as_str().unwrap()));
        let want = p["mean"].as_f64().unwrap();
        let got = flip(&a, &b, ppd).mean;
        let rel = (got - want).abs() / want;
        worst = worst.max(rel);
        report += &format!("{name}: ours {got:.6}, flip-evaluator {want:.6}, rel {rel:.2e}\n");
    }
    println!("{report}");
    assert!(
        worst < 0.01,
        "FLIP disagrees with flip-evaluator:\n{report}"
    );
}
