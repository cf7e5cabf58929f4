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
//!
//! A caller may also stop the work at any time by a [`Cancel`] token it
//! keeps (a workbench replacing an older calculation with a newer one):
//! [`with_cancel`] hands it to the work, and every look at the clock sees
//! it fired.

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A deadline: when, the limit (s) it came from, and whose limit it is
/// (`"the run's"`, `"the script's"`).
pub type Deadline = (Instant, f64, &'static str);

thread_local! {
    static DEADLINE: Cell<Option<Deadline>> = const { Cell::new(None) };
    static CANCEL: RefCell<Option<Cancel>> = const { RefCell::new(None) };
}

/// A token the caller of some work keeps and fires to stop it: the work's
/// next look at the clock ([`check`], [`Ticker::tick`]) ends it with
/// [`OverTime`] saying it was cancelled. Clones share the one flag.
#[derive(Debug, Clone, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A token not fired.
    pub fn new() -> Self {
        Self::default()
    }

    /// Stops the work the token was given to, from any thread.
    pub fn fire(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether it was fired.
    pub fn fired(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// The work ran past its time limit, or its caller cancelled it.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{}", self.text())]
pub struct OverTime {
    /// The limit (s); 0 for a cancel.
    pub seconds: f64,
    /// Whose limit it is (`"the run's"`).
    pub whose: &'static str,
    /// What was being done.
    pub stage: &'static str,
    /// Whether the caller cancelled the work ([`Cancel`]) rather than
    /// its time running out.
    pub cancelled: bool,
}

impl OverTime {
    fn text(&self) -> String {
        if self.cancelled {
            format!(
                "the work was cancelled by its caller (in {}) and stopped",
                self.stage
            )
        } else {
            format!(
                "{} time limit of {} s passed (in {}) and the work was stopped",
                self.whose, self.seconds, self.stage
            )
        }
    }
}

/// Runs `f` with `cancel` (`None`: none) as the token its looks at the
/// clock see, restoring the one before afterwards.
pub fn with_cancel<T>(cancel: Option<Cancel>, f: impl FnOnce() -> T) -> T {
    struct Restore(Option<Cancel>);
    impl Drop for Restore {
        fn drop(&mut self) {
            let before = self.0.take();
            CANCEL.with(|c| *c.borrow_mut() = before);
        }
    }
    let _restore = Restore(CANCEL.with(|c| c.replace(cancel)));
    f()
}

/// This thread's cancel token, if any.
pub fn current_cancel() -> Option<Cancel> {
    CANCEL.with(|c| c.borrow().clone())
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
    let (deadline, cancel) = (current(), current_cancel());
    std::thread::scope(|s| {
        let second = s.spawn(|| with_cancel(cancel, || with_deadline(deadline, there)));
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
    if CANCEL.with(|c| c.borrow().as_ref().is_some_and(Cancel::fired)) {
        return Err(OverTime {
            seconds: 0.0,
            whose: "the caller's",
            stage,
            cancelled: true,
        });
    }
    match expired() {
        Some((seconds, whose)) => Err(OverTime {
            seconds,
            whose,
            stage,
            cancelled: false,
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

    /// A token fired from another thread stops the work at its next look
    /// at the clock, in this thread and in one it spawns beside; a token
    /// fired before the work starts stops it at its first look.
    #[test]
    fn a_cancel_stops_the_work_at_its_next_check() {
        // Work that ends only when it is stopped.
        let spin = |stage| -> Result<(), OverTime> {
            let mut ticker = Ticker::new(stage, 16);
            loop {
                ticker.tick()?;
                std::hint::spin_loop();
            }
        };
        let token = Cancel::new();
        let firing = token.clone();
        let (here, there) = std::thread::scope(|s| {
            s.spawn(move || {
                std::thread::sleep(Duration::from_millis(20));
                firing.fire();
            });
            with_cancel(Some(token.clone()), || {
                beside(|| spin("here"), || spin("there"))
            })
        });
        let e = here.unwrap_err();
        assert!(e.cancelled, "{e}");
        assert_eq!(
            e.to_string(),
            "the work was cancelled by its caller (in here) and stopped"
        );
        assert!(there.unwrap_err().cancelled);
        // Fired before: the first look stops it; without the token, no stop.
        assert!(with_cancel(Some(token), || check("first")).is_err());
        assert!(check("after").is_ok());
    }
}
