//! `[[light]]`: point, rectangular area and environment lights.
//!
//! Units. Radiance is the HDR unit the path tracer outputs; a lit surface of the
//! built-in scenes is of order 1.
//! - point: `colour × intensity` is radiant intensity; irradiance at distance d is
//!   `colour × intensity / d²`.
//! - area: `colour × intensity` is the radiance the rectangle emits from its front side
//!   (the side its normal points to), so its power grows with its size.
//! - environment: `colour × intensity` (or `top`/`bottom`/map texel × intensity) is the
//!   radiance arriving from each direction. A gradient blends from `bottom` (direction
//!   −z) to `top` (+z) as `mix(bottom, top, 0.5 + 0.5·dir.z)`; a map is an
//!   equirectangular EXR with `u = atan2(dir.y, dir.x) / 2π + 0.5`, `v = acos(dir.z) / π`
//!   (z up, as the volume conventions in [`super::volume`]).
//!
//! `colour` defaults to white `[1, 1, 1]`; `intensity` is required.
//!
//! A file lists lights flat (`kind = "..."` and that kind's fields); [`Light`] is the
//! typed form. A field that does not belong to the kind is an error rather than being
//! ignored, so typos and copy-paste slips show up.

use std::path::PathBuf;

use glam::{DVec2, DVec3};
use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};

/// Lights the path tracer takes: the size of the light array in
/// `shaders/glsl/include/frame.glsl`, whose twin the engine's shader layer takes from
/// here (its test compares the two). A scene with more is an error, never truncated.
pub const MAX_LIGHTS: usize = 4;

/// Largest light intensity: lit surfaces of order 1 need 1–200; past this the
/// radiance overflows f32 on its way through a path and the image turns black.
pub const MAX_INTENSITY: f64 = 1e6;

/// Farthest a light (or an area light's target) may be from the volume's centre, in
/// world units (the volume is 1 unit across): a point light 1000 units away needs
/// intensity 10⁶ to light it at all.
pub const MAX_LIGHT_DISTANCE: f64 = 1e3;

/// Largest side of an area light, in world units.
pub const MAX_AREA_SIZE: f64 = 100.0;

/// Checks a light intensity (at rest or in a keyframe).
pub(crate) fn check_intensity(ctx: &Ctx, field: &str, x: f64) -> Result<(), SceneError> {
    ctx.in_range(field, x, 0.0, MAX_INTENSITY, "")
}

/// Checks a light position (at rest or in a keyframe).
pub(crate) fn check_position(ctx: &Ctx, field: &str, p: DVec3) -> Result<(), SceneError> {
    ctx.near_origin(
        field,
        p,
        MAX_LIGHT_DISTANCE,
        "a light farther away contributes nothing at any sensible intensity",
    )
}

/// The light types the path tracer implements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LightKind {
    Point,
    Area,
    Environment,
}

/// How an environment light gets its radiance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EnvMode {
    Constant,
    Gradient,
    Map,
}

/// One light of one frame (or of the scene at rest).
#[derive(Debug, Clone, PartialEq)]
pub enum Light {
    Point(PointLight),
    Area(AreaLight),
    Environment(EnvironmentLight),
}

#[derive(Debug, Clone, PartialEq)]
pub struct PointLight {
    pub position: DVec3,
    pub colour: DVec3,
    pub intensity: f64,
}

/// Which way an area light faces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Facing {
    /// Always faces this point, wherever the light moves (the usual choice).
    Target(DVec3),
    /// A fixed normal direction (non-zero, not necessarily unit).
    Normal(DVec3),
}

/// A rectangle of `size` (width, height) centred at `position`.
#[derive(Debug, Clone, PartialEq)]
pub struct AreaLight {
    pub position: DVec3,
    pub facing: Facing,
    pub size: DVec2,
    pub colour: DVec3,
    pub intensity: f64,
}

#[derive(Debug, Clone, PartialEq)]
pub enum EnvSource {
    Constant {
        colour: DVec3,
    },
    Gradient {
        top: DVec3,
        bottom: DVec3,
    },
    /// An equirectangular EXR; the path is already joined to the scene file's folder.
    Map {
        path: PathBuf,
    },
}

#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentLight {
    pub source: EnvSource,
    pub intensity: f64,
}

impl AreaLight {
    /// Unit normal of the emitting side.
    pub fn normal(&self) -> DVec3 {
        let n = match self.facing {
            Facing::Target(t) => t - self.position,
            Facing::Normal(n) => n,
        };
        n.normalize_or(DVec3::NEG_Z)
    }

    /// Half-extent vectors `(u, v)`: the corners are `position ± u ± v`. `u` (width)
    /// is horizontal (perpendicular to world +z) unless the light faces straight up or
    /// down, where it is world +x; `v` (height) completes a right-handed frame
    /// `(u, v, normal)`.
    pub fn half_axes(&self) -> (DVec3, DVec3) {
        let n = self.normal();
        let reference = if n.cross(DVec3::Z).length_squared() > 1e-8 {
            DVec3::Z
        } else {
            DVec3::Y
        };
        let u = reference.cross(n).normalize();
        let v = n.cross(u);
        (u * (0.5 * self.size.x), v * (0.5 * self.size.y))
    }

    /// Area of the rectangle.
    pub fn area(&self) -> f64 {
        self.size.x * self.size.y
    }
}

impl Light {
    /// Checks values: finite positions, colours `>= 0`, intensity `>= 0`, a positive
    /// area-light size, a facing that is not degenerate. `index` is the light's place in
    /// the scene's list, for the message.
    pub(crate) fn check(&self, ctx: &Ctx, index: usize) -> Result<(), SceneError> {
        let field = |name: &str| format!("light[{index}].{name}");
        check_intensity(ctx, &field("intensity"), self.intensity())?;
        if let Some(p) = self.position() {
            check_position(ctx, &field("position"), p)?;
        }
        if let Some(c) = self.colour() {
            ctx.colour(&field("colour"), c)?;
        }
        match self {
            Self::Point(_) => {}
            Self::Area(a) => {
                for side in [a.size.x, a.size.y] {
                    ctx.positive(&field("size"), side)?;
                    ctx.in_range(&field("size"), side, 0.0, MAX_AREA_SIZE, " world units")?;
                }
                match a.facing {
                    Facing::Target(t) => {
                        check_position(ctx, &field("target"), t)?;
                        if (t - a.position).length_squared() < 1e-12 {
                            return Err(ctx.invalid(field("target"), "equals the light's position"));
                        }
                    }
                    Facing::Normal(n) => ctx.unit_vector(&field("normal"), n)?,
                }
            }
            Self::Environment(e) => match &e.source {
                EnvSource::Constant { .. } => {}
                EnvSource::Map { path } => match dvr_volume::files::not_a_regular_file(path) {
                    Ok(None) => {}
                    Ok(Some(what)) => {
                        return Err(ctx.invalid(
                            field("map"),
                            format!("{} is {what}, not an EXR file", path.display()),
                        ))
                    }
                    Err(e) => {
                        return Err(ctx.invalid(field("map"), format!("{}: {e}", path.display())))
                    }
                },
                EnvSource::Gradient { top, bottom } => {
                    ctx.colour(&field("top"), *top)?;
                    ctx.colour(&field("bottom"), *bottom)?;
                }
            },
        }
        Ok(())
    }

    pub fn kind(&self) -> LightKind {
        match self {
            Self::Point(_) => LightKind::Point,
            Self::Area(_) => LightKind::Area,
            Self::Environment(_) => LightKind::Environment,
        }
    }

    /// The position of point and area lights.
    pub fn position(&self) -> Option<DVec3> {
        match self {
            Self::Point(l) => Some(l.position),
            Self::Area(l) => Some(l.position),
            Self::Environment(_) => None,
        }
    }

    /// The single colour of point, area and constant environment lights.
    pub fn colour(&self) -> Option<DVec3> {
        match self {
            Self::Point(l) => Some(l.colour),
            Self::Area(l) => Some(l.colour),
            Self::Environment(EnvironmentLight {
                source: EnvSource::Constant { colour },
                ..
            }) => Some(*colour),
            Self::Environment(_) => None,
        }
    }

    pub fn intensity(&self) -> f64 {
        match self {
            Self::Point(l) => l.intensity,
            Self::Area(l) => l.intensity,
            Self::Environment(l) => l.intensity,
        }
    }

    /// Sets the position; false (and nothing changes) for an environment light.
    pub fn set_position(&mut self, p: DVec3) -> bool {
        match self {
            Self::Point(l) => l.position = p,
            Self::Area(l) => l.position = p,
            Self::Environment(_) => return false,
        }
        true
    }

    /// Sets the colour; false (and nothing changes) where [`Self::colour`] is `None`.
    pub fn set_colour(&mut self, c: DVec3) -> bool {
        match self {
            Self::Point(l) => l.colour = c,
            Self::Area(l) => l.colour = c,
            Self::Environment(EnvironmentLight {
                source: EnvSource::Constant { colour },
                ..
            }) => *colour = c,
            Self::Environment(_) => return false,
        }
        true
    }

    pub fn set_intensity(&mut self, x: f64) {
        match self {
            Self::Point(l) => l.intensity = x,
            Self::Area(l) => l.intensity = x,
            Self::Environment(l) => l.intensity = x,
        }
    }
}

/// `[[light]]` as written: a kind and every kind's fields, checked into a [`Light`].
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct LightFile {
    kind: LightKind,
    #[serde(skip_serializing_if = "Option::is_none")]
    position: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    target: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    normal: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    size: Option<DVec2>,
    #[serde(skip_serializing_if = "Option::is_none")]
    mode: Option<EnvMode>,
    #[serde(skip_serializing_if = "Option::is_none", alias = "color")]
    colour: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    top: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    bottom: Option<DVec3>,
    #[serde(skip_serializing_if = "Option::is_none")]
    map: Option<PathBuf>,
    intensity: f64,
}

impl LightFile {
    /// Every `[[light]]` of a file, in order.
    pub fn into_lights(files: Vec<Self>, ctx: &Ctx) -> Result<Vec<Light>, SceneError> {
        files
            .into_iter()
            .enumerate()
            .map(|(i, l)| l.into_light(ctx, i))
            .collect()
    }

    /// Structure only (which fields a kind needs and allows); values are checked by
    /// [`Light::check`].
    pub fn into_light(self, ctx: &Ctx, index: usize) -> Result<Light, SceneError> {
        let field = |name: &str| format!("light[{index}].{name}");
        let kind_name = match self.kind {
            LightKind::Point => "point",
            LightKind::Area => "area",
            LightKind::Environment => "environment",
        };
        // Fields that do not belong to this kind (`colour`, which every kind but a
        // gradient or map environment has, is checked per mode below).
        let allowed: &[&str] = match self.kind {
            LightKind::Point => &["position"],
            LightKind::Area => &["position", "target", "normal", "size"],
            LightKind::Environment => &["mode", "top", "bottom", "map"],
        };
        for (name, given) in [
            ("position", self.position.is_some()),
            ("target", self.target.is_some()),
            ("normal", self.normal.is_some()),
            ("size", self.size.is_some()),
            ("mode", self.mode.is_some()),
            ("top", self.top.is_some()),
            ("bottom", self.bottom.is_some()),
            ("map", self.map.is_some()),
        ] {
            if given && !allowed.contains(&name) {
                return Err(ctx.invalid(field(name), format!("not a field of a {kind_name} light")));
            }
        }
        let colour = self.colour.unwrap_or(DVec3::ONE);
        let need = |v: Option<DVec3>, name: &str| -> Result<DVec3, SceneError> {
            v.ok_or_else(|| ctx.invalid(field(name), format!("required for a {kind_name} light")))
        };
        Ok(match self.kind {
            LightKind::Point => Light::Point(PointLight {
                position: need(self.position, "position")?,
                colour,
                intensity: self.intensity,
            }),
            LightKind::Area => {
                let position = need(self.position, "position")?;
                let facing = match (self.target, self.normal) {
                    (Some(t), None) => Facing::Target(t),
                    (None, Some(n)) => Facing::Normal(n),
                    (Some(_), Some(_)) => {
                        return Err(
                            ctx.invalid(field("normal"), "give `target` or `normal`, not both")
                        )
                    }
                    (None, None) => {
                        return Err(ctx
                            .invalid(field("target"), "an area light needs `target` or `normal`"))
                    }
                };
                let size = self.size.ok_or_else(|| {
                    ctx.invalid(field("size"), "required for an area light: [width, height]")
                })?;
                Light::Area(AreaLight {
                    position,
                    facing,
                    size,
                    colour,
                    intensity: self.intensity,
                })
            }
            LightKind::Environment => {
                let mode = self.mode.unwrap_or(EnvMode::Constant);
                let colour_given = self.colour.is_some();
                let source = match mode {
                    EnvMode::Constant => {
                        for (name, given) in [
                            ("top", self.top.is_some()),
                            ("bottom", self.bottom.is_some()),
                            ("map", self.map.is_some()),
                        ] {
                            if given {
                                return Err(ctx.invalid(
                                    field(name),
                                    "not used by mode = \"constant\" (use `colour`)",
                                ));
                            }
                        }
                        EnvSource::Constant { colour }
                    }
                    EnvMode::Gradient => {
                        if self.map.is_some() || colour_given {
                            let name = if self.map.is_some() { "map" } else { "colour" };
                            return Err(ctx.invalid(
                                field(name),
                                "not used by mode = \"gradient\" (use `top` and `bottom`)",
                            ));
                        }
                        EnvSource::Gradient {
                            top: need(self.top, "top")?,
                            bottom: need(self.bottom, "bottom")?,
                        }
                    }
                    EnvMode::Map => {
                        for (name, given) in [
                            ("top", self.top.is_some()),
                            ("bottom", self.bottom.is_some()),
                            ("colour", colour_given),
                        ] {
                            if given {
                                return Err(ctx.invalid(
                                    field(name),
                                    "not used by mode = \"map\" (only `map` and `intensity`)",
                                ));
                            }
                        }
                        let path = self.map.ok_or_else(|| {
                            ctx.invalid(field("map"), "required for mode = \"map\"")
                        })?;
                        EnvSource::Map {
                            path: ctx.resolve(&path),
                        }
                    }
                };
                Light::Environment(EnvironmentLight {
                    source,
                    intensity: self.intensity,
                })
            }
        })
    }

    pub fn from_light(l: &Light) -> Self {
        let mut f = Self {
            kind: l.kind(),
            position: l.position(),
            target: None,
            normal: None,
            size: None,
            mode: None,
            colour: l.colour(),
            top: None,
            bottom: None,
            map: None,
            intensity: l.intensity(),
        };
        match l {
            Light::Point(_) => {}
            Light::Area(a) => {
                f.size = Some(a.size);
                match a.facing {
                    Facing::Target(t) => f.target = Some(t),
                    Facing::Normal(n) => f.normal = Some(n),
                }
            }
            Light::Environment(e) => match &e.source {
                EnvSource::Constant { .. } => f.mode = Some(EnvMode::Constant),
                EnvSource::Gradient { top, bottom } => {
                    f.mode = Some(EnvMode::Gradient);
                    f.top = Some(*top);
                    f.bottom = Some(*bottom);
                }
                EnvSource::Map { path } => {
                    f.mode = Some(EnvMode::Map);
                    f.map = Some(path.clone());
                }
            },
        }
        f
    }
}

/// A scene's lights as a whole: at least one unless the TF emits, at most
/// [`MAX_LIGHTS`], at most one environment, each light checked. Scene files and a live
/// session's light edits are checked by this one function.
pub(crate) fn check_lights(ctx: &Ctx, lights: &[Light], emission: bool) -> Result<(), SceneError> {
    if lights.is_empty() && !emission {
        return Err(ctx.invalid(
            "light",
            "a scene needs at least one [[light]] (or render.emission = true)",
        ));
    }
    if lights.len() > MAX_LIGHTS {
        return Err(ctx.invalid(
            "light",
            format!(
                "{} lights; the path tracer takes at most {MAX_LIGHTS} (remove or merge some)",
                lights.len(),
            ),
        ));
    }
    let mut environments = 0;
    for (i, light) in lights.iter().enumerate() {
        light.check(ctx, i)?;
        if matches!(light, Light::Environment(_)) {
            environments += 1;
            if environments > 1 {
                return Err(ctx.invalid(
                    format!("light[{i}].kind"),
                    "a scene has at most one environment light",
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn area_light_frame_is_orthonormal_and_faces_its_target() {
        let a = AreaLight {
            position: DVec3::new(-0.6, 1.0, 1.1),
            facing: Facing::Target(DVec3::ZERO),
            size: DVec2::new(0.5, 0.25),
            colour: DVec3::ONE,
            intensity: 1.0,
        };
        let n = a.normal();
        assert!((n - (-a.position).normalize()).length() < 1e-12);
        let (u, v) = a.half_axes();
        assert!((u.length() - 0.25).abs() < 1e-12 && (v.length() - 0.125).abs() < 1e-12);
        assert!(u.dot(v).abs() < 1e-12 && u.dot(n).abs() < 1e-12 && v.dot(n).abs() < 1e-12);
        assert!(
            u.cross(v).normalize().dot(n) > 0.999,
            "(u, v, n) right-handed"
        );
        assert!(u.z.abs() < 1e-12, "width is horizontal");
        let down = AreaLight {
            facing: Facing::Normal(DVec3::NEG_Z),
            ..a
        };
        let (u, v) = down.half_axes();
        assert!(u.is_finite() && v.is_finite() && u.length() > 0.0);
    }
}
