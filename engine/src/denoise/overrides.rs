//! Denoiser parameters overridden from the environment (`DVR_OURS`, `DVR_WRLS`,
//! `DVR_SVGF`): each method's parameter struct says its variable and table
//! ([`Tunables`]), its registry row names them ([`Overrides::of`]), and the commands
//! check and warn about the variables through the registry.

use super::registry;
use crate::error::{EngineError, Result};

/// The environment variable that overrides a denoiser's parameters (`name=value` pairs,
/// see [`with_overrides`]), and the check of its value as the denoiser will read it, so
/// a command refuses a bad value before it renders anything. A registry row names it
/// with [`Overrides::of`] its parameter struct.
#[derive(Clone, Copy, Debug)]
pub struct Overrides {
    pub variable: &'static str,
    pub check: fn(Option<&str>) -> Result<()>,
}

impl Overrides {
    /// The variable and check of the parameters `P`.
    pub const fn of<P: Tunables>() -> Self {
        Self {
            variable: P::VARIABLE,
            check: check::<P>,
        }
    }

    /// The variable's value in the environment, if it is set.
    pub fn value(&self) -> Option<String> {
        std::env::var(self.variable).ok()
    }
}

fn check<P: Tunables>(spec: Option<&str>) -> Result<()> {
    P::default().with_overrides(spec).map(drop)
}

/// A denoiser's parameters, overridable by `name=value` pairs in an environment variable
/// for parameter studies with `dvr eval`.
pub trait Tunables: Default + Sized + 'static {
    /// The variable (`DVR_OURS`, …).
    const VARIABLE: &'static str;
    /// The parameters it may set, the range each takes, and where each goes.
    const TABLE: &'static [Overridable<Self>];

    /// The parameters after the pairs are applied, or an error where they disagree with
    /// each other (each pair's own range is checked before).
    fn consistent(self) -> Result<Self> {
        Ok(self)
    }

    /// These parameters with the `name=value` pairs (comma-separated) of `spec` applied.
    fn with_overrides(self, spec: Option<&str>) -> Result<Self> {
        with_overrides(self, Self::VARIABLE, spec, Self::TABLE)?.consistent()
    }

    /// The defaults with the environment's overrides applied.
    fn from_env() -> Result<Self> {
        let spec = Overrides::of::<Self>().value();
        Self::default().with_overrides(spec.as_deref())
    }
}

/// One overridable parameter of a denoiser: its name, the range it takes, and where it
/// goes.
pub type Overridable<P> = (&'static str, f32, f32, fn(&mut P, f32));

/// The environment variables that override denoiser parameters (`DVR_SVGF`,
/// `DVR_OURS`, `DVR_WRLS`: each registry row names the one its method reads), in table
/// order: what a method computes depends on them.
pub fn override_variables() -> Vec<&'static str> {
    registry::BUILTIN
        .overrides()
        .iter()
        .map(|o| o.variable)
        .collect()
}

/// A sentence for each override variable set in the environment that none of the
/// `running` methods reads, naming the variable and the methods it applies to: a user
/// who set one expects it to act, or to be told that it does not.
pub fn unused_overrides(running: &[&str]) -> Vec<String> {
    override_variables()
        .into_iter()
        .filter(|v| std::env::var(v).is_ok_and(|s| !s.trim().is_empty()))
        .filter_map(|v| {
            let readers: Vec<&str> = registry::DENOISERS
                .iter()
                .filter(|d| d.override_variable() == Some(v))
                .map(|d| d.name)
                .collect();
            (!running.iter().any(|r| readers.contains(r))).then(|| {
                format!(
                    "{v} is set but no method it applies to runs ({} read it; running: {})",
                    readers.join(", "),
                    running.join(", ")
                )
            })
        })
        .collect()
}

/// Checks the parameter overrides in the environment (each row's variable) as the
/// denoisers will read them, so a command can refuse a bad value before it renders
/// anything, not when the method is built after the references.
pub fn check_env_overrides() -> Result<()> {
    for o in registry::BUILTIN.overrides() {
        (o.check)(o.value().as_deref())?;
    }
    Ok(())
}

/// `params` with the `name=value` pairs of `spec` (comma-separated, e.g. from the
/// environment variable `variable`) applied, for parameter studies with `dvr eval`. An
/// unknown name lists the known ones; a value outside its range (or not finite) is an
/// error naming the range.
pub fn with_overrides<P>(
    mut params: P,
    variable: &'static str,
    spec: Option<&str>,
    table: &[Overridable<P>],
) -> Result<P> {
    let Some(spec) = spec else {
        return Ok(params);
    };
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let bad = |problem: String| EngineError::InvalidSetting {
            name: variable,
            value: format!("{item:?}"),
            allowed: problem,
        };
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| bad("expected name=value pairs, comma-separated".into()))?;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|e| bad(format!("the value must be a number ({e})")))?;
        let (_, lo, hi, set) = table
            .iter()
            .find(|(n, ..)| *n == name.trim())
            .ok_or_else(|| {
                let known: Vec<&str> = table.iter().map(|(n, ..)| *n).collect();
                bad(format!("parameters: {}", known.join(", ")))
            })?;
        // Checked as given (f64), so the documented inclusive bounds hold.
        if !(v >= f64::from(*lo) && v <= f64::from(*hi)) {
            return Err(bad(format!("{} must be in [{lo}, {hi}]", name.trim())));
        }
        set(&mut params, v as f32);
    }
    Ok(params)
}

/// Fails unless `with_overrides` refuses every `(spec, says)` of `cases` with an error
/// naming `variable` and saying `says`: the overrides' tests of every denoiser.
#[cfg(test)]
pub(crate) fn assert_overrides_refused<P: std::fmt::Debug>(
    with_overrides: impl Fn(Option<&str>) -> Result<P>,
    variable: &str,
    cases: &[(&str, &str)],
) {
    for &(spec, says) in cases {
        let e = with_overrides(Some(spec)).expect_err(spec).to_string();
        assert!(e.contains(variable) && e.contains(says), "{spec}: {e}");
    }
}
