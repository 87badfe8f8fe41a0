//! Long calls: the work runs on a scoped worker thread without the GIL;
//! the calling thread wakes every 50 ms (or when the work ends) to report
//! progress to an optional Python callback and to check for Ctrl-C. On
//! KeyboardInterrupt (or an exception raised by the callback) the stop is
//! requested through the [`Interrupt`] the work was given, the worker is
//! joined, and the exception propagates. A panic in the worker becomes a
//! `VibroimpactError`, never a crash of the interpreter.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{mpsc, Mutex};
use std::time::Duration;

use pyo3::prelude::*;
use vibroimpact::integrate::Interrupt;

use crate::VibroimpactError;

/// What the work shares with the monitoring thread.
#[derive(Default)]
pub struct Progress {
    /// Units done so far.
    pub done: AtomicUsize,
    /// Units in all (0: unknown).
    pub total: AtomicUsize,
    /// The stop request handed to the library.
    pub interrupt: Interrupt,
}

impl Progress {
    /// One more unit done.
    pub fn tick(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }
}

/// How often the calling thread wakes.
const POLL: Duration = Duration::from_millis(50);

/// Runs `work` on a worker thread, reporting to `callback(done, total)`
/// when `done` changes and checking for signals.
pub fn run<T, F>(py: Python<'_>, callback: Option<&Bound<'_, PyAny>>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&Progress) -> T + Send,
{
    let progress = Progress::default();
    let (tx, rx) = mpsc::channel();
    // Shared with the GIL-free closures below (a Receiver alone is not Sync).
    let rx = Mutex::new(rx);
    let recv = |timeout: Option<Duration>| {
        let rx = rx.lock().unwrap_or_else(|e| e.into_inner());
        match timeout {
            Some(t) => rx.recv_timeout(t),
            None => rx.recv().map_err(|_| mpsc::RecvTimeoutError::Disconnected),
        }
    };
    std::thread::scope(|scope| {
        let shared = &progress;
        scope.spawn(move || {
            let r = catch_unwind(AssertUnwindSafe(|| work(shared)));
            // The receiver outlives the scope; a send cannot fail.
            let _ = tx.send(r);
        });
        let mut reported = usize::MAX;
        loop {
            let received = py.detach(|| recv(Some(POLL)));
            let stop = py.check_signals().and_then(|()| {
                let done = progress.done.load(Ordering::Relaxed);
                match callback {
                    Some(cb) if done != reported => {
                        reported = done;
                        cb.call1((done, progress.total.load(Ordering::Relaxed)))
                            .map(|_| ())
                    }
                    _ => Ok(()),
                }
            });
            let result = match (received, stop) {
                (Ok(r), Ok(())) => r,
                (Ok(_), Err(e)) => return Err(e),
                (Err(mpsc::RecvTimeoutError::Timeout), Ok(())) => continue,
                (Err(_), Err(e)) => {
                    progress.interrupt.request();
                    // Wait for the worker to notice (at its next step).
                    let _ = py.detach(|| recv(None));
                    return Err(e);
                }
                (Err(mpsc::RecvTimeoutError::Disconnected), Ok(())) => {
                    return Err(VibroimpactError::new_err(
                        "internal error: the worker thread ended without a result",
                    ))
                }
            };
            return result.map_err(|panic| {
                let msg = panic
                    .downcast_ref::<&str>()
                    .map(|s| s.to_string())
                    .or_else(|| panic.downcast_ref::<String>().cloned())
                    .unwrap_or_else(|| "unknown".into());
                VibroimpactError::new_err(format!(
                    "internal error (please report): the computation panicked: {msg}"
                ))
            });
        }
    })
}
