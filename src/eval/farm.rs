//! An eval split over machines (see [`crate::shard`]): the references alone
//! (`--references-only`, a unit per frame), the check that every unit is done
//! (`--verify`), and the reports written from scenes evaluated by shards (`--merge`).
//!
//! The eval's top layer: it drives the layers below (plan, references, results, run)
//! as the command does, and nothing below imports it.

use super::plan::settings::{scene_args, EvalArgs};
use super::plan::Plan;
use super::references::ReferenceCache;
use super::results::{record, SceneResult};
use super::run::timing::Timing;
use super::run::ReferenceProgress;
use crate::setup::Setup;
use crate::shard::{FolderReport, RunReport, ShardArgs};
use anyhow::{Context, Result};
use std::sync::Arc;

/// The reference frames of this shard, numbered over all scenes in order.
fn reference_units(plan: &Plan, shard: &ShardArgs) -> Vec<Vec<u32>> {
    let mut k = 0;
    plan.scenes
        .iter()
        .map(|s| {
            let frames = (0..s.frames).filter(|_| {
                k += 1;
                shard.takes(k - 1)
            });
            frames.collect()
        })
        .collect()
}

/// `--references-only`: fills this shard's reference frames (or, with `--verify`,
/// checks them).
pub fn references(args: &EvalArgs, plan: &Plan, timing: &Arc<Timing>) -> Result<()> {
    let shard = &args.farm.shard;
    let units = reference_units(plan, shard);
    if shard.verify {
        let problems: Vec<String> = plan
            .scenes
            .iter()
            .zip(&units)
            .flat_map(|(s, frames)| ReferenceCache::of(s).problems(frames))
            .collect();
        let checked = units.iter().map(Vec::len).sum();
        return crate::shard::verdict("reference frames", checked, &problems);
    }
    crate::setup::create_out_dir(&args.out)?;
    let missing: usize = plan
        .scenes
        .iter()
        .zip(&units)
        // A scene with none of this shard's frames is not read back at all.
        .filter(|(_, frames)| !frames.is_empty())
        .map(|(s, frames)| {
            let m = ReferenceCache::of(s).missing();
            frames.iter().filter(|f| m.contains(f)).count()
        })
        .sum();
    let mut progress = crate::progress::Progress::new(missing as f64 * f64::from(args.ref_spp));
    let mut report = RunReport::new(shard);
    for (i, (scene, frames)) in plan.scenes.iter().zip(&units).enumerate() {
        if frames.is_empty() {
            continue;
        }
        let label = format!("[{}/{}] {}", i + 1, plan.scenes.len(), scene.name);
        progress.show(&format!("{label} | loading"));
        let setup = Setup::new(&scene_args(args, &scene.spec))?;
        let references = ReferenceCache::of(scene);
        let filled = references
            .fill_frames(
                &setup,
                &mut ReferenceProgress {
                    progress: &mut progress,
                    label: &label,
                    ref_spp: args.ref_spp,
                    timing,
                    writes: None,
                },
                frames,
            )
            .with_context(|| format!("rendering the references of {}", scene.name))?;
        report.references.push(FolderReport {
            scene: scene.name.clone(),
            folder: references.dir.clone(),
            selected: frames.clone(),
            rendered: filled.rendered,
            reused: filled.reused,
        });
        report.write(shard.report.as_deref())?;
    }
    progress.finish();
    report.write(shard.report.as_deref())?;
    let rendered: usize = report.references.iter().map(|r| r.rendered.len()).sum();
    let selected: usize = units.iter().map(Vec::len).sum();
    println!(
        "eval: {selected} reference frame(s){} in {} ({rendered} rendered, {} already there)",
        shard
            .label()
            .map(|s| format!(" of shard {s}"))
            .unwrap_or_default(),
        args.out.display(),
        selected - rendered
    );
    Ok(())
}

/// `--verify` without `--references-only`: the references and the results of this
/// shard's scenes.
pub fn verify(args: &EvalArgs, plan: &Plan, methods: &[String]) -> Result<()> {
    let mut problems = Vec::new();
    let mut checked = 0;
    for (_, scene) in plan
        .scenes
        .iter()
        .enumerate()
        .filter(|(i, _)| args.farm.shard.takes(*i))
    {
        checked += 1;
        let frames: Vec<u32> = (0..scene.frames).collect();
        problems.extend(ReferenceCache::of(scene).problems(&frames));
        if let Err(p) = record::load(&scene.dir, &scene.result_key(args, methods)) {
            problems.push(p);
        }
    }
    crate::shard::verdict("scene(s)", checked, &problems)
}

/// `--merge`: every scene's result, in the plan's order, and the seconds they took
/// together; an error naming each missing or stale one.
pub fn results(
    args: &EvalArgs,
    plan: &Plan,
    methods: &[String],
) -> Result<(Vec<SceneResult>, f64)> {
    let mut results = Vec::new();
    let mut problems = Vec::new();
    let mut seconds = 0.0;
    for scene in &plan.scenes {
        match record::load(&scene.dir, &scene.result_key(args, methods)) {
            Ok((r, s)) => {
                results.push(r);
                seconds += s;
            }
            Err(p) => problems.push(p),
        }
    }
    if !problems.is_empty() {
        for p in &problems {
            eprintln!("missing: {p}");
        }
        anyhow::bail!(
            "cannot merge {}: {} of {} scene(s) have no usable result (listed above); run \
             the shards that evaluate them (`dvr eval --shard I/N` with the same options)",
            args.out.display(),
            problems.len(),
            plan.scenes.len()
        );
    }
    Ok((results, seconds))
}
