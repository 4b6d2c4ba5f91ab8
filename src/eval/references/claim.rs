//! A run's claim on a reference folder: while a live run with another key holds one,
//! the folder is refused; under the claim, the folder is made consistent with the run's
//! key (stale frames removed, the key written).

use super::ReferenceCache;
use crate::eval::plan::keys::ReferenceKey;
use anyhow::{Context, Result};
use dvr_engine::files::Durability;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Age past which a temporary file in the cache is the leftover of a killed writer.
const STALE_TEMPORARY: std::time::Duration = std::time::Duration::from_secs(600);

/// A run's hold on a reference folder: `reference/.run-<pid>-<n>.json`, locked (an
/// advisory `flock`) for as long as this value lives, holding the run's key. The lock,
/// not the file, says the run is alive: a killed run's lock goes with its process and
/// the next claimer removes its file.
pub struct Claim {
    run: Option<(std::fs::File, PathBuf)>,
    /// What [`ReferenceCache::prepare`] threw away, for the log.
    pub note: Option<String>,
}

impl Drop for Claim {
    fn drop(&mut self) {
        if let Some((_, path)) = self.run.take() {
            let _ = std::fs::remove_file(path);
        }
    }
}

/// What a claim file holds.
#[derive(Serialize, Deserialize)]
struct RunRecord {
    pid: u32,
    key: ReferenceKey,
}

impl ReferenceCache {
    /// Claims the folder for a run with this key (see the module's comment) and makes
    /// it consistent with the key ([`ReferenceCache::prepare`]), both under the
    /// folder's lock (`reference/.lock`), so no other claim runs between the check and
    /// the clean-up. Fails, naming the other run, while a live run with another key
    /// holds a claim. A folder that cannot be written (read-only) is claimed without a
    /// lock: it can be read, and nothing can change it under this run.
    pub fn claim(&self) -> Result<Claim> {
        use std::fs::{File, OpenOptions, TryLockError};
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("creating {}", self.dir.display()))?;
        let lock_path = self.dir.join(".lock");
        let lock = match OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&lock_path)
        {
            Ok(f) => f,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::ReadOnlyFilesystem
                ) =>
            {
                return Ok(Claim {
                    run: None,
                    note: None,
                })
            }
            Err(e) => return Err(e).with_context(|| format!("opening {}", lock_path.display())),
        };
        lock.lock()
            .with_context(|| format!("locking {}", lock_path.display()))?;
        // A frame written by a run killed mid-write is only ever a temporary file (the
        // cache reads exact names): what such runs left is removed here.
        let stale = dvr_engine::files::remove_stale_temporaries(&self.dir, STALE_TEMPORARY)
            .with_context(|| format!("clearing {}", self.dir.display()))?;
        if stale > 0 {
            log::info!(
                "{}: removed {stale} temporary file(s) of interrupted writes",
                self.dir.display()
            );
        }
        for path in self.files_named(|n| n.starts_with(".run-") && n.ends_with(".json"))? {
            let Ok(file) = File::open(&path) else {
                continue; // removed since it was listed: its run ended
            };
            match file.try_lock_shared() {
                // Nobody holds it: the run that wrote it is gone.
                Ok(()) => {
                    let _ = std::fs::remove_file(&path);
                }
                Err(TryLockError::WouldBlock) => {
                    let record = dvr_engine::files::read_text(&path, 1 << 16)
                        .ok()
                        .and_then(|t| serde_json::from_str::<RunRecord>(&t).ok());
                    match record {
                        Some(r) if r.key == self.key => {}
                        Some(r) => anyhow::bail!(
                            "{} is in use by another dvr run (pid {}: {}) with other settings \
                             than this one ({}); wait for it to finish or use another --out",
                            self.dir.display(),
                            r.pid,
                            r.key.describe(),
                            self.key.describe()
                        ),
                        None => anyhow::bail!(
                            "{} is in use by another dvr run ({} is held but unreadable); \
                             wait for it to finish or use another --out",
                            self.dir.display(),
                            path.display()
                        ),
                    }
                }
                Err(TryLockError::Error(e)) => {
                    return Err(e).with_context(|| format!("checking {}", path.display()))
                }
            }
        }
        let note = self.prepare()?;
        static CLAIMS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = CLAIMS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path = self
            .dir
            .join(format!(".run-{}-{n}.json", std::process::id()));
        let record = serde_json::to_string_pretty(&RunRecord {
            pid: std::process::id(),
            key: self.key.clone(),
        })?;
        let mut file =
            File::create(&path).with_context(|| format!("creating {}", path.display()))?;
        file.lock()
            .with_context(|| format!("locking {}", path.display()))?;
        std::io::Write::write_all(&mut file, record.as_bytes())
            .with_context(|| format!("writing {}", path.display()))?;
        // The folder's lock is released here (dropped); the run's own stays.
        Ok(Claim {
            run: Some((file, path)),
            note,
        })
    }

    /// The entries of the folder whose file name `keep` accepts.
    fn files_named(&self, keep: impl Fn(&str) -> bool) -> Result<Vec<PathBuf>> {
        let mut paths = Vec::new();
        for entry in std::fs::read_dir(&self.dir)
            .with_context(|| format!("reading {}", self.dir.display()))?
        {
            let path = entry?.path();
            if path.file_name().and_then(|n| n.to_str()).is_some_and(&keep) {
                paths.push(path);
            }
        }
        Ok(paths)
    }

    /// Makes the folder consistent with this key before rendering: a different (or
    /// unreadable) key removes the old frames and writes the new key. Returns a note for
    /// the log when something was thrown away. Called under a claim.
    pub(super) fn prepare(&self) -> Result<Option<String>> {
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("creating {}", self.dir.display()))?;
        if self.key_matches() {
            return Ok(None);
        }
        let unreadable = self.key_path().exists() && self.stored_key().is_none();
        let note = if unreadable {
            Some(format!(
                "{} is unreadable or from another version of dvr, re-rendering",
                self.key_path().display()
            ))
        } else {
            self.stored_key().map(|old| self.change_note(&old))
        };
        let is_frame = |n: &str| {
            n.split_once('.').is_some_and(|(stem, ext)| {
                stem.len() == 4
                    && stem.bytes().all(|b| b.is_ascii_digit())
                    && matches!(ext, "exr" | "png")
            })
        };
        for path in self.files_named(is_frame)? {
            std::fs::remove_file(&path)
                .with_context(|| format!("removing stale {}", path.display()))?;
        }
        let json = serde_json::to_string_pretty(&self.key)?;
        dvr_engine::files::write_atomic(&self.key_path(), json.as_bytes(), Durability::Synced)
            .with_context(|| format!("writing {}", self.key_path().display()))?;
        Ok(note)
    }

    /// What differs between the stored key and this one, for the log.
    fn change_note(&self, old: &ReferenceKey) -> String {
        let edited = [
            (old.scene_hash != self.key.scene_hash, "scene edited"),
            (
                old.content_hash != self.key.content_hash,
                "volume, transfer function or environment map changed",
            ),
            (
                old.renderer_hash != self.key.renderer_hash,
                "path tracer changed",
            ),
        ];
        let what: String = edited
            .iter()
            .filter(|(changed, _)| *changed)
            .map(|(_, what)| format!(", {what}"))
            .collect();
        format!(
            "reference settings changed ({}x{}, {} frames, {} spp → {}x{}, {} frames, {} spp{what}), \
             re-rendering",
            old.width,
            old.height,
            old.frames,
            old.ref_spp,
            self.key.width,
            self.key.height,
            self.key.frames,
            self.key.ref_spp,
        )
    }
}
