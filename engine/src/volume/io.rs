//! File access shared by the loaders: whole-file reads, bounded gzip reads and the
//! data-length check that tells "truncated" from "dims do not match".

use std::io::Read;
use std::path::Path;

use flate2::read::MultiGzDecoder;

use super::error::VolumeError;
use super::samples::SampleKind;

/// Reads a whole file, naming it in the error.
pub(crate) fn read_all(path: &Path) -> Result<Vec<u8>, VolumeError> {
    std::fs::read(path).map_err(|source| VolumeError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Bytes of voxel data that `dims` of `kind` need.
pub(crate) fn expected_bytes(dims: [u32; 3], kind: SampleKind) -> u64 {
    super::voxel_count(dims) * kind.bytes() as u64
}

/// `Truncated` when `found` is short of what `dims` need, `SizeMismatch` when it is
/// longer.
pub(crate) fn check_len(
    path: &Path,
    dims: [u32; 3],
    kind: SampleKind,
    found: u64,
) -> Result<(), VolumeError> {
    let expected = expected_bytes(dims, kind);
    if found < expected {
        Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected,
            found,
        })
    } else if found > expected {
        Err(VolumeError::SizeMismatch {
            path: path.to_path_buf(),
            dims,
            format: kind.name(),
            expected,
            found,
        })
    } else {
        Ok(())
    }
}

/// Gzip-decompresses `compressed` (concatenated members allowed); see [`read_bounded`].
pub(crate) fn gunzip_bounded(
    path: &Path,
    compressed: &[u8],
    skip: u64,
    want: u64,
) -> Result<Vec<u8>, VolumeError> {
    read_bounded(path, MultiGzDecoder::new(compressed), skip, want)
}

/// Skips `skip` bytes of a (decompressing) reader and returns at most `want + 1` bytes
/// after them, so that a caller can tell a too-long stream from an exact one without
/// inflating an arbitrarily large file. A stream that ends early (a cut gzip file) is
/// reported as [`VolumeError::Truncated`], other decoder errors as
/// [`VolumeError::Decompress`].
pub(crate) fn read_bounded<R: Read>(
    path: &Path,
    mut reader: R,
    skip: u64,
    want: u64,
) -> Result<Vec<u8>, VolumeError> {
    let total = skip.saturating_add(want);
    let mut got: u64 = 0;
    let mut out = Vec::new();
    let mut buf = vec![0u8; 1 << 16];
    let limit = total.saturating_add(1);
    while got < limit {
        let room = usize::try_from(limit - got)
            .unwrap_or(usize::MAX)
            .min(buf.len());
        let n = match reader.read(&mut buf[..room]) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                return Err(VolumeError::Truncated {
                    path: path.to_path_buf(),
                    expected: want,
                    found: got.saturating_sub(skip),
                })
            }
            Err(source) => {
                return Err(VolumeError::Decompress {
                    path: path.to_path_buf(),
                    source,
                })
            }
        };
        // Drop what still falls inside the skipped prefix.
        let start = usize::try_from(skip.saturating_sub(got))
            .unwrap_or(usize::MAX)
            .min(n);
        out.extend_from_slice(&buf[start..n]);
        got += n as u64;
    }
    if got < skip {
        return Err(VolumeError::Truncated {
            path: path.to_path_buf(),
            expected: want,
            found: 0,
        });
    }
    Ok(out)
}
