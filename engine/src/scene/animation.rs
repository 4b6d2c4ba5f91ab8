//! `[animation]`: the frame count and keyframe tracks that move the camera, the lights
//! and the TF blend over a scripted sequence.
//!
//! Model. Every animatable property (camera position, target, fov; each light's
//! position, colour, intensity; the TF blend) is its own track, made of the keyframes
//! that set it. At frame f a track takes the value of its keyframes around f:
//! - the value at rest (`[camera]`, `[[light]]`, blend 0) is an implicit keyframe at
//!   frame 0, unless a keyframe sets frame 0 itself; after its last keyframe a track
//!   holds the last value;
//! - between keyframes it interpolates linearly, unless the earlier keyframe says
//!   `interpolation = "step"`: then it holds that value up to the next keyframe and
//!   changes there in one frame (a jump). Two linear keyframes on consecutive frames
//!   are a jump too, but only at the scene's own frame count: `step` survives
//!   [`super::Scene::with_frames`], consecutive frames do not.
//!
//! Camera orbits are a separate track, `[animation.orbit]`, because straight lines
//! between keyframes cut through the volume: the camera circles `center` (default: the
//! camera target) about the camera's `up` axis at `degrees_per_frame` (counter-clockwise
//! seen from above), starting from the `[camera]` position's azimuth plus
//! `start_degrees`; `radius` and `height` (along up, relative to `center`) default to
//! the `[camera]` position's. The orbit sets position and target; camera keyframes may
//! still animate `fov_y_degrees`.
//!
//! Frame counts. `frames` defaults to 60 (two seconds at 30 fps; a change at the middle
//! frame leaves 30 frames of history before it and 30 frames to recover after it).
//! [`super::Scene::with_frames`] resamples an animation at another frame count: keyframe
//! frames scale by `(n−1)/(frames−1)` (rounded), so the same motion is sampled more or
//! less finely. The orbit is a rate and is *not* rescaled: the per-frame rotation is what
//! makes an orbit easy or hard for a temporal method, so it stays the same and a longer
//! sequence simply orbits further.

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::camera::{check_fov, CameraSpec, MAX_CAMERA_DISTANCE};
use super::cut::{ClipPlane, CropBox, Cut};
use super::error::{Ctx, SceneError};
use super::light::{check_intensity, check_position, Light};

/// Frames in a scene that does not say.
pub const DEFAULT_FRAMES: u32 = 60;

/// How a track gets from one keyframe to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Interpolation {
    /// Linear in every component (the default).
    #[default]
    Linear,
    /// Hold this keyframe's value until the next keyframe, then jump.
    Step,
}

impl Interpolation {
    pub(crate) fn is_linear(&self) -> bool {
        *self == Self::Linear
    }
}

/// `[[animation.camera]]`: sets any of position, target, fov at one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraKey {
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fov_y_degrees: Option<f64>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.light]]`: sets any of position, colour, intensity of light `index`
/// (0-based, in `[[light]]` order) at one frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightKey {
    pub index: usize,
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none", alias = "color")]
    pub colour: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intensity: Option<f64>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.tf]]`: sets either or both of the blend between `transfer.a` (0) and
/// `transfer.b` (1), and the shift: the TF slides along the density axis by `shift` (a
/// fraction of the density range, −1 to 1; the TF at density d is the blended TF at
/// d − shift), so a positive shift moves every feature of the TF to higher densities,
/// like a window sliding up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TfKey {
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shift: Option<f64>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.time]]`: the time point a series shows at `frame` (fractional times
/// interpolate the two time points around them; frame 0 shows time 0 unless a key says).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeKey {
    pub frame: u32,
    pub time: f64,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.channel]]`: sets the visibility and/or colour of channel `index` at
/// `frame` (visibility holds until the next key; colours interpolate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelKey {
    pub index: usize,
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible: Option<bool>,
    #[serde(default, alias = "color", skip_serializing_if = "Option::is_none")]
    pub colour: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.label]]`: sets the visibility, opacity and/or colour of label `value`
/// at `frame` (visibility holds until the next key; opacity and colour interpolate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelKey {
    pub value: u16,
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub visible: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub opacity: Option<f64>,
    #[serde(default, alias = "color", skip_serializing_if = "Option::is_none")]
    pub colour: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.clip]]`: sets any of point, normal, enabled of plane `index` at `frame`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipKey {
    pub index: usize,
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub enabled: Option<bool>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[[animation.crop]]`: sets any of min, max, enabled of the crop box at `frame`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CropKey {
    pub frame: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub enabled: Option<bool>,
    #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
    pub interpolation: Interpolation,
}

/// `[animation.orbit]`: see the module docs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    pub degrees_per_frame: f64,
    #[serde(default, skip_serializing_if = "is_zero")]
    pub start_degrees: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center: Option<DVec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<f64>,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Orbit {
    /// Camera position and target at `frame`, orbiting from `base`.
    pub fn eval(&self, base: &CameraSpec, frame: u32) -> (DVec3, DVec3) {
        let (center, axis, e1, r0, h0) = self.frame_of(base);
        let e2 = axis.cross(e1);
        let theta = (self.start_degrees + self.degrees_per_frame * f64::from(frame)).to_radians();
        let r = self.radius.unwrap_or(r0);
        let h = self.height.unwrap_or(h0);
        let position = center + axis * h + (e1 * theta.cos() + e2 * theta.sin()) * r;
        (position, center)
    }

    /// Centre, unit axis, unit direction of azimuth 0, and the base camera's radius and
    /// height about the centre.
    fn frame_of(&self, base: &CameraSpec) -> (DVec3, DVec3, DVec3, f64, f64) {
        let center = self.center.unwrap_or(base.target);
        let axis = base.up.normalize_or(DVec3::Z);
        let offset = base.position - center;
        let h0 = offset.dot(axis);
        let planar = offset - axis * h0;
        let r0 = planar.length();
        let e1 = if r0 > 1e-9 {
            planar / r0
        } else {
            axis.any_orthonormal_vector()
        };
        (center, axis, e1, r0, h0)
    }
}

/// The keyframe tracks of a scene (the frame count is [`super::Scene::frames`]).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Animation {
    pub camera: Vec<CameraKey>,
    pub orbit: Option<Orbit>,
    pub light: Vec<LightKey>,
    pub tf: Vec<TfKey>,
    /// `[[animation.clip]]`: keyframes of the clip planes (see [`super::cut`]).
    pub clip: Vec<ClipKey>,
    /// `[[animation.crop]]`: keyframes of the crop box.
    pub crop: Vec<CropKey>,
    /// `[[animation.time]]`: keyframes of a series' time point.
    pub time: Vec<TimeKey>,
    /// `[[animation.channel]]`: keyframes of the channels' visibility and colour.
    pub channel: Vec<ChannelKey>,
    /// `[[animation.label]]`: keyframes of the labels' visibility, opacity and colour.
    pub label: Vec<LabelKey>,
}

/// `[animation]` as written.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct AnimationFile {
    #[serde(default = "default_frames")]
    frames: u32,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    orbit: Option<Orbit>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    camera: Vec<CameraKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    light: Vec<LightKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    tf: Vec<TfKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    clip: Vec<ClipKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    crop: Vec<CropKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    time: Vec<TimeKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    channel: Vec<ChannelKey>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    label: Vec<LabelKey>,
}

fn default_frames() -> u32 {
    DEFAULT_FRAMES
}

impl Default for AnimationFile {
    fn default() -> Self {
        Self {
            frames: DEFAULT_FRAMES,
            orbit: None,
            camera: Vec::new(),
            light: Vec::new(),
            tf: Vec::new(),
            clip: Vec::new(),
            crop: Vec::new(),
            time: Vec::new(),
            channel: Vec::new(),
            label: Vec::new(),
        }
    }
}

impl AnimationFile {
    pub fn split(self) -> (u32, Animation) {
        let a = Animation {
            camera: self.camera,
            orbit: self.orbit,
            light: self.light,
            tf: self.tf,
            clip: self.clip,
            crop: self.crop,
            time: self.time,
            channel: self.channel,
            label: self.label,
        };
        (self.frames, a)
    }

    pub fn join(frames: u32, a: &Animation) -> Self {
        Self {
            frames,
            orbit: a.orbit.clone(),
            camera: a.camera.clone(),
            light: a.light.clone(),
            tf: a.tf.clone(),
            clip: a.clip.clone(),
            time: a.time.clone(),
            channel: a.channel.clone(),
            label: a.label.clone(),
            crop: a.crop.clone(),
        }
    }
}

/// Maps a keyframe's frame from a sequence of `from` frames to one of `to` frames so
/// the first and last frames stay first and last (rounded to nearest).
pub fn rescale_frame(frame: u32, from: u32, to: u32) -> u32 {
    let last_to = u64::from(to.max(1) - 1);
    if from <= 1 {
        return frame.min(last_to as u32);
    }
    let last_from = u64::from(from - 1);
    let scaled = (2 * u64::from(frame) * last_to + last_from) / (2 * last_from);
    scaled.min(last_to) as u32
}

impl Animation {
    /// The same animation resampled from `from` to `to` frames (see the module docs).
    pub fn rescaled(&self, from: u32, to: u32) -> Self {
        let f = |frame: u32| rescale_frame(frame, from, to);
        let mut a = self.clone();
        a.camera.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.light.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.tf.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.clip.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.crop.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.time.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.channel.iter_mut().for_each(|k| k.frame = f(k.frame));
        a.label.iter_mut().for_each(|k| k.frame = f(k.frame));
        a
    }

    /// One keyframe per track and frame in a scene file: with two, which one holds
    /// depends on their order in the file, which is a slip, not an intent. (A scene
    /// resampled to fewer frames may bring keyframes together; there the later one
    /// holds, see [`sample`].)
    pub(crate) fn check_unique_frames(&self, ctx: &Ctx) -> Result<(), SceneError> {
        let duplicate = |track: &str, i: usize, j: usize, frame: u32| {
            Err(ctx.invalid(
                format!("animation.{track}[{j}].frame"),
                format!(
                    "{frame} is also the frame of animation.{track}[{i}]; one keyframe per \
                     frame (merge the two)"
                ),
            ))
        };
        for (j, k) in self.camera.iter().enumerate() {
            if let Some(i) = self.camera[..j].iter().position(|o| o.frame == k.frame) {
                return duplicate("camera", i, j, k.frame);
            }
        }
        for (j, k) in self.light.iter().enumerate() {
            let same = |o: &LightKey| o.frame == k.frame && o.index == k.index;
            if let Some(i) = self.light[..j].iter().position(same) {
                return duplicate("light", i, j, k.frame);
            }
        }
        // Blend and shift are tracks of their own (a key may set either or both, each
        // key with its own interpolation): two keys on one frame clash only when both
        // set the same value.
        for (j, k) in self.tf.iter().enumerate() {
            let same = |o: &TfKey| {
                o.frame == k.frame
                    && ((o.blend.is_some() && k.blend.is_some())
                        || (o.shift.is_some() && k.shift.is_some()))
            };
            if let Some(i) = self.tf[..j].iter().position(same) {
                return duplicate("tf", i, j, k.frame);
            }
        }
        for (j, k) in self.time.iter().enumerate() {
            if let Some(i) = self.time[..j].iter().position(|o| o.frame == k.frame) {
                return duplicate("time", i, j, k.frame);
            }
            if !(k.time.is_finite() && k.time >= 0.0) {
                return Err(ctx.invalid(
                    format!("animation.time[{j}].time"),
                    format!(
                        "{} must be a time point >= 0 (fractional times interpolate)",
                        k.time
                    ),
                ));
            }
        }
        for (j, k) in self.channel.iter().enumerate() {
            let same = |o: &ChannelKey| o.frame == k.frame && o.index == k.index;
            if let Some(i) = self.channel[..j].iter().position(same) {
                return duplicate("channel", i, j, k.frame);
            }
            if k.index >= super::channel::MAX_CHANNELS {
                return Err(ctx.invalid(
                    format!("animation.channel[{j}].index"),
                    format!(
                        "{} is past the last channel a medium holds (0 to {})",
                        k.index,
                        super::channel::MAX_CHANNELS - 1
                    ),
                ));
            }
            if let Some(c) = k.colour {
                ctx.colour(&format!("animation.channel[{j}].colour"), c)?;
            }
        }
        for (j, k) in self.label.iter().enumerate() {
            let same = |o: &LabelKey| o.frame == k.frame && o.value == k.value;
            if let Some(i) = self.label[..j].iter().position(same) {
                return duplicate("label", i, j, k.frame);
            }
            if let Some(o) = k.opacity {
                if !(0.0..=1.0).contains(&o) {
                    return Err(ctx.invalid(
                        format!("animation.label[{j}].opacity"),
                        format!("{o} must be in [0, 1]"),
                    ));
                }
            }
            if let Some(c) = k.colour {
                if !(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0) {
                    return Err(ctx.invalid(
                        format!("animation.label[{j}].colour"),
                        format!("{c} must be in [0, 1] in every component"),
                    ));
                }
            }
        }
        for (j, k) in self.clip.iter().enumerate() {
            let same = |o: &ClipKey| o.frame == k.frame && o.index == k.index;
            if let Some(i) = self.clip[..j].iter().position(same) {
                return duplicate("clip", i, j, k.frame);
            }
        }
        for (j, k) in self.crop.iter().enumerate() {
            if let Some(i) = self.crop[..j].iter().position(|o| o.frame == k.frame) {
                return duplicate("crop", i, j, k.frame);
            }
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    pub(crate) fn check(
        &self,
        ctx: &Ctx,
        frames: u32,
        camera: &CameraSpec,
        lights: &[Light],
        has_tf_b: bool,
        cut: &Cut,
    ) -> Result<(), SceneError> {
        if frames == 0 {
            return Err(ctx.invalid("animation.frames", "must be at least 1"));
        }
        let frame_ok = |field: String, frame: u32| {
            if frame < frames {
                Ok(())
            } else {
                Err(ctx.invalid(
                    field,
                    format!("{frame} is past the last frame ({})", frames - 1),
                ))
            }
        };
        for (i, k) in self.camera.iter().enumerate() {
            let field = |name: &str| format!("animation.camera[{i}].{name}");
            frame_ok(field("frame"), k.frame)?;
            if self.orbit.is_some() && (k.position.is_some() || k.target.is_some()) {
                return Err(ctx.invalid(
                    field(if k.position.is_some() {
                        "position"
                    } else {
                        "target"
                    }),
                    "the camera follows [animation.orbit]; keyframes may only set fov_y_degrees",
                ));
            }
            if let Some(p) = k.position {
                ctx.finite3(&field("position"), p)?;
            }
            if let Some(t) = k.target {
                ctx.finite3(&field("target"), t)?;
            }
            if let Some(fov) = k.fov_y_degrees {
                check_fov(ctx, &field("fov_y_degrees"), fov)?;
            }
        }
        if let Some(o) = &self.orbit {
            ctx.in_range(
                "animation.orbit.degrees_per_frame",
                o.degrees_per_frame,
                -360.0,
                360.0,
                " degrees",
            )?;
            ctx.in_range(
                "animation.orbit.start_degrees",
                o.start_degrees,
                -360.0,
                360.0,
                " degrees",
            )?;
            if let Some(c) = o.center {
                ctx.near_origin(
                    "animation.orbit.center",
                    c,
                    MAX_CAMERA_DISTANCE,
                    "the camera looks at it",
                )?;
            }
            if let Some(h) = o.height {
                ctx.in_range(
                    "animation.orbit.height",
                    h,
                    -MAX_CAMERA_DISTANCE,
                    MAX_CAMERA_DISTANCE,
                    " world units",
                )?;
            }
            if let Some(r) = o.radius {
                ctx.in_range(
                    "animation.orbit.radius",
                    r,
                    0.0,
                    MAX_CAMERA_DISTANCE,
                    " world units",
                )?;
            }
            let radius = o.radius.unwrap_or_else(|| o.frame_of(camera).3);
            if !(radius.is_finite() && radius > 1e-6) {
                return Err(ctx.invalid(
                    "animation.orbit.radius",
                    format!("{radius} must be > 0 (the camera would sit on the orbit axis)"),
                ));
            }
        }
        for (i, k) in self.light.iter().enumerate() {
            let field = |name: &str| format!("animation.light[{i}].{name}");
            let light = lights.get(k.index).ok_or_else(|| {
                ctx.invalid(
                    field("index"),
                    format!(
                        "light {} does not exist (the scene has {} [[light]])",
                        k.index,
                        lights.len()
                    ),
                )
            })?;
            frame_ok(field("frame"), k.frame)?;
            if let Some(p) = k.position {
                if light.position().is_none() {
                    return Err(ctx.invalid(
                        field("position"),
                        format!("light {} has no position", k.index),
                    ));
                }
                check_position(ctx, &field("position"), p)?;
            }
            if let Some(c) = k.colour {
                if light.colour().is_none() {
                    return Err(ctx.invalid(
                        field("colour"),
                        format!(
                            "light {} has no single colour (animate its intensity instead)",
                            k.index
                        ),
                    ));
                }
                ctx.colour(&field("colour"), c)?;
            }
            if let Some(x) = k.intensity {
                check_intensity(ctx, &field("intensity"), x)?;
            }
        }
        for (i, k) in self.tf.iter().enumerate() {
            let field = |name: &str| format!("animation.tf[{i}].{name}");
            frame_ok(field("frame"), k.frame)?;
            if k.blend.is_none() && k.shift.is_none() {
                return Err(ctx.invalid(field("blend"), "a TF keyframe sets blend, shift or both"));
            }
            if let Some(blend) = k.blend {
                if !has_tf_b {
                    return Err(ctx.invalid(
                        field("blend"),
                        "TF blend keyframes need a blend target: set transfer.b",
                    ));
                }
                if !(0.0..=1.0).contains(&blend) {
                    return Err(ctx.invalid(field("blend"), format!("{blend} is outside [0, 1]")));
                }
            }
            if let Some(shift) = k.shift {
                if !(-1.0..=1.0).contains(&shift) {
                    return Err(ctx.invalid(
                        field("shift"),
                        format!("{shift} is outside [-1, 1] (a fraction of the density range)"),
                    ));
                }
            }
        }
        self.check_cut(ctx, &frame_ok, cut)
    }

    /// The clip and crop keyframes: each names a plane (or the crop box) the scene
    /// has, its values are checked as the plane's or box's own, and consecutive normals
    /// of one plane are never opposite (the interpolated normal would pass through
    /// zero).
    fn check_cut(
        &self,
        ctx: &Ctx,
        frame_ok: &dyn Fn(String, u32) -> Result<(), SceneError>,
        cut: &Cut,
    ) -> Result<(), SceneError> {
        for (i, k) in self.clip.iter().enumerate() {
            let field = |name: &str| format!("animation.clip[{i}].{name}");
            let plane = cut.planes.get(k.index).ok_or_else(|| {
                ctx.invalid(
                    field("index"),
                    format!(
                        "clip plane {} does not exist (the scene has {} [[clip]])",
                        k.index,
                        cut.planes.len()
                    ),
                )
            })?;
            frame_ok(field("frame"), k.frame)?;
            ClipPlane {
                point: k.point.unwrap_or(plane.point),
                normal: k.normal.unwrap_or(plane.normal),
                enabled: true,
            }
            .check(ctx, &format!("animation.clip[{i}]"))?;
        }
        for index in 0..cut.planes.len() {
            let mut normals: Vec<(u32, DVec3)> = std::iter::once((0, cut.planes[index].normal))
                .chain(
                    self.clip
                        .iter()
                        .filter(|k| k.index == index)
                        .filter_map(|k| Some((k.frame, k.normal?))),
                )
                .collect();
            normals.sort_by_key(|n| n.0);
            for w in normals.windows(2) {
                let (a, b) = (w[0].1.normalize(), w[1].1.normalize());
                if (a + b).length() < 1e-6 {
                    return Err(ctx.invalid(
                        format!("animation.clip (plane {index}, frame {})", w[1].0),
                        "the normal turns half a circle between two keyframes, through zero \
                         (add a keyframe in between)",
                    ));
                }
            }
        }
        if !self.crop.is_empty() {
            let Some(crop) = cut.crop else {
                return Err(
                    ctx.invalid("animation.crop", "crop keyframes need a [crop] box at rest")
                );
            };
            for (i, k) in self.crop.iter().enumerate() {
                frame_ok(format!("animation.crop[{i}].frame"), k.frame)?;
                CropBox {
                    min: k.min.unwrap_or(crop.min),
                    max: k.max.unwrap_or(crop.max),
                    ..crop
                }
                .check(ctx, &format!("animation.crop[{i}]"))?;
            }
        }
        Ok(())
    }
}

/// Values that a track can interpolate.
pub(crate) trait Lerp: Copy {
    fn lerp(a: Self, b: Self, t: f64) -> Self;
}

impl Lerp for f64 {
    fn lerp(a: Self, b: Self, t: f64) -> Self {
        a * (1.0 - t) + b * t
    }
}

impl Lerp for DVec3 {
    fn lerp(a: Self, b: Self, t: f64) -> Self {
        a * (1.0 - t) + b * t
    }
}

/// A switch holds its value until the keyframe that changes it.
impl Lerp for bool {
    fn lerp(a: Self, b: Self, t: f64) -> Self {
        if t >= 1.0 {
            b
        } else {
            a
        }
    }
}

/// The value of the track made of `keys` (frame, interpolation, value; any order) at
/// `frame`, or `None` for an empty track. Before the first keyframe the first value
/// holds (callers prepend the value at rest at frame 0, see the module docs).
pub(crate) fn sample<T: Lerp>(
    keys: impl IntoIterator<Item = (u32, Interpolation, T)>,
    frame: u32,
) -> Option<T> {
    let mut keys: Vec<_> = keys.into_iter().collect();
    keys.sort_by_key(|k| k.0); // stable: keyframes on the same frame keep file order
    let after = keys.partition_point(|k| k.0 <= frame);
    if after == 0 {
        return keys.first().map(|k| k.2);
    }
    let (fa, interp, a) = keys[after - 1];
    match keys.get(after) {
        None => Some(a),
        Some(_) if interp == Interpolation::Step => Some(a),
        // fb > frame >= fa, so the denominator is positive.
        Some(&(fb, _, b)) => Some(T::lerp(a, b, f64::from(frame - fa) / f64::from(fb - fa))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Interpolation::{Linear, Step};

    #[test]
    fn tracks_interpolate_hold_and_step() {
        let keys = [(10, Linear, 1.0), (20, Step, 3.0), (30, Linear, 5.0)];
        let at = |f| sample(keys, f).expect("non-empty");
        assert_eq!(at(0), 1.0, "holds the first value before it");
        assert_eq!(at(10), 1.0);
        assert_eq!(at(15), 2.0);
        assert_eq!(at(20), 3.0);
        assert_eq!(at(29), 3.0, "step holds");
        assert_eq!(at(30), 5.0, "then jumps");
        assert_eq!(at(99), 5.0, "holds the last value after it");
        assert_eq!(sample::<f64>([], 3), None);
        // Order in the file does not matter; same-frame keys: the later one wins after.
        let keys = [(30, Linear, 5.0), (10, Linear, 1.0), (10, Linear, 2.0)];
        assert_eq!(sample(keys, 10), Some(2.0));
        assert_eq!(sample(keys, 20), Some(3.5));
    }

    #[test]
    fn rescaling_keeps_the_ends_and_proportions() {
        assert_eq!(rescale_frame(0, 60, 8), 0);
        assert_eq!(rescale_frame(59, 60, 8), 7);
        assert_eq!(rescale_frame(30, 60, 119), 60);
        assert_eq!(rescale_frame(30, 60, 120), 61); // 30·119/59 = 60.5
        assert_eq!(rescale_frame(59, 60, 120), 119);
        assert_eq!(rescale_frame(30, 60, 8), 4); // 30·7/59 = 3.56
        assert_eq!(rescale_frame(5, 1, 8), 5);
        assert_eq!(rescale_frame(9, 1, 8), 7);
        assert_eq!(rescale_frame(100, 60, 8), 7, "clamped");
    }

    #[test]
    fn orbit_starts_at_the_camera_and_keeps_its_distance() {
        let base = CameraSpec::default();
        let o = Orbit {
            degrees_per_frame: 90.0,
            start_degrees: 0.0,
            center: None,
            radius: None,
            height: None,
        };
        let (p0, t0) = o.eval(&base, 0);
        assert!((p0 - base.position).length() < 1e-12 && t0 == base.target);
        let (p1, _) = o.eval(&base, 1);
        assert!((p1.length() - base.position.length()).abs() < 1e-12);
        assert!((p1.z - base.position.z).abs() < 1e-12, "orbits about +z");
        // Counter-clockwise seen from +z: the azimuth grows by 90 degrees.
        let az = |p: DVec3| p.y.atan2(p.x);
        let d = (az(p1) - az(p0)).rem_euclid(std::f64::consts::TAU);
        assert!((d - std::f64::consts::FRAC_PI_2).abs() < 1e-9, "{d}");
    }
}
