//! Files as the engine reads and writes them. Inputs are opened only when they are
//! regular files, and read only up to a size no real one reaches: a FIFO blocks its
//! reader forever and `/dev/zero` never ends. Outputs go only to a regular file or a new
//! path, written under a temporary name in the same folder and renamed over the target,
//! so a reader (or the next run of a cache) never sees half a file: a crash leaves the
//! old file or none. A symbolic link is written through (its target is replaced, the
//! link stays); a device, FIFO, socket or folder is refused, since a rename would put a
//! regular file in its place (`/dev/stdout` included: it links to a pipe or terminal).

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
    String::from_utf8(read_bounded(path, limit)?)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidData, e.utf8_error()))
}

/// Reads a whole regular file of at most `limit` bytes (fonts, network weights, text),
/// refusing a larger one before reading it.
pub fn read_bounded(path: &Path, limit: u64) -> std::io::Result<Vec<u8>> {
    let (file, len) = open_regular(path)?;
    if len > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("is {len} bytes, more than the {limit} bytes a file of this kind may have"),
        ));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    // One byte past the limit: a file that grew since it was measured is not cut short
    // silently.
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("grew past the {limit} bytes a file of this kind may have while it was read"),
        ));
    }
    Ok(bytes)
}

/// Symbolic links followed at most this deep when resolving an output (the kernel's own
/// limit is 40).
const MAX_LINK_DEPTH: usize = 40;

/// The path an output for `path` is written to: `path` itself when it is new or a
/// regular file; a symbolic link's final target (which may be new) when it is a link;
/// an error saying what it is for anything else (folder, FIFO, device, socket).
pub fn output_target(path: &Path) -> std::io::Result<PathBuf> {
    let mut target = path.to_path_buf();
    for _ in 0..MAX_LINK_DEPTH {
        let meta = match std::fs::symlink_metadata(&target) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(target),
            other => other?,
        };
        if meta.file_type().is_symlink() {
            let link = std::fs::read_link(&target)?;
            target = match target.parent() {
                Some(dir) if link.is_relative() => dir.join(link),
                _ => link,
            };
            continue;
        }
        return match not_a_regular_file(&target)? {
            None => Ok(target),
            Some(what) => {
                let through = if target == path {
                    String::new()
                } else {
                    format!(" (through the link to {})", target.display())
                };
                Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!(
                        "is {what}{through}: outputs are written only to regular files or new paths"
                    ),
                ))
            }
        };
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("is a chain of more than {MAX_LINK_DEPTH} symbolic links"),
    ))
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

/// Writes `bytes` to `path` (through a symbolic link: to its target, see
/// [`output_target`]) via a temporary file in the same folder and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8], durability: Durability) -> std::io::Result<()> {
    let path = &output_target(path)?;
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

/// Removes, in `dir`, the temporary files of [`write_atomic`] that no writer will
/// finish: those of a process of this machine that is gone, and any last modified more
/// than `older_than` ago (a write takes milliseconds, so one that old belongs to no live
/// writer on any machine sharing the folder). What a writer killed mid-write left is
/// never read (outputs are read by their exact names) and, after this, not left either.
/// Returns how many were removed.
pub fn remove_stale_temporaries(
    dir: &Path,
    older_than: std::time::Duration,
) -> std::io::Result<usize> {
    let mut removed = 0;
    for entry in std::fs::read_dir(dir)? {
        let entry = entry?;
        let name = entry.file_name();
        let Some((host, pid)) = temporary_writer(&name.to_string_lossy()) else {
            continue;
        };
        let gone = host == this_host() && !Path::new(&format!("/proc/{pid}")).exists();
        let age = entry.metadata()?.modified()?.elapsed().unwrap_or_default();
        if (gone || age > older_than) && entry.file_type()?.is_file() {
            std::fs::remove_file(entry.path())?;
            removed += 1;
        }
    }
    Ok(removed)
}

/// The host and process id a temporary name of [`temporary_name`] records.
fn temporary_writer(name: &str) -> Option<(String, u32)> {
    let inner = name.strip_prefix('.')?.strip_suffix(".tmp")?;
    let mut parts = inner.rsplitn(4, '.');
    let _n: u64 = parts.next()?.parse().ok()?;
    let pid = parts.next()?.parse().ok()?;
    let host = parts.next()?.to_string();
    parts.next()?; // the target's own name
    Some((host, pid))
}

/// This machine's name as a temporary name records it: letters, digits and '-'.
fn this_host() -> &'static str {
    static HOST: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    HOST.get_or_init(|| {
        let raw = std::fs::read_to_string("/proc/sys/kernel/hostname").unwrap_or_default();
        let host: String = raw
            .trim()
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' {
                    c
                } else {
                    '-'
                }
            })
            .collect();
        if host.is_empty() {
            "host".into()
        } else {
            host
        }
    })
}

/// `.<name>.<host>.<pid>.<n>.tmp` beside `path`: hidden, unique per machine, process
/// and call, never mistaken for an output (caches look for exact names), and telling
/// [`remove_stale_temporaries`] whose it is.
pub fn temporary_name(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!(
        ".{name}.{}.{}.{n}.tmp",
        this_host(),
        std::process::id()
    ))
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

    #[cfg(unix)]
    #[test]
    fn outputs_write_through_links_and_refuse_what_is_not_a_file() {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        // A link to a regular file: the target is replaced, the link stays a link.
        std::fs::write(d.join("real.json"), b"old").expect("write");
        std::os::unix::fs::symlink("real.json", d.join("link.json")).expect("symlink");
        write_atomic(&d.join("link.json"), b"new", Durability::Renamed).expect("through");
        assert_eq!(std::fs::read(d.join("real.json")).expect("read"), b"new");
        let meta = std::fs::symlink_metadata(d.join("link.json")).expect("meta");
        assert!(meta.file_type().is_symlink());
        // A dangling link (and a chain of two) creates its target.
        std::fs::create_dir(d.join("sub")).expect("mkdir");
        std::os::unix::fs::symlink("sub/made.txt", d.join("dangling")).expect("symlink");
        std::os::unix::fs::symlink(d.join("dangling"), d.join("chain")).expect("symlink");
        write_atomic(&d.join("chain"), b"x", Durability::Synced).expect("through");
        assert_eq!(std::fs::read(d.join("sub/made.txt")).expect("read"), b"x");
        // A FIFO, a socket, a folder and a link to a FIFO are refused, and left alone.
        let fifo = d.join("fifo");
        let ok = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(ok.success());
        let socket = d.join("socket");
        let _listener = std::os::unix::net::UnixListener::bind(&socket).expect("bind");
        std::os::unix::fs::symlink(&fifo, d.join("to-fifo")).expect("symlink");
        for (name, what) in [
            ("fifo", "named pipe"),
            ("socket", "socket"),
            ("sub", "a folder"),
            ("to-fifo", "through the link"),
        ] {
            let err = write_atomic(&d.join(name), b"y", Durability::Renamed).unwrap_err();
            assert!(err.to_string().contains(what), "{name}: {err}");
        }
        let t = std::fs::symlink_metadata(&fifo).expect("meta").file_type();
        assert!(std::os::unix::fs::FileTypeExt::is_fifo(&t));
        // A character device made in the folder (root only may: mknod c 1 3 is
        // /dev/null's numbers).
        let dev = d.join("null");
        let made = std::process::Command::new("mknod")
            .arg(&dev)
            .args(["c", "1", "3"])
            .status()
            .is_ok_and(|s| s.success());
        if made {
            let err = write_atomic(&dev, b"z", Durability::Renamed).unwrap_err();
            assert!(err.to_string().contains("character device"), "{err}");
            let t = std::fs::symlink_metadata(&dev).expect("meta").file_type();
            assert!(std::os::unix::fs::FileTypeExt::is_char_device(&t));
        }
        // Nothing was left behind under a temporary name.
        let leftovers: Vec<_> = std::fs::read_dir(d)
            .expect("list")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }

    #[test]
    fn bounded_reads_refuse_large_files() {
        let dir = tempfile::tempdir().expect("tempdir");
        let p = dir.path().join("f.bin");
        std::fs::write(&p, [7u8; 10]).expect("write");
        assert_eq!(read_bounded(&p, 10).expect("fits").len(), 10);
        let err = read_bounded(&p, 9).unwrap_err();
        assert!(err.to_string().contains("10 bytes"), "{err}");
    }

    #[test]
    fn temporaries_of_killed_writers_are_removed_and_live_ones_kept() {
        let dir = tempfile::tempdir().expect("temp dir");
        let d = dir.path();
        // A writer of this machine that is gone (no such process), one that is alive
        // (this test), one of another machine written just now, and the same an hour ago.
        let gone = d.join(format!(".0003.exr.{}.4194300.0.tmp", this_host()));
        let live = temporary_name(&d.join("0004.exr"));
        let remote = d.join(".0005.exr.elsewhere.12.0.tmp");
        let old = d.join(".0006.exr.elsewhere.13.0.tmp");
        let output = d.join("0007.exr");
        for p in [&gone, &live, &remote, &old, &output] {
            std::fs::write(p, b"half a frame").expect("write");
        }
        let hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
        std::fs::File::options()
            .write(true)
            .open(&old)
            .and_then(|f| f.set_modified(hour_ago))
            .expect("age");
        let removed =
            remove_stale_temporaries(d, std::time::Duration::from_secs(600)).expect("cleared");
        assert_eq!(removed, 2);
        assert!(!gone.exists() && !old.exists());
        assert!(live.exists() && remote.exists() && output.exists());
        assert_eq!(
            temporary_writer(&live.file_name().unwrap().to_string_lossy()),
            Some((this_host().to_string(), std::process::id()))
        );
    }
}
