//! Progress on stderr for the long commands (capture, reference, profile, eval): what is
//! running, how far it is, and an estimate of the time left.
//!
//! On a terminal one status line is redrawn in place (`\r`). Anywhere else (a log file,
//! a CI console, a pipe) carriage returns would pile up into one endless line, so a new
//! line is written only when the run has moved on by at least [`LOG_STEP_PERCENT`] —
//! at most about 50 lines for a whole run, whatever its length.
//!
//! Work is counted in "units" the caller picks (frames, or for an eval roughly one
//! sample per pixel of one frame); time left is the elapsed time per unit so far times
//! the units left.

use std::io::{IsTerminal, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Without a terminal, a progress line is written each time the run passes another
/// multiple of this many percent.
pub const LOG_STEP_PERCENT: f64 = 2.0;

/// True while a terminal status line has no newline yet: whatever is printed next
/// (an error, a warning) must start a line of its own.
static LINE_OPEN: AtomicBool = AtomicBool::new(false);

/// Ends an open status line, so a message that follows starts on a line of its own.
pub fn end_line() {
    if LINE_OPEN.swap(false, Ordering::Relaxed) {
        eprintln!();
    }
}

pub struct Progress {
    started: Instant,
    total: f64,
    done: f64,
    terminal: bool,
    /// Width of the last terminal line, so a shorter one can blank it out.
    last_len: usize,
    /// Log mode: the last [`LOG_STEP_PERCENT`] step a line was written for.
    last_step: Option<u64>,
}

impl Progress {
    /// Progress over `total_units`, redrawn in place when stderr is a terminal.
    pub fn new(total_units: f64) -> Self {
        Self::with_terminal(total_units, std::io::stderr().is_terminal())
    }

    pub fn with_terminal(total_units: f64, terminal: bool) -> Self {
        Self {
            started: Instant::now(),
            total: total_units.max(1.0),
            done: 0.0,
            terminal,
            last_len: 0,
            last_step: None,
        }
    }

    /// Counts `units` as done and shows `status`.
    pub fn advance(&mut self, units: f64, status: &str) {
        self.done = (self.done + units).min(self.total);
        self.show(status);
    }

    pub fn show(&mut self, status: &str) {
        if let Some(text) = self.render(status) {
            let mut err = std::io::stderr().lock();
            let _ = err.write_all(text.as_bytes());
            let _ = err.flush();
            LINE_OPEN.store(self.terminal, Ordering::Relaxed);
        }
    }

    /// Seconds since the start.
    pub fn elapsed(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }

    /// What [`show`](Self::show) writes for `status`: a redrawn line on a terminal, else
    /// a whole line when another [`LOG_STEP_PERCENT`] step has been passed (or nothing).
    fn render(&mut self, status: &str) -> Option<String> {
        let percent = 100.0 * self.done / self.total;
        if !self.terminal {
            let step = (percent / LOG_STEP_PERCENT).floor() as u64;
            if self.last_step.is_some_and(|last| step <= last) {
                return None;
            }
            self.last_step = Some(step);
        }
        let secs = self.elapsed();
        let left = if self.done > 0.0 {
            format!(
                "{} left",
                format_secs(secs / self.done * (self.total - self.done))
            )
        } else {
            "estimating".to_string()
        };
        let line = format!(
            "{status} | {percent:.0}% | {} elapsed, ~{left}",
            format_secs(secs)
        );
        if !self.terminal {
            return Some(format!("{line}\n"));
        }
        let pad = self.last_len.saturating_sub(line.chars().count());
        self.last_len = line.chars().count();
        Some(format!("\r{line}{}", " ".repeat(pad)))
    }

    /// Ends the current status line (a message that must stay visible follows).
    pub fn newline(&mut self) {
        if self.terminal && self.last_len > 0 {
            end_line();
            self.last_len = 0;
        }
    }

    pub fn finish(&mut self) {
        self.newline();
    }
}

/// Frames per second of a renderer that keeps frames in flight: the first results
/// arrive only after the pipeline has filled, so counting from the start would report
/// thousands of frames per second for the frames merely submitted. The rate counts
/// finished frames from the moment the first one arrived.
#[derive(Default)]
pub struct FrameRate {
    first: Option<Instant>,
    finished: u32,
}

impl FrameRate {
    /// Counts one finished frame.
    pub fn finished(&mut self) {
        self.first.get_or_insert_with(Instant::now);
        self.finished += 1;
    }

    /// Frames per second after the first result; `None` until two frames are finished.
    pub fn fps(&self) -> Option<f64> {
        let secs = self.first?.elapsed().as_secs_f64();
        (self.finished > 1 && secs > 0.0).then(|| f64::from(self.finished - 1) / secs)
    }

    /// `"12.3 fps"`, or `"measuring fps"` before there is a rate.
    pub fn text(&self) -> String {
        match self.fps() {
            Some(fps) => format!("{fps:.1} fps"),
            None => "measuring fps".to_string(),
        }
    }
}

pub fn format_secs(s: f64) -> String {
    let s = s.max(0.0).round() as u64;
    if s >= 3600 {
        format!("{}h{:02}m", s / 3600, (s % 3600) / 60)
    } else if s >= 60 {
        format!("{}m{:02}s", s / 60, s % 60)
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations() {
        assert_eq!(format_secs(4.4), "4s");
        assert_eq!(format_secs(125.0), "2m05s");
        assert_eq!(format_secs(3725.0), "1h02m");
        assert_eq!(format_secs(-1.0), "0s");
    }

    #[test]
    fn a_log_gets_whole_lines_at_most_one_per_step() {
        let mut p = Progress::with_terminal(1000.0, false);
        let mut lines = Vec::new();
        lines.extend(p.render("loading"));
        lines.extend(p.render("loading again"));
        for i in 0..1000 {
            p.done += 1.0;
            lines.extend(p.render(&format!("unit {i}")));
        }
        assert_eq!(lines.len(), 1 + (100.0 / LOG_STEP_PERCENT) as usize);
        assert!(lines.iter().all(|l| l.ends_with('\n') && !l.contains('\r')));
        assert!(lines[0].starts_with("loading | 0%"), "{}", lines[0]);
        assert!(lines.last().unwrap().contains("| 100% |"));
    }

    #[test]
    fn a_terminal_line_is_redrawn_in_place() {
        let mut p = Progress::with_terminal(10.0, true);
        let long = p.render("a long status").unwrap();
        p.done = 1.0;
        let short = p.render("short").unwrap();
        assert!(long.starts_with('\r') && short.starts_with('\r'));
        assert!(!long.contains('\n') && !short.contains('\n'));
        assert_eq!(
            short.chars().count(),
            long.chars().count(),
            "blanks the rest"
        );
    }

    #[test]
    fn frame_rate_starts_at_the_first_result() {
        let mut r = FrameRate::default();
        assert_eq!(r.fps(), None);
        r.finished();
        assert_eq!(r.text(), "measuring fps");
        std::thread::sleep(std::time::Duration::from_millis(20));
        r.finished();
        let fps = r.fps().unwrap();
        assert!(fps > 0.0 && fps < 100.0, "{fps}");
    }
}
