//! SIGINT/SIGTERM during `dvr profile`: the first one stops the frame loop, so the
//! statistics so far are written (marked as interrupted) and the process exits 130 or
//! 143 as a shell expects; a second one ends the process at once.

use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::SigId;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Flags set by the handlers while a profile runs; the handlers go with it.
pub struct Interrupt {
    flags: [(i32, Arc<AtomicBool>); 2],
    ids: Vec<SigId>,
}

impl Interrupt {
    pub fn install() -> std::io::Result<Self> {
        let flags = [SIGINT, SIGTERM].map(|s| (s, Arc::new(AtomicBool::new(false))));
        let mut ids = Vec::new();
        for (signal, flag) in &flags {
            // Order matters: the conditional shutdown sees the flag before this signal
            // sets it, so only a second signal ends the process.
            ids.push(signal_hook::flag::register_conditional_shutdown(
                *signal,
                128 + signal,
                flag.clone(),
            )?);
            ids.push(signal_hook::flag::register(*signal, flag.clone())?);
        }
        Ok(Self { flags, ids })
    }

    /// The signal received, if any.
    pub fn received(&self) -> Option<Interrupted> {
        self.flags
            .iter()
            .find(|(_, f)| f.load(Ordering::Relaxed))
            .map(|(s, _)| Interrupted { signal: *s })
    }
}

impl Drop for Interrupt {
    fn drop(&mut self) {
        for id in self.ids.drain(..) {
            signal_hook::low_level::unregister(id);
        }
    }
}

/// The error a profile ends with after writing its partial report: `main` exits with
/// [`Interrupted::exit_code`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interrupted {
    pub signal: i32,
}

impl Interrupted {
    pub fn name(&self) -> &'static str {
        if self.signal == SIGTERM {
            "SIGTERM"
        } else {
            "SIGINT"
        }
    }

    /// 128 + the signal number, what a shell reports for a process the signal ended.
    pub fn exit_code(&self) -> i32 {
        128 + self.signal
    }
}

impl std::fmt::Display for Interrupted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "interrupted by {}", self.name())
    }
}

impl std::error::Error for Interrupted {}
