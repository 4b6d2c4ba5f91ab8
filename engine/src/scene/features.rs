//! [`Features`]: what a scene uses, summarised for pipeline specialisation.
//!
//! DESIGN §7 ("model no more than a scene needs"): the path-tracing pipeline is built
//! with specialisation constants from this, so a scene without area lights, environment
//! maps, emission or a TF blend compiles those paths out.

use super::light::{EnvMode, EnvSource, Light};
use super::render::{Estimator, Phase};
use super::Scene;

/// The features one scene needs from the path tracer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Features {
    pub point_lights: bool,
    pub area_lights: bool,
    /// The environment light's mode, if the scene has one.
    pub environment: Option<EnvMode>,
    pub emission: bool,
    pub phase: Phase,
    pub estimator: Estimator,
    /// True when the TF animates between `transfer.a` and `transfer.b`.
    pub tf_blend: bool,
}

impl Scene {
    /// What this scene needs (constant over its frames: animation changes values, not
    /// which features are used).
    pub fn features(&self) -> Features {
        let has = |f: fn(&Light) -> bool| self.lights.iter().any(f);
        Features {
            point_lights: has(|l| matches!(l, Light::Point(_))),
            area_lights: has(|l| matches!(l, Light::Area(_))),
            environment: self.lights.iter().find_map(|l| match l {
                Light::Environment(e) => Some(match e.source {
                    EnvSource::Constant { .. } => EnvMode::Constant,
                    EnvSource::Gradient { .. } => EnvMode::Gradient,
                    EnvSource::Map { .. } => EnvMode::Map,
                }),
                _ => None,
            }),
            emission: self.render.emission,
            phase: self.render.phase,
            estimator: self.render.estimator,
            tf_blend: self.tf_b.is_some() && !self.animation.tf.is_empty(),
        }
    }
}
