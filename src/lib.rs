//! `dvr`: real-time Monte Carlo direct volume rendering with temporal denoising.
//! Subcommands: demo (the main job: a small eval sized for the device), explore (the
//! interactive window), capture (offscreen sequences),
//! reference (high-sample references), eval (denoisers against references: metrics,
//! plots, HTML), profile (per-pass GPU timing), bench (the one-call GPU benchmark), scenes
//! (the built-in scenes), info (what a volume file holds: grid, channels, time points).
//!
//! The application is this library and a binary, `src/main.rs`, that only calls
//! [`cli::main`]: tests reach the command line's definition ([`cli::Cli`],
//! [`cli::Command`], [`cli::run`]) to add a toy command the way a real one is added.

mod args;
mod bench;
mod capture;
pub mod cli;
mod demo;
mod eval;
mod explore;
mod font;
mod info;
mod logger;
mod output;
mod profile;
mod progress;
mod setup;
mod shard;
mod video;
