//! [`FrameState`]: everything that animates, evaluated at one frame, and [`changed`],
//! which tells the renderer what to reset between two frames.
//!
//! The GPU code calls [`super::Scene::frame_state`] for the current and the previous
//! frame: the camera pair gives reprojection, [`changed`] decides which history is
//! invalid (progressive accumulation restarts on any change; a temporal denoiser cares
//! mostly about camera motion, since lights and TF edits leave the geometry in place).

use super::animation::{sample, Interpolation, Lerp};
use super::camera::{Camera, CameraSpec};
use super::cut::Cut;
use super::light::Light;
use super::Scene;

/// A track's value at `frame`: its keyframes, preceded by the value at rest as an
/// implicit linear keyframe at frame 0 (an explicit frame-0 keyframe wins over it).
fn track<T: Lerp>(
    rest: T,
    keys: impl IntoIterator<Item = (u32, Interpolation, T)>,
    frame: u32,
) -> T {
    sample(
        std::iter::once((0, Interpolation::Linear, rest)).chain(keys),
        frame,
    )
    .unwrap_or(rest)
}

/// The animated state of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameState {
    /// The frame this state is for (after clamping to the scene's last frame).
    pub frame: u32,
    pub camera: Camera,
    /// The scene's lights, in `[[light]]` order, with this frame's values.
    pub lights: Vec<Light>,
    /// Blend between `transfer.a` (0) and `transfer.b` (1): the TF in effect is
    /// `TfLut::lerp(a, b, tf_blend)`. Always 0 without `transfer.b`.
    pub tf_blend: f32,
    /// How far that TF slides along the density axis (`TfLut::shifted`).
    pub tf_shift: f32,
    /// The time point a series shows (fractional: between two); 0 without keys.
    pub time: f64,
}

/// What differs between two frame states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Change {
    pub camera: bool,
    pub lights: bool,
    /// The TF or the time point (the medium changes in place).
    pub tf: bool,
}

impl Change {
    /// True if anything changed (progressive accumulation must restart).
    pub fn any(&self) -> bool {
        self.camera || self.lights || self.tf
    }
}

/// Exact comparison: any difference at all counts, since accumulating across even a
/// tiny change converges to a mix of two images.
pub fn changed(a: &FrameState, b: &FrameState) -> Change {
    Change {
        camera: a.camera != b.camera,
        lights: a.lights != b.lights,
        tf: a.tf_blend != b.tf_blend || a.tf_shift != b.tf_shift || a.time != b.time,
    }
}

impl Scene {
    /// The animated state at `frame`. Frames past the last one give the last frame's
    /// state (a sequence "holds" at its end), so any `u32` is accepted.
    pub fn frame_state(&self, frame: u32) -> FrameState {
        let f = self.clamp_frame(frame);
        let anim = &self.animation;
        let mut lights = self.lights.clone();
        for (i, light) in lights.iter_mut().enumerate() {
            let keys = || anim.light.iter().filter(move |k| k.index == i);
            if let Some(p) = light.position() {
                light.set_position(track(
                    p,
                    keys().filter_map(|k| Some((k.frame, k.interpolation, k.position?))),
                    f,
                ));
            }
            if let Some(c) = light.colour() {
                light.set_colour(track(
                    c,
                    keys().filter_map(|k| Some((k.frame, k.interpolation, k.colour?))),
                    f,
                ));
            }
            light.set_intensity(track(
                light.intensity(),
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.intensity?))),
                f,
            ));
        }

        let tf_blend = if self.tf_b.is_some() {
            let keys = anim
                .tf
                .iter()
                .filter_map(|k| Some((k.frame, k.interpolation, k.blend?)));
            track(0.0, keys, f)
        } else {
            0.0
        };

        FrameState {
            frame: f,
            camera: self.camera_at(f).camera(),
            lights,
            tf_blend: tf_blend.clamp(0.0, 1.0) as f32,
            tf_shift: track(
                0.0,
                anim.tf
                    .iter()
                    .filter_map(|k| Some((k.frame, k.interpolation, k.shift?))),
                f,
            )
            .clamp(-1.0, 1.0) as f32,
            time: self.time_at(f),
        }
    }

    /// The channels' views at `frame`: visibility and colour after their
    /// `[[animation.channel]]` keys.
    pub fn channels_at(&self, frame: u32) -> Vec<super::ChannelView> {
        let f = self.clamp_frame(frame);
        let mut views = self.channel_views.clone();
        for (i, c) in views.iter_mut().enumerate() {
            let keys = || self.animation.channel.iter().filter(move |k| k.index == i);
            c.visible = track(
                c.visible,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.visible?))),
                f,
            );
            let colour = track(
                glam::Vec3::from(c.colour).as_dvec3(),
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.colour?))),
                f,
            );
            c.colour = colour.as_vec3().to_array();
        }
        views
    }

    /// The labels' views at `frame`: visibility, opacity and colour after their
    /// `[[animation.label]]` keys.
    pub fn labels_at(&self, frame: u32) -> Vec<super::LabelView> {
        let f = self.clamp_frame(frame);
        let mut views = self.label_views.clone();
        for l in &mut views {
            let keys = || self.animation.label.iter().filter(|k| k.value == l.value);
            l.visible = track(
                l.visible,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.visible?))),
                f,
            );
            l.opacity = track(
                f64::from(l.opacity),
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.opacity?))),
                f,
            ) as f32;
            let colour = track(
                glam::Vec3::from(l.colour).as_dvec3(),
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.colour?))),
                f,
            );
            l.colour = colour.as_vec3().to_array();
        }
        views
    }

    /// The time point the scene shows at `frame` (its `[[animation.time]]` keys).
    pub fn time_at(&self, frame: u32) -> f64 {
        let keys = self
            .animation
            .time
            .iter()
            .map(|k| (k.frame, k.interpolation, k.time));
        track(0.0, keys, self.clamp_frame(frame)).max(0.0)
    }

    /// The clip planes and crop box at `frame`, after their keyframes.
    pub fn cut_at(&self, frame: u32) -> Cut {
        let f = self.clamp_frame(frame);
        let anim = &self.animation;
        let mut cut = self.cut.clone();
        for (i, plane) in cut.planes.iter_mut().enumerate() {
            let keys = || anim.clip.iter().filter(move |k| k.index == i);
            plane.point = track(
                plane.point,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.point?))),
                f,
            );
            plane.normal = track(
                plane.normal,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.normal?))),
                f,
            );
            plane.enabled = track(
                plane.enabled,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.enabled?))),
                f,
            );
        }
        if let Some(crop) = &mut cut.crop {
            let keys = || anim.crop.iter();
            crop.min = track(
                crop.min,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.min?))),
                f,
            );
            crop.max = track(
                crop.max,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.max?))),
                f,
            );
            crop.enabled = track(
                crop.enabled,
                keys().filter_map(|k| Some((k.frame, k.interpolation, k.enabled?))),
                f,
            );
        }
        cut
    }

    /// The camera (as written: f64, degrees) at `frame`, after keyframes and orbit.
    pub fn camera_at(&self, frame: u32) -> CameraSpec {
        let f = self.clamp_frame(frame);
        let base = &self.camera;
        let keys = &self.animation.camera;
        let mut cam = CameraSpec {
            position: track(
                base.position,
                keys.iter()
                    .filter_map(|k| Some((k.frame, k.interpolation, k.position?))),
                f,
            ),
            target: track(
                base.target,
                keys.iter()
                    .filter_map(|k| Some((k.frame, k.interpolation, k.target?))),
                f,
            ),
            fov_y_degrees: track(
                base.fov_y_degrees,
                keys.iter()
                    .filter_map(|k| Some((k.frame, k.interpolation, k.fov_y_degrees?))),
                f,
            ),
            ..*base
        };
        if let Some(orbit) = &self.animation.orbit {
            (cam.position, cam.target) = orbit.eval(base, f);
        }
        cam
    }

    fn clamp_frame(&self, frame: u32) -> u32 {
        frame.min(self.frames.max(1) - 1)
    }
}
