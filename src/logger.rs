//! The one logger: the engine's and the application's `log` records on stderr as
//! `dvr: warning: …`. Warnings are on by default (a warning that nobody sees is how a
//! DICOM series with a missing slice once rendered with the wrong geometry and exit 0);
//! `--quiet` leaves only errors; `DVR_LOG=info|debug|trace` shows more.

use log::{Level, LevelFilter, Log, Metadata, Record};

struct Stderr;

impl Log for Stderr {
    fn enabled(&self, metadata: &Metadata) -> bool {
        metadata.level() <= log::max_level()
    }

    fn log(&self, record: &Record) {
        if !self.enabled(record.metadata()) {
            return;
        }
        let level = match record.level() {
            Level::Error => "error",
            Level::Warn => "warning",
            Level::Info => "info",
            Level::Debug => "debug",
            Level::Trace => "trace",
        };
        // A warning during a run starts a line of its own, not the end of the
        // progress line a terminal is redrawing.
        crate::progress::end_line();
        eprintln!("dvr: {level}: {}", record.args());
    }

    fn flush(&self) {}
}

/// The level `--quiet` and `DVR_LOG` ask for: `DVR_LOG` wins when set to a level name.
pub fn level(quiet: bool, dvr_log: Option<&str>) -> LevelFilter {
    match dvr_log
        .map(str::trim)
        .and_then(|s| s.parse::<LevelFilter>().ok())
    {
        Some(level) => level,
        None if quiet => LevelFilter::Error,
        None => LevelFilter::Warn,
    }
}

/// Installs the logger (once per process; later calls only change the level).
pub fn init(quiet: bool) {
    static LOGGER: Stderr = Stderr;
    let _ = log::set_logger(&LOGGER);
    log::set_max_level(level(quiet, std::env::var("DVR_LOG").ok().as_deref()));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warnings_by_default_errors_when_quiet_and_dvr_log_wins() {
        assert_eq!(level(false, None), LevelFilter::Warn);
        assert_eq!(level(true, None), LevelFilter::Error);
        assert_eq!(level(true, Some("debug")), LevelFilter::Debug);
        assert_eq!(level(false, Some("nonsense")), LevelFilter::Warn);
    }
}
