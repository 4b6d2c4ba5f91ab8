//! Files as the engine reads and writes them. Inputs are opened only when they are
//! regular files, and text inputs only up to a size no real one reaches: a FIFO blocks
//! its reader forever and `/dev/zero` never ends. Outputs are written under a temporary
//! name in the same folder and renamed over the target, so a reader (or the next run of
//! a cache) never sees half a file: a crash leaves the old file or none.

use std::fs::File;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Largest scene or transfer-function file read: real ones are a few KB.
pub const MAX_TEXT_FILE_BYTES: u64 = 1 << 20;

/// What `path` is when it is not a regular file ("a folder", "a named pipe (FIFO)",
/// ...), `None` for a regular file (symbolic links followed).
pub fn not_a_regular_file(path: &Path) -> std::io::Result<Option<&'static str>> {
    let t = std::fs::metadata(path)?.file_type();
    if t.is_file() {
        return Ok(None);
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return Ok(Some("a named pipe (FIFO)"));
        }
        if t.is_char_device() {
            return Ok(Some("a character device"));
        }
        if t.is_block_device() {
            return Ok(Some("a block device"));
        }
        if t.is_socket() {
            return Ok(Some("a socket"));
        }
    }
    Ok(Some(if t.is_dir() {
        "a folder"
    } else {
        "not a regular file"
    }))
}

/// Opens a regular file for reading and returns it with its length; anything else is
/// refused before it is opened, with an error saying what it is.
pub fn open_regular(path: &Path) -> std::io::Result<(File, u64)> {
    if let Some(what) = not_a_regular_file(path)? {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("is {what}, not a file"),
        ));
    }
    let file = File::open(path)?;
    let len = file.metadata()?.len();
    Ok((file, len))
}

/// Reads a UTF-8 text file of at most `limit` bytes (scene and TF files).
pub fn read_text(path: &Path, limit: u64) -> std::io::Result<String> {
    let (file, len) = open_regular(path)?;
    if len > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "is {len} bytes, more than the {limit} bytes a text file of this kind may have"
            ),
        ));
    }
    let mut text = String::new();
    file.take(limit).read_to_string(&mut text)?;
    Ok(text)
}

/// How far [`write_atomic`] goes to make a file survive a crash.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Durability {
    /// Renamed into place: readers see the old file or the whole new one.
    Renamed,
    /// Also flushed to disk (fsync) before the rename, so a power cut cannot leave an
    /// empty file under the final name: for caches that a later run trusts.
    Synced,
}

/// Writes `bytes` to `path` through a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8], durability: Durability) -> std::io::Result<()> {
    let tmp = temporary_name(path);
    let result = (|| {
        let mut file = File::create(&tmp)?;
        file.write_all(bytes)?;
        if durability == Durability::Synced {
            file.sync_all()?;
        }
        drop(file);
        std::fs::rename(&tmp, path)?;
        if durability == Durability::Synced {
            // The rename itself is durable once the folder is synced (POSIX; a no-op
            // where folders cannot be opened).
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                if let Ok(d) = File::open(dir) {
                    let _ = d.sync_all();
                }
            }
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// `.<name>.<pid>.<n>.tmp` beside `path`: hidden, unique per process and call, and
/// never mistaken for an output (caches look for exact names).
fn temporary_name(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(".{name}.{}.{n}.tmp", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_writes_replace_whole_files_and_leave_no_temporaries() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("a.json");
        write_atomic(&p, b"first", Durability::Renamed).expect("write");
        write_atomic(&p, b"second", Durability::Synced).expect("write");
        assert_eq!(std::fs::read(&p).expect("read"), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(names, ["a.json"]);
        // A folder that does not exist: an error, and nothing left behind.
        assert!(write_atomic(&dir.path().join("no/b"), b"x", Durability::Renamed).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn text_reads_refuse_devices_folders_and_huge_files() {
        let err = read_text(Path::new("/dev/zero"), 100).unwrap_err();
        assert!(err.to_string().contains("character device"), "{err}");
        let dir = tempfile::tempdir().expect("tempdir");
        let err = read_text(dir.path(), 100).unwrap_err();
        assert!(err.to_string().contains("a folder"), "{err}");
        let big = dir.path().join("big.toml");
        std::fs::write(&big, vec![b'#'; 200]).expect("write");
        let err = read_text(&big, 100).unwrap_err();
        assert!(err.to_string().contains("200 bytes"), "{err}");
        assert_eq!(read_text(&big, 200).expect("fits").len(), 200);
    }
}
