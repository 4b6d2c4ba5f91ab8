//! Scenes: what to render (volume, transfer functions, camera, lights, render settings)
//! and how it moves over a scripted sequence of frames.
//!
//! No GPU: this crate builds and tests without a Vulkan loader (`cargo test -p
//! dvr-scene`), and the engine re-exports it as `dvr_engine::scene`, with its
//! [`transfer`] module (transfer functions and their presets) as `dvr_engine::transfer`.
//! The limits the GPU's frame block is sized by ([`MAX_LIGHTS`], [`MAX_CLIP_PLANES`],
//! [`MAX_CHANNELS`], [`transfer::LUT_SIZE`]) are declared here, where scenes are
//! checked against them; the engine's shader layer takes them from here.
//!
//! A scene is a TOML file, or one of the 30 built-in scenes (`<dataset>/<animation>`,
//! see [`builtin`]). The renderer never reads the file itself: it asks a [`Scene`] for
//! the [`FrameState`] of each frame (camera with its matrices, lights, TF blend),
//! uploads the TF LUTs from [`Scene::tf_luts`], specialises its pipeline from
//! [`Scene::render`] (its [`PipelineKey`]) and the lights, and uses [`changed`] between consecutive frames to decide which
//! history to reset. Scripted animations are what makes denoisers comparable: every
//! method sees exactly the same sequence, and `with_frames` resamples it for an 8-frame
//! test or a 120-frame evaluation.
//!
//! # Conventions
//!
//! - **World space** is set by the volume: centred at the origin, longest side 1.0
//!   world unit, voxel axes i, j, k along x, y, z; right-handed. Built-in scenes use
//!   +z as up (superior, for RAS medical volumes). See [`volume`].
//! - **Extinction** `μt = TF opacity × volume.density_scale` per world unit.
//! - **Camera**: right-handed view space; Vulkan clip space (y down, depth 0..1). See
//!   [`camera`].
//! - **Light units**: see [`light`]. Radiance on lit surfaces of the built-in scenes is
//!   of order 1.
//! - **Animation**: keyframe tracks per property, linear or step; orbits as a rate. See
//!   [`animation`]. Frames default to 60.
//! - Relative paths in a scene file are relative to the file's folder.
//!
//! # File format
//!
//! Sections: `[volume]` and `[transfer]` are required, `[camera]`, `[render]` and
//! `[animation]` are optional, and `[[light]]` is needed at least once unless
//! `render.emission = true`. Unknown fields are errors. This is
//! `assets/scenes/example.toml`, which uses every section (a test loads it):
//!
//! ```toml
#![doc = include_str!("../../../assets/scenes/example.toml")]
//! ```

pub mod animation;
pub mod builtin;
pub mod camera;
pub mod channel;
pub mod cut;
pub mod error;
mod file;
pub mod frame;
pub mod labels;
pub mod light;
pub mod render;
pub mod transfer;
pub mod transfer_ref;
pub mod view;
pub mod volume;

#[cfg(test)]
mod tests;

use std::path::Path;

pub use animation::{
    Animation, CameraKey, ChannelKey, ClipKey, CropKey, Interpolation, LabelKey, LightKey, Orbit,
    TfKey, TimeKey, DEFAULT_FRAMES,
};
pub use camera::{Camera, CameraSpec, CAMERA_FAR, CAMERA_NEAR, MAX_CAMERA_DISTANCE};
pub use channel::{ChannelFile, ChannelSpec, ChannelView, MAX_CHANNELS};
pub use cut::{ClipPlane, CropBox, CropUnits, Cut, MAX_CLIP_PLANES};
pub use dvr_volume::bytes::parse_memory_size;
pub use error::{SceneError, SettingError};
pub use frame::{changed, Change, FrameState};
pub use labels::{LabelFile, LabelMode, LabelView, LabelsSpec};
pub use light::{
    AreaLight, EnvMode, EnvSource, EnvironmentLight, Facing, Light, LightKind, PointLight,
    MAX_LIGHTS,
};
pub use render::{parse_gpu_memory, Estimator, Phase, PipelineKey, RenderSettings, MAX_BOUNCES};
pub use transfer_ref::TransferSpec;
pub use view::{TfState, View, ViewSections};
pub use volume::{BuiltinVolume, RawLayout, VolumeSource, VolumeSpec};

use crate::transfer::{TfLut, TransferFunction};
use error::Ctx;

/// A checked scene: everything needed to render any of its frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The file's `name`, its file stem, or `<dataset>/<animation>` for a built-in.
    pub name: String,
    pub volume: VolumeSpec,
    /// Where the TFs came from (what [`Scene::to_toml`] writes).
    pub transfer: TransferSpec,
    /// The TF at rest (blend 0), loaded from `transfer.a`. An editor may change it in
    /// place; `to_toml` still writes `transfer.a`, so save the TF itself too.
    pub tf_a: TransferFunction,
    /// The blend target (blend 1), loaded from `transfer.b`.
    pub tf_b: Option<TransferFunction>,
    /// The camera at rest; animation may override it per frame.
    pub camera: CameraSpec,
    /// The lights at rest, in file order (animation keys refer to these indices).
    pub lights: Vec<Light>,
    pub render: RenderSettings,
    /// The clip planes and crop box at rest (`[[clip]]`, `[crop]`); animation may
    /// override them per frame.
    pub cut: Cut,
    /// Number of frames in the scripted sequence (>= 1).
    pub frames: u32,
    pub animation: Animation,
    /// The `[[channel]]` sections, in channel order.
    pub channels: Vec<ChannelSpec>,
    /// Every channel of a multi-channel medium as its views start (empty for one
    /// field): filled when the scene meets its volume (`SceneSetup`), which knows the
    /// channels' names, windows and colours.
    pub channel_views: Vec<ChannelView>,
    /// `[labels]`: the label map beside the volume, its table and mode.
    pub labels: Option<LabelsSpec>,
    /// The `[[label]]` sections, in file order.
    pub label_sections: Vec<LabelFile>,
    /// Every label of the map as its views start (sorted by value; empty without a
    /// map): filled when the scene meets its label map (`SceneSetup`).
    pub label_views: Vec<LabelView>,
}

/// Longest scene name, in bytes (checked with the rest of a scene by `Scene::check`).
pub const MAX_NAME_BYTES: usize = 200;

impl Scene {
    /// Reads and checks a scene file. Relative paths inside it are relative to its
    /// folder.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, SceneError> {
        let path = path.as_ref();
        let text = dvr_volume::files::read_text(path, dvr_volume::files::MAX_TEXT_FILE_BYTES)
            .map_err(|source| SceneError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        file::parse(&text, &path.display().to_string(), path.parent())
    }

    /// Parses and checks scene text. `origin` names it in error messages and gives the
    /// default name (its file stem); relative paths stay relative to the working
    /// directory.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SceneError> {
        file::parse(text, origin, None)
    }

    /// A built-in scene (`<dataset>/<animation>`) if `name_or_path` is one, else the
    /// scene file at that path: what `--scene` accepts.
    pub fn open(name_or_path: &str) -> Result<Self, SceneError> {
        if Self::builtin_names().iter().any(|n| n == name_or_path) {
            Self::builtin(name_or_path)
        } else {
            Self::load(name_or_path)
        }
    }

    /// A built-in scene, e.g. `"phantom/orbit"`, with [`DEFAULT_FRAMES`] frames.
    pub fn builtin(name: &str) -> Result<Self, SceneError> {
        builtin::build(name)
    }

    /// All built-in scene names: `<dataset>/<animation>` for the datasets `phantom`,
    /// `mri`, `cloud` and the animations in [`builtin::ANIMATIONS`].
    pub fn builtin_names() -> Vec<String> {
        builtin::names()
    }

    /// The same scene resampled to `frames` frames (keyframes scale proportionally,
    /// orbits keep their rate; see [`animation`]).
    pub fn with_frames(&self, frames: u32) -> Result<Self, SceneError> {
        if frames == 0 {
            return Err(SceneError::Invalid {
                origin: self.name.clone(),
                field: "animation.frames".into(),
                message: "must be at least 1".into(),
            });
        }
        Ok(Self {
            frames,
            animation: self.animation.rescaled(self.frames, frames),
            ..self.clone()
        })
    }

    /// The scene as a TOML file that [`Scene::from_toml_str`] reads back into an equal
    /// scene (with `tf_a`/`tf_b` reloaded from `transfer`).
    pub fn to_toml(&self) -> Result<String, SceneError> {
        file::write(self)
    }

    /// Checks a scene built or edited in code, as loading checks a file. Errors name
    /// the scene by its `name`.
    pub fn validate(&self) -> Result<(), SceneError> {
        self.check(&Ctx {
            origin: &self.name,
            base: None,
        })
    }

    /// The TF LUTs at blend 0 and 1 (`b` = `a` when the scene has no blend target). A
    /// renderer that blends on the GPU uploads both; see also [`Scene::tf_lut`].
    pub fn tf_luts(&self) -> (TfLut, TfLut) {
        let a = self.tf_a.lut();
        let b = self
            .tf_b
            .as_ref()
            .map_or_else(|| a.clone(), TransferFunction::lut);
        (a, b)
    }

    /// The LUT in effect at a blend and shift ([`FrameState::tf_blend`],
    /// [`FrameState::tf_shift`]).
    pub fn tf_lut(&self, blend: f32, shift: f32) -> TfLut {
        let (a, b) = self.tf_luts();
        TfLut::lerp(&a, &b, blend).shifted(shift)
    }

    pub(crate) fn check(&self, ctx: &Ctx) -> Result<(), SceneError> {
        // The name becomes a folder name (at most 255 bytes) and a label on every
        // progress line: a long one is refused here, before anything echoes it.
        if self.name.len() > MAX_NAME_BYTES {
            return Err(ctx.invalid(
                "name",
                format!(
                    "{} bytes long; a scene name may have at most {MAX_NAME_BYTES}",
                    self.name.len()
                ),
            ));
        }
        self.volume.check(ctx)?;
        self.check_channel_sections(ctx)?;
        labels::check_sections(ctx, self.labels.as_ref(), &self.label_sections)?;
        if self.labels.is_none() && !self.animation.label.is_empty() {
            return Err(ctx.invalid(
                "animation.label",
                "label keys without a [labels] file = \"...\" to apply to",
            ));
        }
        let tf_err = |field: &str| {
            let field = field.to_string();
            move |source| SceneError::Transfer {
                origin: ctx.origin.to_string(),
                field,
                source: Box::new(source),
            }
        };
        self.tf_a.validate().map_err(tf_err("transfer.a"))?;
        if let Some(b) = &self.tf_b {
            b.validate().map_err(tf_err("transfer.b"))?;
        }
        self.camera.check(ctx, "camera")?;
        light::check_lights(ctx, &self.lights, self.render.emission())?;
        self.cut.check(ctx)?;
        self.render.check(ctx)?;
        self.animation.check(
            ctx,
            self.frames,
            &self.camera,
            &self.lights,
            self.tf_b.is_some(),
            &self.cut,
        )?;
        // The crop box where keyframes put it (corners interpolate linearly, so a box
        // valid at its keyframes is valid between them).
        for (i, k) in self.animation.crop.iter().enumerate() {
            if let Some(crop) = self.cut_at(k.frame).crop {
                crop.check(ctx, &format!("animation.crop[{i}]"))?;
            }
        }
        // The camera must be well defined where keyframes put it, and in between.
        for (i, k) in self.animation.camera.iter().enumerate() {
            self.camera_at(k.frame)
                .check(ctx, &format!("animation.camera[{i}]"))?;
        }
        for f in self.camera_closest_approaches() {
            self.camera_at(f)
                .check(ctx, &format!("animation.camera (frame {f})"))?;
        }
        Ok(())
    }

    /// The frames where the camera comes closest to its target, or to looking along its
    /// up vector, between keyframes. Between two consecutive keyframe frames a and b
    /// every track is linear (or held), so the view direction is affine in the frame
    /// on [a, b − 1], and the minimum of |direction| (or of |direction × up|) over
    /// that range is at the integer frames around the continuous minimum. An orbit
    /// keeps both constant, so it needs none.
    /// `[[channel]]` sections and channel keys need a volume that can hold channels (a
    /// file read as a series, or `files`): a built-in or raw volume has one field, and
    /// sections on it would be ignored without a word.
    fn check_channel_sections(&self, ctx: &Ctx) -> Result<(), SceneError> {
        let one_field = matches!(
            &self.volume.source,
            VolumeSource::Builtin { .. } | VolumeSource::File { raw: Some(_), .. }
        );
        let why = "a built-in or raw volume has one field; channels come from `[volume] file` \
                   (a file of channels) or `files` (one per file)";
        if one_field && !self.channels.is_empty() {
            return Err(ctx.invalid("channel", why));
        }
        if one_field && !self.animation.channel.is_empty() {
            return Err(ctx.invalid("animation.channel", why));
        }
        Ok(())
    }

    fn camera_closest_approaches(&self) -> Vec<u32> {
        if self.animation.orbit.is_some() || self.animation.camera.is_empty() {
            return Vec::new();
        }
        let last = self.frames.saturating_sub(1);
        let mut stops: Vec<u32> = self
            .animation
            .camera
            .iter()
            .map(|k| k.frame.min(last))
            .chain([0, last])
            .collect();
        stops.sort_unstable();
        stops.dedup();
        let dir = |f: u32| {
            let c = self.camera_at(f);
            c.target - c.position
        };
        let up = self.camera.up.normalize_or(glam::DVec3::Z);
        let mut out = Vec::new();
        for w in stops.windows(2) {
            let (a, b) = (w[0], w[1] - 1);
            if b <= a {
                continue;
            }
            let (d0, d1) = (dir(a), dir(b));
            for (v0, v1) in [(d0, d1), (d0.cross(up), d1.cross(up))] {
                let e = v1 - v0;
                let s = if e.length_squared() > 0.0 {
                    (-v0.dot(e) / e.length_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let f = f64::from(a) + s * f64::from(b - a);
                out.extend([f.floor() as u32, f.ceil() as u32]);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}
