//! The plan of an eval, made before anything renders: which scenes, under which labels
//! and folders ([`scenes`]), with which options ([`settings`]), and the keys its files
//! are made under ([`keys`]).
//!
//! The bottom layer of the eval: it imports nothing of the eval (only the command
//! line's options, the scene loader and the engine). Above it: `references`, `results`,
//! then `run` and `scores`, then `report`, then `farm` and the command itself.

pub mod keys;
pub mod scenes;
pub mod settings;

use anyhow::Result;
use keys::{ReferenceKey, ResultKey};
use settings::EvalArgs;
use std::path::PathBuf;

/// One scene as planned before anything renders.
pub struct PlannedScene {
    /// What `--scene` named: a built-in name or a scene file's path (opened again for
    /// rendering).
    pub spec: String,
    /// The label in tables, plots and the page: the scene's `name` (a file's own name or
    /// its file stem, `dvr scenes`' name for a built-in), made unique within the eval.
    pub name: String,
    pub dir: PathBuf,
    pub frames: u32,
    pub spp: u32,
    /// What its references are rendered under (their cache is
    /// `ReferenceCache::of(scene)`, in `<dir>/reference/`).
    pub reference_key: ReferenceKey,
}

impl PlannedScene {
    /// The key this scene's `result.json` must carry for this eval.
    pub fn result_key(&self, args: &EvalArgs, methods: &[String]) -> ResultKey {
        ResultKey::new(args, methods, self.spp, &self.reference_key)
    }
}

/// Every scene of an eval, in order, and what sizes its work besides the frames.
pub struct Plan {
    pub scenes: Vec<PlannedScene>,
    /// Samples per pixel of the references (`--ref-spp`).
    pub ref_spp: u32,
    /// How many methods run on every frame.
    pub methods: usize,
    /// Whether the accumulation baseline is measured (not `--no-baseline`).
    pub baseline: bool,
}

impl Plan {
    pub fn new(args: &EvalArgs, names: &[String], methods: &[String]) -> Result<Self> {
        let mut opened = Vec::new();
        for spec in names {
            let mut scene = crate::setup::open_scene(spec)?;
            if let Some(n) = args.frames {
                scene = scene.with_frames(n)?;
            }
            opened.push((spec, scene));
        }
        let labels: Vec<String> = opened.iter().map(|(_, s)| s.name.clone()).collect();
        let mut scenes = Vec::new();
        for ((spec, scene), (label, dir)) in opened.into_iter().zip(scenes::unique_labels(&labels))
        {
            let dir = args.out.join(dir);
            let key = ReferenceKey::new(&scene, args.size, args.ref_spp, args.render.volume_size)?;
            scenes.push(PlannedScene {
                spec: spec.clone(),
                name: label,
                frames: scene.frames,
                spp: args.render.spp.unwrap_or(scene.render.spp()),
                reference_key: key,
                dir,
            });
        }
        Ok(Self {
            scenes,
            ref_spp: args.ref_spp,
            methods: methods.len(),
            baseline: !args.no_baseline,
        })
    }
}
