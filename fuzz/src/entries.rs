//! The fuzz targets' entry points: each takes arbitrary bytes, feeds them to one loader
//! of untrusted input through its public entry point, and must return (an `Ok` or a
//! clear error) without panicking, hanging or allocating more than the input's header
//! promises. The fuzz targets (`fuzz/fuzz_targets/`) call these under libFuzzer; the
//! engine's test `engine/tests/fuzz_corpus.rs` includes this file and replays every
//! committed corpus file through the same functions, so CI checks the seeds and every
//! input that once failed without needing nightly.

use std::path::{Path, PathBuf};

use dvr_engine::scene::Scene;
use dvr_engine::transfer::TransferFunction;
use dvr_engine::volume::{RawFormat, RawParams, Volume};

/// A target's entry point: the input, and a folder for the files it writes.
pub type Entry = fn(&[u8], &Path);

/// Every target: its name (the folder under `fuzz/corpus/`) and its entry point.
pub const TARGETS: [(&str, Entry); 7] = [
    ("volume_nifti", volume_nifti),
    ("volume_nrrd", volume_nrrd),
    ("volume_nhdr", volume_nhdr),
    ("volume_raw", volume_raw),
    ("volume_dicom", volume_dicom),
    ("scene_toml", scene_toml),
    ("tf_toml", tf_toml),
];

/// Separates slice files in a `volume_dicom` input.
pub const SLICE_SEPARATOR: &[u8] = b"\n--next-slice--\n";

/// Most slice files a `volume_dicom` input is split into.
const MAX_SLICES: usize = 4;

/// The folder for one target's files under `scratch`, made once; each input overwrites
/// the files it uses (cheaper than a new folder per input, which halves the rate).
fn folder(scratch: &Path, name: &str) -> PathBuf {
    let dir = scratch.join(name);
    if !dir.is_dir() {
        std::fs::create_dir_all(&dir).expect("scratch folder");
    }
    dir
}

fn load_file(scratch: &Path, file_name: &str, bytes: &[u8], raw: Option<&RawParams>) {
    let dir = folder(scratch, "file");
    let path = dir.join(file_name);
    std::fs::write(&path, bytes).expect("write input");
    let _ = Volume::load(&path, raw);
}

/// `.nii` (or gzipped: the loader looks at the magic bytes, not the name).
pub fn volume_nifti(bytes: &[u8], scratch: &Path) {
    load_file(scratch, "in.nii", bytes, None);
}

/// An `.nrrd` with attached data.
pub fn volume_nrrd(bytes: &[u8], scratch: &Path) {
    load_file(scratch, "in.nrrd", bytes, None);
}

/// An `.nhdr` header beside two data files it may name: `data.raw` (256 bytes) and
/// `data.raw.gz` (the same, gzipped).
pub fn volume_nhdr(bytes: &[u8], scratch: &Path) {
    let dir = folder(scratch, "nhdr");
    if !dir.join("data.raw.gz").is_file() {
        let data: Vec<u8> = (0..=255).collect();
        std::fs::write(dir.join("data.raw"), &data).expect("write data");
        std::fs::write(dir.join("data.raw.gz"), gzip_0_to_255()).expect("write data");
    }
    let path = dir.join("in.nhdr");
    std::fs::write(&path, bytes).expect("write input");
    let _ = Volume::load(&path, None);
}

/// `0, 1, …, 255` gzipped, the data file an `.nhdr` input may name.
fn gzip_0_to_255() -> Vec<u8> {
    use std::io::Write;
    let data: Vec<u8> = (0..=255).collect();
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(&data).expect("gzip");
    e.finish().expect("gzip")
}

/// A raw file: the first four bytes choose dims (1–16 each) and the format, the rest
/// is the file (so sizes, NaN and windowing are all reachable).
pub fn volume_raw(bytes: &[u8], scratch: &Path) {
    let Some((head, data)) = bytes.split_first_chunk::<4>() else {
        return;
    };
    let params = RawParams {
        dims: [0, 1, 2].map(|i| u32::from(head[i] % 16) + 1),
        format: match head[3] % 4 {
            0 => RawFormat::U8,
            1 => RawFormat::U16,
            2 => RawFormat::I16,
            _ => RawFormat::F32,
        },
        spacing: [1.0; 3],
    };
    load_file(scratch, "in.raw", data, Some(&params));
}

/// A DICOM series folder: the input split at [`SLICE_SEPARATOR`] into up to four
/// `.dcm` files.
pub fn volume_dicom(bytes: &[u8], scratch: &Path) {
    let dir = folder(scratch, "dicom");
    for i in 0..MAX_SLICES {
        let _ = std::fs::remove_file(dir.join(format!("s{i}.dcm")));
    }
    let mut rest = bytes;
    for i in 0..MAX_SLICES {
        let cut = rest
            .windows(SLICE_SEPARATOR.len())
            .position(|w| w == SLICE_SEPARATOR)
            .filter(|_| i + 1 < MAX_SLICES);
        let (slice, next) = match cut {
            Some(at) => (&rest[..at], &rest[at + SLICE_SEPARATOR.len()..]),
            None => (rest, &[][..]),
        };
        std::fs::write(dir.join(format!("s{i}.dcm")), slice).expect("write slice");
        if cut.is_none() {
            break;
        }
        rest = next;
    }
    let _ = Volume::load(&dir, None);
}

/// Scene text (relative paths resolve against the working folder).
pub fn scene_toml(bytes: &[u8], _scratch: &Path) {
    if let Ok(text) = std::str::from_utf8(bytes) {
        if let Ok(scene) = Scene::from_toml_str(text, "fuzz.toml") {
            // What every renderer asks of a loaded scene must not panic either.
            let _ = scene.to_toml();
            for f in [0, scene.frames / 2, scene.frames.saturating_sub(1)] {
                let _ = scene.frame_state(f);
            }
            let _ = scene.with_frames(3).map(|s| s.frame_state(2));
        }
    }
}

/// Transfer-function text.
pub fn tf_toml(bytes: &[u8], _scratch: &Path) {
    if let Ok(text) = std::str::from_utf8(bytes) {
        if let Ok(tf) = TransferFunction::from_toml_str(text, "fuzz.toml") {
            let _ = tf.lut();
            let _ = TransferFunction::from_toml_str(&tf.to_toml(), "round-trip.toml");
        }
    }
}

/// The scratch folder of a fuzzing process (one per process, in memory under
/// `/dev/shm` where there is one, else under the system's temporary folder).
pub fn process_scratch() -> PathBuf {
    let shm = Path::new("/dev/shm");
    let base = if shm.is_dir() {
        shm.to_path_buf()
    } else {
        std::env::temp_dir()
    };
    let dir = base.join(format!("dvr-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}
