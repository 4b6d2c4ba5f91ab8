//! Filling a reference cache: what is there is reused, what is missing or unreadable is
//! rendered by a session of its own and written, each frame told to a [`FillReport`].

use super::claim::Claim;
use super::ReferenceCache;
use crate::setup::Setup;
use anyhow::Result;
use dvr_engine::image_io::to_rgb;
use dvr_engine::metrics::Rgb32Image;

impl ReferenceCache {
    /// Renders frame `f` in as few dispatches as the device takes (one per frame on a
    /// GPU at 256x256; lavapipe's loop limiter needs 4-sample ones).
    pub fn render(
        &self,
        setup: &Setup,
        session: &mut dvr_engine::session::Session,
        f: u32,
    ) -> Result<Rgb32Image> {
        let batch = session.renderer()?.samples_per_dispatch();
        let pixels = session.reference_at(f, self.key.ref_spp, batch)?;
        Ok(to_rgb(setup.width(), setup.height(), &pixels))
    }

    /// Brings the cache up to date: reuses what is there, warns about and re-renders
    /// unreadable frames, renders the rest with a renderer made by `setup` only when
    /// some frame is missing. Returns the run's claim on the folder (keep it while the
    /// frames are read) and what it rendered.
    pub fn fill(&self, setup: &Setup, report: &mut dyn FillReport) -> Result<Filled> {
        let all: Vec<u32> = (0..self.key.frames).collect();
        self.fill_frames(setup, report, &all)
    }

    /// [`ReferenceCache::fill`] for the frames `wanted` only (`dvr reference
    /// --frame-range`/`--shard`). Each frame's image depends on nothing but the key and
    /// its index (the renderer renders references only, from the reference stream), so
    /// frames rendered by separate runs are the frames one run renders.
    pub fn fill_frames(
        &self,
        setup: &Setup,
        report: &mut dyn FillReport,
        wanted: &[u32],
    ) -> Result<Filled> {
        let claim = self.claim()?;
        let mut state = self.state();
        state.missing.retain(|f| wanted.contains(f));
        state.unreadable.retain(|(path, _)| {
            wanted
                .iter()
                .any(|&f| *path == self.exr(f) || *path == self.png(f))
        });
        let reused = wanted.len() - state.missing.len();
        for (path, why) in &state.unreadable {
            report.note(None);
            log::warn!(
                "{}: cached reference does not read back ({why}); re-rendering it",
                path.display()
            );
        }
        if let Some(changed) = &claim.note {
            report.note(Some(changed));
        }
        if state.missing.is_empty() {
            report.note(Some(&format!(
                "reusing {reused} reference frame(s) in {}",
                self.dir.display()
            )));
            return Ok(Filled {
                claim,
                rendered: Vec::new(),
                reused: wanted.to_vec(),
            });
        }
        if reused > 0 {
            report.note(Some(&format!(
                "reusing {reused} reference frame(s), rendering {}",
                state.missing.len()
            )));
        }
        // The same renderer set-up for `dvr reference` and `dvr eval`, so their cached
        // frames are identical.
        let mut session = setup.session(&["none"])?;
        report.rendered(0, state.missing.len());
        for (i, &f) in state.missing.iter().enumerate() {
            let img = self.render(setup, &mut session, f)?;
            report.store(self, f, img)?;
            report.rendered(i + 1, state.missing.len());
        }
        report.finished(session.renderer()?)?;
        Ok(Filled {
            claim,
            reused: wanted
                .iter()
                .copied()
                .filter(|f| !state.missing.contains(f))
                .collect(),
            rendered: state.missing,
        })
    }
}

/// What [`ReferenceCache::fill_frames`] did: the claim to keep while the frames are
/// read, and which of the wanted frames it rendered and which it found done.
pub struct Filled {
    pub claim: Claim,
    pub rendered: Vec<u32>,
    pub reused: Vec<u32>,
}

/// How [`ReferenceCache::fill`] tells the user what it does, and how it writes frames.
pub trait FillReport {
    /// A line for the log (`None`: only end a progress line, a warning follows).
    fn note(&mut self, text: Option<&str>);
    /// `done` of `of` frames rendered.
    fn rendered(&mut self, done: usize, of: usize);
    /// Writes rendered frame `f` through [`ReferenceCache::store`]: here at once;
    /// `dvr eval` hands it to a worker thread while the next frame renders.
    fn store(&mut self, cache: &ReferenceCache, f: u32, img: Rgb32Image) -> Result<()> {
        cache.store(f, &img)
    }
    /// Every missing frame has been rendered by `renderer` (and handed to
    /// [`FillReport::store`]): wait for writes still running, count GPU time.
    fn finished(&mut self, _renderer: &dvr_engine::renderer::Renderer) -> Result<()> {
        Ok(())
    }
}
