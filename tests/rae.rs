//! `rae` on the device: the compute shaders reproduce the framework that trained the
//! network (tools/rae/model.py in torch, fp32) on a short clip stored as a fixture by
//! tools/rae/fixture.py from the shipped weights — 3 frames at 30×22, a size that is not
//! a multiple of 2^levels, so the padding is exercised, and the recurrent state carries
//! from frame to frame. The shipped manifests load; a truncated weight file, a manifest
//! naming a missing file or a wrong layer list are clear errors naming the file.

mod common;

use common::harness::Harness;
use common::*;
use dvr_engine::denoise::rae::{network_for, RaeWeights, NETS};
use std::path::{Path, PathBuf};

/// Agreement bound between the shaders and torch, in HDR units (fixture outputs reach
/// ~1.5). Measured on lavapipe: 1.1e-6 (phantom), 9.5e-7 (mri); the margin allows for
/// other devices' FMA contraction and exp/log precision.
const TOLERANCE: f32 = 5e-5;

fn assets() -> PathBuf {
    dvr_engine::transfer::assets_dir().join("rae")
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

#[test]
fn shaders_match_torch_on_a_clip() {
    for net in ["phantom", "mri"] {
        let path =
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/fixtures/rae/{net}.bin"));
        if !path.exists() {
            assert_ne!(net, "phantom", "the phantom fixture must exist");
            continue;
        }
        let f = fixture(net);
        let name = NETS
            .iter()
            .find(|(_, n)| *n == net)
            .map(|(d, _)| *d)
            .unwrap();
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
            println!("{net} frame {t}: max |shader - torch| = {diff:.3e}");
            worst = worst.max(diff);
        }
        println!("{net}: max abs difference {worst:.3e} over 3 frames (outputs up to {peak:.3})");
        assert!(
            worst < TOLERANCE,
            "{net}: shaders differ from torch by {worst}"
        );
        assert!(peak > 0.0, "{net}: the fixture's output is all zero");
    }
    assert_validation_clean();
}

#[test]
fn shipped_weights_load() {
    let picked = [Some("phantom"), Some("mri"), Some("cloud"), None].map(network_for);
    assert_eq!(picked, ["phantom", "mri", "mri", "mri"]);
    let named = NETS
        .iter()
        .map(|(_, net)| *net)
        .filter(|net| *net != "auto");
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

    // Truncated weights: the error names the .bin file and says truncated.
    std::fs::write(dir.path().join("phantom.json"), &manifest).unwrap();
    std::fs::write(dir.path().join("phantom.bin"), &bin[..bin.len() - 100]).unwrap();
    let e = RaeWeights::load(&dir.path().join("phantom.json"))
        .unwrap_err()
        .to_string();
    println!("{e}");
    assert!(e.contains("phantom.bin") && e.contains("truncated"), "{e}");

    // A manifest naming a weight file that does not exist.
    std::fs::remove_file(dir.path().join("phantom.bin")).unwrap();
    let e = RaeWeights::load(&dir.path().join("phantom.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("phantom.bin") && e.contains("cannot read"),
        "{e}"
    );

    // A manifest whose widths do not match its layers.
    let bad = manifest.replacen("\"widths\": [\n    16", "\"widths\": [\n    20", 1);
    assert_ne!(bad, manifest, "the widths edit must apply");
    std::fs::write(dir.path().join("bad.json"), bad).unwrap();
    std::fs::write(dir.path().join("phantom.bin"), &bin).unwrap();
    let e = RaeWeights::load(&dir.path().join("bad.json"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.json") && e.contains("layer"), "{e}");

    // Not JSON at all.
    std::fs::write(dir.path().join("junk.json"), "widths = 3").unwrap();
    let e = RaeWeights::load(&dir.path().join("junk.json"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("junk.json") && e.contains("not a RAE manifest"),
        "{e}"
    );
}
