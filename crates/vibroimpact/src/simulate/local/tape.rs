//! The local integrator's tangent tape (docs/theory.md §10): products
//! `Φ v` of a local run replayed on its own record, as
//! [`TangentTape`](crate::integrate::TangentTape) does for the global
//! integrator.
//!
//! The run records, in order, every form of its active set (the time, its
//! groups and bodies, its row) and every accepted DOP853 step of the set
//! with the contact Jacobians at its stages. A product then replays the
//! run's linearisation without its state: each group's rows move by the
//! exact homogeneous motion of the group while it is not integrated, and
//! the set's rows by the stage recurrence of its steps. Activation times
//! are held fixed: a contact enters where its force is negligible at the
//! tolerance, so moving the time moves the flow by less than that.

use super::*;
use crate::integrate::tangent::{replay_step, ReplayScratch, STAGES as N_STAGES};
use crate::integrate::RecordedJacobian;

/// What the set's row records of its Jacobian at a stage.
type Entry = <ChainDynamics as RecordedJacobian>::Entry;

/// One form of the active set: from `t` with these groups and bodies
/// (ascending), integrated as `chain` by the steps `first_step..` up to the
/// next form's.
#[derive(Clone, Debug)]
struct Segment {
    t: f64,
    groups: Vec<usize>,
    bodies: Vec<usize>,
    chain: Option<ChainDynamics>,
    first_step: usize,
}

/// The record a local run makes of its linearisation, while it runs.
#[derive(Clone, Debug, Default)]
pub(super) struct TapeRecord {
    segments: Vec<Segment>,
    /// Accepted steps of the sets: (start, size).
    steps: Vec<(f64, f64)>,
    /// Stage `s` of step `k` is record `N_STAGES k + s`.
    offsets: Vec<usize>,
    entries: Vec<Entry>,
    /// The Jacobian at the current set's point: stage 0 of its next step.
    start: Vec<Entry>,
}

impl TapeRecord {
    /// The set is formed at `t` (`chain` None: no set) with the Jacobian
    /// `start` at its first point.
    pub(super) fn form(
        &mut self,
        t: f64,
        groups: &[usize],
        bodies: &[usize],
        chain: Option<&ChainDynamics>,
        start: &[Entry],
    ) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        self.segments.push(Segment {
            t,
            groups: groups.to_vec(),
            bodies: bodies.to_vec(),
            chain: chain.cloned(),
            first_step: self.steps.len(),
        });
        self.start.clear();
        self.start.extend_from_slice(start);
    }

    /// The set kept a step of size `h` from `t`, whose stages 1..11 and end
    /// point `rec` recorded from `first` on.
    pub(super) fn step(&mut self, t: f64, h: f64, rec: &Recorder<ChainDynamics>, first: usize) {
        self.entries.extend_from_slice(&self.start);
        self.offsets.push(self.entries.len());
        for i in first..first + N_STAGES - 1 {
            self.entries.extend_from_slice(rec.evaluation(i));
            self.offsets.push(self.entries.len());
        }
        self.start.clear();
        self.start
            .extend_from_slice(rec.evaluation(first + N_STAGES - 1));
        self.steps.push((t, h));
    }

    /// The tape of the run, which ended at `t_end`.
    pub(super) fn finish(self, free: FreeMotion, n: usize, t_end: f64) -> LocalTape {
        LocalTape {
            record: self,
            free,
            n,
            t_end,
        }
    }
}

/// The tape of a local run: products with the sensitivity of its end state
/// to its start state, and the sensitivity to a forcing parameter.
#[derive(Clone, Debug)]
pub struct LocalTape {
    record: TapeRecord,
    free: FreeMotion,
    n: usize,
    t_end: f64,
}

/// A source term of the replayed recurrence: in the set, `set(chain's
/// bodies, t, out)` adds `∂f/∂p` of those bodies at `t` to the stage
/// derivative; for a group moving exactly, `group(g, t0, t1, w)` adds the
/// response of its exact motion from `t0` to `t1` to the source alone.
struct Source<'s> {
    set: &'s mut SetSource<'s>,
    group: &'s GroupSource<'s>,
}

/// The set's source term (see [`Source`]).
type SetSource<'s> = dyn FnMut(&[usize], f64, &mut [f64]) + 's;

/// A group's source response (see [`Source`]).
type GroupSource<'s> = dyn Fn(usize, f64, f64, &mut [f64]) + 's;

impl LocalTape {
    /// Accepted steps of the integrated sets.
    pub fn steps(&self) -> usize {
        self.record.steps.len()
    }

    /// Contact Jacobian entries recorded.
    pub fn entries(&self) -> usize {
        self.record.entries.len()
    }

    /// `Φ v` (interleaved state order).
    pub fn apply(&self, v: &[f64]) -> Vec<f64> {
        self.replay(v, None)
    }

    /// The sensitivity of the end state to a parameter that changes the
    /// forcing alone, from `model` (the run's) to `model_p` at `p + dp`:
    /// the recurrence from 0 with the source `∂f/∂p` (docs/theory.md §5),
    /// exact where the bodies move exactly.
    pub fn parameter_column(
        &self,
        model: &Model,
        model_p: &Model,
        dp: f64,
    ) -> Result<Vec<f64>, OptionsError> {
        let free_p = FreeMotion::new(model_p).map_err(|e| OptionsError(e.to_string()))?;
        let (here, shifted) = (
            ChainDynamics::new(model, false),
            ChainDynamics::new(model_p, false),
        );
        let (mut q, mut q_p) = (Vec::new(), Vec::new());
        let mut set = |bodies: &[usize], t: f64, out: &mut [f64]| {
            here.source_of(t, bodies, &mut q);
            shifted.source_of(t, bodies, &mut q_p);
            for ((o, a), b) in out.iter_mut().zip(&q).zip(&q_p) {
                *o += (b - a) / dp;
            }
        };
        let group = |g: usize, t0: f64, t1: f64, w: &mut [f64]| {
            let (mut a, mut b) = (vec![0.0; w.len()], vec![0.0; w.len()]);
            self.free.propagate(g, t0, t1, &mut a);
            free_p.propagate(g, t0, t1, &mut b);
            for ((o, a), b) in w.iter_mut().zip(&a).zip(&b) {
                *o += (b - a) / dp;
            }
        };
        let source = Source {
            set: &mut set,
            group: &group,
        };
        Ok(self.replay(&vec![0.0; 2 * self.n], Some(source)))
    }

    /// Moves group `g`'s rows `w` (at `t0`) to `t` by its exact motion.
    fn move_group(&self, g: usize, t0: f64, t: f64, w: &mut [f64], source: &Option<Source>) {
        if t > t0 {
            self.free.propagate_homogeneous(g, t - t0, w);
            if let Some(s) = source {
                (s.group)(g, t0, t, w);
            }
        }
    }

    /// The run's linearisation replayed from `v` (module docs).
    fn replay(&self, v: &[f64], mut source: Option<Source>) -> Vec<f64> {
        let groups = self.free.groups();
        // Per group: the time and rows of its exact motion.
        let mut exact: Vec<(f64, Rows)> = groups
            .iter()
            .map(|g| (0.0, rows_of(g.bodies(), v)))
            .collect();
        let mut in_set = vec![false; groups.len()];
        let mut set: Option<&Segment> = None;
        let mut w: Vec<f64> = Vec::new();
        let mut scratch = ReplayScratch::default();
        let rec = &self.record;
        for (si, seg) in rec.segments.iter().enumerate() {
            // Groups leaving the set take its rows; groups joining move
            // exactly up to here.
            if let Some(old) = set {
                for &g in &old.groups {
                    if seg.groups.binary_search(&g).is_err() {
                        let rows = &mut exact[g];
                        rows.0 = seg.t;
                        for (j, &i) in groups[g].bodies().iter().enumerate() {
                            let o = old.bodies.binary_search(&i).unwrap_or(0);
                            rows.1[2 * j] = w[2 * o];
                            rows.1[2 * j + 1] = w[2 * o + 1];
                        }
                        in_set[g] = false;
                    }
                }
            }
            let mut joined = vec![0.0; 2 * seg.bodies.len()];
            for (j, &i) in seg.bodies.iter().enumerate() {
                let (g, jg) = self.free.place(i);
                let value = if in_set[g] {
                    let o = set.map_or(0, |s| s.bodies.binary_search(&i).unwrap_or(0));
                    [w[2 * o], w[2 * o + 1]]
                } else {
                    let (t0, rows) = &mut exact[g];
                    if *t0 < seg.t {
                        self.move_group(g, *t0, seg.t, rows, &source);
                        *t0 = seg.t;
                    }
                    [rows[2 * jg], rows[2 * jg + 1]]
                };
                joined[2 * j] = value[0];
                joined[2 * j + 1] = value[1];
            }
            for &g in &seg.groups {
                in_set[g] = true;
            }
            w = joined;
            set = Some(seg);
            let Some(chain) = &seg.chain else { continue };
            let end = rec
                .segments
                .get(si + 1)
                .map_or(rec.steps.len(), |s| s.first_step);
            for step in seg.first_step..end {
                let (t, h) = rec.steps[step];
                let first = N_STAGES * step;
                replay_step(&mut w, t, h, &mut scratch, |s, ts, ws, ks| {
                    let i = first + s;
                    let entries = &rec.entries[rec.offsets[i]..rec.offsets[i + 1]];
                    chain.apply_recorded(entries, ws, ks);
                    if let Some(src) = source.as_mut() {
                        (src.set)(&seg.bodies, ts, ks);
                    }
                });
            }
        }
        // The end: the set's rows, the others moved exactly to the end.
        let mut out = vec![0.0; 2 * self.n];
        for (g, (t0, rows)) in exact.iter_mut().enumerate() {
            if in_set[g] {
                continue;
            }
            self.move_group(g, *t0, self.t_end, rows, &source);
            put_rows(groups[g].bodies(), rows, &mut out);
        }
        if let Some(seg) = set {
            put_rows(&seg.bodies, &w, &mut out);
        }
        out
    }
}
