//! How the binding runs core work: off the GIL, with panics contained and Ctrl-C working.

use crate::errors::{panic_error, to_py};
use ballbal_core::{cancel, Error};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// How often an entry point waiting for the core looks for Ctrl-C (and other signals).
const POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// Runs `f` without the GIL, with panics contained (as `InternalError`) and with Ctrl-C
/// working: see [`run_polled`]. A cancelled call raises `KeyboardInterrupt` and its
/// partial result is dropped.
pub fn guarded<T: Send, F: FnOnce() -> Result<T, Error> + Send>(
    py: Python<'_>,
    f: F,
) -> PyResult<T> {
    guarded_progress(py, None, f)
}

/// [`guarded`], calling `progress(done)` (a Python callable, with the GIL) whenever the
/// count of work the core reports done ([`cancel::advance`]: a continuation's points)
/// has grown, at most every [`POLL`] and once at the end. An error it raises cancels the
/// work, as Ctrl-C does.
pub fn guarded_progress<T: Send, F: FnOnce() -> Result<T, Error> + Send>(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    f: F,
) -> PyResult<T> {
    let mut shown = 0usize;
    run_ticking(
        py,
        |tok, _: &std::sync::mpsc::Sender<()>| cancel::with(Some(tok.clone()), f),
        |()| Ok(()),
        |done| match progress {
            Some(p) if done > shown => {
                shown = done;
                p.call1((done,)).map(|_| ())
            }
            _ => Ok(()),
        },
    )
}

/// The one way the binding runs core work: `work` runs on a worker thread (given a
/// cancellation token and a channel), while this thread, without the GIL, waits and
/// checks for signals every [`POLL`] (only the main thread sees them) and hands every
/// message the work sends to `on_msg` with the GIL. A signal's exception (Ctrl-C's
/// `KeyboardInterrupt`), or `on_msg`'s first error, cancels the token; the core's long
/// loops notice it within milliseconds, and that exception is raised once the worker
/// has stopped. A panic in the work becomes `InternalError`.
pub fn run_polled<T, M, W, H>(py: Python<'_>, work: W, on_msg: H) -> PyResult<T>
where
    T: Send,
    M: Send,
    W: FnOnce(&cancel::Token, &std::sync::mpsc::Sender<M>) -> Result<T, Error> + Send,
    H: FnMut(M) -> PyResult<()>,
{
    run_ticking(py, work, on_msg, |_| Ok(()))
}

/// [`run_polled`], also handing `on_tick` the token's count of work done at every poll
/// and once when the work has ended.
fn run_ticking<T, M, W, H, K>(py: Python<'_>, work: W, mut on_msg: H, mut on_tick: K) -> PyResult<T>
where
    T: Send,
    M: Send,
    W: FnOnce(&cancel::Token, &std::sync::mpsc::Sender<M>) -> Result<T, Error> + Send,
    H: FnMut(M) -> PyResult<()>,
    K: FnMut(usize) -> PyResult<()>,
{
    use std::sync::mpsc;
    let token = cancel::Token::new();
    let (tx, rx) = mpsc::channel::<M>();
    // `detach` needs a `Sync` capture; the receiver is only used from this thread.
    let rx = std::sync::Mutex::new(rx);
    let mut pending: Option<PyErr> = None;
    let worker = std::thread::scope(|s| {
        let tok = &token;
        // The calling thread's stack size: the core was written for it.
        let handle = std::thread::Builder::new()
            .name("ballbal-core".into())
            .stack_size(8 << 20)
            .spawn_scoped(s, move || {
                let tx = tx;
                catch_unwind(AssertUnwindSafe(|| work(tok, &tx)))
            });
        let handle = match handle {
            Ok(h) => h,
            Err(e) => {
                return Err(PyRuntimeError::new_err(format!(
                    "could not start a worker thread: {e}"
                )))
            }
        };
        loop {
            let msg = py.detach(|| rx.lock().expect("receiver lock").recv_timeout(POLL));
            match msg {
                // Messages that arrive after a cancellation are still handed over
                // (a scan's chunks that finish are stored).
                Ok(m) => {
                    if let Err(e) = on_msg(m) {
                        if pending.is_none() {
                            token.cancel();
                            pending = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if pending.is_none() {
                        if let Err(e) = py.check_signals().and_then(|()| on_tick(token.done())) {
                            token.cancel();
                            pending = Some(e);
                        }
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => break,
            }
        }
        if pending.is_none() {
            pending = on_tick(token.done()).err();
        }
        Ok(py.detach(|| handle.join()))
    })?;
    if let Some(e) = pending {
        return Err(e);
    }
    match worker {
        Ok(Ok(r)) => r.map_err(to_py),
        Ok(Err(p)) | Err(p) => Err(panic_error(p)),
    }
}
