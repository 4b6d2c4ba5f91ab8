//! The reference cache: `DIR/reference/NNNN.{exr,png}` plus `reference.json`, the key
//! they were rendered under (`dvr eval` keeps one per scene folder, `dvr reference` one
//! in its `--out`). Frames are reused only when the key matches and the frame reads
//! back; a different key re-renders them all, an unreadable frame is re-rendered with a
//! warning. The key holds a hash of the **content** of everything a reference depends
//! on, not of names: the scene, the transfer functions it loads, the volume's voxels
//! (whichever files they came from: NRRD data files, DICOM slices, sidecars, or a
//! procedural generator), the environment map's texels, the path tracer's SPIR-V and
//! the settings. Every file is written under a temporary name, flushed to disk and
//! renamed, so an interrupted run never leaves a file that looks finished.
//!
//! Several processes may use one folder at once (shards of one reference, two evals
//! with one `--out`) only when their keys are equal: a run first *claims* the folder
//! ([`ReferenceCache::claim`]), which refuses it, naming the other run, while a live run
//! with another key holds a claim there. So every frame in a folder is one its key
//! describes, whatever runs in parallel; runs with equal keys render frames whose bytes
//! are equal, written atomically, so which of them writes a frame does not matter.

use crate::setup::Setup;
use anyhow::{Context, Result};
use dvr_engine::files::Durability;
use dvr_engine::image_io::{encode_exr, encode_png, read_exr, to_rgb, write_file};
use dvr_engine::metrics::Rgb32Image;
use dvr_engine::renderer::scene_setup::{load_environment, load_volume, on_demand};
use dvr_engine::scene::Scene;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Age past which a temporary file in the cache is the leftover of a killed writer.
const STALE_TEMPORARY: std::time::Duration = std::time::Duration::from_secs(600);

/// What a reference frame depends on. Written before the first frame is rendered, so
/// frames finished under it are reusable after an interruption.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ReferenceKey {
    pub scene: String,
    /// Hash of the scene as TOML (camera path, lights, render settings, file names), so
    /// an edited scene file invalidates its references.
    pub scene_hash: String,
    /// Hash of what the scene's files hold: both transfer functions' control points,
    /// the volume's dims, spacing, window and voxels, and the environment map's texels.
    /// Editing a TF file or replacing a volume changes it though no name changes.
    pub content_hash: String,
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub ref_spp: u32,
    pub volume_size: u32,
    /// Hash of the SPIR-V that makes references (path tracing and accumulation), so a
    /// change to the path tracer invalidates them.
    pub renderer_hash: String,
}

impl ReferenceKey {
    /// The key of `scene`'s references; loads its volume and environment map to hash
    /// their content.
    pub fn new(scene: &Scene, size: (u32, u32), ref_spp: u32, volume_size: u32) -> Result<Self> {
        let toml = scene
            .to_toml()
            .with_context(|| format!("describing scene {}", scene.name))?;
        Ok(Self {
            scene: scene.name.clone(),
            scene_hash: ContentHash::of(toml.as_bytes()),
            content_hash: content_hash(scene, volume_size)?,
            width: size.0,
            height: size.1,
            frames: scene.frames,
            ref_spp,
            volume_size,
            renderer_hash: renderer_hash(),
        })
    }
}

/// See [`ReferenceKey::content_hash`].
fn content_hash(scene: &Scene, volume_size: u32) -> Result<String> {
    let mut h = ContentHash::new();
    h.write(scene.tf_a.to_toml().as_bytes());
    if let Some(b) = &scene.tf_b {
        h.write(b.to_toml().as_bytes());
    }
    // A volume made on demand is named by its generator and size (its voxels are made
    // brick by brick and never held whole).
    if let Some(v) = on_demand(scene, volume_size) {
        h.write(v.identity.as_bytes());
    } else {
        let volume = load_volume(scene, volume_size)
            .with_context(|| format!("loading the volume of {}", scene.name))?;
        for d in volume.dims {
            h.write(&d.to_le_bytes());
        }
        for x in volume.spacing.iter().chain(&volume.window) {
            h.write(&x.to_le_bytes());
        }
        h.write(volume.data.as_bytes());
    }
    let environment = load_environment(&scene.lights)
        .with_context(|| format!("loading the environment map of {}", scene.name))?;
    if let Some(env) = environment {
        h.write(&env.width.to_le_bytes());
        h.write(&env.height.to_le_bytes());
        let texels: Vec<u8> = env
            .rgba
            .iter()
            .flatten()
            .flat_map(|c| c.to_le_bytes())
            .collect();
        h.write(&texels);
    }
    Ok(h.finish())
}

/// Hash of the shaders a reference depends on.
fn renderer_hash() -> String {
    let mut h = ContentHash::new();
    for (name, spirv) in dvr_engine::shaders::SHADERS {
        if matches!(*name, "path_trace" | "accumulate") {
            h.write(name.as_bytes());
            h.write(spirv);
        }
    }
    h.finish()
}

/// Hash of every shader dvr runs: results of another build are not mixed with these.
pub fn shaders_hash() -> String {
    let mut h = ContentHash::new();
    for (name, spirv) in dvr_engine::shaders::SHADERS {
        h.write(name.as_bytes());
        h.write(spirv);
    }
    h.finish()
}

/// FNV-1a (64-bit) over 8-byte words, each chunk's length mixed in: a stable hash (the
/// key files outlive compiler versions, unlike `std`'s hasher) that reads a gigabyte
/// volume in well under a second. A cache key, not a signature.
struct ContentHash(u64);

impl ContentHash {
    const PRIME: u64 = 0x0100_0000_01b3;

    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn of(bytes: &[u8]) -> String {
        let mut h = Self::new();
        h.write(bytes);
        h.finish()
    }

    fn mix(&mut self, word: u64) {
        self.0 = (self.0 ^ word).wrapping_mul(Self::PRIME);
    }

    fn write(&mut self, bytes: &[u8]) {
        self.mix(bytes.len() as u64);
        let mut words = bytes.chunks_exact(8);
        for w in &mut words {
            self.mix(u64::from_le_bytes(w.try_into().unwrap_or([0; 8])));
        }
        for &b in words.remainder() {
            self.mix(u64::from(b));
        }
    }

    fn finish(&self) -> String {
        format!("{:016x}", self.0)
    }
}

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

impl ReferenceKey {
    /// The settings a user sets, for messages.
    fn describe(&self) -> String {
        format!(
            "{}, {}x{}, {} frames, {} spp",
            self.scene, self.width, self.height, self.frames, self.ref_spp
        )
    }
}

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

    pub fn key(&self) -> &ReferenceKey {
        &self.key
    }

    fn key_path(&self) -> PathBuf {
        self.dir.join("reference.json")
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

    pub fn exr(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.exr", frame_name(f)))
    }

    pub fn png(&self, f: u32) -> PathBuf {
        self.dir.join(format!("{}.png", frame_name(f)))
    }

    fn stored_key(&self) -> Option<ReferenceKey> {
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
    fn prepare(&self) -> Result<Option<String>> {
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

    /// Renders frame `f` in as few dispatches as the device takes (one per frame on a
    /// GPU at 256x256; lavapipe's loop limiter needs 4-sample ones).
    pub fn render(
        &self,
        setup: &Setup,
        session: &mut dvr_engine::session::Session,
        f: u32,
    ) -> Result<Rgb32Image> {
        let batch = session.renderer()?.samples_per_dispatch();
        let pixels = session.reference_at(f, self.key.ref_spp, batch)?;
        Ok(to_rgb(setup.width(), setup.height(), &pixels))
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

    /// Brings the cache up to date: reuses what is there, warns about and re-renders
    /// unreadable frames, renders the rest with a renderer made by `setup` only when
    /// some frame is missing. Returns the run's claim on the folder (keep it while the
    /// frames are read) and what it rendered.
    pub fn fill(&self, setup: &Setup, report: &mut dyn FillReport) -> Result<Filled> {
        let all: Vec<u32> = (0..self.key.frames).collect();
        self.fill_frames(setup, report, &all)
    }

    /// [`ReferenceCache::fill`] for the frames `wanted` only (`dvr reference
    /// --frame-range`/`--shard`). Each frame's image depends on nothing but the key and
    /// its index (the renderer renders references only, from the reference stream), so
    /// frames rendered by separate runs are the frames one run renders.
    pub fn fill_frames(
        &self,
        setup: &Setup,
        report: &mut dyn FillReport,
        wanted: &[u32],
    ) -> Result<Filled> {
        let claim = self.claim()?;
        let mut state = self.state();
        state.missing.retain(|f| wanted.contains(f));
        state.unreadable.retain(|(path, _)| {
            wanted
                .iter()
                .any(|&f| *path == self.exr(f) || *path == self.png(f))
        });
        let reused = wanted.len() - state.missing.len();
        for (path, why) in &state.unreadable {
            report.note(None);
            log::warn!(
                "{}: cached reference does not read back ({why}); re-rendering it",
                path.display()
            );
        }
        if let Some(changed) = &claim.note {
            report.note(Some(changed));
        }
        if state.missing.is_empty() {
            report.note(Some(&format!(
                "reusing {reused} reference frame(s) in {}",
                self.dir.display()
            )));
            return Ok(Filled {
                claim,
                rendered: Vec::new(),
                reused: wanted.to_vec(),
            });
        }
        if reused > 0 {
            report.note(Some(&format!(
                "reusing {reused} reference frame(s), rendering {}",
                state.missing.len()
            )));
        }
        // The same renderer set-up for `dvr reference` and `dvr eval`, so their cached
        // frames are identical.
        let mut session = setup.session(&["none"])?;
        report.rendered(0, state.missing.len());
        for (i, &f) in state.missing.iter().enumerate() {
            let img = self.render(setup, &mut session, f)?;
            report.store(self, f, img)?;
            report.rendered(i + 1, state.missing.len());
        }
        report.finished(session.renderer()?)?;
        Ok(Filled {
            claim,
            reused: wanted
                .iter()
                .copied()
                .filter(|f| !state.missing.contains(f))
                .collect(),
            rendered: state.missing,
        })
    }
}

/// What [`ReferenceCache::fill_frames`] did: the claim to keep while the frames are
/// read, and which of the wanted frames it rendered and which it found done.
pub struct Filled {
    pub claim: Claim,
    pub rendered: Vec<u32>,
    pub reused: Vec<u32>,
}

/// How [`ReferenceCache::fill`] tells the user what it does, and how it writes frames.
pub trait FillReport {
    /// A line for the log (`None`: only end a progress line, a warning follows).
    fn note(&mut self, text: Option<&str>);
    /// `done` of `of` frames rendered.
    fn rendered(&mut self, done: usize, of: usize);
    /// Writes rendered frame `f` through [`ReferenceCache::store`]: here at once;
    /// `dvr eval` hands it to a worker thread while the next frame renders.
    fn store(&mut self, cache: &ReferenceCache, f: u32, img: Rgb32Image) -> Result<()> {
        cache.store(f, &img)
    }
    /// Every missing frame has been rendered by `renderer` (and handed to
    /// [`FillReport::store`]): wait for writes still running, count GPU time.
    fn finished(&mut self, _renderer: &dvr_engine::renderer::Renderer) -> Result<()> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene() -> Scene {
        Scene::builtin("cloud/orbit")
            .unwrap()
            .with_frames(3)
            .unwrap()
    }

    fn key(spp: u32) -> ReferenceKey {
        ReferenceKey::new(&scene(), (8, 8), spp, 16).unwrap()
    }

    #[test]
    fn key_depends_on_settings_and_scene() {
        assert_eq!(key(16), key(16));
        assert_ne!(key(16), key(32));
        let b = Scene::builtin("cloud/point-light")
            .unwrap()
            .with_frames(3)
            .unwrap();
        let kb = ReferenceKey::new(&b, (8, 8), 16, 16).unwrap();
        assert_ne!(key(16).scene_hash, kb.scene_hash);
        // A different procedural volume: same scene text, other voxels.
        let k32 = ReferenceKey::new(&scene(), (8, 8), 16, 32).unwrap();
        assert_ne!(key(16).content_hash, k32.content_hash);
        // A cut is part of the scene: references of a cut view are not the uncut ones.
        let mut cut = scene();
        cut.cut.planes.push(dvr_engine::scene::ClipPlane {
            point: glam::DVec3::ZERO,
            normal: glam::DVec3::Z,
            enabled: true,
        });
        let kc = ReferenceKey::new(&cut, (8, 8), 16, 16).unwrap();
        assert_ne!(key(16).scene_hash, kc.scene_hash);
    }

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

    #[test]
    fn content_hash_is_stable_and_length_aware() {
        assert_eq!(ContentHash::of(b"abc"), ContentHash::of(b"abc"));
        assert_ne!(ContentHash::of(b"abc"), ContentHash::of(b"abd"));
        let mut a = ContentHash::new();
        a.write(b"ab");
        a.write(b"c");
        let mut b = ContentHash::new();
        b.write(b"a");
        b.write(b"bc");
        assert_ne!(a.finish(), b.finish(), "chunk boundaries count");
        // Pinned: keys written by earlier runs must keep matching.
        assert_eq!(ContentHash::of(b""), "af63bd4c8601b7df");
    }
}
