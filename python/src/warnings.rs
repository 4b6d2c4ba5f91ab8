//! What a loader drops (an OME-Zarr image's or OME-TIFF stack's extra channels and time
//! points) the engine reports with `log::warn!`; the CLI prints it, but in Python a log
//! line is easily missed, so the extension collects the warnings a load logs on its
//! thread and re-issues them as `dvr.DataDroppedWarning` (a `UserWarning`).

use pyo3::prelude::*;
use std::cell::RefCell;

pyo3::create_exception!(
    _native,
    DataDroppedWarning,
    pyo3::exceptions::PyUserWarning,
    "A loader read part of a file and dropped the rest (extra channels, time points)."
);

thread_local! {
    /// The warnings logged on this thread while a capture runs (`None`: none runs).
    static CAPTURED: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
}

/// Collects warnings during a capture; anything else goes to stderr as the CLI's logger
/// would show it, so engine messages outside loads are not lost.
struct Sink;

impl log::Log for Sink {
    fn enabled(&self, metadata: &log::Metadata<'_>) -> bool {
        metadata.level() <= log::Level::Warn
    }

    fn log(&self, record: &log::Record<'_>) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let message = record.args().to_string();
        let kept = CAPTURED.with(|c| match c.borrow_mut().as_mut() {
            Some(list) => {
                list.push(message.clone());
                true
            }
            None => false,
        });
        if !kept {
            eprintln!("dvr: {}: {message}", record.level().as_str().to_lowercase());
        }
    }

    fn flush(&self) {}
}

static SINK: Sink = Sink;

/// Installs the sink as the process's logger (once; if the host already installed one,
/// that one keeps the messages and loads raise no warnings).
pub fn install() {
    if log::set_logger(&SINK).is_ok() {
        log::set_max_level(log::LevelFilter::Warn);
    }
}

/// Runs `f` (on this thread: `Python::detach` does) and returns its result with the
/// warnings it logged.
pub fn capture<T>(f: impl FnOnce() -> T) -> (T, Vec<String>) {
    let outer = CAPTURED.with(|c| c.borrow_mut().replace(Vec::new()));
    let out = f();
    let logged = CAPTURED.with(|c| std::mem::replace(&mut *c.borrow_mut(), outer));
    (out, logged.unwrap_or_default())
}

/// Re-issues `messages` as `DataDroppedWarning`s, attributed to the Python frame
/// `stacklevel` up (1: the line that called the loader).
pub fn issue(py: Python<'_>, messages: &[String], stacklevel: i32) -> PyResult<()> {
    let category = py.get_type::<DataDroppedWarning>();
    for m in messages {
        let text = std::ffi::CString::new(m.replace('\0', " ")).expect("NULs replaced");
        PyErr::warn(py, category.as_any(), &text, stacklevel)?;
    }
    Ok(())
}
