//! How long-running library functions report progress and read the time.
//!
//! The experiment functions ([`crate::experiment`], and the renderer's
//! comparisons) neither draw progress bars nor read a clock: the caller
//! passes a [`Progress`] (for example a progress bar; `&()` for none) and a
//! [`Clock`] (for example a [`SystemClock`]; a test may pass a fake one).

use std::time::{Duration, Instant};

/// Receives progress: a task with a label and a total number of steps
/// starts, then its steps are done a few at a time. Both methods do nothing
/// by default. Calls may come from several threads at once.
pub trait Progress: Sync {
    /// A task of `total` steps starts; `label` says what it is (e.g.
    /// `estimating` or `mis 16 spp`).
    fn start(&self, _label: &str, _total: u64) {}
    /// `n` more steps of the current task are done.
    fn advance(&self, _n: u64) {}
}

/// No progress report.
impl Progress for () {}

/// A monotonic clock: the time elapsed since some fixed origin.
pub trait Clock: Sync {
    /// The time since the clock's origin.
    fn now(&self) -> Duration;
}

/// The system's monotonic clock, with its origin at construction.
#[derive(Debug, Clone, Copy)]
pub struct SystemClock {
    origin: Instant,
}

impl SystemClock {
    /// A clock whose origin is now.
    #[must_use]
    pub fn new() -> Self {
        SystemClock {
            origin: Instant::now(),
        }
    }
}

impl Default for SystemClock {
    fn default() -> Self {
        SystemClock::new()
    }
}

impl Clock for SystemClock {
    fn now(&self) -> Duration {
        self.origin.elapsed()
    }
}

/// Seconds `clock` takes to advance while `f` runs, with `f`'s result.
pub fn timed<T>(clock: &dyn Clock, f: impl FnOnce() -> T) -> (T, f64) {
    let t0 = clock.now();
    let value = f();
    let t1 = clock.now();
    (value, t1.saturating_sub(t0).as_secs_f64())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn system_clock_advances() {
        let c = SystemClock::new();
        let a = c.now();
        std::thread::sleep(Duration::from_millis(2));
        assert!(c.now() > a);
        let ((), t) = timed(&c, || std::thread::sleep(Duration::from_millis(2)));
        assert!(t >= 0.002, "{t}");
    }
}
