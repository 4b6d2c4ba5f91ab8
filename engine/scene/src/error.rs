//! Errors from reading and checking scenes, and the small checking helpers that make
//! every message name the file and the field.

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::transfer::TransferError;

/// Everything that can go wrong reading, checking or writing a scene. Messages start
/// with the file (or label) the scene came from, then the field, e.g.
/// `scenes/head.toml: animation.light[2].index: light 3 does not exist (...)`.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{}: cannot read scene: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown field, a missing required field or a value of the
    /// wrong type (negative counts included). The message carries line and column.
    #[error("{origin}: {source}")]
    Parse {
        origin: String,
        source: Box<toml::de::Error>,
    },
    /// A value parsed but is out of range or inconsistent with the rest of the scene.
    #[error("{origin}: {field}: {message}")]
    Invalid {
        origin: String,
        field: String,
        message: String,
    },
    /// A transfer function named by the scene is missing or invalid.
    #[error("{origin}: {field}: {source}")]
    Transfer {
        origin: String,
        field: String,
        source: Box<TransferError>,
    },
    /// `Scene::builtin` with a name that is not in [`super::Scene::builtin_names`].
    #[error("unknown built-in scene `{name}`; available: {available}")]
    UnknownBuiltin { name: String, available: String },
    /// The scene could not be written as TOML (e.g. a path that is not UTF-8).
    #[error("{name}: cannot write scene as TOML: {source}")]
    Serialize {
        name: String,
        source: Box<toml::ser::Error>,
    },
}

/// A render setting outside its allowed range: what each `RenderSettings` setter
/// returns. The engine's error takes it as its `InvalidSetting`, with the same message.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{name} = {value} is not allowed; {allowed}")]
pub struct SettingError {
    /// The setting, as a scene file's `[render]` field names it.
    pub name: &'static str,
    /// The value refused, as written.
    pub value: String,
    /// The range the setting allows.
    pub allowed: String,
}

/// Largest colour channel: colours scale radiance (with a light's intensity), and
/// colour × intensity must stay far inside f32 through a path's products.
pub const MAX_COLOUR: f64 = 1e6;

/// Where a scene came from: names it in errors and anchors its relative paths.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Ctx<'a> {
    pub origin: &'a str,
    /// Relative paths in the scene are joined to this (the scene file's folder).
    pub base: Option<&'a Path>,
}

impl Ctx<'_> {
    pub fn invalid(&self, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        SceneError::Invalid {
            origin: self.origin.to_string(),
            field: field.into(),
            message: message.into(),
        }
    }

    pub fn resolve(&self, path: &Path) -> PathBuf {
        match self.base {
            Some(base) if path.is_relative() => base.join(path),
            _ => path.to_path_buf(),
        }
    }

    pub fn positive(&self, field: &str, x: f64) -> Result<(), SceneError> {
        if x.is_finite() && x > 0.0 {
            Ok(())
        } else {
            Err(self.invalid(field, format!("{x} must be finite and > 0")))
        }
    }

    /// `x` finite and in `[lo, hi]`; `why` (may be empty) says what the range means.
    pub fn in_range(
        &self,
        field: &str,
        x: f64,
        lo: f64,
        hi: f64,
        why: &str,
    ) -> Result<(), SceneError> {
        if x.is_finite() && (lo..=hi).contains(&x) {
            Ok(())
        } else {
            Err(self.invalid(
                field,
                format!("{} is outside [{}, {}]{why}", num(x), num(lo), num(hi)),
            ))
        }
    }

    /// `x` finite and in `(0, hi]`; `why` (may be empty) says what the range means.
    pub fn positive_up_to(
        &self,
        field: &str,
        x: f64,
        hi: f64,
        why: &str,
    ) -> Result<(), SceneError> {
        if x.is_finite() && x > 0.0 && x <= hi {
            Ok(())
        } else {
            Err(self.invalid(
                field,
                format!("{} is outside (0, {}]{why}", num(x), num(hi)),
            ))
        }
    }

    /// A point finite and at most `max` world units from the origin (the volume's
    /// centre); `why` says what is lost past it.
    pub fn near_origin(
        &self,
        field: &str,
        v: DVec3,
        max: f64,
        why: &str,
    ) -> Result<(), SceneError> {
        self.finite3(field, v)?;
        if v.length() <= max {
            Ok(())
        } else {
            Err(self.invalid(
                field,
                format!(
                    "{v} is {} world units from the volume's centre; at most {} ({why})",
                    num(v.length()),
                    num(max)
                ),
            ))
        }
    }

    pub fn finite3(&self, field: &str, v: DVec3) -> Result<(), SceneError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.invalid(field, format!("{v} has a component that is not finite")))
        }
    }

    /// A colour: finite, every channel in `[0, MAX_COLOUR]`.
    pub fn colour(&self, field: &str, c: DVec3) -> Result<(), SceneError> {
        if c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= MAX_COLOUR {
            Ok(())
        } else {
            Err(self.invalid(
                field,
                format!("colour {c} must be finite and in [0, {MAX_COLOUR:e}] in every channel"),
            ))
        }
    }

    pub fn unit_vector(&self, field: &str, v: DVec3) -> Result<(), SceneError> {
        self.finite3(field, v)?;
        if v.length_squared() > 1e-12 {
            Ok(())
        } else {
            Err(self.invalid(field, "must not be the zero vector"))
        }
    }
}

/// A number as a person writes it: plain when moderate, `1e300` when huge or tiny.
pub(crate) fn num(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}
