//! The run's time limit, seen from inside the kernel's long loops.
//!
//! A run (and each call of a family's script within it) has a deadline:
//! [`with_limit`] sets it for the work `f` does on this thread (a nested
//! limit can only bring it closer). Native loops whose length the input
//! drives (the steady rest's track, replays, posts, lints, meshes) call
//! [`check`], or [`Ticker::tick`] where an iteration is cheap, and stop with
//! [`OverTime`] once the deadline has passed: a limit holds wherever the
//! work is done, not only between a script's operations. Threads a loop
//! spawns take the deadline along ([`current`], [`with_deadline`]).

use std::cell::Cell;
use std::time::{Duration, Instant};

/// A deadline: when, the limit (s) it came from, and whose limit it is
/// (`"the run's"`, `"the script's"`).
pub type Deadline = (Instant, f64, &'static str);

thread_local! {
    static DEADLINE: Cell<Option<Deadline>> = const { Cell::new(None) };
}

/// The work ran past its time limit.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{whose} time limit of {seconds} s passed (in {stage}) and the work was stopped")]
pub struct OverTime {
    /// The limit (s).
    pub seconds: f64,
    /// Whose limit it is (`"the run's"`).
    pub whose: &'static str,
    /// What was being done.
    pub stage: &'static str,
}

/// Runs `f` with `whose` time limit of `seconds` from now (or the one
/// already set, if that is sooner), restoring the outer limit afterwards.
pub fn with_limit<T>(seconds: f64, whose: &'static str, f: impl FnOnce() -> T) -> T {
    let limit = Duration::try_from_secs_f64(seconds.max(0.0)).unwrap_or(Duration::MAX);
    let mine = Instant::now()
        .checked_add(limit)
        .map(|t| (t, seconds, whose));
    let outer = current();
    let chosen = match (outer, mine) {
        (Some(o), Some(m)) if o.0 <= m.0 => Some(o),
        (_, Some(m)) => Some(m),
        (o, None) => o,
    };
    with_deadline(chosen, f)
}

/// Runs `f` with `deadline` (a spawned thread takes its parent's).
pub fn with_deadline<T>(deadline: Option<Deadline>, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<Deadline>);
    impl Drop for Restore {
        fn drop(&mut self) {
            DEADLINE.with(|d| d.set(self.0));
        }
    }
    let _restore = Restore(DEADLINE.with(|d| d.replace(deadline)));
    f()
}

/// `here` on this thread and, at the same time, `there` on a second one
/// that keeps this thread's deadline; both results. Both may borrow from
/// the caller (a scoped thread); a panic on the second is passed on.
pub fn beside<A, B: Send>(here: impl FnOnce() -> A, there: impl FnOnce() -> B + Send) -> (A, B) {
    let deadline = current();
    std::thread::scope(|s| {
        let second = s.spawn(|| with_deadline(deadline, there));
        let a = here();
        let b = second
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        (a, b)
    })
}

/// This thread's deadline, if any.
pub fn current() -> Option<Deadline> {
    DEADLINE.with(Cell::get)
}

/// The limit (s) whose deadline has passed, and whose it is, if it has.
pub fn expired() -> Option<(f64, &'static str)> {
    current()
        .and_then(|(until, seconds, whose)| (Instant::now() > until).then_some((seconds, whose)))
}

/// An error once the deadline has passed, naming `stage`.
pub fn check(stage: &'static str) -> Result<(), OverTime> {
    match expired() {
        Some((seconds, whose)) => Err(OverTime {
            seconds,
            whose,
            stage,
        }),
        None => Ok(()),
    }
}

/// A wait of at most `wait` that ends no later than the run's deadline:
/// the deadline, and the run's limit (s) if it is the nearer one.
pub fn bounded(wait: Duration) -> (Option<f64>, Instant) {
    let mine = Instant::now() + wait;
    match current() {
        Some((until, seconds, _)) if until < mine => (Some(seconds), until),
        _ => (None, mine),
    }
}

/// [`check`] every `every` ticks, for loops whose iterations are cheap.
#[derive(Debug, Clone)]
pub struct Ticker {
    every: u32,
    count: u32,
    stage: &'static str,
}

impl Ticker {
    /// A ticker looking at the clock every `every` ticks, for `stage`.
    pub fn new(stage: &'static str, every: u32) -> Self {
        Self {
            every: every.max(1),
            count: 0,
            stage,
        }
    }

    /// Counts one iteration; every `every`-th, [`check`].
    pub fn tick(&mut self) -> Result<(), OverTime> {
        self.count += 1;
        if self.count >= self.every {
            self.count = 0;
            check(self.stage)
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_nest_to_the_nearer_and_restore() {
        assert!(current().is_none());
        with_limit(100.0, "the run's", || {
            let outer = current().unwrap();
            with_limit(1000.0, "the script's", || {
                assert_eq!(current().unwrap(), outer)
            });
            with_limit(0.0, "the script's", || {
                std::thread::sleep(Duration::from_millis(2));
                let e = check("a test").unwrap_err();
                assert_eq!(e.seconds, 0.0);
                assert_eq!(
                    e.to_string(),
                    "the script's time limit of 0 s passed (in a test) and the work was stopped"
                );
            });
            assert_eq!(current().unwrap().0, outer.0);
            assert!(check("x").is_ok());
        });
        assert!(current().is_none());
    }
}
