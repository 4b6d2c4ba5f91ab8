//! `--video` for an eval: per scene, the reference and every method as MP4s and one
//! side-by-side comparison whose labels carry each frame's PSNR, in
//! `DIR/<scene>/videos/` (see [`crate::video`]).

use crate::eval::results::SceneResult;
use crate::video::{self, Track};
use anyhow::Result;
use std::path::Path;

/// The track name of the references (also their folder name).
pub const REFERENCE: &str = "reference";

pub fn write_scene_videos(out: &Path, r: &SceneResult, fps: u32) -> Result<()> {
    let dir = out.join(&r.dir);
    let mut tracks = vec![Track::from_folder(
        REFERENCE,
        &dir.join(REFERENCE),
        r.frames,
    )];
    for m in &r.methods {
        let mut t = Track::from_folder(m, &dir.join(m), r.frames);
        t.captions = r
            .series(m)
            .iter()
            .map(|row| format!("{:.2} dB", row.psnr))
            .collect();
        tracks.push(t);
    }
    video::write_videos(&dir, &tracks, fps)?;
    Ok(())
}
