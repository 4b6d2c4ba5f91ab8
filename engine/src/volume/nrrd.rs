//! NRRD volumes (<https://teem.sourceforge.net/nrrd/format.html>): `.nrrd` with the
//! data attached after the header, `.nhdr` with the data in a separate file.
//!
//! Hand-parsed: the header is a few `field: value` text lines, and the format features a
//! volume renderer needs are small. Read: encodings `raw` and `gzip`; types uint8,
//! uint16, int16 and float; `endian`; spacing from `space directions` (vector lengths) or
//! `spacings`; `byte skip` and `line skip`; 2D images (one slice) and 4D files whose extra
//! axis has size 1. Multi-file data (`data file: LIST` or a format pattern) and other
//! encodings are rejected with a message saying so.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use super::error::VolumeError;
use super::samples::{SampleKind, Samples, Stored};
use super::{io, name_of, validate_dims, validate_spacing, Volume};

const SUPPORTED_TYPES: &str = "uint8, uint16, int16, float";

/// A parsed header.
struct Header {
    fields: HashMap<String, String>,
    /// Offset of the first byte after the header's blank line, if there is one.
    data_offset: Option<usize>,
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

/// Loads a `.nrrd` or `.nhdr` file.
pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let file = io::read_all(path)?;
    let header = parse_header(path, &file)?;
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
    let axes = spatial_axes(path, &sizes)?;
    let dims = validate_dims(
        path,
        [0, 1, 2].map(|i| axes.get(i).map_or(1, |&a| sizes[a])),
    )?;
    let spacing = parse_spacing(path, &header.fields, dimension, &axes)?;

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

    // Where the (possibly compressed) data lives.
    let data_field = header
        .fields
        .get("data file")
        .or_else(|| header.fields.get("datafile"));
    let (data_path, data_file, start) = match data_field {
        Some(name) => {
            let name = name.trim();
            if name.starts_with("LIST") || name.contains(' ') || name.contains('%') {
                return Err(VolumeError::Unsupported {
                    path: path.to_path_buf(),
                    reason: format!("multi-file NRRD data (`data file: {name}`)"),
                });
            }
            let p = resolve(path, name);
            let bytes = io::read_all(&p)?;
            (p, bytes, 0)
        }
        None => {
            let offset = header.data_offset.ok_or_else(|| {
                malformed(
                    "data file",
                    "no data after the header and no `data file` field".into(),
                )
            })?;
            (path.to_path_buf(), file, offset)
        }
    };
    let start = skip_lines(&data_file, start, line_skip).ok_or_else(|| {
        malformed(
            "line skip",
            format!("the data has fewer than {line_skip} lines"),
        )
    })?;
    let region = &data_file[start..];
    let expected = io::expected_bytes(dims, kind);

    let encoding = field("encoding")?.trim().to_ascii_lowercase();
    let bytes = match encoding.as_str() {
        "raw" => {
            let skip = if byte_skip == -1 {
                // -1: the data is the last `expected` bytes of the file.
                (region.len() as u64).saturating_sub(expected)
            } else {
                byte_skip as u64
            };
            let skip = usize::try_from(skip)
                .unwrap_or(usize::MAX)
                .min(region.len());
            region[skip..].to_vec()
        }
        "gzip" | "gz" => {
            if byte_skip < 0 {
                return Err(malformed(
                    "byte skip",
                    "-1 is only allowed with raw encoding".into(),
                ));
            }
            io::gunzip_bounded(&data_path, region, byte_skip as u64, expected)?
        }
        other => {
            return Err(VolumeError::Unsupported {
                path: path.to_path_buf(),
                reason: format!("NRRD encoding `{other}`; supported: raw, gzip"),
            })
        }
    };
    io::check_len(&data_path, dims, kind, bytes.len() as u64)?;
    let stored = Stored::plain(Samples::decode(kind, bytes, big_endian));
    Volume::from_stored(path, name_of(path), dims, spacing, stored)
}

/// Splits the header into fields; `data_offset` is set when a blank line ends it.
fn parse_header(path: &Path, file: &[u8]) -> Result<Header, VolumeError> {
    let mut fields = HashMap::new();
    let mut pos = 0;
    let mut first = true;
    let mut data_offset = None;
    while pos < file.len() {
        let end = file[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(file.len(), |i| pos + i);
        let raw = &file[pos..end];
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        pos = (end + 1).min(file.len());
        let line = std::str::from_utf8(raw).map_err(|_| VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: "header".into(),
            problem: "header line is not text (missing blank line before the data?)".into(),
        })?;
        if first {
            if !line.starts_with("NRRD000") {
                return Err(VolumeError::MalformedHeader {
                    path: path.to_path_buf(),
                    field: "magic".into(),
                    problem: format!("file does not start with NRRD000x (found {line:.16?})"),
                });
            }
            first = false;
            continue;
        }
        if line.is_empty() {
            data_offset = Some(end + 1);
            break;
        }
        if line.starts_with('#') || line.contains(":=") {
            continue; // comment or key/value pair
        }
        let Some((key, value)) = line.split_once(':') else {
            return Err(VolumeError::MalformedHeader {
                path: path.to_path_buf(),
                field: line.to_string(),
                problem: "expected `field: value`".into(),
            });
        };
        fields.insert(key.trim().to_ascii_lowercase(), value.trim().to_string());
    }
    if first {
        return Err(VolumeError::MalformedHeader {
            path: path.to_path_buf(),
            field: "magic".into(),
            problem: "empty file".into(),
        });
    }
    Ok(Header {
        fields,
        data_offset: data_offset.filter(|&o| o <= file.len()),
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

/// The axes that become x, y, z: all of them for 2D/3D data; for 4D, the three left
/// when an axis of size 1 is dropped.
fn spatial_axes(path: &Path, sizes: &[i64]) -> Result<Vec<usize>, VolumeError> {
    match sizes.len() {
        1..=3 => Ok((0..sizes.len()).collect()),
        4 => match sizes.iter().position(|&s| s == 1) {
            Some(drop) => Ok((0..4).filter(|&a| a != drop).collect()),
            None => Err(VolumeError::Unsupported {
                path: path.to_path_buf(),
                reason: format!("4D NRRD with sizes {sizes:?}: only one scalar 3D volume is read"),
            }),
        },
        n => Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!("NRRD dimension {n}; 2, 3 or 4 (with a size-1 axis) are read"),
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
        v
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

/// Parses `(1,0,0) (0,1.5,0) none ...` into vector lengths (`None` for `none`).
fn parse_directions(s: &str) -> Option<Vec<Option<f64>>> {
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
        let len = comps.iter().map(|c| c * c).sum::<f64>().sqrt();
        out.push(Some(len));
        rest = r[close + 1..].trim_start();
    }
    Some(out)
}

/// Offset after skipping `lines` newline-terminated lines from `start`.
fn skip_lines(data: &[u8], mut start: usize, lines: usize) -> Option<usize> {
    for _ in 0..lines {
        let nl = data.get(start..)?.iter().position(|&b| b == b'\n')?;
        start += nl + 1;
    }
    Some(start)
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

#[cfg(test)]
mod tests;
