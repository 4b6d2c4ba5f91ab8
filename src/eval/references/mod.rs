//! The reference cache: `DIR/reference/NNNN.{exr,png}` plus `reference.json`, the key
//! they were rendered under ([`ReferenceKey`]; `dvr eval` keeps one cache per scene
//! folder, `dvr reference` one in its `--out`). Frames are reused only when the key
//! matches and the frame reads back; a different key re-renders them all, an unreadable
//! frame is re-rendered with a warning. Every file is written under a temporary name,
//! flushed to disk and renamed, so an interrupted run never leaves a file that looks
//! finished.
//!
//! Several processes may use one folder at once (shards of one reference, two evals
//! with one `--out`) only when their keys are equal: a run first *claims* the folder
//! ([`ReferenceCache::claim`], in `claim.rs`), which refuses it, naming the other run,
//! while a live run with another key holds a claim there. So every frame in a folder is
//! one its key describes, whatever runs in parallel; runs with equal keys render frames
//! whose bytes are equal, written atomically, so which of them writes a frame does not
//! matter. [`fill`] renders what is missing.
//!
//! The second layer of the eval: it imports the plan (`super::plan`) and nothing else
//! of the eval.

mod claim;
pub mod fill;

use super::plan::keys::ReferenceKey;
use super::plan::PlannedScene;
use anyhow::Result;
use dvr_engine::files::Durability;
use dvr_engine::image_io::{encode_exr, encode_png, read_exr, write_file};
use dvr_engine::metrics::Rgb32Image;
use std::path::{Path, PathBuf};

pub fn frame_name(f: u32) -> String {
    format!("{f:04}")
}

/// One reference folder.
#[derive(Clone, Debug)]
pub struct ReferenceCache {
    pub dir: PathBuf,
    key: ReferenceKey,
}

/// The cached frames that can be reused and what is wrong with the others.
pub struct CacheState {
    /// Frames to render: all when the key differs, else those absent or unreadable.
    pub missing: Vec<u32>,
    /// Frames on disk under the right key that did not read back, and why.
    pub unreadable: Vec<(PathBuf, String)>,
}

impl ReferenceCache {
    /// The cache in `parent/reference/`.
    pub fn new(parent: &Path, key: ReferenceKey) -> Self {
        Self {
            dir: parent.join("reference"),
            key,
        }
    }

    /// The cache of a planned scene: `<scene folder>/reference/`.
    pub fn of(scene: &PlannedScene) -> Self {
        Self::new(&scene.dir, scene.reference_key.clone())
    }

    pub(super) fn key_path(&self) -> PathBuf {
        self.dir.join("reference.json")
    }

    pub fn exr(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.exr", frame_name(f)))
    }

    pub fn png(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.png", frame_name(f)))
    }

    pub(super) fn stored_key(&self) -> Option<ReferenceKey> {
        let text = dvr_engine::files::read_text(&self.key_path(), 1 << 16).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// True when the stored key matches (the frames on disk may be reused).
    pub fn key_matches(&self) -> bool {
        self.stored_key().as_ref() == Some(&self.key)
    }

    /// Which frames are reusable: under the right key, both files present and reading
    /// back at the key's size (a crash or a full disk can leave a cut file).
    pub fn state(&self) -> CacheState {
        if !self.key_matches() {
            return CacheState {
                missing: (0..self.key.frames).collect(),
                unreadable: Vec::new(),
            };
        }
        let mut state = CacheState {
            missing: Vec::new(),
            unreadable: Vec::new(),
        };
        for f in 0..self.key.frames {
            let (exr, png) = (self.exr(f), self.png(f));
            if !exr.exists() || !png.exists() {
                state.missing.push(f);
                continue;
            }
            let problem = match self.load(f) {
                Err(e) => Some((exr, format!("{e:#}"))),
                // Decoded whole: a cut PNG keeps a valid header.
                Ok(_) => match image::open(&png).map(|i| (i.width(), i.height())) {
                    Err(e) => Some((png, e.to_string())),
                    Ok(size) if size != (self.key.width, self.key.height) => Some((
                        png,
                        format!(
                            "is {}x{}, expected {}x{}",
                            size.0, size.1, self.key.width, self.key.height
                        ),
                    )),
                    Ok(_) => None,
                },
            };
            if let Some(p) = problem {
                state.missing.push(f);
                state.unreadable.push(p);
            }
        }
        state
    }

    /// Frames still to render (see [`ReferenceCache::state`]).
    pub fn missing(&self) -> Vec<u32> {
        self.state().missing
    }

    /// What keeps the frames `wanted` from being reused, one line each, naming the
    /// file (`--verify`); empty when every one is present under this key and reads
    /// back. Renders and changes nothing.
    pub fn problems(&self, wanted: &[u32]) -> Vec<String> {
        if !self.key_matches() {
            let why = match self.stored_key() {
                Some(old) => format!(
                    "rendered under other settings ({}, now {})",
                    old.describe(),
                    self.key.describe()
                ),
                None if self.key_path().exists() => {
                    format!("{} is unreadable", self.key_path().display())
                }
                None => "no reference rendered yet".into(),
            };
            return vec![format!(
                "{}: {} frame(s) missing: {why}",
                self.dir.display(),
                wanted.len()
            )];
        }
        let state = self.state();
        let mut lines: Vec<String> = state
            .unreadable
            .iter()
            .filter(|(path, _)| wanted.iter().any(|&f| self.frame_of(path) == Some(f)))
            .map(|(path, why)| format!("{}: does not read back ({why})", path.display()))
            .collect();
        for f in state.missing.iter().filter(|f| wanted.contains(f)) {
            let unreadable = |p: &PathBuf| state.unreadable.iter().any(|(u, _)| u == p);
            for path in [self.exr(*f), self.png(*f)] {
                if !path.exists() && !unreadable(&path) {
                    lines.push(format!("{}: missing", path.display()));
                }
            }
        }
        lines.sort();
        lines
    }

    /// The frame a cached file holds, from its name.
    fn frame_of(&self, path: &Path) -> Option<u32> {
        path.file_stem()?.to_str()?.parse().ok()
    }

    /// Writes frame `f`'s files, each whole or not at all (temporary name, fsync,
    /// rename): PNG, then the EXR that [`ReferenceCache::load`] reads. `dvr eval` calls
    /// it on a worker thread while the next frame renders.
    pub fn store(&self, f: u32, img: &Rgb32Image) -> Result<()> {
        let (png, exr) = (self.png(f), self.exr(f));
        write_file(&png, &encode_png(&png, img)?, Durability::Synced)?;
        write_file(&exr, &encode_exr(&exr, img)?, Durability::Synced)?;
        Ok(())
    }

    pub fn load(&self, f: u32) -> Result<Rgb32Image> {
        let img = read_exr(&self.exr(f))?;
        if (img.width, img.height) != (self.key.width, self.key.height) {
            anyhow::bail!(
                "{} is {}x{}, expected {}x{}",
                self.exr(f).display(),
                img.width,
                img.height,
                self.key.width,
                self.key.height
            );
        }
        Ok(img)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::eval::plan::keys::tests::key;
    use dvr_engine::scene::Scene;

    /// Defect: editing a TF file or replacing the volume file a scene names kept the
    /// key (it hashed only the scene text), so stale references were reused.
    #[test]
    fn key_follows_the_content_of_tf_and_volume_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let tf = |opacity: f64| {
            format!(
                "[[point]]\ndensity = 0.0\nopacity = 0.0\ndiffuse = [1, 1, 1]\n\
                 [[point]]\ndensity = 1.0\nopacity = {opacity}\ndiffuse = [1, 1, 1]\n"
            )
        };
        std::fs::write(d.join("tf.toml"), tf(0.8)).unwrap();
        std::fs::write(d.join("v.raw"), [10u8, 20, 30, 40, 50, 60, 70, 80]).unwrap();
        std::fs::write(
            d.join("s.toml"),
            "[volume]\nfile = \"v.raw\"\ndims = [2, 2, 2]\nformat = \"u8\"\n[transfer]\n\
             a = \"tf.toml\"\n[[light]]\nkind = \"point\"\nposition = [1, 1, 1]\nintensity = 1\n",
        )
        .unwrap();
        let key = || {
            let s = Scene::load(d.join("s.toml")).unwrap();
            ReferenceKey::new(&s, (8, 8), 4, 16).unwrap()
        };
        let before = key();
        assert_eq!(before, key());
        std::fs::write(d.join("tf.toml"), tf(0.05)).unwrap();
        let tf_edited = key();
        assert_ne!(before, tf_edited, "TF edited");
        std::fs::write(d.join("v.raw"), [80u8, 70, 60, 50, 40, 30, 20, 10]).unwrap();
        let volume_replaced = key();
        assert_ne!(tf_edited, volume_replaced, "volume replaced");
        assert_eq!(before.scene_hash, volume_replaced.scene_hash);
        let cache = ReferenceCache::new(d, before);
        cache.prepare().unwrap();
        let note = ReferenceCache::new(d, volume_replaced).prepare().unwrap();
        assert!(
            note.is_some_and(|n| n.contains("volume, transfer function")),
            "a note saying why"
        );
    }

    #[test]
    fn mismatched_key_clears_frames_and_matching_key_keeps_them() {
        let tmp = tempfile::tempdir().unwrap();
        let cache = ReferenceCache::new(tmp.path(), key(16));
        assert_eq!(cache.missing(), vec![0, 1, 2]);
        assert!(cache.prepare().unwrap().is_none());
        let img = Rgb32Image::filled(8, 8, [0.5; 3]);
        for f in 0..2 {
            cache.store(f, &img).unwrap();
        }
        // Same key: frames 0 and 1 are reused, only 2 is missing.
        assert_eq!(cache.missing(), vec![2]);
        assert!(cache.prepare().unwrap().is_none());
        assert!(cache.exr(0).is_file());
        assert_eq!(cache.load(1).unwrap().data[0], [0.5; 3]);
        // Different ref-spp: everything goes.
        let other = ReferenceCache::new(tmp.path(), key(32));
        assert_eq!(other.missing(), vec![0, 1, 2]);
        let note = other.prepare().unwrap().expect("a note about re-rendering");
        assert!(note.contains("16 spp → 8x8, 3 frames, 32 spp"), "{note}");
        assert!(!other.exr(0).is_file() && !other.png(1).is_file());
        assert!(other.key_matches() && !cache.key_matches());
        // A key file this version cannot read (e.g. an older format) also re-renders.
        std::fs::write(
            tmp.path().join("reference/reference.json"),
            "{\"scene\": 1}",
        )
        .unwrap();
        assert_eq!(other.missing(), vec![0, 1, 2]);
        let note = other.prepare().unwrap().expect("a note");
        assert!(note.contains("unreadable"), "{note}");
        assert!(other.key_matches());
    }

    /// Defect: a cached EXR cut to 0 bytes (a crash without fsync) was "reused" and
    /// then failed every later eval; now it is re-rendered with a warning.
    #[test]
    fn cut_or_wrong_sized_frames_are_missing_not_reused() {
        let tmp = tempfile::tempdir().unwrap();
        let cache = ReferenceCache::new(tmp.path(), key(16));
        cache.prepare().unwrap();
        for f in 0..3 {
            cache.store(f, &Rgb32Image::filled(8, 8, [0.5; 3])).unwrap();
        }
        assert!(cache.missing().is_empty());
        std::fs::write(cache.exr(0), b"").unwrap();
        std::fs::write(cache.png(2), b"\x89PNG").unwrap();
        let state = cache.state();
        assert_eq!(state.missing, vec![0, 2]);
        assert_eq!(state.unreadable.len(), 2);
        assert!(state.unreadable[0].0.ends_with("0000.exr"));
        // The other frames' files are whole: written to a temporary name and renamed.
        let leftovers: Vec<_> = std::fs::read_dir(&cache.dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
    }
}
