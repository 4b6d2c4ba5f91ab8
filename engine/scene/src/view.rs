//! What one view of a scene is: [`View`] (camera, lights, transfer function), the state a
//! live session holds and edits, and the state a scripted animation sets at each frame
//! ([`Scene::view_at`]); and [`ViewSections`], the editable parts as a scene file's
//! `[camera]`, `[[light]]` and `[render]` sections, read and checked by the code that
//! reads and checks a file (the Python package hands edits over as the dicts those
//! sections hold, so a bad edit gets the message a bad file gets).

use serde::{Deserialize, Serialize};

use super::camera::CameraSpec;
use super::channel::ChannelView;
use super::cut::{ClipPlane, CropBox, Cut};
use super::error::{Ctx, SceneError};
use super::light::{check_lights, Light, LightFile};
use super::render::RenderSettings;
use super::Scene;
use crate::transfer::{TfLut, TransferFunction};

/// The transfer function in effect: `a`, or the blend of `a` and `b` at `blend`, slid
/// along the density axis by `shift` (as [`super::TfKey`] animates them).
#[derive(Debug, Clone, PartialEq)]
pub struct TfState {
    pub a: TransferFunction,
    pub b: Option<TransferFunction>,
    /// 0 is `a`, 1 is `b`; ignored without `b`.
    pub blend: f32,
    /// A fraction of the density range, −1 to 1 ([`TfLut::shifted`]).
    pub shift: f32,
}

impl TfState {
    /// One transfer function, unblended and unshifted.
    pub fn single(tf: TransferFunction) -> Self {
        Self {
            a: tf,
            b: None,
            blend: 0.0,
            shift: 0.0,
        }
    }

    /// The LUT the renderer uploads for this state.
    pub fn lut(&self) -> TfLut {
        let a = self.a.lut();
        let lut = match &self.b {
            Some(b) if self.blend > 0.0 => TfLut::lerp(&a, &b.lut(), self.blend),
            _ => a,
        };
        if self.shift != 0.0 {
            lut.shifted(self.shift)
        } else {
            lut
        }
    }
}

/// One view: what the renderer turns into a frame's camera, lights, LUTs and cut.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    pub camera: CameraSpec,
    pub lights: Vec<Light>,
    pub tf: TfState,
    /// The clip planes and crop box.
    pub cut: Cut,
    /// Each channel of a multi-channel medium (empty for one field).
    pub channels: Vec<ChannelView>,
    /// The time point of a series (fractional: the two around it interpolated).
    pub time: f64,
    /// Each label of the label map, by value (empty without one).
    pub labels: Vec<super::LabelView>,
}

impl View {
    /// The LUTs the renderer uploads: the TF state's, and with several channels every
    /// channel's segment after it ([`super::channel::medium_lut`]).
    pub fn lut(&self) -> TfLut {
        super::channel::medium_lut(self.tf.lut(), &self.channels)
    }
}

impl Scene {
    /// The view the scene's animation sets at `frame` (frames past the last hold it):
    /// the camera after keyframes and orbit, the lights' animated values, and the TF
    /// blend and shift between `transfer.a` and `transfer.b`.
    pub fn view_at(&self, frame: u32) -> View {
        let state = self.frame_state(frame);
        View {
            camera: self.camera_at(frame),
            lights: state.lights,
            tf: TfState {
                a: self.tf_a.clone(),
                b: self.tf_b.clone(),
                blend: state.tf_blend,
                shift: state.tf_shift,
            },
            cut: self.cut_at(frame),
            channels: self.channels_at(frame),
            time: self.time_at(frame),
            labels: self.labels_at(frame),
        }
    }
}

/// The camera, lights, render settings and cut of one view.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewSections {
    pub camera: CameraSpec,
    pub lights: Vec<Light>,
    pub render: RenderSettings,
    pub cut: Cut,
}

/// The sections as written.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ViewFile {
    camera: CameraSpec,
    #[serde(default, rename = "light")]
    lights: Vec<LightFile>,
    #[serde(default)]
    render: RenderSettings,
    #[serde(default, rename = "clip", skip_serializing_if = "Vec::is_empty")]
    clip: Vec<ClipPlane>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    crop: Option<CropBox>,
}

impl ViewSections {
    /// Parses and checks `[camera]`, `[[light]]` and `[render]` (every other key is an
    /// error); `origin` names the text in errors. Relative paths (an environment map)
    /// are relative to the working directory.
    pub fn from_toml_str(text: &str, origin: &str) -> Result<Self, SceneError> {
        let ctx = Ctx { origin, base: None };
        let file: ViewFile = toml::from_str(text).map_err(|source| SceneError::Parse {
            origin: origin.to_string(),
            source: Box::new(source),
        })?;
        let lights = LightFile::into_lights(file.lights, &ctx)?;
        let view = Self {
            camera: file.camera,
            lights,
            render: file.render,
            cut: Cut {
                planes: file.clip,
                crop: file.crop,
            },
        };
        view.check(origin)?;
        Ok(view)
    }

    /// The sections as TOML that [`ViewSections::from_toml_str`] reads back.
    pub fn to_toml(&self) -> Result<String, SceneError> {
        let file = ViewFile {
            camera: self.camera,
            lights: self.lights.iter().map(LightFile::from_light).collect(),
            render: self.render,
            clip: self.cut.planes.clone(),
            crop: self.cut.crop,
        };
        toml::to_string(&file).map_err(|source| SceneError::Serialize {
            name: "view".into(),
            source: Box::new(source),
        })
    }

    /// Checks every section as a scene file's are checked; `origin` names the view in
    /// errors.
    pub fn check(&self, origin: &str) -> Result<(), SceneError> {
        let ctx = Ctx { origin, base: None };
        self.camera.check(&ctx, "camera")?;
        check_lights(&ctx, &self.lights, self.render.emission())?;
        self.cut.check(&ctx)?;
        self.render.check(&ctx)
    }
}

/// A camera as `[camera]` is checked, named `camera` in errors.
pub fn check_camera_spec(camera: &CameraSpec, origin: &str) -> Result<(), SceneError> {
    camera.check(&Ctx { origin, base: None }, "camera")
}

/// Lights as `[[light]]` are checked (with or without the TF's emission).
pub fn check_light_list(lights: &[Light], emission: bool, origin: &str) -> Result<(), SceneError> {
    check_lights(&Ctx { origin, base: None }, lights, emission)
}

/// Clip planes and a crop box as `[[clip]]` and `[crop]` are checked.
pub fn check_cut(cut: &Cut, origin: &str) -> Result<(), SceneError> {
    cut.check(&Ctx { origin, base: None })
}

/// Render settings as `[render]` is checked.
pub fn check_render(render: &RenderSettings, origin: &str) -> Result<(), SceneError> {
    render.check(&Ctx { origin, base: None })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;

    #[test]
    fn a_scenes_view_round_trips_through_its_sections() {
        let scene = Scene::builtin("mri/area-light").expect("builtin");
        let view = ViewSections {
            camera: scene.camera,
            lights: scene.lights.clone(),
            render: scene.render,
            cut: Cut {
                planes: vec![ClipPlane {
                    point: glam::DVec3::new(0.0, 0.0, 0.1),
                    normal: glam::DVec3::new(0.0, 1.0, 1.0),
                    enabled: false,
                }],
                crop: Some(CropBox {
                    min: glam::DVec3::splat(-0.4),
                    max: glam::DVec3::splat(0.3),
                    units: crate::CropUnits::Box,
                    enabled: true,
                }),
            },
        };
        let text = view.to_toml().expect("toml");
        assert_eq!(
            ViewSections::from_toml_str(&text, "view").expect("parse"),
            view
        );
    }

    #[test]
    fn bad_sections_are_errors_naming_the_field() {
        let ok = "[camera]\nposition = [0.0, 2.0, 0.0]\n[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 5.0\n";
        ViewSections::from_toml_str(ok, "python").expect("a good view");
        for (text, needle) in [
            (
                ok.replace("0.0, 2.0, 0.0", "0.0, nan, 0.0"),
                "camera.position",
            ),
            (
                ok.replace("intensity = 5.0", "intensity = -5.0"),
                "light[0].intensity",
            ),
            (format!("{ok}[render]\nspp = 0\n"), "spp"),
            (
                format!("{ok}[volume]\nbuiltin = \"cloud\"\n"),
                "unknown field",
            ),
            (
                ok.replace(
                    "[[light]]\nkind = \"point\"\nposition = [1.0, 1.0, 1.0]\nintensity = 5.0\n",
                    "",
                ),
                "at least one",
            ),
        ] {
            let e = ViewSections::from_toml_str(&text, "python")
                .expect_err(&text)
                .to_string();
            assert!(e.starts_with("python") && e.contains(needle), "{text}: {e}");
        }
    }
}
