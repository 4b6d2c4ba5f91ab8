//! `[transfer]`: which transfer functions a scene uses, by preset name or file path.
//!
//! `a` is the TF at rest; `b`, when given, is the target of `[[animation.tf]]` blends
//! (blend 0 = a, 1 = b; the functions are blended, see [`crate::transfer::TfLut::lerp`]).
//! A value containing `/` or `\` or ending in `.toml` is a file path (relative to the
//! scene file's folder); anything else is a preset in `assets/transfer/`.

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::error::{Ctx, SceneError};
use crate::transfer::TransferFunction;

/// `[transfer]` as written (paths already joined to the scene file's folder).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransferSpec {
    pub a: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b: Option<String>,
}

/// True if `spec` names a file rather than a preset.
pub fn is_path(spec: &str) -> bool {
    spec.contains(['/', '\\']) || spec.ends_with(".toml")
}

impl TransferSpec {
    /// Loads both TFs. Returns the spec with paths joined to the scene's folder.
    pub(crate) fn resolve(
        &self,
        ctx: &Ctx,
    ) -> Result<(Self, TransferFunction, Option<TransferFunction>), SceneError> {
        let (a, tf_a) = resolve_one(ctx, "transfer.a", &self.a)?;
        let (b, tf_b) = match &self.b {
            Some(spec) => {
                let (b, tf) = resolve_one(ctx, "transfer.b", spec)?;
                (Some(b), Some(tf))
            }
            None => (None, None),
        };
        Ok((Self { a, b }, tf_a, tf_b))
    }
}

pub(crate) fn resolve_one(
    ctx: &Ctx,
    field: &str,
    spec: &str,
) -> Result<(String, TransferFunction), SceneError> {
    let err = |source| SceneError::Transfer {
        origin: ctx.origin.to_string(),
        field: field.to_string(),
        source: Box::new(source),
    };
    if is_path(spec) {
        let path = ctx.resolve(Path::new(spec));
        let tf = TransferFunction::load(&path).map_err(err)?;
        Ok((path.display().to_string(), tf))
    } else {
        Ok((
            spec.to_string(),
            TransferFunction::preset(spec).map_err(err)?,
        ))
    }
}
