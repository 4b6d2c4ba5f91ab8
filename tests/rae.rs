//! `rae` on the device: the compute shaders reproduce the framework that trained the
//! network (tools/rae/model.py in torch, fp32) on a short clip stored as a fixture by
//! tools/rae/fixture.py from the shipped weights — 3 frames at 30×22, a size that is not
//! a multiple of 2^levels, so the padding is exercised, and the recurrent state carries
//! from frame to frame. The shipped manifests load; a truncated weight file, a manifest
//! naming a missing file or a wrong layer list are clear errors naming the file.

mod common;

use common::harness::Harness;
use common::*;
use dvr_engine::denoise::rae::{network_for, Precision, RaeNet, RaeWeights};
use dvr_engine::denoise::{registry, DENOISERS};
use std::path::{Path, PathBuf};

/// Agreement bound between the shaders and torch, in HDR units (fixture outputs reach
/// ~1.6). Measured on lavapipe: 1.0e-6 (phantom), 8.3e-7 (mri); the margin allows for
/// other devices' FMA contraction and exp/log precision.
const TOLERANCE: f32 = 5e-5;
/// The same for fp16 tensors, relative to the clip's largest output (at least 1).
/// Measured on lavapipe (which converts to fp16 toward zero): see
/// fp16_tensors_stay_close_to_torch's output and README.md.
const F16_TOLERANCE: f32 = 1e-2;

fn assets() -> PathBuf {
    dvr_engine::assets::rae_dir()
}

struct Fixture {
    width: u32,
    height: u32,
    input: Vec<Vec<[f32; 4]>>,
    expected: Vec<Vec<[f32; 4]>>,
}

fn fixture(net: &str) -> Fixture {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/rae/{net}.bin"));
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let word = |i: usize| u32::from_le_bytes(bytes[4 * i..4 * i + 4].try_into().unwrap());
    let (width, height, frames) = (word(0), word(1), word(2) as usize);
    let n = (width * height) as usize;
    let floats: Vec<f32> = bytes[12..]
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    assert_eq!(floats.len(), 2 * frames * n * 4, "{}: size", path.display());
    let frame = |k: usize| -> Vec<[f32; 4]> {
        floats[k * n * 4..(k + 1) * n * 4]
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect()
    };
    Fixture {
        width,
        height,
        input: (0..frames).map(frame).collect(),
        expected: (frames..2 * frames).map(frame).collect(),
    }
}

/// Runs fixture `net` through denoiser `name` on the device; returns the largest
/// difference from torch over the clip and the largest expected output.
fn difference_from_torch(name: &str, net: &str) -> (f32, f32) {
    let f = fixture(net);
    let mut h = Harness::new(name, f.width, f.height);
    let mut worst = 0.0f32;
    let mut peak = 0.0f32;
    for (t, (input, expected)) in f.input.iter().zip(&f.expected).enumerate() {
        let out = h.step(input);
        let diff = out
            .iter()
            .zip(expected)
            .flat_map(|(o, e)| (0..3).map(move |c| (o[c] - e[c]).abs()))
            .fold(0.0f32, f32::max);
        peak = expected
            .iter()
            .flat_map(|e| e[..3].to_vec())
            .fold(peak, f32::max);
        println!("{name} on {net} frame {t}: max |shader - torch| = {diff:.3e}");
        worst = worst.max(diff);
    }
    println!(
        "{name} on {net}: max abs difference {worst:.3e} over 3 frames (outputs up to {peak:.3})"
    );
    assert!(peak > 0.0, "{net}: the fixture's output is all zero");
    (worst, peak)
}

#[test]
fn shaders_match_torch_on_a_clip() {
    for net in ["phantom", "mri"] {
        let name = DENOISERS
            .iter()
            // The harness builds denoisers for no dataset: the entry that runs `net` then.
            .find(|d| d.variant::<RaeNet>().map(|r| r.network(None)) == Some((net, Precision::F32)))
            .map(|d| d.name)
            .unwrap();
        let (worst, _) = difference_from_torch(name, net);
        assert!(
            worst < TOLERANCE,
            "{net}: shaders differ from torch by {worst}"
        );
    }
    assert_validation_clean();
}

/// fp16 tensors (`rae-fp16`, the mri network without a dataset) against torch's fp32:
/// each of the 16 layers' outputs and the recurrent state are rounded to half precision.
#[test]
fn fp16_tensors_stay_close_to_torch() {
    let fp16 = registry::find("rae-fp16").expect("in the registry");
    let fp16 = fp16.variant::<RaeNet>().map(|r| r.network(None));
    assert_eq!(fp16, Some(("mri", Precision::F16)));
    let (worst, peak) = difference_from_torch("rae-fp16", "mri");
    assert!(
        worst < F16_TOLERANCE * peak.max(1.0),
        "rae-fp16: differs from torch's fp32 by {worst} (outputs up to {peak})"
    );
    // It is really half precision: fp32 agreement would be ~1e-6.
    assert!(worst > TOLERANCE, "rae-fp16 matches fp32 to {worst}");
    assert_validation_clean();
}

#[test]
fn shipped_weights_load() {
    let picked = [Some("phantom"), Some("mri"), Some("cloud"), None].map(network_for);
    assert_eq!(picked, ["phantom", "mri", "mri", "mri"]);
    let named = DENOISERS
        .iter()
        .filter_map(|d| d.variant::<RaeNet>())
        .map(|r| r.network(None))
        .map(|(net, _)| net);
    for net in named.chain(picked) {
        let w = RaeWeights::builtin(net).unwrap_or_else(|e| panic!("{net}: {e}"));
        assert!(w.levels() >= 2);
        assert!(!w.floats.is_empty());
    }
}

#[test]
fn bad_weight_files_are_clear_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let manifest = std::fs::read_to_string(assets().join("phantom.json")).expect("manifest");
    let bin = std::fs::read(assets().join("phantom.bin")).expect("weights");

    let load_error = |manifest: &str| {
        let e = RaeWeights::load(&dir.path().join(manifest))
            .expect_err("a bad weight file must not load")
            .to_string();
        println!("{e}");
        e
    };

    // Truncated weights: the error names the .bin file and says truncated.
    std::fs::write(dir.path().join("phantom.json"), &manifest).unwrap();
    std::fs::write(dir.path().join("phantom.bin"), &bin[..bin.len() - 100]).unwrap();
    let e = load_error("phantom.json");
    assert!(e.contains("phantom.bin") && e.contains("truncated"), "{e}");

    // A manifest naming a weight file that does not exist.
    std::fs::remove_file(dir.path().join("phantom.bin")).unwrap();
    let e = load_error("phantom.json");
    assert!(
        e.contains("phantom.bin") && e.contains("cannot read"),
        "{e}"
    );

    // A manifest whose widths do not match its layers.
    let bad = manifest.replacen("\"widths\": [\n    16", "\"widths\": [\n    20", 1);
    assert_ne!(bad, manifest, "the widths edit must apply");
    std::fs::write(dir.path().join("bad.json"), bad).unwrap();
    std::fs::write(dir.path().join("phantom.bin"), &bin).unwrap();
    let e = load_error("bad.json");
    assert!(e.contains("bad.json") && e.contains("layer"), "{e}");

    // Not JSON at all.
    std::fs::write(dir.path().join("junk.json"), "widths = 3").unwrap();
    let e = load_error("junk.json");
    assert!(
        e.contains("junk.json") && e.contains("not a RAE manifest"),
        "{e}"
    );
}
