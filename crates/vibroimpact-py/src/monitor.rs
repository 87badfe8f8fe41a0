//! Long calls: the work runs on a worker thread without the GIL; the
//! calling thread wakes every 50 ms (or when the work ends) to report
//! progress to an optional Python callback and to check for Ctrl-C. On
//! KeyboardInterrupt (or an exception raised by the callback) the stop is
//! requested through the [`Interrupt`] the work was given, the worker is
//! waited for, and the exception propagates. A panic in the worker becomes
//! a `VibroimpactError`, never a crash of the interpreter.
//!
//! A simulation or a pounding study (whose estimates come from the
//! simulation's own step count: a branch's or a map's are guesses, which
//! a `ds_max` or a transient can exceed a hundredfold) that its estimate
//! puts under [`INLINE`], with no callback, runs on the calling thread
//! instead, the GIL released: a hand-over to a worker cost
//! 0.1–0.6 ms a call on a 2-core virtual machine whose idle core had to
//! be woken (the 4-storey IMK frame under record 1a through
//! `vi.pounding`, medians of 12 rounds of 21 calls: 2.56–3.06 ms on a
//! worker, 2.39–2.47 ms inline; docs/decisions.md D44). A signal that
//! arrives meanwhile is met as the call returns, a few milliseconds
//! later at most, as the worker's result would be.
//!
//! Worker threads are kept for the next call (one per call running at the
//! same time): a fresh thread per call cost ~50 µs and a cold allocator
//! arena, 5–10 % of a 2 ms simulation (bench/python). Both sides poll for
//! [`SPIN`] before they sleep (the caller for the result, a worker for its
//! next job), yielding the core between polls: waking a sleeping thread
//! twice a call cost ~70 µs (a call on an elastic frame under three record
//! samples, least of 201: 0.113 → 0.039 ms; the 4-storey IMK frame under
//! a whole record 1.67 → 1.62 ms; no slower on one core).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{mpsc, Arc, Mutex};
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
    /// Bits of the end time when progress is the integration time reached
    /// (0: progress counts units).
    t_end: AtomicU64,
}

impl Progress {
    /// One more unit done.
    pub fn tick(&self) {
        self.done.fetch_add(1, Ordering::Relaxed);
    }

    /// Sets the number of units in all.
    pub fn set_total(&self, total: usize) {
        self.total.store(total, Ordering::Relaxed);
    }

    /// Reports progress as the time the integration has reached out of
    /// `t_end`, in thousandths.
    pub fn track_time(&self, t_end: f64) {
        self.set_total(1000);
        self.t_end.store(t_end.to_bits(), Ordering::Relaxed);
    }

    /// Units done so far.
    fn done(&self) -> usize {
        let t_end = f64::from_bits(self.t_end.load(Ordering::Relaxed));
        if t_end > 0.0 {
            (1000.0 * (self.interrupt.time() / t_end).clamp(0.0, 1.0)) as usize
        } else {
            self.done.load(Ordering::Relaxed)
        }
    }
}

/// A job for a worker: computes, then returns what delivers the result
/// (run after the worker is back in the idle list, so that the next call
/// finds it there).
type Job = Box<dyn FnOnce() -> Box<dyn FnOnce() + Send> + Send>;

/// Idle workers, each waiting on its job channel.
static IDLE: Mutex<Vec<mpsc::Sender<Job>>> = Mutex::new(Vec::new());

fn idle() -> std::sync::MutexGuard<'static, Vec<mpsc::Sender<Job>>> {
    IDLE.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs `job` on an idle worker, or on a new one.
fn submit(job: Job) {
    let mut job = job;
    while let Some(tx) = idle().pop() {
        match tx.send(job) {
            Ok(()) => return,
            Err(mpsc::SendError(back)) => job = back,
        }
    }
    std::thread::spawn(move || {
        let (tx, rx) = mpsc::channel::<Job>();
        let mut next = Some(job);
        while let Some(job) = next {
            let deliver = job();
            idle().push(tx.clone());
            deliver();
            next = spin(|| rx.try_recv().ok()).or_else(|| rx.recv().ok());
        }
    });
}

/// How long a thread polls for what it waits for before it sleeps: a
/// short call's result, a worker's next job.
const SPIN: Duration = Duration::from_micros(200);

/// `poll()` until it gives something or [`SPIN`] has passed.
fn spin<T>(mut poll: impl FnMut() -> Option<T>) -> Option<T> {
    let start = std::time::Instant::now();
    loop {
        if let Some(x) = poll() {
            return Some(x);
        }
        if start.elapsed() > SPIN {
            return None;
        }
        std::thread::yield_now();
    }
}

/// How often the calling thread wakes.
const POLL: Duration = Duration::from_millis(50);

/// How long an interrupted call waits for its worker to stop.
const ABANDON: Duration = Duration::from_secs(1);

/// Work expected to take less than this (seconds, by its
/// `WorkEstimate`; they run up to a few times longer) runs on the
/// calling thread: a Ctrl-C waits for it to end.
const INLINE: f64 = 0.02;

/// Runs `work` on a worker thread, reporting to `callback(done, total)`
/// when `done` changes and checking for signals; on the calling thread
/// where it is `expected` (seconds) to take less than [`INLINE`] and no
/// callback waits for progress.
pub fn run<T, F>(
    py: Python<'_>,
    callback: Option<&Bound<'_, PyAny>>,
    expected: Option<f64>,
    work: F,
) -> PyResult<T>
where
    T: Send + 'static,
    F: FnOnce(&Progress) -> T + Send + 'static,
{
    run_keeping(py, callback, expected, work).map_err(|(e, _)| e)
}

/// [`run`], and on KeyboardInterrupt (or the callback's exception) what
/// the work returned once stopped, if it did within [`ABANDON`]: the
/// caller attaches it to the exception as `result`, as the command line
/// keeps it (a branch with `stop: "Interrupted"`).
pub fn run_keeping<T, F>(
    py: Python<'_>,
    callback: Option<&Bound<'_, PyAny>>,
    expected: Option<f64>,
    work: F,
) -> Result<T, (PyErr, Option<T>)>
where
    T: Send + 'static,
    F: FnOnce(&Progress) -> T + Send + 'static,
{
    if callback.is_none() && expected.is_some_and(|s| s < INLINE) {
        let progress = Progress::default();
        let r = py
            .detach(|| catch_unwind(AssertUnwindSafe(|| work(&progress))))
            .map_err(|panic| (panicked(panic), None))?;
        return match py.check_signals() {
            Ok(()) => Ok(r),
            Err(e) => Err((e, Some(r))),
        };
    }
    let progress = Arc::new(Progress::default());
    let (tx, rx) = mpsc::channel();
    let shared = progress.clone();
    submit(Box::new(move || {
        let r = catch_unwind(AssertUnwindSafe(|| work(&shared)));
        Box::new(move || {
            // The caller waits for this result, even after an interrupt.
            let _ = tx.send(r);
        })
    }));
    // Shared with the GIL-free closures below (a Receiver alone is not Sync).
    let rx = Mutex::new(rx);
    let recv = |timeout: Option<Duration>| {
        let rx = rx.lock().unwrap_or_else(|e| e.into_inner());
        match timeout {
            Some(t) => rx.recv_timeout(t),
            None => rx.recv().map_err(|_| mpsc::RecvTimeoutError::Disconnected),
        }
    };
    let mut reported = usize::MAX;
    let mut first = true;
    loop {
        let received = py.detach(|| {
            let quick = if std::mem::take(&mut first) {
                spin(|| rx.lock().ok()?.try_recv().ok())
            } else {
                None
            };
            quick
                .ok_or(mpsc::RecvTimeoutError::Timeout)
                .or_else(|_| recv(Some(POLL)))
        });
        let finished = received.is_ok();
        let stop = py.check_signals().and_then(|()| {
            let total = progress.total.load(Ordering::Relaxed);
            // Time-tracked work marks the start of its last step: report
            // the end on completion.
            let done = if finished && total > 0 {
                total
            } else {
                progress.done()
            };
            match callback {
                Some(cb) if done != reported => {
                    reported = done;
                    cb.call1((done, total)).map(|_| ())
                }
                _ => Ok(()),
            }
        });
        let result = match (received, stop) {
            (Ok(r), Ok(())) => r,
            (Ok(r), Err(e)) => return Err((e, r.ok())),
            (Err(mpsc::RecvTimeoutError::Timeout), Ok(())) => continue,
            (Err(_), Err(e)) => {
                progress.interrupt.request();
                // Integrations stop at their next step; work that cannot be
                // interrupted (a least-squares fit) finishes on its own: the
                // job owns its data, so it is left to end in the background.
                let stopped = py.detach(|| recv(Some(ABANDON)));
                return Err((e, stopped.ok().and_then(Result::ok)));
            }
            (Err(mpsc::RecvTimeoutError::Disconnected), Ok(())) => {
                return Err((
                    VibroimpactError::new_err(
                        "internal error: the worker thread ended without a result",
                    ),
                    None,
                ))
            }
        };
        return result.map_err(|panic| (panicked(panic), None));
    }
}

/// The error a panic in the work becomes.
fn panicked(panic: Box<dyn std::any::Any + Send>) -> PyErr {
    let msg = panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown".into());
    VibroimpactError::new_err(format!(
        "internal error (please report): the computation panicked: {msg}"
    ))
}
