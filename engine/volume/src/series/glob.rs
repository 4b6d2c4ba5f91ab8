//! Globs of time-point files (`scan_*.nii.gz`): `*` and `?` in the file name only, the
//! matches sorted by name, so `t0001 … t0120` come in time order when zero-padded.

use std::path::{Path, PathBuf};

use crate::VolumeError;

/// Most files one glob may name: a time series of a few thousand volumes is long.
pub const MAX_GLOB_FILES: usize = 100_000;

/// The files (not folders other than Zarr stores) in `pattern`'s folder whose names
/// match its last component, sorted by name. A pattern without `*` or `?` is itself.
pub fn expand(pattern: &Path) -> Result<Vec<PathBuf>, VolumeError> {
    let name = pattern
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if !name.contains(['*', '?']) {
        return Ok(vec![pattern.to_path_buf()]);
    }
    let dir = match pattern.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if dir.to_string_lossy().contains(['*', '?']) {
        return Err(VolumeError::Unsupported {
            path: pattern.to_path_buf(),
            reason: "a glob's wildcards must be in the file name, not its folders".into(),
        });
    }
    let entries = std::fs::read_dir(&dir).map_err(|source| VolumeError::Io {
        path: dir.clone(),
        source,
    })?;
    let mut out = Vec::new();
    for e in entries {
        let e = e.map_err(|source| VolumeError::Io {
            path: dir.clone(),
            source,
        })?;
        let n = e.file_name().to_string_lossy().into_owned();
        if matches(name.as_bytes(), n.as_bytes()) {
            out.push(dir.join(n));
            if out.len() > MAX_GLOB_FILES {
                return Err(VolumeError::Unsupported {
                    path: pattern.to_path_buf(),
                    reason: format!("the glob names more than {MAX_GLOB_FILES} files"),
                });
            }
        }
    }
    if out.is_empty() {
        return Err(VolumeError::MalformedHeader {
            path: pattern.to_path_buf(),
            field: "time".into(),
            problem: "the glob matches no file: the time axis is empty".into(),
        });
    }
    out.sort();
    Ok(out)
}

/// Whether `name` matches `pat` (`*` any run, `?` one byte). Iterative with one
/// backtrack point, so a pattern of many stars cannot take exponential time.
fn matches(pat: &[u8], name: &[u8]) -> bool {
    let (mut p, mut n) = (0, 0);
    let mut star: Option<(usize, usize)> = None;
    while n < name.len() {
        if p < pat.len() && (pat[p] == b'?' || pat[p] == name[n]) {
            p += 1;
            n += 1;
        } else if p < pat.len() && pat[p] == b'*' {
            star = Some((p, n));
            p += 1;
        } else if let Some((sp, sn)) = star {
            p = sp + 1;
            n = sn + 1;
            star = Some((sp, sn + 1));
        } else {
            return false;
        }
    }
    pat[p..].iter().all(|&c| c == b'*')
}

#[cfg(test)]
mod tests {
    use super::matches;

    #[test]
    fn stars_and_question_marks() {
        assert!(matches(b"t*.nii", b"t001.nii"));
        assert!(matches(b"t???.nii", b"t001.nii"));
        assert!(!matches(b"t??.nii", b"t001.nii"));
        assert!(matches(b"*", b""));
        assert!(!matches(b"a*b", b"ac"));
        assert!(matches(&[b'*'; 64], b"x"));
    }
}
