//! NRRD volumes (<https://teem.sourceforge.net/nrrd/format.html>): `.nrrd` with the
//! data attached after the header, `.nhdr` with the data in a separate file.
//!
//! Hand-parsed: the header is a few `field: value` text lines, and the format features a
//! volume renderer needs are small. Read: encodings `raw` and `gzip`; types uint8,
//! uint16, int16 and float; `endian`; spacing from `space directions` (vector lengths) or
//! `spacings`; the orientation from `space`, `space directions` and `space origin` (LPS
//! and LAS converted to RAS); `byte skip` and `line skip`; 2D images (one slice) and 4D files whose extra
//! axis has size 1. Multi-file data (`data file: LIST` or a format pattern) and other
//! encodings are rejected with a message saying so.

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::error::VolumeError;
use super::samples::{SampleKind, Samples, Stored};
use super::series::{channel_list, Source, SourceInfo, Window, Windowed};
use super::{io, name_of, validate_dims, validate_spacing, PatientTransform, Volume};
use axes::{classify_axes, gather, Axes};

const SUPPORTED_TYPES: &str = "uint8, uint16, int16, float";

/// Longest header read before giving up: real headers are a few hundred bytes.
const MAX_HEADER_BYTES: u64 = 1 << 20;

/// A parsed header.
struct Header {
    fields: HashMap<String, String>,
    /// Offset of the first byte after the header's blank line, if there is one.
    data_offset: Option<u64>,
}

impl Header {
    /// A field that must be present.
    fn required(&self, path: &Path, name: &str) -> Result<&str, VolumeError> {
        self.fields
            .get(name)
            .map(String::as_str)
            .ok_or_else(|| VolumeError::MalformedHeader {
                path: path.to_path_buf(),
                field: name.to_string(),
                problem: "required field missing".into(),
            })
    }
}

/// Loads a `.nrrd` or `.nhdr` file of one 3D volume (a series' one channel at its one
/// time point).
pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let nrrd = open(path)?;
    if nrrd.channels * nrrd.times > 1 {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "{}D NRRD with sizes {:?}: one scalar 3D volume is read here: open it as a \
                 series of channels and time points (`dvr info`)",
                nrrd.sizes.len(),
                nrrd.sizes
            ),
        });
    }
    nrrd.volume(0, 0, None).map(|(v, _)| v)
}

/// Opens a NRRD file as a series (see `series.rs` for which axes are channels and time).
pub(crate) fn open_series(path: &Path) -> Result<Box<dyn Source>, VolumeError> {
    let nrrd = open(path)?;
    let info = SourceInfo {
        path: path.to_path_buf(),
        name: name_of(path),
        dims: nrrd.dims,
        orientation: nrrd.orientation,
        channels: channel_list(path, nrrd.channels as u64, Vec::new())?,
        times: nrrd.times,
    };
    Ok(Box::new(NrrdSeries { info, nrrd }))
}

struct NrrdSeries {
    info: SourceInfo,
    nrrd: Nrrd,
}

impl Source for NrrdSeries {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed {
        self.nrrd.volume(channel, time, window)
    }
}

/// A checked header: where the data is and how its axes run. Nothing of the data is
/// read until [`Nrrd::volume`].
struct Nrrd {
    path: PathBuf,
    data_path: PathBuf,
    /// Byte offset of the data (after the header of an attached file).
    data_start: u64,
    /// Bytes from `data_start` to the end of the data file.
    data_len: u64,
    line_skip: usize,
    byte_skip: i64,
    encoding: String,
    kind: SampleKind,
    big_endian: bool,
    sizes: Vec<i64>,
    /// The axes that are x, y, z, then the channel and time axes, if any.
    axes: Axes,
    dims: [u32; 3],
    spacing: [f32; 3],
    orientation: Option<PatientTransform>,
    channels: usize,
    times: usize,
}

/// Opens and checks a NRRD header.
fn open(path: &Path) -> Result<Nrrd, VolumeError> {
    let (file, file_len) = io::open_regular(path)?;
    let mut reader = BufReader::new(file);
    let header = parse_header(path, &mut reader)?;
    let malformed = |field: &str, problem: String| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.to_string(),
        problem,
    };
    let field = |name: &str| header.required(path, name);

    let kind = parse_type(path, field("type")?)?;
    let dimension: usize = field("dimension")?
        .trim()
        .parse()
        .map_err(|_| malformed("dimension", "not an integer".into()))?;
    let sizes: Vec<i64> = field("sizes")?
        .split_whitespace()
        .map(|s| s.parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| malformed("sizes", "not a list of integers".into()))?;
    if sizes.len() != dimension {
        return Err(malformed(
            "sizes",
            format!("{} sizes for dimension {dimension}", sizes.len()),
        ));
    }
    let roles = classify_axes(path, &header.fields, &sizes)?;
    let axes = roles.spatial.clone();
    let dims = validate_dims(
        path,
        [0, 1, 2].map(|i| axes.get(i).map_or(1, |&a| sizes[a])),
    )?;
    let spacing = parse_spacing(path, &header.fields, dimension, &axes)?;
    let size_of = |a: Option<usize>| a.map_or(Ok(1), |a| usize::try_from(sizes[a]));
    let (channels, times) = match (size_of(roles.channel), size_of(roles.time)) {
        (Ok(c), Ok(t)) if c >= 1 && t >= 1 => (c, t),
        _ => {
            return Err(malformed(
                "sizes",
                format!("{sizes:?}: the channel or time (T) axis is empty"),
            ))
        }
    };
    // Every byte offset below is within this product; a header whose sizes overflow it
    // describes more data than any file holds.
    sizes
        .iter()
        .try_fold(kind.bytes() as u64, |a, &n| a.checked_mul(n as u64))
        .ok_or_else(|| malformed("sizes", format!("{sizes:?}: more data than a file holds")))?;

    let big_endian = match header.fields.get("endian").map(|s| s.trim()) {
        Some("little") => false,
        Some("big") => true,
        None if kind.bytes() == 1 => false,
        None => {
            return Err(malformed(
                "endian",
                format!("required for {} data", kind.name()),
            ))
        }
        Some(other) => return Err(malformed("endian", format!("`{other}` is not little/big"))),
    };
    let byte_skip: i64 = match header.fields.get("byte skip") {
        Some(s) => s
            .trim()
            .parse()
            .ok()
            .filter(|&b| b >= -1)
            .ok_or_else(|| malformed("byte skip", format!("`{s}` is not an integer >= -1")))?,
        None => 0,
    };
    let line_skip: usize = match header.fields.get("line skip") {
        Some(s) => s
            .trim()
            .parse()
            .map_err(|_| malformed("line skip", format!("`{s}` is not an integer >= 0")))?,
        None => 0,
    };

    // Where the (possibly compressed) data lives: a detached file, or this file after
    // the header's blank line. Nothing is read yet.
    let data_field = header
        .fields
        .get("data file")
        .or_else(|| header.fields.get("datafile"));
    let (data_path, data_start, data_len): (PathBuf, u64, u64) = match data_field {
        Some(name) => {
            let name = name.trim();
            if name.starts_with("LIST") || name.contains(' ') || name.contains('%') {
                return Err(VolumeError::Unsupported {
                    path: path.to_path_buf(),
                    reason: format!("multi-file NRRD data (`data file: {name}`)"),
                });
            }
            if name.is_empty() {
                return Err(malformed("data file", "is empty".into()));
            }
            let p = resolve(path, name);
            let (_, len) = io::open_regular(&p).map_err(|e| match e {
                // Name the header too: it is what the user points at.
                VolumeError::NotAFile { what, .. } => malformed(
                    "data file",
                    format!("{} is {what}, not a file of voxel data", p.display()),
                ),
                other => other,
            })?;
            (p, 0, len)
        }
        None if is_detached_header(path) => {
            return Err(malformed(
                "data file",
                "missing: a detached header (.nhdr) names the file holding the voxel data \
                 with `data file: NAME`"
                    .into(),
            ))
        }
        None => {
            let offset = header.data_offset.ok_or_else(|| {
                malformed(
                    "data file",
                    "no blank line ends the header, so no data follows it, and there is no \
                     `data file` field"
                        .into(),
                )
            })?;
            (path.to_path_buf(), offset, file_len.saturating_sub(offset))
        }
    };
    let encoding = field("encoding")?.trim().to_ascii_lowercase();
    if !["raw", "gzip", "gz"].contains(&encoding.as_str()) {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!("NRRD encoding `{encoding}`; supported: raw, gzip"),
        });
    }
    let orientation = patient_transform(&header.fields, &axes, spacing)
        .map_err(|(field, problem)| malformed(field, problem))?;
    Ok(Nrrd {
        path: path.to_path_buf(),
        data_path,
        data_start,
        data_len,
        line_skip,
        byte_skip,
        encoding,
        kind,
        big_endian,
        sizes,
        axes: roles,
        dims,
        spacing,
        orientation,
        channels,
        times,
    })
}

impl Nrrd {
    /// Channel `channel` at time point `time`, normalised through `window` where given.
    fn volume(
        &self,
        channel: usize,
        time: usize,
        window: Option<(f64, f64)>,
    ) -> Result<(Volume, (f64, f64)), VolumeError> {
        let path = self.path.as_path();
        let bytes = self.read(channel, time)?;
        let mut stored = Stored::plain(Samples::decode(self.kind, bytes, self.big_endian));
        stored.orientation = self.orientation;
        Volume::from_stored_in(path, name_of(path), self.dims, self.spacing, stored, window)
    }

    /// The bytes of one channel at one time point, x fastest: the span of the data from
    /// its first voxel to its last is read (one time point's worth when channels are
    /// interleaved), then gathered.
    fn read(&self, channel: usize, time: usize) -> Result<Vec<u8>, VolumeError> {
        let path = self.path.as_path();
        let malformed = |field: &str, problem: String| VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: field.to_string(),
            problem,
        };
        let (kind, dims, byte_skip, line_skip) =
            (self.kind, self.dims, self.byte_skip, self.line_skip);
        let data_path = &self.data_path;
        // Element strides of every axis (axis 0 fastest).
        let mut stride = Vec::with_capacity(self.sizes.len());
        let mut n = 1u64;
        for &s in &self.sizes {
            stride.push(n);
            n *= s as u64;
        }
        let total_elements = n;
        let b = kind.bytes() as u64;
        let st = |a: Option<usize>| a.map_or(0, |a| stride[a]);
        let base = channel as u64 * st(self.axes.channel) + time as u64 * st(self.axes.time);
        let sp: Vec<u64> = (0..3)
            .map(|i| st(self.axes.spatial.get(i).copied()))
            .collect();
        let span = 1
            + (0..3)
                .map(|i| (u64::from(dims[i]) - 1) * sp[i])
                .sum::<u64>();
        let last = base + span == total_elements;
        let (file, _) = io::open_regular(data_path)?;
        let mut file = BufReader::new(file);
        file.seek(SeekFrom::Start(self.data_start))
            .map_err(|source| VolumeError::Io {
                path: data_path.clone(),
                source,
            })?;
        let mut data = file;
        let mut skipped_lines: u64 = 0;
        for _ in 0..line_skip {
            let mut line = Vec::new();
            let n = (&mut data)
                .take(MAX_HEADER_BYTES)
                .read_until(b'\n', &mut line)
                .map_err(|source| VolumeError::Io {
                    path: data_path.clone(),
                    source,
                })?;
            if n == 0 || line.last() != Some(&b'\n') {
                return Err(malformed(
                    "line skip",
                    format!("the data has fewer than {line_skip} lines"),
                ));
            }
            skipped_lines += n as u64;
        }
        let region_len = self.data_len.saturating_sub(skipped_lines);
        let expected = total_elements * b;
        let skip_past_end = |got: u64| {
            malformed(
                "byte skip",
                format!("skips {byte_skip} bytes, but the data has only {got}"),
            )
        };

        let bytes = match self.encoding.as_str() {
            "raw" => {
                let skip = if byte_skip == -1 {
                    // -1: the data is the last `expected` bytes of the file.
                    region_len.saturating_sub(expected)
                } else {
                    byte_skip as u64
                };
                if skip > region_len {
                    return Err(skip_past_end(region_len));
                }
                // Check the size before reading, so wrong dims on a huge file fail fast.
                check_total(data_path, dims, kind, expected, region_len - skip)?;
                // The length is checked: seek to the span rather than read up to it, so
                // a late time point costs no more than the first.
                let at = self.data_start + skipped_lines + skip + base * b;
                data.seek(SeekFrom::Start(at))
                    .map_err(|source| VolumeError::Io {
                        path: data_path.clone(),
                        source,
                    })?;
                io::read_bounded(data_path, data, 0, span * b, &skip_past_end)?
            }
            "gzip" | "gz" => {
                if byte_skip < 0 {
                    return Err(malformed(
                        "byte skip",
                        "-1 is only allowed with raw encoding".into(),
                    ));
                }
                let mut gz = io::GzMembers::new(data);
                let mut bytes = io::read_bounded(
                    data_path,
                    &mut gz,
                    byte_skip as u64 + base * b,
                    span * b,
                    &skip_past_end,
                )?;
                if last && bytes.len() as u64 == span * b {
                    io::note_trailing_bytes(data_path, &gz);
                }
                if !last {
                    // The byte past the span is the next one's.
                    bytes.truncate((span * b) as usize);
                }
                bytes
            }
            other => {
                return Err(VolumeError::Unsupported {
                    path: path.to_path_buf(),
                    reason: format!("NRRD encoding `{other}`; supported: raw, gzip"),
                })
            }
        };
        let mut bytes = bytes;
        if self.encoding == "raw" {
            bytes.truncate((span * b) as usize);
        }
        if (bytes.len() as u64) < span * b {
            return Err(VolumeError::Truncated {
                path: data_path.clone(),
                expected,
                found: base * b + bytes.len() as u64,
            });
        }
        if bytes.len() as u64 > span * b {
            return Err(check_total(
                data_path,
                dims,
                kind,
                expected,
                base * b + bytes.len() as u64,
            )
            .err()
            .unwrap_or(VolumeError::Truncated {
                path: data_path.clone(),
                expected,
                found: bytes.len() as u64,
            }));
        }
        Ok(gather(bytes, b as usize, dims, [sp[0], sp[1], sp[2]]))
    }
}

/// `Truncated` or `SizeMismatch` when `found` bytes are not the `expected` of every
/// channel and time point.
fn check_total(
    path: &Path,
    dims: [u32; 3],
    kind: SampleKind,
    expected: u64,
    found: u64,
) -> Result<(), VolumeError> {
    if expected == io::expected_bytes(dims, kind) {
        return io::check_len(path, dims, kind, found);
    }
    if found < expected {
        Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected,
            found,
        })
    } else if found > expected {
        Err(VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: "sizes".into(),
            problem: format!(
                "the sizes need {expected} bytes of {} data, but the file holds {found}",
                kind.name()
            ),
        })
    } else {
        Ok(())
    }
}

/// True for a `.nhdr` file, which by definition keeps its data in another file.
fn is_detached_header(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nhdr"))
}

/// Reads the header's lines into fields, leaving `reader` at the first byte after the
/// blank line that ends it (`data_offset`), or at the end of a file without one. Reads
/// at most [`MAX_HEADER_BYTES`].
fn parse_header(path: &Path, reader: &mut impl BufRead) -> Result<Header, VolumeError> {
    let malformed = |field: &str, problem: String| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.to_string(),
        problem,
    };
    let mut fields = HashMap::new();
    let mut pos: u64 = 0;
    let mut first = true;
    let mut data_offset = None;
    let mut raw = Vec::new();
    loop {
        raw.clear();
        let room = MAX_HEADER_BYTES.saturating_sub(pos);
        let n = reader
            .take(room)
            .read_until(b'\n', &mut raw)
            .map_err(|source| VolumeError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        if n == 0 {
            if pos >= MAX_HEADER_BYTES {
                return Err(malformed(
                    "header",
                    format!(
                        "no blank line ends the header within its first {MAX_HEADER_BYTES} bytes"
                    ),
                ));
            }
            break;
        }
        pos += n as u64;
        let line = raw.strip_suffix(b"\n").unwrap_or(&raw);
        let line = line.strip_suffix(b"\r").unwrap_or(line);
        let line = std::str::from_utf8(line).map_err(|_| {
            malformed(
                "header",
                "header line is not text (missing blank line before the data?)".into(),
            )
        })?;
        if first {
            if !line.starts_with("NRRD000") {
                return Err(malformed(
                    "magic",
                    format!("file does not start with NRRD000x (found {line:.16?})"),
                ));
            }
            first = false;
            continue;
        }
        if line.is_empty() {
            data_offset = Some(pos);
            break;
        }
        if line.starts_with('#') || line.contains(":=") {
            continue; // comment or key/value pair
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(malformed(line, "expected `field: value`".into()));
        };
        fields.insert(key.trim().to_ascii_lowercase(), value.trim().to_string());
    }
    if first {
        return Err(malformed("magic", "empty file".into()));
    }
    Ok(Header {
        fields,
        data_offset,
    })
}

fn parse_type(path: &Path, t: &str) -> Result<SampleKind, VolumeError> {
    match t.trim() {
        "uchar" | "unsigned char" | "uint8" | "uint8_t" => Ok(SampleKind::U8),
        "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
            Ok(SampleKind::I16)
        }
        "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
            Ok(SampleKind::U16)
        }
        "float" => Ok(SampleKind::F32),
        other => Err(VolumeError::UnsupportedType {
            path: path.to_path_buf(),
            datatype: other.to_string(),
            supported: SUPPORTED_TYPES,
        }),
    }
}

/// Spacing of the spatial axes from `space directions` or `spacings` (1 mm when
/// neither is present or an axis has `none`/`nan`).
fn parse_spacing(
    path: &Path,
    fields: &HashMap<String, String>,
    dimension: usize,
    axes: &[usize],
) -> Result<[f32; 3], VolumeError> {
    let malformed = |field: &str, problem: String| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.to_string(),
        problem,
    };
    let per_axis: Vec<Option<f64>> = if let Some(dirs) = fields.get("space directions") {
        let v = parse_directions(dirs)
            .ok_or_else(|| malformed("space directions", format!("cannot parse `{dirs}`")))?;
        if v.len() != dimension {
            return Err(malformed(
                "space directions",
                format!("{} entries for dimension {dimension}", v.len()),
            ));
        }
        check_axes(path, axes, &v).map_err(|p| malformed("space directions", p))?;
        v.iter().map(|d| d.as_ref().map(|d| norm(d))).collect()
    } else if let Some(sp) = fields.get("spacings") {
        let v: Vec<Option<f64>> = sp
            .split_whitespace()
            .map(|s| match s.to_ascii_lowercase().as_str() {
                "nan" => Ok(None),
                _ => s.parse::<f64>().map(|x| Some(x.abs())),
            })
            .collect::<Result<_, _>>()
            .map_err(|_| malformed("spacings", format!("cannot parse `{sp}`")))?;
        if v.len() != dimension {
            return Err(malformed(
                "spacings",
                format!("{} entries for dimension {dimension}", v.len()),
            ));
        }
        v
    } else {
        vec![None; dimension]
    };
    let field = if fields.contains_key("space directions") {
        "space directions"
    } else {
        "spacings"
    };
    let spacing = [0, 1, 2].map(|i| {
        axes.get(i)
            .and_then(|&a| per_axis.get(a).copied().flatten())
            .unwrap_or(1.0)
    });
    validate_spacing(path, field, spacing)
}

/// The index-to-patient transform from `space`, `space directions` and `space origin`,
/// in RAS. `None` without `space` or `space directions` (the index axes are then taken
/// as R, A, S). Spaces other than the anatomical ones (`scanner-xyz`, `3D-right-handed`
/// …) are taken as RAS with a note.
fn patient_transform(
    fields: &HashMap<String, String>,
    axes: &[usize],
    spacing: [f32; 3],
) -> Result<Option<PatientTransform>, (&'static str, String)> {
    let (Some(space), Some(dirs)) = (fields.get("space"), fields.get("space directions")) else {
        return Ok(None);
    };
    // The sign each anatomical space's x and y take in RAS.
    let sign = match space.trim().to_ascii_lowercase().as_str() {
        "right-anterior-superior" | "ras" => [1.0, 1.0, 1.0],
        "left-anterior-superior" | "las" => [-1.0, 1.0, 1.0],
        "left-posterior-superior" | "lps" => [-1.0, -1.0, 1.0],
        other => {
            log::info!("NRRD space `{other}` is not anatomical: its axes are taken as R, A, S");
            [1.0, 1.0, 1.0]
        }
    };
    let v = parse_directions(dirs).ok_or(("space directions", format!("cannot parse `{dirs}`")))?;
    let to_ras = |d: &[f64]| -> Option<[f64; 3]> {
        (d.len() == 3).then(|| [d[0] * sign[0], d[1] * sign[1], d[2] * sign[2]])
    };
    let mut out = [[0.0; 3]; 3];
    for i in 0..3 {
        let dir = axes
            .get(i)
            .and_then(|&a| v.get(a))
            .and_then(|d| d.as_deref());
        out[i] = match dir.map(to_ras) {
            Some(Some(d)) => d,
            Some(None) => {
                return Err((
                    "space directions",
                    "an orientation needs 3-component vectors".to_string(),
                ))
            }
            // A 2D image's missing third axis: the normal of the other two, 1 voxel deep.
            None => {
                let (a, b) = (out[0], out[1]);
                let n = [
                    a[1] * b[2] - a[2] * b[1],
                    a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0],
                ];
                let len = norm(&n).max(f64::MIN_POSITIVE);
                n.map(|c| c / len * f64::from(spacing[i]))
            }
        };
    }
    let origin = match fields.get("space origin") {
        Some(o) => {
            let parsed = parse_directions(o)
                .and_then(|v| v.into_iter().next().flatten())
                .and_then(|d| to_ras(&d))
                .ok_or(("space origin", format!("cannot parse `{o}` as (x,y,z)")))?;
            parsed
        }
        None => [0.0; 3],
    };
    let t = PatientTransform { axes: out, origin };
    t.check().map_err(|p| ("space directions", p))?;
    Ok(Some(t))
}

/// Parses `(1,0,0) (0,1.5,0) none ...` into vectors (`None` for `none`).
fn parse_directions(s: &str) -> Option<Vec<Option<Vec<f64>>>> {
    let mut out = Vec::new();
    let mut rest = s.trim();
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("none") {
            out.push(None);
            rest = r.trim_start();
            continue;
        }
        let r = rest.strip_prefix('(')?;
        let close = r.find(')')?;
        let comps: Vec<f64> = r[..close]
            .split(',')
            .map(|c| c.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .ok()?;
        out.push(Some(comps));
        rest = r[close + 1..].trim_start();
    }
    Some(out)
}

fn norm(v: &[f64]) -> f64 {
    v.iter().map(|c| c * c).sum::<f64>().sqrt()
}

/// |cos| of the angle between two spatial axes beyond which they are one direction:
/// the grid has no extent along a third of its dimensions.
const COLLINEAR_COS: f64 = 0.999;
/// |cos| beyond which axes count as oblique (DICOM's orientation check uses the same).
const OBLIQUE_COS: f64 = 0.01;

/// The spatial axes' directions must span space: collinear (or zero) ones are an
/// error. dvr renders the grid as rectangular, so oblique (sheared, e.g. a tilted
/// gantry) axes are rendered without their shear: a warning says by how much.
fn check_axes(path: &Path, axes: &[usize], dirs: &[Option<Vec<f64>>]) -> Result<(), String> {
    let spatial: Vec<(usize, &Vec<f64>)> = axes
        .iter()
        .filter_map(|&a| dirs.get(a).and_then(|d| d.as_ref()).map(|d| (a, d)))
        .collect();
    for (i, &(a, da)) in spatial.iter().enumerate() {
        if norm(da).is_nan() || norm(da) <= 0.0 {
            return Err(format!("axis {a}'s direction {da:?} has no length"));
        }
        for &(b, db) in &spatial[i + 1..] {
            if da.len() != db.len() {
                return Err(format!(
                    "axes {a} and {b} have vectors of {} and {} components",
                    da.len(),
                    db.len()
                ));
            }
            let dot: f64 = da.iter().zip(db).map(|(x, y)| x * y).sum();
            let cos = (dot / (norm(da) * norm(db))).abs();
            if cos.is_nan() || cos >= COLLINEAR_COS {
                return Err(format!(
                    "axes {a} and {b} point the same way ({da:?}, {db:?}): the directions \
                     must span three dimensions"
                ));
            }
            if cos > OBLIQUE_COS {
                log::warn!(
                    "{}: space directions of axes {a} and {b} are {:.1}° from orthogonal \
                     (a sheared grid); dvr renders the voxels on a rectangular grid",
                    path.display(),
                    90.0 - cos.acos().to_degrees()
                );
            }
        }
    }
    Ok(())
}

/// A detached data file name, relative to the header's folder unless absolute.
fn resolve(header: &Path, name: &str) -> PathBuf {
    let p = Path::new(name);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        header.parent().unwrap_or(Path::new(".")).join(p)
    }
}

mod axes;
#[cfg(test)]
mod tests;
