//! The hand-over between a branch's corrector and its finisher
//! (docs/decisions.md D38): the corrector runs ahead on another thread,
//! handing each point over as it is corrected, while the calling thread
//! finishes them in order; [`Continuation`] as an iterator of finished
//! points.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, Sender, TryRecvError};

use super::{BranchStep, Continuation, Corrected, Ending, Family};

/// A corrected point, or why the branch ends.
pub(super) type Step = Result<Corrected, Ending>;

/// How many points the corrector may hand over in one batch, ahead of
/// the points being finished: a location takes about as long as seven
/// corrections on R2 N = 2, and the branch's nine special points come in
/// clusters (32 ahead: 0.163 s, 8 ahead: 0.21 s). Matrix-free points carry
/// their integrations' records, a few megabytes each: four.
const AHEAD: (usize, usize) = (32, 4);

impl<F: Family + Send> Continuation<F> {
    /// Corrects points ahead, in order, handing each to the finisher
    /// through `hand`, until `finished` is set, the branch ends or
    /// [`AHEAD`] are handed over in this batch.
    fn run_ahead(&mut self, finished: &AtomicBool, hand: &Sender<Step>) {
        let most = match self.problem.opts.krylov {
            None => AHEAD.0,
            Some(_) => AHEAD.1,
        };
        let mut handed = 0;
        while !finished.load(Ordering::Acquire) && handed < most && !self.ended {
            let step = self.advance();
            handed += 1;
            // (The finisher's receiver outlives the batch.)
            let _ = hand.send(step);
        }
    }
}

/// How many times the finisher looks for a handed point, yielding its
/// core between looks, before it sleeps until one comes.
const LOOKS: usize = 1000;

/// The next point handed over, None once the corrector has stopped. The
/// finisher looks ([`LOOKS`] times, yielding between) before it sleeps: a
/// sleeping finisher costs the corrector a wake-up call at each point it
/// hands over, 5 % of its thread on the R2 N = 2 rigid branch.
fn receive(handed: &Receiver<Step>) -> Option<Step> {
    for _ in 0..LOOKS {
        match handed.try_recv() {
            Ok(step) => return Some(step),
            Err(TryRecvError::Disconnected) => return None,
            Err(TryRecvError::Empty) => std::thread::yield_now(),
        }
    }
    handed.recv().ok()
}

impl<F: Family + Send> Iterator for Continuation<F> {
    type Item = BranchStep;

    /// The next point, finished: its orbit summary and the special points
    /// before it. The points corrected so far are finished on this thread
    /// while the next ones (`AHEAD` at most) are corrected in the pool.
    fn next(&mut self) -> Option<BranchStep> {
        if self.done {
            return None;
        }
        if self.finished.is_empty() {
            self.finish_batch();
        }
        Some(match self.finished.pop_front()? {
            Ok((e, special)) => {
                let mut point = e.point;
                point.label = special.last().map(|s| s.label.clone());
                BranchStep::Point { point, special }
            }
            Err(end) => {
                self.done = true;
                BranchStep::Stop(end.reason)
            }
        })
    }
}

impl<F: Family + Send> Continuation<F> {
    /// Finishes the start first while it is not yielded (its orbit
    /// summary), then every point corrected so far (correcting one first
    /// if there is neither), and then each point the corrector hands over
    /// as it runs ahead on another thread, until it stops (the branch's end, or
    /// [`AHEAD`] points in this batch) or a point ends the branch. (A
    /// finisher faster than the corrector had stopped it after each batch
    /// of one point and corrected the next point itself: R2 N = 2 rigid,
    /// 2.30–2.35 ms, 1.95–2.15 ms with the hand-over.)
    fn finish_batch(&mut self) {
        let start = std::mem::take(&mut self.start);
        if self.ahead.is_empty() && !start {
            let step = self.advance();
            self.ahead.push_back(step);
        }
        let batch: Vec<_> = self.ahead.drain(..).collect();
        let Some(mut finisher) = self.finisher.take() else {
            return;
        };
        let done = AtomicBool::new(false);
        let (hand, handed) = channel::<Step>();
        let finish = |handed: Option<&Receiver<Step>>| {
            let mut out = Vec::with_capacity(batch.len() + 1);
            if start {
                let first = finisher.start().map(|e| (e, Vec::new()));
                let stop = first.is_err();
                out.push(first.map_err(|reason| Ending {
                    reason,
                    with_point: false,
                }));
                if stop {
                    done.store(true, Ordering::Release);
                    return out;
                }
            }
            let handed = std::iter::from_fn(|| handed.and_then(receive));
            for step in batch.into_iter().chain(handed) {
                let finished = step.and_then(|s| {
                    finisher.finish(s).map_err(|reason| Ending {
                        reason,
                        with_point: false,
                    })
                });
                let stop = finished.is_err();
                out.push(finished);
                if stop {
                    break;
                }
            }
            done.store(true, Ordering::Release);
            out
        };
        // One thread: no hand-over (it costs more than it saves).
        let out = if rayon::current_num_threads() < 2 {
            drop(hand);
            finish(None)
        } else {
            // Finished here, corrected in the pool (no sleep per batch: D38).
            let (this, done) = (&mut *self, &done);
            rayon::in_place_scope(|s| {
                s.spawn(move |_| this.run_ahead(done, &hand));
                finish(Some(&handed))
            })
        };
        // Points handed over after a point that ends the branch.
        self.ahead.extend(handed.try_iter());
        self.finisher = Some(finisher);
        self.finished.extend(out);
    }
}
