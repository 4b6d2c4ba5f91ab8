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
use dvr_engine::volume::labels::{LabelMap, LabelTable};
use dvr_engine::volume::{
    RawFormat, RawParams, Series, Volume, VolumeError, MAX_ANISOTROPY, MAX_DIM, MAX_SPACING_MM,
    MAX_VOXELS, MIN_SPACING_MM,
};

/// A target's entry point: the input, and a folder for the files it writes.
pub type Entry = fn(&[u8], &Path);

/// Every target: its name (the folder under `fuzz/corpus/`) and its entry point.
pub const TARGETS: [(&str, Entry); 10] = [
    ("volume_nifti", volume_nifti),
    ("volume_nrrd", volume_nrrd),
    ("volume_nhdr", volume_nhdr),
    ("volume_raw", volume_raw),
    ("volume_dicom", volume_dicom),
    ("volume_zarr", volume_zarr),
    ("volume_ome_tiff", volume_ome_tiff),
    ("scene_toml", scene_toml),
    ("tf_toml", tf_toml),
    ("label_table", label_table),
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
    if raw.is_none() {
        read_as_series(&path);
    }
}

/// The same input as a series: its header's channels and time points, and its last time
/// point (the read furthest into the data), which must be what the limits allow.
fn read_as_series(path: &Path) {
    if let Ok(series) = Series::open(path, None) {
        if let Ok(channels) = series.read(series.info().times - 1) {
            for c in channels {
                check_loaded(Ok(c));
            }
        }
    }
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

/// Starts each file of a `volume_zarr` input: the marker, the file's path (relative to
/// the image's folder) up to the next newline, then its bytes up to the next marker.
pub const ZARR_FILE_MARKER: &[u8] = b"\n--file ";

/// Most files a `volume_zarr` input writes (the rest are ignored).
const ZARR_MAX_FILES: usize = 64;

/// Most folders deep a `volume_zarr` file may lie (a v3 chunk of a 5D level is
/// `s0/c/0/0/0/0/0`).
const ZARR_MAX_DEPTH: usize = 10;

/// Largest volume (x·y·z voxels) of a level a `volume_zarr` input may describe: chunks a
/// writer skipped read as the fill value, so a few bytes of metadata describe a volume
/// the loader rightly reads whole (up to `MAX_VOXELS`, 8 GiB of float32) but a fuzzing
/// process (2 GiB) cannot hold. Inputs with such a level are skipped; every other part
/// of the input (chunk shapes, codecs, other axes) is the loader's to bound.
const ZARR_MAX_FUZZ_VOXELS: u64 = 1 << 22;

/// An OME-Zarr image folder, `image.zarr`, made afresh for each input from records:
///
/// ```text
/// <path to open> [<memory budget in bytes>]        (the first line: `.` is the image)
/// \n--file zarr.json\n{...}                         (a file: its path, a newline, its bytes)
/// \n--file s0/c/0/0/0\n<chunk bytes>
/// ```
///
/// then loaded as `dvr --volume image.zarr` (or `image.zarr/s1`, one level) and the
/// Python package's `dvr.load_volume` do: `Volume::load_within` with the budget (at least
/// 64 KiB, as `[render] gpu_memory` requires), which picks the level. Paths are relative,
/// of plain names (letters, digits, `.`, `_`, `-`; not `.` or `..`); a record with
/// another path, or whose path clashes with a file already written, is skipped.
pub fn volume_zarr(bytes: &[u8], scratch: &Path) {
    let dir = scratch.join("zarr");
    match std::fs::remove_dir_all(&dir) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => panic!("scratch folder: {e}"),
        _ => {}
    }
    let image = dir.join("image.zarr");
    std::fs::create_dir_all(&image).expect("scratch folder");
    let mut parts = split_at_marker(bytes, ZARR_FILE_MARKER);
    let header = String::from_utf8_lossy(parts.next().unwrap_or_default());
    let mut words = header.lines().next().unwrap_or_default().split_whitespace();
    let open = match words.next().filter(|w| *w != ".") {
        Some(rel) => match relative_path(rel) {
            Some(p) => image.join(p),
            None => return,
        },
        None => image.clone(),
    };
    let budget = words
        .next()
        .and_then(|w| w.parse::<u64>().ok())
        .map(|b| b.max(64 << 10));
    for record in parts.take(ZARR_MAX_FILES) {
        let (name, data) = match record.iter().position(|&b| b == b'\n') {
            Some(at) => (&record[..at], &record[at + 1..]),
            None => (record, &[][..]),
        };
        let Some(rel) = std::str::from_utf8(name).ok().and_then(relative_path) else {
            continue;
        };
        if too_large_for_fuzzing(&rel, data) {
            return;
        }
        let path = image.join(&rel);
        if let Some(parent) = path.parent() {
            if std::fs::create_dir_all(parent).is_err() {
                continue;
            }
        }
        let _ = std::fs::write(&path, data);
    }
    check_loaded(Volume::load_within(&open, None, budget));
    read_as_series(&open);
    // The same store as a label map: an image's `labels/` group, a label image's
    // `image-label` colours and names.
    if let Ok((map, _table)) = LabelMap::load_with_table(&open) {
        let voxels: u64 = map.dims.iter().map(|&d| u64::from(d)).product();
        assert_eq!(
            map.values.len() as u64,
            voxels,
            "label map dims {:?}",
            map.dims
        );
    }
}

/// A volume a loader returned must be what its limits allow (README "Reliability"):
/// dims 1–`MAX_DIM` and at most `MAX_VOXELS`, as many voxels as the dims say, spacing in
/// `MIN_SPACING_MM`–`MAX_SPACING_MM` within `MAX_ANISOTROPY`. A panic here is a crash.
fn check_loaded(result: Result<Volume, VolumeError>) {
    let Ok(v) = result else {
        return;
    };
    let voxels: u64 = v.dims.iter().map(|&d| u64::from(d)).product();
    assert!(
        v.dims.iter().all(|&d| (1..=MAX_DIM).contains(&d)) && voxels <= MAX_VOXELS,
        "dims {:?} past the limits",
        v.dims
    );
    assert_eq!(v.data.len() as u64, voxels, "dims {:?}", v.dims);
    let (lo, hi) = (MIN_SPACING_MM as f32, MAX_SPACING_MM as f32);
    assert!(
        v.spacing.iter().all(|s| (lo..=hi).contains(s)),
        "spacing {:?} past the limits",
        v.spacing
    );
    let ratio = f64::from(v.spacing.iter().fold(0f32, |a, &s| a.max(s)))
        / f64::from(v.spacing.iter().fold(f32::MAX, |a, &s| a.min(s)));
    assert!(
        ratio <= MAX_ANISOTROPY * (1.0 + 1e-6),
        "spacing {:?}",
        v.spacing
    );
}

/// The pieces of `bytes` between occurrences of `marker` (the first piece is what
/// precedes the first marker).
fn split_at_marker<'a>(bytes: &'a [u8], marker: &'a [u8]) -> impl Iterator<Item = &'a [u8]> {
    let mut rest = Some(bytes);
    std::iter::from_fn(move || {
        let r = rest?;
        match r.windows(marker.len()).position(|w| w == marker) {
            Some(at) => {
                rest = Some(&r[at + marker.len()..]);
                Some(&r[..at])
            }
            None => {
                rest = None;
                Some(r)
            }
        }
    })
}

/// `text` as a relative path of plain names, at most [`ZARR_MAX_DEPTH`] deep.
fn relative_path(text: &str) -> Option<PathBuf> {
    let names: Vec<&str> = text.split('/').collect();
    let plain = |n: &&str| {
        !n.is_empty()
            && *n != "."
            && *n != ".."
            && n.len() <= 64
            && n.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b"._-".contains(&b))
    };
    (names.len() <= ZARR_MAX_DEPTH && names.iter().all(plain)).then(|| names.iter().collect())
}

/// Whether `data`, written at `rel`, is array metadata (`.zarray`, or a `zarr.json`
/// with a `shape`) whose last three axes make a volume the loader may read (each side
/// at most `MAX_DIM`, at most `MAX_VOXELS`) but larger than [`ZARR_MAX_FUZZ_VOXELS`].
fn too_large_for_fuzzing(rel: &Path, data: &[u8]) -> bool {
    let is_metadata = rel
        .file_name()
        .is_some_and(|n| n == ".zarray" || n == "zarr.json");
    if !is_metadata {
        return false;
    }
    let Ok(json) = serde_json::from_slice::<serde_json::Value>(data) else {
        return false;
    };
    let Some(shape) = json.get("shape").and_then(|s| s.as_array()) else {
        return false;
    };
    let sides: Vec<u64> = shape
        .iter()
        .rev()
        .take(3)
        .map(|s| s.as_u64().unwrap_or(0))
        .collect();
    let voxels = sides.iter().try_fold(1u64, |a, &s| a.checked_mul(s));
    sides.iter().all(|&s| s <= u64::from(MAX_DIM))
        && voxels.is_some_and(|v| v <= MAX_VOXELS && v > ZARR_MAX_FUZZ_VOXELS)
}

/// An OME-TIFF (or plain TIFF stack): the input is the file, `in.ome.tif`, loaded as
/// `dvr --volume in.ome.tif` does, and as a series (its C and T axes).
pub fn volume_ome_tiff(bytes: &[u8], scratch: &Path) {
    let path = folder(scratch, "tiff").join("in.ome.tif");
    std::fs::write(&path, bytes).expect("write input");
    check_loaded(Volume::load(&path, None));
    read_as_series(&path);
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

/// A label table in both formats (ITK-SNAP's label description, Slicer's `.ctbl`), and
/// completed with the values its own labels and a few more name.
pub fn label_table(bytes: &[u8], _scratch: &Path) {
    if let Ok(text) = std::str::from_utf8(bytes) {
        for parse in [LabelTable::parse_itksnap, LabelTable::parse_slicer] {
            if let Ok(mut t) = parse(text, Path::new("fuzz.label")) {
                let values: Vec<u16> = t.labels.iter().map(|l| l.value.wrapping_add(1)).collect();
                let _ = t.complete(&values);
            }
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
