//! Toys added the way OVERVIEW.md's "Extending dvr" adds a real one of their kind.
//!
//! A toy denoiser: one registry row ([`Registry::with`]), which the renderer finds by
//! name, builds and runs in the frame like any built-in method. The row's flags reach the
//! frame (the features and guides it asks for are rendered for it), its pass is counted
//! as its own, and a name no row has is refused.
//!
//! A toy command: its module (arguments and `run`), a variant beside dvr's [`Command`]
//! whose doc comment is its help, and its arm in the dispatch. It parses and runs, dvr's
//! commands parse, help and dispatch as before, and the book's command-line page check
//! names it as missing from the page. Needs no GPU.
//!
//! (The toy volume format is `engine/volume/src/formats.rs`' `a_new_format_is_one_row`,
//! the toy scene field `engine/scene/tests/toy_field.rs`.)

mod common;

use clap::{Parser, Subcommand};
use common::cli_page;
use common::*;
use dvr::cli::{self, Cli, Command};
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

/// The toy command's module, as `src/<command>.rs` would be: its arguments and `run`.
mod toy {
    use std::sync::atomic::{AtomicU32, Ordering};

    /// The `--n` the toy last ran with: how the test sees the dispatch reach it.
    pub static RAN_WITH: AtomicU32 = AtomicU32::new(0);

    #[derive(clap::Args)]
    pub struct ToyArgs {
        /// How far to count.
        #[arg(long)]
        pub n: u32,
    }

    pub fn run(args: &ToyArgs) -> anyhow::Result<()> {
        RAN_WITH.store(args.n, Ordering::SeqCst);
        Ok(())
    }
}

/// dvr's commands and the toy's variant, as `src/cli.rs`' `Command` would be with it
/// (dvr's boxed: clippy's `large_enum_variant` beside the toy's few bytes).
#[derive(Subcommand)]
enum WithToy {
    #[command(flatten)]
    Dvr(Box<Command>),
    /// Count to N: a toy command, added the way a real one is.
    Toy(toy::ToyArgs),
}

/// `cli::run` with the toy's arm.
fn run_with_toy(command: WithToy) -> anyhow::Result<()> {
    match command {
        WithToy::Dvr(command) => cli::run(*command),
        WithToy::Toy(args) => toy::run(&args),
    }
}

/// `dvr [SUB] --help` of the command set `C`, rendered in this process as the binary
/// prints it.
fn help<C: Subcommand>(sub: Option<&str>) -> String {
    let argv = ["dvr"].into_iter().chain(sub).chain(["--help"]);
    match Cli::<C>::try_parse_from(argv) {
        Err(e) if e.kind() == clap::error::ErrorKind::DisplayHelp => e.render().to_string(),
        Err(e) => panic!("dvr {sub:?} --help: {e}"),
        Ok(_) => panic!("dvr {sub:?} --help parsed as a command"),
    }
}

#[test]
fn a_toy_command_is_one_variant() {
    // Parsed, global options included, and dispatched to the toy's `run`.
    let cli = Cli::<WithToy>::try_parse_from(["dvr", "--quiet", "toy", "--n", "3"])
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(cli.quiet);
    run_with_toy(cli.command).expect("the toy runs");
    assert_eq!(toy::RAN_WITH.load(std::sync::atomic::Ordering::SeqCst), 3);

    // Its doc comment is its help: its line in `dvr --help`, the head of `dvr toy --help`.
    let about = "Count to N: a toy command, added the way a real one is";
    let top = help::<WithToy>(None);
    assert!(
        top.lines()
            .any(|l| l.trim_start().starts_with("toy ") && l.ends_with(about)),
        "no `toy  {about}` line in dvr --help:\n{top}"
    );
    let own = help::<WithToy>(Some("toy"));
    assert!(own.starts_with(about), "dvr toy --help:\n{own}");

    // dvr's own commands parse with the same help beside it...
    let dvr_commands = cli_page::subcommands(&help::<Command>(None));
    assert!(dvr_commands.len() >= 8, "{dvr_commands:?}");
    for sub in &dvr_commands {
        assert_eq!(
            help::<WithToy>(Some(sub)),
            help::<Command>(Some(sub)),
            "dvr {sub} --help"
        );
    }
    // ...and reach the same command: each fails alike on an input it refuses before any
    // device opens.
    for argv in [
        &["scenes", "--dump", "no/such-scene"][..],
        &["info", "/no/such-volume.nrrd"],
        &["capture", "--scene", "no/such-scene"],
        &["reference", "--scene", "no/such-scene"],
        &["eval", "--scene", "no/such-scene"],
    ] {
        let argv = || ["dvr"].iter().chain(argv);
        let theirs = cli::run(<Cli>::try_parse_from(argv()).expect("parses").command);
        let ours = run_with_toy(
            Cli::<WithToy>::try_parse_from(argv())
                .expect("parses")
                .command,
        );
        let (theirs, ours) = (theirs.expect_err("refused"), ours.expect_err("refused"));
        assert_eq!(
            ours.to_string(),
            theirs.to_string(),
            "{argv:?}",
            argv = argv()
        );
        assert!(ours.to_string().contains("no/such-"), "{ours}");
    }

    // The page check: dvr's commands rendered here give the committed page; with the toy
    // it names the toy's missing section (the recipe regenerates the page).
    let committed = std::fs::read_to_string(cli_page::PAGE).expect("docs/src/cli.md");
    cli_page::compare(&committed, &cli_page::render(help::<Command>))
        .unwrap_or_else(|e| panic!("{e}"));
    let missing = cli_page::compare(&committed, &cli_page::render(help::<WithToy>))
        .expect_err("the page has no section for the toy");
    assert!(
        missing.contains("no section for `dvr toy`") && !missing.contains("a section for"),
        "{missing}"
    );
}
