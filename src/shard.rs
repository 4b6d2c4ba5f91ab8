//! Splitting a reference or eval job over processes and machines: which units a shard
//! takes, the check that every unit is done (`--verify`), and the record of what one
//! run did (`--report`), for a scheduler (Slurm arrays, Kubernetes indexed Jobs, the Ray
//! runner in `python -m dvr.farm`) to drive.
//!
//! A unit is a reference frame (`dvr reference`, `dvr eval --references-only`) or a
//! scene (`dvr eval`: a temporal denoiser runs a scene's frames in order, so a scene is
//! the smallest piece of its work). Units are numbered in the order one run does them
//! (scenes as listed, frames in order) and shard I of N takes every N-th from the I-th.
//! Every unit's output depends only on its own identity and the settings (a reference
//! frame's samples are seeded by its index; a scene's methods start from frame 0), and
//! is written atomically into a folder claimed under one key, so shards may run in any
//! order, at once, or again: the files are those one run writes.

use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(clap::Args, Clone, Debug, Default)]
pub struct ShardArgs {
    /// Only shard I of N (`I/N`, 0-based): every N-th unit from the I-th, so N runs with
    /// I = 0..N-1 on one folder do each unit once and leave the files one run leaves
    /// (`$SLURM_ARRAY_TASK_ID/N`, `$JOB_COMPLETION_INDEX/N`). A unit is a reference
    /// frame for `dvr reference` and `dvr eval --references-only`, a scene for `dvr
    /// eval` (then `dvr eval --merge` writes the reports).
    #[arg(long, value_parser = crate::args::parse_shard)]
    pub shard: Option<(u32, u32)>,
    /// Render nothing: check that every selected unit is present under these settings
    /// and reads back, name each one that is not, and exit 1 if any is not (a rerun
    /// without --verify renders just those).
    #[arg(long)]
    pub verify: bool,
    /// Also write what this run did as JSON: per reference folder the frames selected,
    /// rendered and found done; the scenes evaluated.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

impl ShardArgs {
    /// Whether unit `k` (0-based, in one run's order) is this shard's.
    pub fn takes(&self, k: usize) -> bool {
        let (i, n) = self.shard.unwrap_or((0, 1));
        k % n as usize == i as usize
    }

    /// `I/N`, for messages and the report.
    pub fn label(&self) -> Option<String> {
        self.shard.map(|(i, n)| format!("{i}/{n}"))
    }
}

/// What one run did (`--report`).
#[derive(Serialize, Default)]
pub struct RunReport {
    pub shard: Option<String>,
    pub references: Vec<FolderReport>,
    /// Scenes whose methods this run evaluated (`dvr eval`).
    pub scenes: Vec<String>,
}

/// One reference folder's share of a run.
#[derive(Serialize)]
pub struct FolderReport {
    pub scene: String,
    pub folder: PathBuf,
    pub selected: Vec<u32>,
    pub rendered: Vec<u32>,
    pub reused: Vec<u32>,
}

impl RunReport {
    pub fn new(args: &ShardArgs) -> Self {
        Self {
            shard: args.label(),
            ..Self::default()
        }
    }

    pub fn write(&self, path: Option<&Path>) -> Result<()> {
        match path {
            Some(p) => crate::output::write_json(p, self),
            None => Ok(()),
        }
    }
}

/// Ends a `--verify`: success when nothing is wrong, else an error listing each problem
/// (the frames or scenes to rerun).
pub fn verdict(what: &str, checked: usize, problems: &[String]) -> Result<()> {
    if problems.is_empty() {
        println!("verified {checked} {what}: all present and readable");
        return Ok(());
    }
    for p in problems {
        eprintln!("missing: {p}");
    }
    anyhow::bail!(
        "{} problem(s) among {checked} {what} (listed above); rerun the same command without \
         --verify to render what is missing",
        problems.len()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_cover_every_unit_once() {
        for n in 1..6u32 {
            let mut seen = vec![0; 17];
            for i in 0..n {
                let args = ShardArgs {
                    shard: Some((i, n)),
                    ..ShardArgs::default()
                };
                for (k, s) in seen.iter_mut().enumerate() {
                    if args.takes(k) {
                        *s += 1;
                    }
                }
            }
            assert!(seen.iter().all(|&s| s == 1), "{n} shards: {seen:?}");
        }
        assert!((0..9).all(|k| ShardArgs::default().takes(k)));
    }
}
