//! `<scene>/result.json`: one evaluated scene's per-frame scores, baseline and the
//! settings they were made under. Every eval writes it (sharded or not), so `dvr eval
//! --merge` can write the reports one run writes from scenes evaluated anywhere, and
//! refuses results made under other settings.

use super::reference::{shaders_hash, ReferenceCache};
use super::run::SceneResult;
use super::EvalArgs;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

const FILE: &str = "result.json";

/// What a scene's results depend on beyond its references.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultKey {
    /// The references' key (scene content, size, frames, ref-spp, path tracer).
    pub references: super::reference::ReferenceKey,
    pub methods: Vec<String>,
    pub spp: u32,
    pub motion: String,
    pub aux: bool,
    /// Every shader, so results of another build of dvr are not merged with these.
    pub shaders: String,
    /// The denoiser parameter overrides in the environment (`DVR_OURS`, …) that are set.
    pub overrides: Vec<(String, String)>,
}

impl ResultKey {
    pub fn new(args: &EvalArgs, methods: &[String], spp: u32, refs: &ReferenceCache) -> Self {
        Self {
            references: refs.key().clone(),
            methods: methods.to_vec(),
            spp,
            motion: args.render.motion.to_string(),
            aux: args.aux,
            shaders: shaders_hash(),
            overrides: dvr_engine::denoise::OVERRIDE_VARIABLES
                .iter()
                .filter_map(|v| Some((v.to_string(), std::env::var(v).ok()?)))
                .collect(),
        }
    }
}

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

/// `f64` fields that may be infinite (the PSNR of a frame equal to its reference) or
/// NaN, which JSON numbers cannot hold: written as the strings `inf`, `-inf`, `NaN`.
pub mod float {
    use serde::{de, Deserialize, Deserializer, Serializer};

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Number {
        Finite(f64),
        Text(String),
    }

    pub fn serialize<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        if v.is_finite() {
            s.serialize_f64(*v)
        } else {
            s.serialize_str(&v.to_string())
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Number::deserialize(d)? {
            Number::Finite(v) => Ok(v),
            Number::Text(t) => t.parse().map_err(de::Error::custom),
        }
    }

    /// The same for `Option<f64>` (`null` for none).
    pub mod option {
        use serde::{Deserialize, Deserializer, Serializer};

        pub fn serialize<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
            match v {
                Some(v) => super::serialize(v, s),
                None => s.serialize_none(),
            }
        }

        pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
            #[derive(Deserialize)]
            struct Wrapped(#[serde(with = "super")] f64);
            Ok(Option::<Wrapped>::deserialize(d)?.map(|w| w.0))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, Deserialize, PartialEq, Debug)]
    struct Row {
        #[serde(with = "float")]
        a: f64,
        #[serde(with = "float::option")]
        b: Option<f64>,
    }

    #[test]
    fn floats_round_trip_exactly_including_infinity() {
        for row in [
            Row {
                a: f64::INFINITY,
                b: None,
            },
            Row {
                a: 0.1 + 0.2,
                b: Some(f64::NEG_INFINITY),
            },
            Row {
                a: 31.876_543_210_987_654,
                b: Some(1e-300),
            },
        ] {
            let text = serde_json::to_string(&row).unwrap();
            let back: Row = serde_json::from_str(&text).unwrap();
            assert_eq!(back, row, "{text}");
            assert_eq!(back.a.to_bits(), row.a.to_bits());
        }
        let nan: Row = serde_json::from_str(r#"{"a": "NaN", "b": null}"#).unwrap();
        assert!(nan.a.is_nan());
    }
}
