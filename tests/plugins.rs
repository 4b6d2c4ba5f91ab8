//! A toy denoiser added the way a real one is: one registry row ([`Registry::with`]),
//! which the renderer finds by name, builds and runs in the frame like any built-in
//! method. The row's flags reach the frame (the features and guides it asks for are
//! rendered for it), its pass is counted as its own, and a name no row has is refused.
//! (The toy volume format is `engine/volume/src/formats.rs`' `a_new_format_is_one_row`.)

mod common;

use common::*;
use dvr_engine::denoise::{Built, DenoiseFrame, Denoiser, DenoiserConfig, DenoiserInfo};
use dvr_engine::denoise::{FeatureUse, Registry};
use dvr_engine::error::{EngineError, Result};
use dvr_engine::gpu::timestamps::PassOwner;
use dvr_engine::gpu::GpuContext;
use dvr_engine::graph::ImageHandle;
use dvr_engine::passes::accumulate::Accumulate;

/// The running mean of the noisy frames (accum without its restarts), which insists on
/// the surface features and the guide albedo its row says it reads.
struct ToyMean {
    name: &'static str,
    pass: Accumulate,
}

impl ToyMean {
    fn create(ctx: &GpuContext, name: &'static str, _: &DenoiserConfig) -> Built {
        Ok(Box::new(Self {
            name,
            pass: Accumulate::new(ctx)?,
        }))
    }
}

impl Denoiser for ToyMean {
    fn add<'f>(&'f self, mut f: DenoiseFrame<'_, 'f>) -> Result<ImageHandle> {
        let (ctx, graph, frame, input) = f.parts();
        input.features(self.name)?;
        input.guides.ok_or_else(|| EngineError::Pass {
            pass: self.name.into(),
            problem: "no guide albedo".into(),
        })?;
        let weight = input.spp as f32;
        self.pass.add(
            ctx,
            graph,
            frame,
            self.name,
            input.noisy,
            weight,
            input.size,
        )
    }
}

/// The toy's row: all a new denoiser adds besides its module.
const TOY: DenoiserInfo = DenoiserInfo::new(
    "toy-mean",
    "the running mean of the noisy frames",
    FeatureUse::Always,
    &ToyMean::create,
)
.reading_guides();

#[test]
fn a_toy_denoiser_is_one_row() {
    const FRAMES: u32 = 3;
    let mut setup = builtin_setup("phantom/orbit", FRAMES, 16);
    let names = ["none", TOY.name];
    let refused = setup
        .renderer(context(), &names)
        .err()
        .map(|e| e.to_string());
    assert!(
        refused.as_deref().is_some_and(|e| e.contains("toy-mean")),
        "{refused:?}"
    );

    setup.config.registry = Registry::default().with(TOY).expect("a new name");
    let mut r = setup.renderer(context(), &names).expect("renderer");
    let frames = (0..FRAMES).map(|f| setup.frame_inputs(f));
    let results = render_frames(&mut r, frames, &readback());
    assert_eq!(results.len(), FRAMES as usize);

    let mut sum: Vec<[f64; 3]> = Vec::new();
    for (k, done) in results.iter().enumerate() {
        let image = |name: &str| {
            let found = done.images.iter().find(|(n, _)| n == name);
            found.map(|(_, px)| px).expect(name)
        };
        let (noisy, toy) = (image("none"), image("toy-mean"));
        sum.resize(noisy.len(), [0.0; 3]);
        for ((s, n), t) in sum.iter_mut().zip(noisy).zip(toy) {
            for c in 0..3 {
                s[c] += f64::from(n[c]);
                let mean = s[c] / (k + 1) as f64;
                let err = (f64::from(t[c]) - mean).abs();
                assert!(err <= 1e-5 * mean.max(1.0), "frame {k}: {} ≠ {mean}", t[c]);
            }
        }
        let own = PassOwner::Method(TOY.name.into());
        assert!(
            done.timings.iter().any(|t| t.owner == own),
            "frame {k}: no pass counted as the toy's"
        );
    }
    drop(r);
    assert_validation_clean();
}
