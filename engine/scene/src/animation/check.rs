//! The checks of `[animation]` against the scene it animates: one keyframe per track
//! and frame, every frame within the animation, every value within its property's
//! limits, and every light, channel, clip plane or crop box a key names one the scene has.

use glam::DVec3;

use super::super::camera::{check_fov, CameraSpec, MAX_CAMERA_DISTANCE};
use super::super::channel::MAX_CHANNELS;
use super::super::cut::{ClipPlane, CropBox, Cut};
use super::super::error::{Ctx, SceneError};
use super::super::light::{check_intensity, check_position, Light};
use super::{Animation, Keyframe, TfKey};

impl Animation {
    /// One keyframe per track and frame in a scene file: with two, which one holds
    /// depends on their order in the file, which is a slip, not an intent. (A scene
    /// resampled to fewer frames may bring keyframes together; there the later one
    /// holds, see [`super::sample`].)
    pub(crate) fn check_unique_frames(&self, ctx: &Ctx) -> Result<(), SceneError> {
        let unique = |track: &str, clash: Option<(usize, usize, u32)>| match clash {
            Some((i, j, frame)) => Err(ctx.invalid(
                format!("animation.{track}[{j}].frame"),
                format!(
                    "{frame} is also the frame of animation.{track}[{i}]; one keyframe per \
                     frame (merge the two)"
                ),
            )),
            None => Ok(()),
        };
        fn always<K>(_: &K, _: &K) -> bool {
            true
        }
        unique("camera", first_clash(&self.camera, always))?;
        unique("light", first_clash(&self.light, always))?;
        // Blend and shift are tracks of their own (a key may set either or both, each
        // key with its own interpolation): two keys on one frame clash only when both
        // set the same value.
        let tf_clash = |o: &TfKey, k: &TfKey| {
            (o.blend.is_some() && k.blend.is_some()) || (o.shift.is_some() && k.shift.is_some())
        };
        unique("tf", first_clash(&self.tf, tf_clash))?;
        unique("time", first_clash(&self.time, always))?;
        for (j, k) in self.time.iter().enumerate() {
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
        unique("channel", first_clash(&self.channel, always))?;
        for (j, k) in self.channel.iter().enumerate() {
            if k.index >= MAX_CHANNELS {
                return Err(ctx.invalid(
                    format!("animation.channel[{j}].index"),
                    format!(
                        "{} is past the last channel a medium holds (0 to {})",
                        k.index,
                        MAX_CHANNELS - 1
                    ),
                ));
            }
            if let Some(c) = k.colour {
                ctx.colour(&format!("animation.channel[{j}].colour"), c)?;
            }
        }
        unique("label", first_clash(&self.label, always))?;
        for (j, k) in self.label.iter().enumerate() {
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
        unique("clip", first_clash(&self.clip, always))?;
        unique("crop", first_clash(&self.crop, always))?;
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

/// The first key of `keys` (by position, with the earlier key it clashes with) that sets
/// the same track on the same frame as an earlier key, where `also` says they clash.
fn first_clash<K: Keyframe>(
    keys: &[K],
    also: impl Fn(&K, &K) -> bool,
) -> Option<(usize, usize, u32)> {
    keys.iter().enumerate().find_map(|(j, k)| {
        keys[..j]
            .iter()
            .position(|o| o.frame() == k.frame() && o.same_track(k) && also(o, k))
            .map(|i| (i, j, k.frame()))
    })
}
