//! CPU work of an eval handed to a thread pool (rayon's) while the main thread keeps the
//! GPU busy: scoring finished frames, writing references, scoring the baseline. At most
//! a few jobs per pool thread wait at once, so memory stays bounded when the CPU falls
//! behind; the main thread then waits, and that wait is what [`Timing::metrics_wait`]
//! counts.

use super::timing::Timing;
use anyhow::{anyhow, Result};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::Arc;
use std::time::Instant;

/// Jobs allowed in flight per pool thread.
const JOBS_PER_THREAD: usize = 2;

type Done<T> = (usize, Result<T>);

/// Jobs in flight and their results, returned in the order they were spawned.
pub struct Overlap<T> {
    tx: Sender<Done<T>>,
    rx: Receiver<Done<T>>,
    spawned: usize,
    results: Vec<(usize, T)>,
    limit: usize,
    timing: Arc<Timing>,
}

impl<T: Send + 'static> Overlap<T> {
    pub fn new(timing: &Arc<Timing>) -> Self {
        let (tx, rx) = channel();
        Self {
            tx,
            rx,
            spawned: 0,
            results: Vec::new(),
            limit: rayon::current_num_threads().max(1) * JOBS_PER_THREAD,
            timing: Arc::clone(timing),
        }
    }

    /// Runs `job` on the pool; first waits for earlier jobs while too many are pending.
    pub fn spawn(&mut self, job: impl FnOnce() -> Result<T> + Send + 'static) -> Result<()> {
        while self.spawned - self.results.len() >= self.limit {
            self.receive()?;
        }
        let (tx, index) = (self.tx.clone(), self.spawned);
        self.spawned += 1;
        rayon::spawn(move || {
            // A panic in a job must not leave the main thread waiting forever.
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(job))
                .unwrap_or_else(|_| Err(anyhow!("a scoring job panicked")));
            let _ = tx.send((index, result));
        });
        Ok(())
    }

    /// Waits for one result (the first error ends the eval).
    fn receive(&mut self) -> Result<()> {
        let started = Instant::now();
        let received = self.rx.recv();
        self.timing.metrics_wait.add(started.elapsed());
        let (index, result) = received.map_err(|_| anyhow!("a scoring job was lost"))?;
        self.results.push((index, result?));
        Ok(())
    }

    /// Waits for every job; their results in spawn order.
    pub fn finish(mut self) -> Result<Vec<T>> {
        while self.results.len() < self.spawned {
            self.receive()?;
        }
        self.results.sort_by_key(|(i, _)| *i);
        Ok(self.results.into_iter().map(|(_, r)| r).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn results_come_back_in_spawn_order() {
        let timing = Timing::shared();
        let mut jobs = Overlap::new(&timing);
        for i in 0..20u64 {
            jobs.spawn(move || {
                std::thread::sleep(std::time::Duration::from_millis((20 - i) % 5));
                Ok(i * i)
            })
            .expect("spawn");
        }
        let squares: Vec<u64> = (0..20).map(|i| i * i).collect();
        assert_eq!(jobs.finish().expect("results"), squares);
    }

    #[test]
    fn an_error_or_panic_in_a_job_is_reported() {
        let timing = Timing::shared();
        let mut jobs: Overlap<u32> = Overlap::new(&timing);
        jobs.spawn(|| Ok(1)).expect("spawn");
        jobs.spawn(|| anyhow::bail!("disk full")).expect("spawn");
        let err = jobs.finish().expect_err("the error");
        assert!(err.to_string().contains("disk full"), "{err}");
        let mut jobs: Overlap<u32> = Overlap::new(&timing);
        jobs.spawn(|| panic!("boom")).expect("spawn");
        assert!(jobs.finish().is_err());
    }
}
