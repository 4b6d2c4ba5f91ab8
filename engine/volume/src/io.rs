//! File access shared by the loaders, bounded by what the file's header promises: only
//! regular files are opened (a FIFO would block forever, `/dev/zero` never ends), sizes
//! are checked before data is read, reads stop one byte past the promised length, gzip
//! streams tell trailing bytes apart from corrupt data, and the data-length check tells
//! "truncated" from "dims do not match".

use std::fs::File;
use std::io::{BufRead, Read};
use std::path::Path;

use flate2::bufread::GzDecoder;

use super::error::VolumeError;
use super::samples::SampleKind;

/// Opens `path` for reading if it is a regular file (symbolic links followed) and
/// returns it with its length. Folders, FIFOs, sockets and devices are refused before
/// they are opened: opening a FIFO blocks, and a device may never end.
pub(crate) fn open_regular(path: &Path) -> Result<(File, u64), VolumeError> {
    let io_err = |source| VolumeError::Io {
        path: path.to_path_buf(),
        source,
    };
    if let Some(what) = crate::files::not_a_regular_file(path).map_err(io_err)? {
        return Err(VolumeError::NotAFile {
            path: path.to_path_buf(),
            what,
        });
    }
    let file = File::open(path).map_err(io_err)?;
    let len = file.metadata().map_err(io_err)?.len();
    Ok((file, len))
}

/// Reads a whole regular file of at most `limit` bytes (sidecars, DICOM slices),
/// naming it in the error. `what` says what the file should be, for the message.
pub(crate) fn read_small(path: &Path, limit: u64, what: &str) -> Result<Vec<u8>, VolumeError> {
    let (file, len) = open_regular(path)?;
    if len > limit {
        return Err(VolumeError::Unsupported {
            path: path.to_path_buf(),
            reason: format!("{len} bytes is too large for {what} (at most {limit} bytes)"),
        });
    }
    let mut bytes = Vec::new();
    file.take(limit)
        .read_to_end(&mut bytes)
        .map_err(|source| VolumeError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(bytes)
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

/// A gzip stream of one or more members (concatenated `.gz` files are valid gzip) that
/// ends cleanly where the bytes after a member do not start another one, and records
/// that it did: `gzip -d` accepts such files with "trailing garbage ignored", while a
/// decoder that reads on reports "invalid gzip header", which names the wrong problem.
pub(crate) struct GzMembers<R: BufRead> {
    decoder: Option<GzDecoder<R>>,
    /// True once the stream stopped at bytes that are not gzip.
    pub trailing_bytes: bool,
}

impl<R: BufRead> GzMembers<R> {
    pub(crate) fn new(reader: R) -> Self {
        Self {
            decoder: Some(GzDecoder::new(reader)),
            trailing_bytes: false,
        }
    }
}

impl<R: BufRead> Read for GzMembers<R> {
    fn read(&mut self, out: &mut [u8]) -> std::io::Result<usize> {
        loop {
            let Some(decoder) = self.decoder.as_mut() else {
                return Ok(0);
            };
            let n = decoder.read(out)?;
            if n > 0 || out.is_empty() {
                return Ok(n);
            }
            // This member is complete: another one, the end, or trailing bytes.
            let Some(decoder) = self.decoder.take() else {
                return Ok(0);
            };
            let mut inner = decoder.into_inner();
            let rest = inner.fill_buf()?;
            if rest.is_empty() {
                return Ok(0);
            }
            if rest[0] == 0x1f && rest.get(1).is_none_or(|&b| b == 0x8b) {
                self.decoder = Some(GzDecoder::new(inner));
            } else {
                self.trailing_bytes = true;
                return Ok(0);
            }
        }
    }
}

/// Warns when a gzip stream whose voxel data was complete ended at trailing bytes.
pub(crate) fn note_trailing_bytes<R: BufRead>(path: &Path, gz: &GzMembers<R>) {
    if gz.trailing_bytes {
        log::warn!(
            "{}: the gzip data is followed by bytes that are not gzip; ignored (as `gzip -d` \
             does), the voxel data itself is complete",
            path.display()
        );
    }
}

/// Skips `skip` bytes of a (decompressing) reader and returns at most `want + 1` bytes
/// after them, so that a caller can tell a too-long stream from an exact one without
/// reading an arbitrarily large (or endless) source. A stream that ends early (a cut
/// gzip file) is reported as [`VolumeError::Truncated`], other decoder errors as
/// [`VolumeError::Decompress`]; a stream that ends inside the skipped prefix as the
/// error `past_end` makes from the number of bytes there were.
pub(crate) fn read_bounded<R: Read>(
    path: &Path,
    mut reader: R,
    skip: u64,
    want: u64,
    past_end: &dyn Fn(u64) -> VolumeError,
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
    if got < skip || (skip > 0 && got == skip && want > 0) {
        return Err(past_end(got));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn gzip(data: &[u8]) -> Vec<u8> {
        let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        e.write_all(data).expect("gzip");
        e.finish().expect("gzip")
    }

    fn read_all<R: Read>(mut r: R) -> Vec<u8> {
        let mut v = Vec::new();
        r.read_to_end(&mut v).expect("read");
        v
    }

    #[test]
    fn gzip_members_concatenate_and_trailing_bytes_end_the_stream() {
        let mut two = gzip(b"abc");
        two.extend(gzip(b"def"));
        let mut gz = GzMembers::new(two.as_slice());
        assert_eq!(read_all(&mut gz), b"abcdef");
        assert!(!gz.trailing_bytes);

        let mut padded = gzip(b"abc");
        padded.extend_from_slice(b"\0\0\0 not gzip");
        let mut gz = GzMembers::new(padded.as_slice());
        assert_eq!(read_all(&mut gz), b"abc");
        assert!(gz.trailing_bytes);
    }

    #[test]
    fn bounded_reads_stop_one_byte_past_the_promise() {
        let never_ending = std::io::repeat(7);
        let past = |_| panic!("not past the end");
        let got = read_bounded(Path::new("zero"), never_ending, 3, 10, &past).expect("read");
        assert_eq!(got.len(), 11);
        let err = read_bounded(Path::new("short"), &[1u8, 2][..], 5, 10, &|got| {
            VolumeError::MalformedHeader {
                path: "short".into(),
                field: "skip".into(),
                problem: format!("{got}"),
            }
        })
        .unwrap_err();
        assert!(err.to_string().contains("skip"), "{err}");
    }

    #[cfg(unix)]
    #[test]
    fn special_files_are_refused_without_opening_them() {
        let err = open_regular(Path::new("/dev/zero")).unwrap_err();
        assert!(err.to_string().contains("character device"), "{err}");
        let dir = tempfile::tempdir().expect("tempdir");
        let err = open_regular(dir.path()).unwrap_err();
        assert!(err.to_string().contains("a folder"), "{err}");
        let fifo = dir.path().join("pipe");
        if crate::make_fifo(&fifo) {
            // Opening a FIFO for reading would block this test forever.
            let err = open_regular(&fifo).unwrap_err();
            assert!(err.to_string().contains("FIFO"), "{err}");
        }
    }
}
