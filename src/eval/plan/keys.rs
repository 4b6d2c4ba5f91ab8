//! The keys an eval's files are made under: a file is reused only under an equal key.
//!
//! A reference frame's key ([`ReferenceKey`], kept as `reference.json` beside the
//! frames) holds a hash of the **content** of everything a reference depends on, not of
//! names: the scene, the transfer functions it loads, the volume's voxels (whichever
//! files they came from: NRRD data files, DICOM slices, sidecars, or a procedural
//! generator), the environment map's texels, the path tracer's SPIR-V and the settings.
//! A scene result's key ([`ResultKey`], in `result.json`) adds what the scores depend on
//! beyond the references.

use super::settings::EvalArgs;
use anyhow::{Context, Result};
use dvr_engine::renderer::medium::load_channels;
use dvr_engine::renderer::scene_setup::{load_environment, load_volume, on_demand};
use dvr_engine::scene::Scene;
use dvr_engine::volume::Volume;
use serde::{Deserialize, Serialize};

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

    /// The settings a user sets, for messages.
    pub fn describe(&self) -> String {
        format!(
            "{}, {}x{}, {} frames, {} spp",
            self.scene, self.width, self.height, self.frames, self.ref_spp
        )
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
    let mut write_volume = |volume: &Volume| {
        for d in volume.dims {
            h.write(&d.to_le_bytes());
        }
        for x in volume.spacing.iter().chain(&volume.window) {
            h.write(&x.to_le_bytes());
        }
        h.write(volume.data.as_bytes());
    };
    let loading = || format!("loading the volume of {}", scene.name);
    if let Some(v) = on_demand(scene, volume_size) {
        h.write(v.identity.as_bytes());
    } else if let Some(channels) = load_channels(scene).with_context(loading)? {
        // A medium of channels and time points: every channel at every time point.
        for c in &channels.volumes {
            write_volume(c);
        }
        for t in 1..channels.series.info().times {
            for c in channels.series.read(t).with_context(loading)? {
                write_volume(&c);
            }
        }
    } else {
        write_volume(&load_volume(scene, volume_size).with_context(loading)?);
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

/// What a scene's results depend on beyond its references.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultKey {
    /// The references' key (scene content, size, frames, ref-spp, path tracer).
    pub references: ReferenceKey,
    pub methods: Vec<String>,
    pub spp: u32,
    pub motion: String,
    pub aux: bool,
    /// Whether the accumulation baseline was measured (`--no-baseline` leaves it out);
    /// results written before the option had it.
    #[serde(default = "measured")]
    pub baseline: bool,
    /// Every shader, so results of another build of dvr are not merged with these.
    pub shaders: String,
    /// The denoiser parameter overrides in the environment (`DVR_OURS`, …) that are set.
    pub overrides: Vec<(String, String)>,
}

fn measured() -> bool {
    true
}

impl ResultKey {
    pub fn new(args: &EvalArgs, methods: &[String], spp: u32, references: &ReferenceKey) -> Self {
        Self {
            references: references.clone(),
            methods: methods.to_vec(),
            spp,
            motion: args.render.motion.to_string(),
            aux: args.aux,
            baseline: !args.no_baseline,
            shaders: shaders_hash(),
            overrides: dvr_engine::denoise::override_variables()
                .into_iter()
                .filter_map(|v| Some((v.to_string(), std::env::var(v).ok()?)))
                .collect(),
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A small built-in scene of three frames.
    pub(crate) fn scene() -> Scene {
        Scene::builtin("cloud/orbit")
            .unwrap()
            .with_frames(3)
            .unwrap()
    }

    /// [`scene`]'s key at 8x8 with `spp` reference samples.
    pub(crate) fn key(spp: u32) -> ReferenceKey {
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
