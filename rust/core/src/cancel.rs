//! Cooperative cancellation of long computations (e.g. Ctrl-C in the Python layer).
//!
//! A caller installs a [`Token`] for the current thread with [`with`]; the core's long
//! loops (the integrator's steps, harmonic-balance Newton iterations, equilibrium starts)
//! poll [`cancelled`] and stop, with [`Error::Cancelled`] where they return a `Result`,
//! early with a partial value otherwise. A partial value is meaningless: whoever cancels
//! must discard the result of the call it cancelled.
//!
//! The token is thread-local so that the numerical signatures stay free of it; work
//! handed to other threads (rayon) must carry it over with [`current`] and [`with`].
//! Without an installed token nothing is ever cancelled, so code that does not know
//! about cancellation (and parallel scans, which cancel between rows with their own
//! flag) behaves exactly as before.

use crate::error::{Error, Result};
use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// A shared flag asking the computations that hold it to stop, and a count of the units
/// of work they report done ([`advance`]: a continuation's points), which whoever
/// installed the token can read while the work runs (a progress bar).
#[derive(Debug, Clone, Default)]
pub struct Token(Arc<AtomicBool>, Arc<AtomicUsize>);

impl Token {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }

    /// The flag itself, for APIs that take one explicitly (the parallel scan).
    pub fn flag(&self) -> &AtomicBool {
        &self.0
    }

    /// The units of work reported done so far.
    pub fn done(&self) -> usize {
        self.1.load(Ordering::Relaxed)
    }
}

thread_local! {
    static CURRENT: RefCell<Option<Token>> = const { RefCell::new(None) };
}

/// Restores the previously installed token when dropped, also when `f` panics.
struct Restore(Option<Token>);

impl Drop for Restore {
    fn drop(&mut self) {
        let prev = self.0.take();
        CURRENT.with(|c| *c.borrow_mut() = prev);
    }
}

/// Runs `f` with `token` installed as this thread's token (`None`: not cancellable).
pub fn with<R>(token: Option<Token>, f: impl FnOnce() -> R) -> R {
    let prev = CURRENT.with(|c| std::mem::replace(&mut *c.borrow_mut(), token));
    let _restore = Restore(prev);
    f()
}

/// This thread's token, to hand on to work done on other threads.
pub fn current() -> Option<Token> {
    CURRENT.with(|c| c.borrow().clone())
}

/// Reports one more unit of work done to this thread's token (nothing without one): a
/// continuation's loops call it per point kept, so that a caller can show progress.
pub fn advance() {
    CURRENT.with(|c| {
        if let Some(t) = c.borrow().as_ref() {
            t.1.fetch_add(1, Ordering::Relaxed);
        }
    });
}

/// Whether this thread's token asks to stop.
pub fn cancelled() -> bool {
    #[cfg(all(test, feature = "studies"))]
    gaps::mark();
    CURRENT.with(|c| c.borrow().as_ref().is_some_and(Token::is_cancelled))
}

/// `Err(Error::Cancelled)` once this thread's token asks to stop.
pub fn check() -> Result<()> {
    if cancelled() {
        Err(Error::Cancelled)
    } else {
        Ok(())
    }
}

/// The longest stretch between two polls of this thread: the longest that a cancellation
/// waits (a measuring aid for the latency studies, so only with the `studies` feature).
#[cfg(all(test, feature = "studies"))]
pub(crate) mod gaps {
    use std::cell::Cell;
    use std::time::Instant;

    thread_local! {
        /// While measuring: the last poll and the longest gap so far (seconds).
        static GAP: Cell<Option<(Instant, f64)>> = const { Cell::new(None) };
    }

    pub(crate) fn mark() {
        GAP.with(|g| {
            if let Some((last, longest)) = g.get() {
                let now = Instant::now();
                g.set(Some((now, longest.max((now - last).as_secs_f64()))));
            }
        });
    }

    /// `f`'s result, its wall time and the longest gap between its polls (the start and
    /// the end count as polls), in seconds.
    pub(crate) fn longest<R>(f: impl FnOnce() -> R) -> (R, f64, f64) {
        let start = Instant::now();
        GAP.with(|g| g.set(Some((start, 0.0))));
        let r = f();
        mark();
        let longest = GAP.with(|g| g.take()).map_or(0.0, |(_, l)| l);
        (r, start.elapsed().as_secs_f64(), longest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn token_is_per_thread_and_restored() {
        let t = Token::new();
        assert!(check().is_ok());
        with(Some(t.clone()), || {
            assert!(check().is_ok());
            t.cancel();
            assert_eq!(check(), Err(Error::Cancelled));
            // Another thread does not see it unless handed over.
            let tok = current();
            std::thread::scope(|s| {
                s.spawn(|| assert!(!cancelled()));
                s.spawn(move || with(tok, || assert!(cancelled())));
            });
            with(None, || assert!(!cancelled()));
            assert!(cancelled());
        });
        assert!(!cancelled());
    }
}
