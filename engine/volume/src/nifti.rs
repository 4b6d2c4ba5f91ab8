//! NIfTI-1 volumes (`.nii`, `.nii.gz`), the format of most MRI tools.
//!
//! The 348-byte header is parsed by hand instead of using the `nifti` crate: we need
//! about a dozen fixed-offset fields, while the crate pulls `ndarray`, `nalgebra` and
//! friends into every build of the engine. Read: single-file NIfTI-1 (`n+1`) in either
//! byte order, datatypes uint8, int16, uint16, float32 and float64 (held as float32), `pixdim` for spacing (with the
//! `xyzt_units` spatial unit converted to mm), `scl_slope/scl_inter` applied before
//! normalisation. `dim[4]` time points and `dim[5]` channels are read as a series
//! (`series.rs`: one 3D volume at a time, sought in the file); `Volume::load` reads
//! files of one 3D volume. The
//! orientation is the sform when `sform_code > 0`, else the qform (quaternion, offsets,
//! `qfac`) when `qform_code > 0`, else none (NIfTI's "method 1": the index axes are R,
//! A, S); the volume is put in RAS order by it (`orientation.rs`).

use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

use super::error::VolumeError;
use super::samples::{Affine, Rescale, SampleKind, Samples, Stored};
use super::series::{channel_list, Source, SourceInfo, Window, Windowed};
use super::{io, name_of, validate_dims, validate_spacing, PatientTransform, Volume};

/// Size of a NIfTI-1 header.
pub(crate) const HEADER_LEN: usize = 348;
const SUPPORTED_TYPES: &str = "uint8 (2), int16 (4), uint16 (512), float32 (16), float64 (64)";

/// The header fields the loader uses.
#[derive(Clone, Debug)]
struct Header {
    big_endian: bool,
    dims: [u32; 3],
    /// `dim[4]`: time points (1 for a 3D file).
    times: u32,
    /// `dim[5]`: channels, e.g. the components of an intent vector (1 for 3D/4D files).
    channels: u32,
    kind: SampleKind,
    spacing: [f32; 3],
    vox_offset: u64,
    rescale: Affine,
    orientation: Option<PatientTransform>,
}

impl Header {
    /// The 3D volumes the file holds, time fastest, then channel.
    fn blocks(&self) -> u64 {
        u64::from(self.times) * u64::from(self.channels)
    }
}

/// Loads a `.nii` or `.nii.gz` file of one 3D volume. The header is read and checked
/// first; the data after it is read only up to what the header's dims promise (one byte
/// more, to tell a too-long file), so a huge or endless file costs no more memory than
/// its volume. Files of several time points or channels are read as a series
/// ([`crate::Series`]).
pub(crate) fn load(path: &Path) -> Result<Volume, VolumeError> {
    let header = read_header(path)?;
    if header.blocks() > 1 {
        let (ndim, d, n) = if header.channels > 1 {
            (5, 5, header.channels)
        } else {
            (4, 4, header.times)
        };
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "{ndim}D NIfTI with dim[{d}] = {n}; one 3D volume is read here: open it as a \
                 series of channels and time points (`dvr info`)"
            ),
        });
    }
    volume(path, &header, 0, None).map(|(v, _)| v)
}

/// Opens a NIfTI file as a series: `dim[4]` time points of `dim[5]` channels.
pub(crate) fn open_series(path: &Path) -> Result<Box<dyn Source>, VolumeError> {
    let header = read_header(path)?;
    let info = SourceInfo {
        path: path.to_path_buf(),
        name: name_of(path),
        dims: header.dims,
        orientation: header.orientation,
        channels: channel_list(path, u64::from(header.channels), Vec::new())?,
        times: header.times as usize,
    };
    Ok(Box::new(NiftiSeries { info, header }))
}

struct NiftiSeries {
    info: SourceInfo,
    header: Header,
}

impl Source for NiftiSeries {
    fn info(&self) -> &SourceInfo {
        &self.info
    }
    fn read(&self, channel: usize, time: usize, window: Option<Window>) -> Windowed {
        let block = channel as u64 * u64::from(self.header.times) + time as u64;
        volume(&self.info.path, &self.header, block, window)
    }
}

/// The 3D volume `block` (time fastest, then channel), normalised through `window`
/// where given.
fn volume(
    path: &Path,
    header: &Header,
    block: u64,
    window: Option<(f64, f64)>,
) -> Result<(Volume, (f64, f64)), VolumeError> {
    let data = read_block(path, header, block)?;
    let stored = Stored {
        samples: Samples::decode(header.kind, data, header.big_endian),
        type_range: header.kind.full_range(),
        rescale: Rescale::Uniform(header.rescale),
        orientation: header.orientation,
    };
    Volume::from_stored_in(
        path,
        name_of(path),
        header.dims,
        header.spacing,
        stored,
        window,
    )
}

/// Opens the file and reads its header (through gzip when the file is gzipped).
fn read_header(path: &Path) -> Result<Header, VolumeError> {
    let (file, _) = io::open_regular(path)?;
    let mut reader = BufReader::new(file);
    let gz = is_gzip(path, &mut reader)?;
    let mut head = Vec::with_capacity(HEADER_LEN);
    if gz {
        let mut dec = io::GzMembers::new(reader);
        head.resize(HEADER_LEN, 0);
        dec.read_exact(&mut head).map_err(|e| match e.kind() {
            std::io::ErrorKind::UnexpectedEof => short_header(path),
            _ => VolumeError::Decompress {
                path: path.to_path_buf(),
                source: e,
            },
        })?;
    } else {
        (&mut reader)
            .take(HEADER_LEN as u64)
            .read_to_end(&mut head)
            .map_err(|source| VolumeError::Io {
                path: path.to_path_buf(),
                source,
            })?;
    }
    parse_header(path, &head)
}

fn is_gzip(path: &Path, reader: &mut BufReader<std::fs::File>) -> Result<bool, VolumeError> {
    Ok(reader
        .fill_buf()
        .map_err(|source| VolumeError::Io {
            path: path.to_path_buf(),
            source,
        })?
        .starts_with(&[0x1f, 0x8b]))
}

/// The bytes of 3D volume `block`, read within what the header promises: an
/// uncompressed file's length is checked against all its volumes before any is read
/// (and the block is seeked to); a gzipped one is decompressed up to the block's end
/// (one byte more for the last, to tell a too-long file).
fn read_block(path: &Path, header: &Header, block: u64) -> Result<Vec<u8>, VolumeError> {
    let (file, len) = io::open_regular(path)?;
    let mut reader = BufReader::new(file);
    let gz = is_gzip(path, &mut reader)?;
    let expected = io::expected_bytes(header.dims, header.kind);
    let blocks = header.blocks();
    let last = block + 1 == blocks;
    let start = header.vox_offset + block * expected;
    let past_end = |got: u64| {
        if block == 0 {
            offset_past_end(path, header.vox_offset, got)
        } else {
            VolumeError::Truncated {
                path: path.to_path_buf(),
                expected: expected * blocks,
                found: got.saturating_sub(header.vox_offset),
            }
        }
    };
    let mut data = if gz {
        let mut dec = io::GzMembers::new(reader);
        let data = io::read_bounded(path, &mut dec, start, expected, &past_end)?;
        if last && data.len() as u64 == expected {
            io::note_trailing_bytes(path, &dec);
        }
        data
    } else {
        if header.vox_offset >= len {
            return Err(offset_past_end(path, header.vox_offset, len));
        }
        // Check the size before reading, so a wrong header on a huge file fails fast.
        check_total(path, header, len - header.vox_offset)?;
        reader
            .seek(SeekFrom::Start(start))
            .map_err(|source| VolumeError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        io::read_bounded(path, reader, 0, expected, &past_end)?
    };
    if !last {
        // The byte past this block is the next block's first.
        data.truncate(expected as usize);
    }
    if blocks == 1 {
        io::check_len(path, header.dims, header.kind, data.len() as u64)?;
    } else if (data.len() as u64) < expected {
        return Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected: expected * blocks,
            found: block * expected + data.len() as u64,
        });
    } else if data.len() as u64 > expected {
        return Err(too_long(path, header, block * expected + data.len() as u64));
    }
    Ok(data)
}

/// `Truncated` or `SizeMismatch` when `found` bytes of voxel data are not what all the
/// file's volumes need.
fn check_total(path: &Path, header: &Header, found: u64) -> Result<(), VolumeError> {
    if header.blocks() == 1 {
        return io::check_len(path, header.dims, header.kind, found);
    }
    let total = io::expected_bytes(header.dims, header.kind) * header.blocks();
    if found < total {
        Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected: total,
            found,
        })
    } else if found > total {
        Err(too_long(path, header, found))
    } else {
        Ok(())
    }
}

fn too_long(path: &Path, header: &Header, found: u64) -> VolumeError {
    VolumeError::MalformedHeader {
        path: path.to_path_buf(),
        field: "dim".into(),
        problem: format!(
            "{} time point(s) × {} channel(s) of {}x{}x{} {} need {} bytes of voxel data, but \
             the file holds {found}",
            header.times,
            header.channels,
            header.dims[0],
            header.dims[1],
            header.dims[2],
            header.kind.name(),
            io::expected_bytes(header.dims, header.kind) * header.blocks()
        ),
    }
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
    // dim[4] is time, dim[5] the components of a vector (channels); 6 and 7 are not read.
    if let Some(extra) = (6..=ndim).find(|&i| dim[i] != 1) {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!(
                "{ndim}D NIfTI with dim[{extra}] = {}; dims 1-3 are space, 4 time and 5 \
                 channels",
                dim[extra]
            ),
        });
    }
    let extra = |i: usize| -> Result<u32, VolumeError> {
        if i > ndim {
            return Ok(1);
        }
        match u32::try_from(dim[i]) {
            Ok(n) if n >= 1 => Ok(n),
            _ => Err(malformed(
                &format!("dim[{i}]"),
                format!(
                    "{} {}: the {} axis is empty",
                    dim[i],
                    if i == 4 { "time points" } else { "channels" },
                    if i == 4 { "time (T)" } else { "channel" }
                ),
            )),
        }
    };
    let (times, channels) = (extra(4)?, extra(5)?);
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
        times,
        channels,
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
