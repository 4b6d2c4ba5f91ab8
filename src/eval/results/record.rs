//! `<scene>/result.json`: one evaluated scene's per-frame scores, baseline and the
//! settings they were made under. Every eval writes it (sharded or not), so `dvr eval
//! --merge` can write the reports one run writes from scenes evaluated anywhere, and
//! refuses results made under other settings.

use super::SceneResult;
use crate::eval::plan::keys::ResultKey;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

const FILE: &str = "result.json";

#[derive(Serialize, Deserialize)]
struct Record {
    key: ResultKey,
    /// Wall-clock seconds the scene took.
    seconds: f64,
    result: SceneResult,
}

pub fn path(scene_dir: &Path) -> PathBuf {
    scene_dir.join(FILE)
}

pub fn save(scene_dir: &Path, key: &ResultKey, seconds: f64, result: &SceneResult) -> Result<()> {
    let record = Record {
        key: key.clone(),
        seconds,
        result: result.clone(),
    };
    crate::output::write_text(&path(scene_dir), &serde_json::to_string(&record)?)
}

/// The scene's result and its seconds, or why there is none to use (naming the file).
pub fn load(scene_dir: &Path, key: &ResultKey) -> Result<(SceneResult, f64), String> {
    let p = path(scene_dir);
    if !p.exists() {
        return Err(format!(
            "{}: missing (the scene was not evaluated)",
            p.display()
        ));
    }
    let record: Record = dvr_engine::files::read_text(&p, 1 << 30)
        .map_err(anyhow::Error::from)
        .and_then(|t| serde_json::from_str(&t).context("not an eval result"))
        .map_err(|e| format!("{}: does not read back ({e:#})", p.display()))?;
    if record.key != *key {
        return Err(format!(
            "{}: made under other settings ({}); evaluate the scene again",
            p.display(),
            differences(&record.key, key)
        ));
    }
    Ok((record.result, record.seconds))
}

/// Which settings differ, for the message.
fn differences(old: &ResultKey, new: &ResultKey) -> String {
    let r = (&old.references, &new.references);
    let checks = [
        (r.0.scene_hash != r.1.scene_hash, "scene edited"),
        (r.0.content_hash != r.1.content_hash, "volume or TF changed"),
        (
            (r.0.width, r.0.height, r.0.frames) != (r.1.width, r.1.height, r.1.frames),
            "size or frames",
        ),
        (r.0.ref_spp != r.1.ref_spp, "ref-spp"),
        (r.0.volume_size != r.1.volume_size, "volume size"),
        (old.methods != new.methods, "denoisers"),
        (old.spp != new.spp, "spp"),
        (old.motion != new.motion, "motion"),
        (old.aux != new.aux, "aux"),
        (
            old.shaders != new.shaders || r.0.renderer_hash != r.1.renderer_hash,
            "another build of dvr",
        ),
        (old.overrides != new.overrides, "DVR_* parameter overrides"),
    ];
    let what: Vec<&str> = checks.iter().filter(|c| c.0).map(|c| c.1).collect();
    if what.is_empty() {
        "unknown".into()
    } else {
        what.join(", ")
    }
}
