//! The reference cache: `DIR/<scene>/reference/NNNN.{exr,png}` plus `reference.json`,
//! the settings they were rendered with. Frames are reused when the key matches, so an
//! interrupted eval resumes where it stopped; a different key re-renders them all.

use crate::setup::Setup;
use anyhow::{Context, Result};
use dvr_engine::image_io::{read_exr, to_rgb, write_exr, write_png};
use dvr_engine::metrics::Rgb32Image;
use dvr_engine::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// What a reference frame depends on. Written before the first frame is rendered, so
/// frames finished under it are reusable after an interruption.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReferenceKey {
    pub scene: String,
    /// FNV-1a of the scene as TOML (camera path, lights, TFs, render settings), so an
    /// edited scene file invalidates its references.
    pub scene_hash: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub ref_spp: u32,
    pub volume_size: u32,
    /// FNV-1a of the SPIR-V that makes references (path tracing and accumulation), so a
    /// change to the path tracer invalidates them.
    pub renderer_hash: String,
}

impl ReferenceKey {
    pub fn new(scene: &Scene, size: (u32, u32), ref_spp: u32, volume_size: u32) -> Result<Self> {
        let toml = scene
            .to_toml()
            .with_context(|| format!("describing scene {}", scene.name))?;
        Ok(Self {
            scene: scene.name.clone(),
            scene_hash: format!("{:016x}", fnv1a(toml.as_bytes())),
            width: size.0,
            height: size.1,
            frames: scene.frames,
            ref_spp,
            volume_size,
            renderer_hash: renderer_hash(),
        })
    }
}

/// Hash of the shaders a reference depends on.
fn renderer_hash() -> String {
    let mut bytes = Vec::new();
    for (name, spirv) in dvr_engine::shaders::SHADERS {
        if matches!(*name, "path_trace" | "accumulate") {
            bytes.extend_from_slice(name.as_bytes());
            bytes.extend_from_slice(spirv);
        }
    }
    format!("{:016x}", fnv1a(&bytes))
}

fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

pub fn frame_name(f: u32) -> String {
    format!("{f:04}")
}

/// One scene's reference folder.
#[derive(Clone, Debug)]
pub struct ReferenceCache {
    pub dir: PathBuf,
    key: ReferenceKey,
}

impl ReferenceCache {
    pub fn new(scene_dir: &Path, key: ReferenceKey) -> Self {
        Self {
            dir: scene_dir.join("reference"),
            key,
        }
    }

    fn key_path(&self) -> PathBuf {
        self.dir.join("reference.json")
    }

    /// What differs between the stored key and this one, for the log.
    fn change_note(&self, old: &ReferenceKey) -> String {
        format!(
            "reference settings changed ({}x{}, {} frames, {} spp → {}x{}, {} frames, {} spp{}), re-rendering",
            old.width,
            old.height,
            old.frames,
            old.ref_spp,
            self.key.width,
            self.key.height,
            self.key.frames,
            self.key.ref_spp,
            match (
                old.scene_hash != self.key.scene_hash,
                old.renderer_hash != self.key.renderer_hash
            ) {
                (true, _) => ", scene edited",
                (false, true) => ", path tracer changed",
                _ => "",
            }
        )
    }

    pub fn exr(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.exr", frame_name(f)))
    }

    pub fn png(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.png", frame_name(f)))
    }

    fn stored_key(&self) -> Option<ReferenceKey> {
        let text = std::fs::read_to_string(self.key_path()).ok()?;
        serde_json::from_str(&text).ok()
    }

    /// True when the stored key matches (the frames on disk may be reused).
    pub fn key_matches(&self) -> bool {
        self.stored_key().as_ref() == Some(&self.key)
    }

    /// Frames still to render: all when the key differs, else those missing on disk.
    pub fn missing(&self) -> Vec<u32> {
        let matches = self.key_matches();
        (0..self.key.frames)
            .filter(|&f| !matches || !self.exr(f).is_file() || !self.png(f).is_file())
            .collect()
    }

    /// Makes the folder consistent with this key before rendering: a different (or
    /// unreadable) key removes the old frames and writes the new key. Returns a note for
    /// the log when something was thrown away.
    pub fn prepare(&self) -> Result<Option<String>> {
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
        for entry in std::fs::read_dir(&self.dir)
            .with_context(|| format!("reading {}", self.dir.display()))?
        {
            let path = entry?.path();
            let is_frame = path
                .file_stem()
                .and_then(|s| s.to_str())
                .is_some_and(|s| s.len() == 4 && s.bytes().all(|b| b.is_ascii_digit()));
            let ext = path.extension().and_then(|e| e.to_str());
            if is_frame && matches!(ext, Some("exr" | "png")) {
                std::fs::remove_file(&path)
                    .with_context(|| format!("removing stale {}", path.display()))?;
            }
        }
        let json = serde_json::to_string_pretty(&self.key)?;
        std::fs::write(self.key_path(), json)
            .with_context(|| format!("writing {}", self.key_path().display()))?;
        Ok(note)
    }

    /// Renders frame `f` in as few dispatches as the device takes (one per frame on a
    /// GPU at 256x256; lavapipe's loop limiter needs 4-sample ones).
    pub fn render(
        &self,
        setup: &Setup,
        renderer: &mut dvr_engine::renderer::Renderer,
        f: u32,
    ) -> Result<Rgb32Image> {
        let batch = renderer.samples_per_dispatch();
        let pixels = renderer.reference(&setup.inputs(f), self.key.ref_spp, batch)?;
        Ok(to_rgb(setup.width(), setup.height(), &pixels))
    }

    /// Stores rendered frame `f` (eval writes it on a worker thread while the next one
    /// renders); the EXR is written under a temporary name and renamed, so an
    /// interruption never leaves a truncated frame that looks finished.
    pub fn store(&self, f: u32, img: &Rgb32Image) -> Result<()> {
        write_png(&self.png(f), img)?;
        let tmp = self.dir.join(format!("{}.partial.exr", frame_name(f)));
        write_exr(&tmp, img)?;
        std::fs::rename(&tmp, self.exr(f))
            .with_context(|| format!("renaming {} to {}", tmp.display(), self.exr(f).display()))
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

    fn key(spp: u32) -> ReferenceKey {
        let scene = Scene::builtin("cloud/orbit")
            .unwrap()
            .with_frames(3)
            .unwrap();
        ReferenceKey::new(&scene, (8, 8), spp, 16).unwrap()
    }

    #[test]
    fn key_depends_on_settings_and_scene() {
        assert_eq!(key(16), key(16));
        assert_ne!(key(16), key(32));
        let a = Scene::builtin("cloud/orbit")
            .unwrap()
            .with_frames(3)
            .unwrap();
        let b = Scene::builtin("cloud/point-light")
            .unwrap()
            .with_frames(3)
            .unwrap();
        let ka = ReferenceKey::new(&a, (8, 8), 16, 16).unwrap();
        let kb = ReferenceKey::new(&b, (8, 8), 16, 16).unwrap();
        assert_ne!(ka.scene_hash, kb.scene_hash);
    }

    #[test]
    fn mismatched_key_clears_frames_and_matching_key_keeps_them() {
        let tmp = tempfile::tempdir().unwrap();
        let cache = ReferenceCache::new(tmp.path(), key(16));
        assert_eq!(cache.missing(), vec![0, 1, 2]);
        assert!(cache.prepare().unwrap().is_none());
        let img = Rgb32Image::filled(8, 8, [0.5; 3]);
        for f in 0..2 {
            write_exr(&cache.exr(f), &img).unwrap();
            write_png(&cache.png(f), &img).unwrap();
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
}
