//! Progress of an eval on stderr: what is running, how far it is, and an estimate of
//! the time left for the whole run.
//!
//! Work is counted in "units" of roughly one sample per pixel of one frame: a reference
//! frame is `ref_spp` units, an evaluated frame `spp` plus one per method (denoising
//! and scoring), a baseline frame the sum of its sample counts. Time left is the
//! elapsed time per unit so far times the units left.

use std::io::Write;
use std::time::Instant;

pub struct Progress {
    started: Instant,
    total: f64,
    done: f64,
    /// Width of the last line, so a shorter one can blank it out.
    last_len: usize,
}

impl Progress {
    pub fn new(total_units: f64) -> Self {
        Self {
            started: Instant::now(),
            total: total_units.max(1.0),
            done: 0.0,
            last_len: 0,
        }
    }

    /// Counts `units` as done and shows `status`.
    pub fn advance(&mut self, units: f64, status: &str) {
        self.done = (self.done + units).min(self.total);
        self.show(status);
    }

    pub fn show(&mut self, status: &str) {
        let secs = self.started.elapsed().as_secs_f64();
        let left = if self.done > 0.0 {
            format!(
                "{} left",
                format_secs(secs / self.done * (self.total - self.done))
            )
        } else {
            "estimating".to_string()
        };
        let line = format!(
            "{status} | {:.0}% | {} elapsed, ~{left}",
            100.0 * self.done / self.total,
            format_secs(secs)
        );
        let pad = self.last_len.saturating_sub(line.chars().count());
        self.last_len = line.chars().count();
        let mut err = std::io::stderr().lock();
        let _ = write!(err, "\r{line}{}", " ".repeat(pad));
        let _ = err.flush();
    }

    /// Ends the current line (a message that must stay visible follows).
    pub fn newline(&mut self) {
        if self.last_len > 0 {
            eprintln!();
            self.last_len = 0;
        }
    }

    pub fn finish(&mut self) {
        self.newline();
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
    use super::format_secs;

    #[test]
    fn durations() {
        assert_eq!(format_secs(4.4), "4s");
        assert_eq!(format_secs(125.0), "2m05s");
        assert_eq!(format_secs(3725.0), "1h02m");
        assert_eq!(format_secs(-1.0), "0s");
    }
}
