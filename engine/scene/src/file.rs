//! Scene files: the TOML layout ([`SceneFile`]), reading it into a checked [`Scene`]
//! and writing a scene back out.
//!
//! Reading happens in three steps so each kind of mistake gets the clearest message:
//! serde (with `deny_unknown_fields`) reports syntax, unknown fields, missing fields
//! and wrong types with line and column; the conversion to typed values reports
//! structural mistakes (a field that does not belong to a light's kind, `builtin` and
//! `file` both given); [`Scene::validate`]'s checks report values out of range. Every
//! message starts with the file and names the field.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::animation::AnimationFile;
use super::camera::CameraSpec;
use super::channel::{ChannelFile, ChannelSpec};
use super::cut::{ClipPlane, CropBox, Cut};
use super::error::{Ctx, SceneError};
use super::labels::{LabelFile, LabelsSpec};
use super::light::LightFile;
use super::render::RenderSettings;
use super::transfer_ref::TransferSpec;
use super::volume::VolumeFile;
use super::Scene;

/// The whole file as written.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    name: Option<String>,
    volume: VolumeFile,
    transfer: TransferSpec,
    #[serde(default)]
    camera: CameraSpec,
    #[serde(default, rename = "light")]
    lights: Vec<LightFile>,
    #[serde(default)]
    render: RenderSettings,
    #[serde(default, rename = "clip", skip_serializing_if = "Vec::is_empty")]
    clip: Vec<ClipPlane>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    crop: Option<CropBox>,
    #[serde(default, rename = "channel", skip_serializing_if = "Vec::is_empty")]
    channels: Vec<ChannelFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    labels: Option<LabelsSpec>,
    #[serde(default, rename = "label", skip_serializing_if = "Vec::is_empty")]
    label: Vec<LabelFile>,
    #[serde(default)]
    animation: AnimationFile,
}

/// Parses and checks scene text. `origin` names it in errors and (via its file stem)
/// gives the default name; relative paths are joined to `base`.
pub(crate) fn parse(text: &str, origin: &str, base: Option<&Path>) -> Result<Scene, SceneError> {
    let ctx = Ctx { origin, base };
    let file: SceneFile = toml::from_str(text).map_err(|source| SceneError::Parse {
        origin: origin.to_string(),
        source: Box::new(source),
    })?;
    let volume = file.volume.into_spec(&ctx)?;
    let (transfer, tf_a, tf_b) = file.transfer.resolve(&ctx)?;
    let lights = LightFile::into_lights(file.lights, &ctx)?;
    let channels = ChannelSpec::resolve(file.channels, &ctx)?;
    let (frames, animation) = file.animation.split();
    animation.check_unique_frames(&ctx)?;
    let scene = Scene {
        name: file.name.unwrap_or_else(|| default_name(origin)),
        volume,
        transfer,
        tf_a,
        tf_b,
        camera: file.camera,
        lights,
        render: file.render,
        cut: Cut {
            planes: file.clip,
            crop: file.crop,
        },
        frames,
        animation,
        channels,
        channel_views: Vec::new(),
        labels: file.labels.map(|l| l.resolve(&ctx)),
        label_sections: file.label,
        label_views: Vec::new(),
    };
    scene.check(&ctx)?;
    Ok(scene)
}

/// The file stem of `origin` if it has one, else `origin` itself.
fn default_name(origin: &str) -> String {
    Path::new(origin)
        .file_stem()
        .map_or_else(|| origin.to_string(), |s| s.to_string_lossy().into_owned())
}

/// The scene as TOML that [`parse`] reads back into an equal scene.
pub(crate) fn write(scene: &Scene) -> Result<String, SceneError> {
    let file = SceneFile {
        name: Some(scene.name.clone()),
        volume: VolumeFile::from_spec(&scene.volume),
        transfer: scene.transfer.clone(),
        camera: scene.camera,
        lights: scene.lights.iter().map(LightFile::from_light).collect(),
        render: scene.render,
        clip: scene.cut.planes.clone(),
        crop: scene.cut.crop,
        channels: scene.channels.iter().map(|c| c.file.clone()).collect(),
        labels: scene.labels.clone(),
        label: scene.label_sections.clone(),
        animation: AnimationFile::join(scene.frames, &scene.animation),
    };
    let body = toml::to_string(&file).map_err(|source| SceneError::Serialize {
        name: scene.name.clone(),
        source: Box::new(source),
    })?;
    Ok(format!(
        "# dvr scene {:?} (format: engine/scene/src/lib.rs, example: assets/scenes/example.toml)\n\n{body}",
        scene.name
    ))
}
