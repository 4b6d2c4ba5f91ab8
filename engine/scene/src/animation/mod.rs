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

use super::camera::CameraSpec;

mod check;

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

/// Declares a keyframe struct of `[animation]`: the track it belongs to (`[index: usize]`,
/// a light's index, a label's value; none for tracks of one), `frame`, the values every
/// key of it sets (`(time: f64)`), the values it may set (`None`: this key leaves that value to the others), and
/// `interpolation`. Every keyframe has that shape, with the same serde attributes, so
/// the file format of every track is written in one place.
macro_rules! keyframe {
    (
        $(#[$doc:meta])*
        $name:ident $([$track:ident: $track_ty:ty])? $(($($set:ident: $set_ty:ty),*))? {
            $($(#[$opt_meta:meta])* $opt:ident: $opt_ty:ty,)*
        }
    ) => {
        $(#[$doc])*
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(deny_unknown_fields)]
        pub struct $name {
            $(pub $track: $track_ty,)?
            pub frame: u32,
            $($(pub $set: $set_ty,)*)?
            $(
                #[serde(default, skip_serializing_if = "Option::is_none")]
                $(#[$opt_meta])*
                pub $opt: Option<$opt_ty>,
            )*
            #[serde(default, skip_serializing_if = "Interpolation::is_linear")]
            pub interpolation: Interpolation,
        }

        impl Keyframe for $name {
            fn frame_mut(&mut self) -> &mut u32 {
                &mut self.frame
            }
            fn frame(&self) -> u32 {
                self.frame
            }
            fn same_track(&self, _other: &Self) -> bool {
                true $(&& self.$track == _other.$track)?
            }
        }
    };
}

/// What every keyframe has: its frame, and the track it sets.
pub(crate) trait Keyframe {
    fn frame(&self) -> u32;
    fn frame_mut(&mut self) -> &mut u32;
    /// Whether `other` sets the same track (the same light, label, plane...).
    fn same_track(&self, other: &Self) -> bool;
}

keyframe! {
    /// `[[animation.camera]]`: sets any of position, target, fov at one frame.
    CameraKey {
        position: DVec3,
        target: DVec3,
        fov_y_degrees: f64,
    }
}

keyframe! {
    /// `[[animation.light]]`: sets any of position, colour, intensity of light `index`
    /// (0-based, in `[[light]]` order) at one frame.
    LightKey [index: usize] {
        position: DVec3,
        #[serde(alias = "color")]
        colour: DVec3,
        intensity: f64,
    }
}

keyframe! {
    /// `[[animation.tf]]`: sets either or both of the blend between `transfer.a` (0) and
    /// `transfer.b` (1), and the shift: the TF slides along the density axis by `shift` (a
    /// fraction of the density range, −1 to 1; the TF at density d is the blended TF at
    /// d − shift), so a positive shift moves every feature of the TF to higher densities,
    /// like a window sliding up.
    TfKey {
        blend: f64,
        shift: f64,
    }
}

keyframe! {
    /// `[[animation.time]]`: the time point a series shows at `frame` (fractional times
    /// interpolate the two time points around them; frame 0 shows time 0 unless a key says).
    TimeKey (time: f64) {}
}

keyframe! {
    /// `[[animation.channel]]`: sets the visibility and/or colour of channel `index` at
    /// `frame` (visibility holds until the next key; colours interpolate).
    ChannelKey [index: usize] {
        visible: bool,
        #[serde(alias = "color")]
        colour: DVec3,
    }
}

keyframe! {
    /// `[[animation.label]]`: sets the visibility, opacity and/or colour of label `value`
    /// at `frame` (visibility holds until the next key; opacity and colour interpolate).
    LabelKey [value: u16] {
        visible: bool,
        opacity: f64,
        #[serde(alias = "color")]
        colour: DVec3,
    }
}

keyframe! {
    /// `[[animation.clip]]`: sets any of point, normal, enabled of plane `index` at `frame`.
    ClipKey [index: usize] {
        point: DVec3,
        normal: DVec3,
        enabled: bool,
    }
}

keyframe! {
    /// `[[animation.crop]]`: sets any of min, max, enabled of the crop box at `frame`.
    CropKey {
        min: DVec3,
        max: DVec3,
        enabled: bool,
    }
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
        fn rescale<K: Keyframe>(keys: &mut [K], f: impl Fn(u32) -> u32) {
            keys.iter_mut().for_each(|k| *k.frame_mut() = f(k.frame()));
        }
        rescale(&mut a.camera, f);
        rescale(&mut a.light, f);
        rescale(&mut a.tf, f);
        rescale(&mut a.clip, f);
        rescale(&mut a.crop, f);
        rescale(&mut a.time, f);
        rescale(&mut a.channel, f);
        rescale(&mut a.label, f);
        a
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
