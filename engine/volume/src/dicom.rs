//! DICOM series: a folder of single-frame slices (CT, MR) stacked into one volume.
//!
//! Parsed by hand rather than with `dicom-object`: that crate family (object, parser,
//! encoding, core, the standard dictionary and their dependencies) would more than double
//! the engine's dependency tree and compile time, while a volume needs about fifteen
//! top-level attributes from uncompressed files. What is read:
//!
//! - transfer syntaxes implicit VR little endian (`1.2.840.10008.1.2`) and explicit VR
//!   little endian (`1.2.840.10008.1.2.1`), with or without the 128-byte preamble;
//!   compressed syntaxes are rejected naming the UID (convert with e.g. `gdcmconv --raw`);
//! - `Rows`, `Columns`, `BitsAllocated` (8 or 16), `BitsStored`, `PixelRepresentation`,
//!   `SamplesPerPixel` (1), `NumberOfFrames` (1), `PixelSpacing`, `SliceThickness`,
//!   `SpacingBetweenSlices`, `ImagePositionPatient`, `ImageOrientationPatient`,
//!   `InstanceNumber`, `RescaleSlope/Intercept` (per slice), `SeriesInstanceUID`;
//! - sequences (defined or undefined length) are skipped.
//!
//! Slices are sorted by their position along the slice normal (the cross product of the
//! orientation's row and column directions); when a slice lacks position or orientation
//! the series falls back to `InstanceNumber` order and `SpacingBetweenSlices` or
//! `SliceThickness` for the slice distance. x runs along columns, y along rows in the
//! file; the orientation and the sorted positions (LPS) then put the volume in RAS order
//! (`orientation.rs`), so an axial series is mirrored in x and y against its file order.

use std::path::{Path, PathBuf};

use super::error::VolumeError;
use super::samples::{Affine, Rescale, SampleKind, Samples, Stored};
use super::{io, validate_dims, validate_spacing, PatientTransform, Volume};

const IMPLICIT_LE: &str = "1.2.840.10008.1.2";
const EXPLICIT_LE: &str = "1.2.840.10008.1.2.1";

/// Attribute tags (group, element) the loader reads.
mod tag {
    pub type Tag = (u16, u16);
    pub const TRANSFER_SYNTAX: Tag = (0x0002, 0x0010);
    pub const SLICE_THICKNESS: Tag = (0x0018, 0x0050);
    pub const SPACING_BETWEEN_SLICES: Tag = (0x0018, 0x0088);
    pub const SERIES_UID: Tag = (0x0020, 0x000E);
    pub const INSTANCE_NUMBER: Tag = (0x0020, 0x0013);
    pub const POSITION: Tag = (0x0020, 0x0032);
    pub const ORIENTATION: Tag = (0x0020, 0x0037);
    pub const SAMPLES_PER_PIXEL: Tag = (0x0028, 0x0002);
    pub const NUMBER_OF_FRAMES: Tag = (0x0028, 0x0008);
    pub const ROWS: Tag = (0x0028, 0x0010);
    pub const COLUMNS: Tag = (0x0028, 0x0011);
    pub const PIXEL_SPACING: Tag = (0x0028, 0x0030);
    pub const BITS_ALLOCATED: Tag = (0x0028, 0x0100);
    pub const BITS_STORED: Tag = (0x0028, 0x0101);
    pub const PIXEL_REPRESENTATION: Tag = (0x0028, 0x0103);
    pub const RESCALE_INTERCEPT: Tag = (0x0028, 0x1052);
    pub const RESCALE_SLOPE: Tag = (0x0028, 0x1053);
    pub const PIXEL_DATA: Tag = (0x7FE0, 0x0010);
    pub const ITEM: Tag = (0xFFFE, 0xE000);
    pub const ITEM_END: Tag = (0xFFFE, 0xE00D);
    pub const SEQUENCE_END: Tag = (0xFFFE, 0xE0DD);
}
use tag::Tag;

/// Largest slice file read: a 4096×4096 16-bit slice (32 MiB, the largest this engine
/// uploads) plus generous room for its other attributes.
const MAX_SLICE_FILE_BYTES: u64 = 96 << 20;

/// One parsed slice.
#[derive(Debug)]
struct Slice {
    file: PathBuf,
    rows: u16,
    cols: u16,
    bits_allocated: u16,
    bits_stored: u16,
    signed: bool,
    pixel_spacing: Option<[f64; 2]>,
    thickness: Option<f64>,
    spacing_between: Option<f64>,
    position: Option<[f64; 3]>,
    orientation: Option<[f64; 6]>,
    instance: Option<i64>,
    rescale: Affine,
    series: Option<String>,
    pixels: Vec<u8>,
}

/// Loads every DICOM slice in `dir` as one series. Files named `*.dcm` are used; if
/// there are none, every visible file carrying the `DICM` preamble marker.
pub(crate) fn load_series(dir: &Path) -> Result<Volume, VolumeError> {
    let io_err = |source| VolumeError::Io {
        path: dir.to_path_buf(),
        source,
    };
    let mut files: Vec<PathBuf> = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(io_err)? {
        let p = entry.map_err(io_err)?.path();
        let hidden = p
            .file_name()
            .is_some_and(|n| n.to_string_lossy().starts_with('.'));
        if p.is_file() && !hidden {
            files.push(p);
        }
    }
    files.sort();
    let dcm: Vec<PathBuf> = files
        .iter()
        .filter(|p| p.extension().is_some_and(|e| e.eq_ignore_ascii_case("dcm")))
        .cloned()
        .collect();
    let files = if dcm.is_empty() {
        files.into_iter().filter(|p| has_preamble(p)).collect()
    } else {
        dcm
    };
    if files.is_empty() {
        return Err(VolumeError::Unsupported {
            path: dir.to_path_buf(),
            reason: "folder holds no DICOM files (*.dcm or files with the DICM marker)".into(),
        });
    }
    load_files(dir, files)
}

fn has_preamble(p: &Path) -> bool {
    use std::io::Read;
    let mut head = [0u8; 132];
    // Regular files only: opening a FIFO that sits in the folder would block.
    crate::files::open_regular(p)
        .and_then(|(mut f, _)| f.read_exact(&mut head))
        .is_ok()
        && &head[128..] == b"DICM"
}

/// Loads the given slice files as one series; `series_path` names the series in errors
/// and gives the volume its name.
pub(crate) fn load_files(series_path: &Path, files: Vec<PathBuf>) -> Result<Volume, VolumeError> {
    let inconsistent = |problem: String| VolumeError::InconsistentSeries {
        path: series_path.to_path_buf(),
        problem,
    };
    // Bound what is read before reading it: the slice count is the volume's depth, and
    // the first slice's size times that count is the whole volume.
    if files.len() as u64 > u64::from(super::MAX_DIM) {
        return Err(inconsistent(format!(
            "{} slice files; at most {} slices are stacked (the largest 3D texture this \
             engine uploads)",
            files.len(),
            super::MAX_DIM
        )));
    }
    let mut slices = Vec::with_capacity(files.len());
    for f in &files {
        let s = parse_file(f)?;
        if slices.is_empty() {
            validate_dims(
                series_path,
                [i64::from(s.cols), i64::from(s.rows), files.len() as i64],
            )?;
        }
        slices.push(s);
    }
    let Some(first) = slices.first() else {
        return Err(inconsistent("no slices".into()));
    };

    // One series, one geometry, one pixel format.
    let mut uids: Vec<&str> = slices.iter().filter_map(|s| s.series.as_deref()).collect();
    uids.sort_unstable();
    uids.dedup();
    if uids.len() > 1 {
        return Err(inconsistent(format!(
            "the folder holds {} series ({}); point at a folder with one",
            uids.len(),
            uids.join(", ")
        )));
    }
    for s in &slices[1..] {
        let a = (
            first.rows,
            first.cols,
            first.bits_allocated,
            first.bits_stored,
            first.signed,
        );
        let b = (s.rows, s.cols, s.bits_allocated, s.bits_stored, s.signed);
        if a != b {
            return Err(inconsistent(format!(
                "{} is {}x{} with {}/{} bits (signed: {}) but {} is {}x{} with {}/{} bits (signed: {})",
                s.file.display(), b.1, b.0, b.2, b.3, b.4,
                first.file.display(), a.1, a.0, a.2, a.3, a.4,
            )));
        }
    }

    let dz = sort_slices(series_path, &mut slices)?;
    let first = &slices[0];
    let n = slices.len();
    let dims = validate_dims(
        series_path,
        [i64::from(first.cols), i64::from(first.rows), n as i64],
    )?;
    // PixelSpacing is (row spacing = along y, column spacing = along x).
    let [dy, dx] = first.pixel_spacing.unwrap_or([1.0, 1.0]);
    let spacing = validate_spacing(series_path, "PixelSpacing / slice distance", [dx, dy, dz])?;

    let bits = first.bits_stored;
    let signed = first.signed;
    let type_range = if signed {
        (
            -(2f64.powi(i32::from(bits) - 1)),
            2f64.powi(i32::from(bits) - 1) - 1.0,
        )
    } else {
        (0.0, 2f64.powi(i32::from(bits)) - 1.0)
    };
    let uniform = slices.iter().all(|s| s.rescale == first.rescale);
    let rescale = if uniform {
        Rescale::Uniform(first.rescale)
    } else {
        Rescale::PerSlice(slices.iter().map(|s| s.rescale).collect())
    };
    let kind = match (first.bits_allocated, signed) {
        (8, false) => SampleKind::U8,
        (16, false) => SampleKind::U16,
        (16, true) => SampleKind::I16,
        _ => {
            return Err(VolumeError::UnsupportedType {
                path: first.file.clone(),
                datatype: format!(
                    "BitsAllocated {} with PixelRepresentation {}",
                    first.bits_allocated,
                    u8::from(signed)
                ),
                supported: "unsigned 8-bit, unsigned or signed 16-bit",
            })
        }
    };
    let mut bytes = Vec::with_capacity(io::expected_bytes(dims, kind) as usize);
    for s in &slices {
        bytes.extend_from_slice(&s.pixels);
    }
    let samples = mask_bits(Samples::decode(kind, bytes, false), bits);
    let name = series_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "dicom".into());
    let name = name.strip_suffix(".dcm").unwrap_or(&name).to_string();
    let stored = Stored {
        samples,
        type_range: Some(type_range),
        rescale,
        orientation: patient_transform(&slices, spacing),
    };
    Volume::from_stored(series_path, name, dims, spacing, stored)
}

/// The series' index-to-patient transform from ImageOrientationPatient and the sorted
/// slices' ImagePositionPatient (DICOM's LPS, converted to RAS); `None` when a slice
/// lacks them (the index axes are then taken as R, A, S).
fn patient_transform(slices: &[Slice], spacing: [f32; 3]) -> Option<PatientTransform> {
    let first = slices.first()?;
    let o = first.orientation?;
    let p0 = first.position?;
    if slices.iter().any(|s| s.position.is_none()) {
        return None;
    }
    let [dx, dy, dz] = spacing.map(f64::from);
    let row = [o[0] * dx, o[1] * dx, o[2] * dx];
    let col = [o[3] * dy, o[4] * dy, o[5] * dy];
    // The slice step: from the first slice to the last, as sorted (its length is the
    // mean gap); one slice: the normal at the slice distance.
    let step = match slices.last().and_then(|s| s.position) {
        Some(pn) if slices.len() > 1 => {
            let n = (slices.len() - 1) as f64;
            [0, 1, 2].map(|i| (pn[i] - p0[i]) / n)
        }
        _ => [
            (o[1] * o[5] - o[2] * o[4]) * dz,
            (o[2] * o[3] - o[0] * o[5]) * dz,
            (o[0] * o[4] - o[1] * o[3]) * dz,
        ],
    };
    Some(PatientTransform::from_lps([row, col, step], p0))
}

/// A slice gap further than this fraction from the mean spacing is an error.
const UNEVEN_SPACING_ERROR: f64 = 0.1;
/// A slice gap further than this fraction from the mean spacing is worth a warning.
const UNEVEN_SPACING_WARNING: f64 = 0.01;

/// Sorts slices in place and returns the slice distance in mm.
fn sort_slices(series_path: &Path, slices: &mut [Slice]) -> Result<f64, VolumeError> {
    let inconsistent = |problem: String| VolumeError::InconsistentSeries {
        path: series_path.to_path_buf(),
        problem,
    };
    let fallback_dz = |s: &Slice| s.spacing_between.or(s.thickness).unwrap_or(1.0).abs();
    let geometric = slices
        .iter()
        .all(|s| s.position.is_some() && s.orientation.is_some());
    if !geometric || slices.len() < 2 {
        if slices.iter().all(|s| s.instance.is_some()) {
            slices.sort_by_key(|s| s.instance);
        }
        return Ok(fallback_dz(&slices[0]));
    }
    let o = slices[0]
        .orientation
        .unwrap_or([1.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    let normal = [
        o[1] * o[5] - o[2] * o[4],
        o[2] * o[3] - o[0] * o[5],
        o[0] * o[4] - o[1] * o[3],
    ];
    for s in slices.iter() {
        let so = s.orientation.unwrap_or(o);
        if so.iter().zip(o.iter()).any(|(a, b)| (a - b).abs() > 1e-3) {
            return Err(inconsistent(format!(
                "{} has ImageOrientationPatient {so:?}, the first slice {o:?}",
                s.file.display()
            )));
        }
    }
    let depth = |s: &Slice| {
        let p = s.position.unwrap_or([0.0; 3]);
        p[0] * normal[0] + p[1] * normal[1] + p[2] * normal[2]
    };
    slices.sort_by(|a, b| depth(a).total_cmp(&depth(b)));
    let d: Vec<f64> = slices.iter().map(depth).collect();
    let gaps: Vec<f64> = d.windows(2).map(|w| w[1] - w[0]).collect();
    if let Some(i) = gaps.iter().position(|&g| g < 1e-4) {
        return Err(inconsistent(format!(
            "{} and {} lie at the same position (several acquisitions in one folder?)",
            slices[i].file.display(),
            slices[i + 1].file.display()
        )));
    }
    let mean = (d[d.len() - 1] - d[0]) / gaps.len() as f64;
    // Slices are stacked at one spacing: a gap far from it (a missing slice, two
    // stacks) would put every slice after it at the wrong place, so it is an error; a
    // small unevenness (rounding in the positions) is only worth a warning.
    let worst = gaps
        .iter()
        .enumerate()
        .max_by(|a, b| (a.1 - mean).abs().total_cmp(&(b.1 - mean).abs()));
    if let Some((i, &g)) = worst {
        let deviation = (g - mean).abs() / mean;
        let between = format!(
            "{} and {}",
            slices[i].file.display(),
            slices[i + 1].file.display()
        );
        if deviation > UNEVEN_SPACING_ERROR {
            return Err(inconsistent(format!(
                "uneven slice spacing: {g:.3} mm between {between}, but {mean:.3} mm on \
                 average (more than {:.0}% off); the slices are stacked at one spacing, so \
                 the volume's geometry would be wrong (a missing slice? two stacks?)",
                UNEVEN_SPACING_ERROR * 100.0
            )));
        }
        if deviation > UNEVEN_SPACING_WARNING {
            log::warn!(
                "{}: uneven slice spacing ({g:.3} mm between {between} vs {mean:.3} mm on \
                 average); slices are stacked at the mean",
                series_path.display()
            );
        }
    }
    Ok(mean)
}

/// Keeps only the `bits` stored bits of each 16-bit sample (sign-extending signed ones):
/// old scanners put overlay bits above them.
fn mask_bits(s: Samples, bits: u16) -> Samples {
    match s {
        Samples::U16(mut v) if bits < 16 => {
            let mask = ((1u32 << bits) - 1) as u16;
            v.iter_mut().for_each(|x| *x &= mask);
            Samples::U16(v)
        }
        Samples::I16(mut v) if bits < 16 => {
            let shift = 16 - bits;
            v.iter_mut().for_each(|x| *x = (*x << shift) >> shift);
            Samples::I16(v)
        }
        other => other,
    }
}

/// Cursor over one file's bytes.
struct Reader<'a> {
    path: &'a Path,
    b: &'a [u8],
    pos: usize,
}

/// One data element header.
struct Element {
    tag: Tag,
    vr: [u8; 2],
    /// `None` for undefined length.
    len: Option<usize>,
}

impl<'a> Reader<'a> {
    fn malformed(&self, field: &str, problem: String) -> VolumeError {
        VolumeError::MalformedHeader {
            path: self.path.to_path_buf(),
            field: field.to_string(),
            problem,
        }
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], VolumeError> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.b.len());
        match end {
            Some(end) => {
                let s = &self.b[self.pos..end];
                self.pos = end;
                Ok(s)
            }
            None => Err(self.malformed(
                what,
                format!("runs past the end of the file at byte {}", self.pos),
            )),
        }
    }

    fn u16(&mut self, what: &str) -> Result<u16, VolumeError> {
        let s = self.take(2, what)?;
        Ok(u16::from_le_bytes([s[0], s[1]]))
    }

    fn u32(&mut self, what: &str) -> Result<u32, VolumeError> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }

    /// Reads an element header in the given VR encoding.
    fn element(&mut self, explicit: bool) -> Result<Element, VolumeError> {
        let tag = (self.u16("tag")?, self.u16("tag")?);
        let name = format!("({:04X},{:04X})", tag.0, tag.1);
        // Item and delimiter tags never carry a VR.
        if tag.0 == 0xFFFE || !explicit {
            let len = self.u32(&name)?;
            return Ok(Element {
                tag,
                vr: *b"UN",
                len: (len != u32::MAX).then_some(len as usize),
            });
        }
        let v = self.take(2, &name)?;
        let vr = [v[0], v[1]];
        let long = matches!(
            &vr,
            b"OB"
                | b"OD"
                | b"OF"
                | b"OL"
                | b"OV"
                | b"OW"
                | b"SQ"
                | b"SV"
                | b"UC"
                | b"UN"
                | b"UR"
                | b"UT"
                | b"UV"
        );
        let len = if long {
            self.take(2, &name)?;
            self.u32(&name)?
        } else {
            u32::from(self.u16(&name)?)
        };
        Ok(Element {
            tag,
            vr,
            len: (len != u32::MAX).then_some(len as usize),
        })
    }

    /// Skips the items of an undefined-length sequence up to its delimiter.
    fn skip_sequence(&mut self, explicit: bool, depth: u32) -> Result<(), VolumeError> {
        if depth > 16 {
            return Err(self.malformed("sequence", "nested more than 16 deep".into()));
        }
        loop {
            let e = self.element(false)?;
            match (e.tag, e.len) {
                (tag::SEQUENCE_END, _) => return Ok(()),
                (tag::ITEM, Some(len)) => {
                    self.take(len, "sequence item")?;
                }
                (tag::ITEM, None) => loop {
                    let inner = self.element(explicit)?;
                    if inner.tag == tag::ITEM_END {
                        break;
                    }
                    self.skip_value(&inner, explicit, depth + 1)?;
                },
                (t, _) => {
                    return Err(self.malformed(
                        "sequence",
                        format!("unexpected tag ({:04X},{:04X}) inside a sequence", t.0, t.1),
                    ))
                }
            }
        }
    }

    fn skip_value(&mut self, e: &Element, explicit: bool, depth: u32) -> Result<(), VolumeError> {
        match e.len {
            Some(len) => self.take(len, "element value").map(|_| ()),
            // An undefined-length UN holds an implicit-VR sequence.
            None => self.skip_sequence(explicit && &e.vr != b"UN", depth),
        }
    }
}

/// ImageOrientationPatient must hold two orthogonal unit vectors (the row and column
/// directions): the slice normal, and so the slice order, comes from them.
fn check_orientation(o: &[f64; 6]) -> Result<(), String> {
    let (r, c) = ([o[0], o[1], o[2]], [o[3], o[4], o[5]]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let unit = |v: [f64; 3]| (dot(v, v).sqrt() - 1.0).abs() < 0.01;
    if unit(r) && unit(c) && dot(r, c).abs() < 0.01 {
        Ok(())
    } else {
        Err(format!(
            "{o:?} is not two orthogonal unit vectors (row and column directions), so the \
             slice order cannot be derived from it"
        ))
    }
}

fn text(v: &[u8]) -> String {
    String::from_utf8_lossy(v)
        .trim_matches(|c: char| c == '\0' || c.is_whitespace())
        .to_string()
}

/// Parses one file down to its pixel data.
fn parse_file(path: &Path) -> Result<Slice, VolumeError> {
    let bytes = io::read_small(path, MAX_SLICE_FILE_BYTES, "a single-frame DICOM slice")?;
    let mut r = Reader {
        path,
        b: &bytes,
        pos: 0,
    };
    let mut explicit = false;
    if bytes.len() >= 132 && &bytes[128..132] == b"DICM" {
        // File meta information: always explicit VR little endian.
        r.pos = 132;
        let mut syntax = None;
        while r.b.get(r.pos..r.pos + 2) == Some(&[0x02, 0x00]) {
            let e = r.element(true)?;
            let len = e
                .len
                .ok_or_else(|| r.malformed("file meta", "undefined length in group 0002".into()))?;
            let v = r.take(len, "file meta")?;
            if e.tag == tag::TRANSFER_SYNTAX {
                syntax = Some(text(v));
            }
        }
        let syntax = syntax.ok_or_else(|| {
            r.malformed(
                "TransferSyntaxUID (0002,0010)",
                "missing from the file meta".into(),
            )
        })?;
        explicit = match syntax.as_str() {
            IMPLICIT_LE => false,
            EXPLICIT_LE => true,
            other => {
                let what = match other {
                    "1.2.840.10008.1.2.2" => "explicit VR big endian (retired)",
                    "1.2.840.10008.1.2.1.99" => "deflated",
                    _ => "compressed (JPEG, JPEG 2000, RLE...)",
                };
                return Err(VolumeError::Unsupported {
                    path: path.to_path_buf(),
                    reason: format!(
                        "DICOM transfer syntax {other}, {what}; only uncompressed little endian \
                         is read (convert with e.g. `gdcmconv --raw`)"
                    ),
                });
            }
        };
    }

    let mut s = Slice {
        file: path.to_path_buf(),
        rows: 0,
        cols: 0,
        bits_allocated: 0,
        bits_stored: 0,
        signed: false,
        pixel_spacing: None,
        thickness: None,
        spacing_between: None,
        position: None,
        orientation: None,
        instance: None,
        rescale: Affine::IDENTITY,
        series: None,
        pixels: Vec::new(),
    };
    let mut samples_per_pixel = 1;
    let mut frames = 1;
    let mut slope = None;
    let mut intercept = None;
    let mut found_pixels = false;
    while r.pos < r.b.len() {
        let e = r.element(explicit)?;
        let name = format!("({:04X},{:04X})", e.tag.0, e.tag.1);
        if e.tag == tag::PIXEL_DATA {
            let Some(len) = e.len else {
                return Err(VolumeError::Unsupported {
                    path: path.to_path_buf(),
                    reason: "encapsulated (compressed) pixel data".into(),
                });
            };
            let avail = r.b.len() - r.pos;
            s.pixels = r.b[r.pos..r.pos + len.min(avail)].to_vec();
            found_pixels = true;
            break;
        }
        let Some(len) = e.len else {
            r.skip_sequence(explicit && &e.vr != b"UN", 0)?;
            continue;
        };
        let v = r.take(len, &name)?;
        let us = |field: &str| -> Result<u16, VolumeError> {
            match v {
                [a, b, ..] => Ok(u16::from_le_bytes([*a, *b])),
                _ => Err(r.malformed(field, format!("{len}-byte value, expected 2"))),
            }
        };
        let numbers = |field: &str| -> Result<Vec<f64>, VolumeError> {
            let t = text(v);
            t.split('\\')
                .map(|p| p.trim().parse::<f64>())
                .collect::<Result<Vec<_>, _>>()
                .map_err(|_| r.malformed(field, format!("cannot parse `{t}` as numbers")))
        };
        let fixed = |field: &str, want: usize| -> Result<Vec<f64>, VolumeError> {
            let n = numbers(field)?;
            if n.len() == want {
                Ok(n)
            } else {
                Err(r.malformed(field, format!("{} values, expected {want}", n.len())))
            }
        };
        match e.tag {
            tag::ROWS => s.rows = us("Rows (0028,0010)")?,
            tag::COLUMNS => s.cols = us("Columns (0028,0011)")?,
            tag::BITS_ALLOCATED => s.bits_allocated = us("BitsAllocated (0028,0100)")?,
            tag::BITS_STORED => s.bits_stored = us("BitsStored (0028,0101)")?,
            tag::PIXEL_REPRESENTATION => s.signed = us("PixelRepresentation (0028,0103)")? == 1,
            tag::SAMPLES_PER_PIXEL => samples_per_pixel = us("SamplesPerPixel (0028,0002)")?,
            tag::NUMBER_OF_FRAMES => frames = fixed("NumberOfFrames (0028,0008)", 1)?[0] as i64,
            tag::PIXEL_SPACING => {
                let p = fixed("PixelSpacing (0028,0030)", 2)?;
                s.pixel_spacing = Some([p[0], p[1]]);
            }
            tag::SLICE_THICKNESS if len > 0 => {
                s.thickness = Some(fixed("SliceThickness (0018,0050)", 1)?[0]);
            }
            tag::SPACING_BETWEEN_SLICES if len > 0 => {
                s.spacing_between = Some(fixed("SpacingBetweenSlices (0018,0088)", 1)?[0]);
            }
            tag::POSITION => {
                let p = fixed("ImagePositionPatient (0020,0032)", 3)?;
                s.position = Some([p[0], p[1], p[2]]);
            }
            tag::ORIENTATION => {
                let field = "ImageOrientationPatient (0020,0037)";
                let o = fixed(field, 6)?;
                let o = [o[0], o[1], o[2], o[3], o[4], o[5]];
                check_orientation(&o).map_err(|problem| r.malformed(field, problem))?;
                s.orientation = Some(o);
            }
            tag::INSTANCE_NUMBER if len > 0 => {
                s.instance = Some(fixed("InstanceNumber (0020,0013)", 1)?[0] as i64);
            }
            tag::RESCALE_SLOPE => slope = Some(fixed("RescaleSlope (0028,1053)", 1)?[0]),
            tag::RESCALE_INTERCEPT => {
                intercept = Some(fixed("RescaleIntercept (0028,1052)", 1)?[0]);
            }
            tag::SERIES_UID => s.series = Some(text(v)),
            _ => {}
        }
    }

    if !found_pixels {
        return Err(r.malformed("PixelData (7FE0,0010)", "missing".into()));
    }
    for (field, value) in [
        ("Rows (0028,0010)", s.rows),
        ("Columns (0028,0011)", s.cols),
    ] {
        if value == 0 {
            return Err(r.malformed(field, "missing or zero".into()));
        }
    }
    if samples_per_pixel != 1 {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!("SamplesPerPixel {samples_per_pixel} (colour); only greyscale is read"),
        });
    }
    if frames != 1 {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "multi-frame DICOM ({frames} frames); only single-frame slices are read"
            ),
        });
    }
    if !matches!(s.bits_allocated, 8 | 16) || (s.bits_allocated == 8 && s.signed) {
        return Err(VolumeError::UnsupportedType {
            path: path.to_path_buf(),
            datatype: format!(
                "BitsAllocated {} with PixelRepresentation {}",
                s.bits_allocated,
                u8::from(s.signed)
            ),
            supported: "unsigned 8-bit, unsigned or signed 16-bit",
        });
    }
    if s.bits_stored == 0 || s.bits_stored > s.bits_allocated {
        s.bits_stored = s.bits_allocated;
    }
    let slope = slope.unwrap_or(1.0);
    if !slope.is_finite() || slope == 0.0 {
        return Err(r.malformed("RescaleSlope (0028,1053)", format!("{slope} is not usable")));
    }
    s.rescale = Affine {
        slope,
        intercept: intercept.filter(|i| i.is_finite()).unwrap_or(0.0),
    };

    // Pixel data may carry one pad byte (odd 8-bit images); more means wrong dims.
    let expected = u64::from(s.rows) * u64::from(s.cols) * u64::from(s.bits_allocated / 8);
    let found = s.pixels.len() as u64;
    if found < expected {
        return Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected,
            found,
        });
    }
    if found > expected + 1 {
        return Err(VolumeError::SizeMismatch {
            path: path.to_path_buf(),
            dims: [u32::from(s.cols), u32::from(s.rows), 1],
            format: if s.bits_allocated == 8 {
                "uint8"
            } else {
                "16-bit"
            },
            expected,
            found,
        });
    }
    s.pixels.truncate(expected as usize);
    Ok(s)
}

#[cfg(test)]
mod tests;
