//! NIfTI-1 volumes (`.nii`, `.nii.gz`), the format of most MRI tools.
//!
//! The 348-byte header is parsed by hand instead of using the `nifti` crate: we need
//! about a dozen fixed-offset fields, while the crate pulls `ndarray`, `nalgebra` and
//! friends into every build of the engine. Read: single-file NIfTI-1 (`n+1`) in either
//! byte order, datatypes uint8, int16, uint16, float32 and float64 (held as float32), `pixdim` for spacing (with the
//! `xyzt_units` spatial unit converted to mm), `scl_slope/scl_inter` applied before
//! normalisation. 4D files are read only when the extra dimensions have size 1. The
//! orientation is the sform when `sform_code > 0`, else the qform (quaternion, offsets,
//! `qfac`) when `qform_code > 0`, else none (NIfTI's "method 1": the index axes are R,
//! A, S); the volume is put in RAS order by it (`orientation.rs`).

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use super::error::VolumeError;
use super::samples::{Affine, Rescale, SampleKind, Samples, Stored};
use super::{io, name_of, validate_dims, validate_spacing, PatientTransform, Volume};

/// Size of a NIfTI-1 header.
pub(crate) const HEADER_LEN: usize = 348;
const SUPPORTED_TYPES: &str = "uint8 (2), int16 (4), uint16 (512), float32 (16), float64 (64)";

/// The header fields the loader uses.
#[derive(Debug)]
struct Header {
    big_endian: bool,
    dims: [u32; 3],
    kind: SampleKind,
    spacing: [f32; 3],
    vox_offset: u64,
    rescale: Affine,
    orientation: Option<PatientTransform>,
}

/// Loads a `.nii` or `.nii.gz` file. The header is read and checked first; the data
/// after it is read only up to what the header's dims promise (one byte more, to tell a
/// too-long file), so a huge or endless file costs no more memory than its volume.
pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let (file, len) = io::open_regular(path)?;
    let io_err = |source| VolumeError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut reader = BufReader::new(file);
    let gz = reader
        .fill_buf()
        .map_err(io_err)?
        .starts_with(&[0x1f, 0x8b]);
    let (header, data) = if gz {
        let mut dec = io::GzMembers::new(reader);
        let mut head = vec![0u8; HEADER_LEN];
        dec.read_exact(&mut head).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => short_header(path),
            _ => VolumeError::Decompress {
                path: path.to_path_buf(),
                source: e,
            },
        })?;
        let header = parse_header(path, &head)?;
        let expected = io::expected_bytes(header.dims, header.kind);
        let skip = header.vox_offset - HEADER_LEN as u64;
        let past_end = |got: u64| offset_past_end(path, header.vox_offset, HEADER_LEN as u64 + got);
        let data = io::read_bounded(path, &mut dec, skip, expected, &past_end)?;
        if data.len() as u64 == expected {
            io::note_trailing_bytes(path, &dec);
        }
        (header, data)
    } else {
        let mut head = Vec::with_capacity(HEADER_LEN);
        (&mut reader)
            .take(HEADER_LEN as u64)
            .read_to_end(&mut head)
            .map_err(io_err)?;
        let header = parse_header(path, &head)?;
        if header.vox_offset >= len {
            return Err(offset_past_end(path, header.vox_offset, len));
        }
        // Check the size before reading, so a wrong header on a huge file fails fast.
        io::check_len(path, header.dims, header.kind, len - header.vox_offset)?;
        let expected = io::expected_bytes(header.dims, header.kind);
        let skip = header.vox_offset - HEADER_LEN as u64;
        let past_end = |got: u64| offset_past_end(path, header.vox_offset, HEADER_LEN as u64 + got);
        let data = io::read_bounded(path, reader, skip, expected, &past_end)?;
        (header, data)
    };
    io::check_len(path, header.dims, header.kind, data.len() as u64)?;
    let stored = Stored {
        samples: Samples::decode(header.kind, data, header.big_endian),
        type_range: header.kind.full_range(),
        rescale: Rescale::Uniform(header.rescale),
        orientation: header.orientation,
    };
    Volume::from_stored(path, name_of(path), header.dims, header.spacing, stored)
}

/// `vox_offset` at or past the end of the (decompressed) file of `len` bytes.
fn offset_past_end(path: &Path, vox_offset: u64, len: u64) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: "vox_offset".into(),
        problem: format!(
            "the voxel data would start at byte {vox_offset}, but the file ends at byte {len}"
        ),
    }
}

fn short_header(path: &Path) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: "sizeof_hdr".into(),
        problem: format!("file is shorter than the {HEADER_LEN}-byte NIfTI-1 header"),
    }
}

/// Little helper reading fixed-offset fields in the header's byte order.
struct Fields<'a> {
    h: &'a [u8],
    big: bool,
}

impl Fields<'_> {
    fn bytes<const N: usize>(&self, at: usize) -> [u8; N] {
        let mut b = [0u8; N];
        b.copy_from_slice(&self.h[at..at + N]);
        if self.big {
            b.reverse();
        }
        b
    }
    fn i16(&self, at: usize) -> i16 {
        i16::from_le_bytes(self.bytes(at))
    }
    fn f32(&self, at: usize) -> f32 {
        f32::from_le_bytes(self.bytes(at))
    }
}

fn parse_header(path: &Path, h: &[u8]) -> Result<Header, VolumeError> {
    let malformed = |field: &str, problem: String| VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: field.to_string(),
        problem,
    };
    if h.len() < HEADER_LEN {
        return Err(short_header(path));
    }
    let le = i32::from_le_bytes([h[0], h[1], h[2], h[3]]);
    let be = i32::from_be_bytes([h[0], h[1], h[2], h[3]]);
    let big = match (le, be) {
        (348, _) => false,
        (_, 348) => true,
        (540, _) | (_, 540) => {
            return Err(VolumeError::Unsupported {
                path: path.to_path_buf(),
                reason: "NIfTI-2 files; save as NIfTI-1".into(),
            })
        }
        _ => return Err(malformed("sizeof_hdr", format!("{le} (expected 348)"))),
    };
    let f = Fields { h, big };
    match &h[344..348] {
        b"n+1\0" => {}
        b"ni1\0" => {
            return Err(VolumeError::Unsupported {
                path: path.to_path_buf(),
                reason: "NIfTI-1 header/image pairs (.hdr/.img); save as a single .nii".into(),
            })
        }
        m => return Err(malformed("magic", format!("{m:?} (expected \"n+1\\0\")"))),
    }

    // dim[0] is the number of dimensions, dim[1..=3] the spatial ones.
    let dim: Vec<i64> = (0..8).map(|i| i64::from(f.i16(40 + 2 * i))).collect();
    let ndim = dim[0];
    if !(1..=7).contains(&ndim) {
        return Err(malformed(
            "dim[0]",
            format!("{ndim} dimensions (expected 1..7)"),
        ));
    }
    let ndim = ndim as usize;
    if let Some(extra) = (4..=ndim).find(|&i| dim[i] != 1) {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "{ndim}D NIfTI with dim[{extra}] = {}; only one 3D volume is read",
                dim[extra]
            ),
        });
    }
    let dims = validate_dims(path, [1, 2, 3].map(|i| if i <= ndim { dim[i] } else { 1 }))?;

    let datatype = f.i16(70);
    let bitpix = f.i16(72);
    let kind = match datatype {
        2 => SampleKind::U8,
        4 => SampleKind::I16,
        512 => SampleKind::U16,
        16 => SampleKind::F32,
        64 => SampleKind::F64,
        other => {
            return Err(VolumeError::UnsupportedType {
                path: path.to_path_buf(),
                datatype: format!("{} ({other})", datatype_name(other)),
                supported: SUPPORTED_TYPES,
            })
        }
    };
    if bitpix as usize != 8 * kind.bytes() {
        return Err(malformed(
            "bitpix",
            format!("{bitpix} does not match datatype {}", kind.name()),
        ));
    }

    // Spatial units (xyzt_units & 7): 1 = m, 2 = mm, 3 = µm, 0 = unknown (taken as mm).
    let to_mm = match h[123] & 0x07 {
        1 => 1000.0,
        3 => 0.001,
        _ => 1.0,
    };
    let pixdim = [1, 2, 3].map(|i| {
        if i <= ndim {
            f64::from(f.f32(76 + 4 * i)).abs() * to_mm
        } else {
            1.0
        }
    });
    let spacing = validate_spacing(path, "pixdim", pixdim)?;

    let vox_offset = f.f32(108);
    if !vox_offset.is_finite() || vox_offset < HEADER_LEN as f32 {
        return Err(malformed(
            "vox_offset",
            format!("{vox_offset} (must be at least {HEADER_LEN})"),
        ));
    }
    // NIfTI-1: a zero or non-finite slope means "no scaling".
    let slope = f.f32(112);
    let inter = f.f32(116);
    let rescale = if slope.is_finite() && slope != 0.0 {
        Affine {
            slope: f64::from(slope),
            intercept: if inter.is_finite() {
                f64::from(inter)
            } else {
                0.0
            },
        }
    } else {
        Affine::IDENTITY
    };
    let orientation = orientation(&f, ndim, to_mm).map_err(|(field, p)| malformed(field, p))?;
    Ok(Header {
        big_endian: big,
        dims,
        kind,
        spacing,
        vox_offset: vox_offset as u64,
        rescale,
        orientation,
    })
}

/// The index-to-patient transform the header states (sform before qform), in mm;
/// `None` when neither code is set. An error names the field that is unusable.
fn orientation(
    f: &Fields<'_>,
    ndim: usize,
    to_mm: f64,
) -> Result<Option<PatientTransform>, (&'static str, String)> {
    let qform_code = f.i16(252);
    let sform_code = f.i16(254);
    let mm = |x: f32| f64::from(x) * to_mm;
    let t = if sform_code > 0 {
        let row = |at: usize| [0, 1, 2, 3].map(|i| mm(f.f32(at + 4 * i)));
        (
            "srow_x/srow_y/srow_z (sform)",
            PatientTransform::from_rows([row(280), row(296), row(312)]),
        )
    } else if qform_code > 0 {
        let [b, c, d] = [256, 260, 264].map(|at| f64::from(f.f32(at)));
        let a = (1.0 - (b * b + c * c + d * d)).max(0.0).sqrt();
        let r = [
            [
                a * a + b * b - c * c - d * d,
                2.0 * (b * c - a * d),
                2.0 * (b * d + a * c),
            ],
            [
                2.0 * (b * c + a * d),
                a * a + c * c - b * b - d * d,
                2.0 * (c * d - a * b),
            ],
            [
                2.0 * (b * d - a * c),
                2.0 * (c * d + a * b),
                a * a + d * d - b * b - c * c,
            ],
        ];
        let qfac = if f.f32(76) < 0.0 { -1.0 } else { 1.0 };
        // pixdim of an axis past dim[0] is meaningless: a 2D file's slice is 1 mm.
        let pix = [1, 2, 3].map(|i| {
            if i <= ndim {
                mm(f.f32(76 + 4 * i)).abs()
            } else {
                1.0
            }
        });
        let scale = [pix[0], pix[1], pix[2] * qfac];
        let axes = [0, 1, 2].map(|col| [0, 1, 2].map(|row| r[row][col] * scale[col]));
        let origin = [268, 272, 276].map(|at| mm(f.f32(at)));
        (
            "quatern_b/c/d, qoffset (qform)",
            PatientTransform { axes, origin },
        )
    } else {
        return Ok(None);
    };
    t.1.check().map_err(|p| (t.0, p))?;
    Ok(Some(t.1))
}

fn datatype_name(code: i16) -> &'static str {
    match code {
        1 => "binary",
        8 => "int32",
        32 => "complex64",
        64 => "float64",
        128 => "rgb24",
        256 => "int8",
        768 => "uint32",
        1024 => "int64",
        1280 => "uint64",
        1536 => "float128",
        1792 => "complex128",
        2304 => "rgba32",
        _ => "unknown datatype",
    }
}

#[cfg(test)]
mod tests;
