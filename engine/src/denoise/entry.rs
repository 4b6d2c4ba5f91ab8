//! What one registry row says about a denoiser: its name and description, what the frame
//! must render for it, the environment variable that overrides its parameters, and how
//! it is built. A row carries all of it, so the registry's table
//! ([`super::registry::DENOISERS`]) is the one place a denoiser is listed.

use super::{Denoiser, MotionSource, Overrides};
use crate::error::Result;
use crate::gpu::GpuContext;
use crate::passes::path_trace::PathTraceFeatures;
use std::any::Any;
use std::fmt;

/// Whether a denoiser reads the surface features (the deterministic opacity-threshold
/// position, normal and albedo), which cost about a path trace on lavapipe and are
/// rendered only for denoisers that read them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeatureUse {
    Never,
    /// When it reprojects with them (`--motion features`).
    ForMotion,
    /// Always (SVGF's edge-stopping and albedo demodulation).
    Always,
}

impl FeatureUse {
    pub fn needed(self, motion: MotionSource) -> bool {
        match self {
            FeatureUse::Never => false,
            FeatureUse::ForMotion => motion == MotionSource::Features,
            FeatureUse::Always => true,
        }
    }
}

/// What building a denoiser depends on besides its row.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DenoiserConfig<'a> {
    /// What temporal methods reproject with.
    pub motion: MotionSource,
    /// The built-in dataset the scene's volume is, if any (learned denoisers pick their
    /// network by it).
    pub dataset: Option<&'a str>,
    /// What the path tracer is specialised for (a denoiser that traces paths again must
    /// trace the same ones).
    pub features: PathTraceFeatures,
}

/// What building a denoiser gives: the denoiser, or why it could not be built (a
/// pipeline, a weight file, an override).
pub type Built = Result<Box<dyn Denoiser>>;

/// How a row builds its denoiser, named `name` (its passes and images are named after
/// it). A method without variants is built by a function of this signature (its
/// `create`); a method with variants implements it on its variant struct, whose value
/// in the row holds the switches ([`super::OursVariant`], [`super::WrlsVariant`],
/// [`super::rae::RaeNet`]).
pub trait Build: Any + Sync {
    fn build(&self, ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built;
}

impl<F> Build for F
where
    F: Fn(&GpuContext, &'static str, &DenoiserConfig) -> Built + Sync + 'static,
{
    fn build(&self, ctx: &GpuContext, name: &'static str, config: &DenoiserConfig) -> Built {
        self(ctx, name, config)
    }
}

/// One denoiser dvr has: a row of the registry.
#[derive(Clone, Copy)]
pub struct DenoiserInfo {
    /// The name on the command line and in every report.
    pub name: &'static str,
    pub description: &'static str,
    pub features: FeatureUse,
    /// Whether it reads the guide albedo composited along the ray
    /// ([`DenoiseInputs::guides`](super::DenoiseInputs::guides)).
    pub guides: bool,
    /// The environment variable that overrides its parameters, if it has one.
    pub overrides: Option<Overrides>,
    /// How it is built: its constructor, or its variant's switches.
    pub build: &'static dyn Build,
}

impl DenoiserInfo {
    /// A row that reads no guides and has no overrides.
    pub const fn new(
        name: &'static str,
        description: &'static str,
        features: FeatureUse,
        build: &'static dyn Build,
    ) -> Self {
        Self {
            name,
            description,
            features,
            guides: false,
            overrides: None,
            build,
        }
    }

    /// The row, reading the guide albedo.
    pub const fn reading_guides(self) -> Self {
        Self {
            guides: true,
            ..self
        }
    }

    /// The row, its parameters overridden by `overrides`.
    pub const fn overridden_by(self, overrides: Overrides) -> Self {
        Self {
            overrides: Some(overrides),
            ..self
        }
    }

    /// The environment variable that overrides its parameters, if it has one.
    pub fn override_variable(&self) -> Option<&'static str> {
        self.overrides.map(|o| o.variable)
    }

    /// The row's variant switches if they are a `T` (an [`super::OursVariant`] for ours
    /// and its ablations, a [`super::rae::RaeNet`] for the RAE's rows, …).
    pub fn variant<T: Any>(&self) -> Option<&'static T> {
        let build: &'static dyn Any = self.build;
        build.downcast_ref()
    }

    /// Builds the denoiser.
    pub fn create(&self, ctx: &GpuContext, config: &DenoiserConfig) -> Built {
        self.build.build(ctx, self.name, config)
    }
}

impl fmt::Debug for DenoiserInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("DenoiserInfo")
            .field("name", &self.name)
            .field("features", &self.features)
            .field("guides", &self.guides)
            .field("overrides", &self.override_variable())
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn feature_use_follows_the_motion_source() {
        assert!(FeatureUse::Always.needed(MotionSource::FirstHit));
        assert!(FeatureUse::ForMotion.needed(MotionSource::Features));
        assert!(!FeatureUse::ForMotion.needed(MotionSource::FirstHit));
        assert!(!FeatureUse::Never.needed(MotionSource::Features));
    }
}
