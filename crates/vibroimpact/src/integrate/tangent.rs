//! Tangent replay: products `Φ v` of a DOP853 integration's sensitivity
//! from the integration's own record, without integrating again
//! (docs/theory.md §5, docs/decisions.md D21).
//!
//! An explicit Runge–Kutta method applied to the state and its variational
//! equations `w' = J(y(t)) w`, with the steps chosen by the state alone,
//! computes exactly the derivative of its own step map: stage by stage
//!
//! ```text
//! W_s = w + h Σ_{j<s} a_sj K_j,   K_s = J(Y_s) W_s,   w_new = w + h Σ_s b_s K_s,
//! ```
//!
//! with `Y_s` the state's stage arguments. So once the state's integration
//! has recorded its step sizes and `J(Y_s)` at every stage of every
//! accepted step, `Φ v` is this linear recurrence replayed: no right-hand
//! side (no contact force, no exponential), no error estimate, no rejected
//! step — and the same numbers, to rounding, as the integration of the
//! state with the column `v` (whose steps the state alone chooses).
//!
//! The record is the system's: [`RecordedJacobian`] stores the
//! state-dependent part of `J` in whatever compact form the system has (for
//! a row, the two partial derivatives of each contact force that is not
//! screened out), so memory is O(steps × stages × active terms).

use super::dop853::tableau::{A, B, C, N_STAGES};
use super::explicit::combine;
use super::{BandMatrix, Dop853, IntegrationError, IntegratorOptions, OdeSystem, Stats};

/// The stages of a DOP853 step: the records of one replayed step.
pub const STAGES: usize = N_STAGES;

/// A system whose Jacobian `∂f/∂y` depends on the state alone and can be
/// recorded compactly at a state and applied to vectors later.
pub trait RecordedJacobian: OdeSystem {
    /// One recorded item (e.g. a contact and its force's two partial
    /// derivatives).
    type Entry: Copy + std::fmt::Debug;

    /// Appends to `out` what [`apply_recorded`](Self::apply_recorded) needs
    /// of the Jacobian at `y`.
    fn record_jacobian(&self, y: &[f64], out: &mut Vec<Self::Entry>);

    /// [`record_jacobian`](Self::record_jacobian) at the `y` of the last
    /// right-hand side, which a system may take from what that call
    /// computed (the same entries).
    fn record_jacobian_after_rhs(&self, y: &[f64], out: &mut Vec<Self::Entry>) {
        self.record_jacobian(y, out)
    }

    /// `out = J v` with the Jacobian recorded as `entries`.
    fn apply_recorded(&self, entries: &[Self::Entry], v: &[f64], out: &mut [f64]);
}

/// A system that records its Jacobian at every right-hand side evaluation
/// while `on` (see [`integrate_recorded`]); otherwise the system itself.
#[derive(Clone, Debug)]
pub struct Recorder<S: RecordedJacobian> {
    sys: S,
    on: bool,
    /// Time of each recorded evaluation since the last accepted step.
    times: Vec<f64>,
    /// Evaluation `i`'s entries at `entries[offsets[i]..offsets[i + 1]]`.
    offsets: Vec<usize>,
    entries: Vec<S::Entry>,
}

impl<S: RecordedJacobian> Recorder<S> {
    /// Wraps `sys`; `on` records (a copy of the system that only serves a
    /// difference quotient, e.g. at a shifted parameter, records nothing).
    pub fn new(sys: S, on: bool) -> Self {
        Self {
            sys,
            on,
            times: Vec::new(),
            offsets: vec![0],
            entries: Vec::new(),
        }
    }

    /// The wrapped system.
    pub fn system(&self) -> &S {
        &self.sys
    }

    /// The wrapped system, mutably.
    pub fn system_mut(&mut self) -> &mut S {
        &mut self.sys
    }

    /// Whether evaluations are recorded.
    pub fn recording(&self) -> bool {
        self.on
    }

    /// Records the Jacobian of the right-hand side just evaluated at
    /// `(t, y)`, if recording.
    fn record(&mut self, t: f64, y: &[f64]) {
        if self.on {
            self.times.push(t);
            self.sys.record_jacobian_after_rhs(y, &mut self.entries);
            self.offsets.push(self.entries.len());
        }
    }

    /// Forgets the evaluations recorded so far.
    pub fn clear(&mut self) {
        self.times.clear();
        self.offsets.truncate(1);
        self.entries.clear();
    }

    /// Time of evaluation `i` since the last [`clear`](Self::clear).
    pub fn time(&self, i: usize) -> Option<f64> {
        self.times.get(i).copied()
    }

    /// Evaluation `i`'s entries.
    pub fn evaluation(&self, i: usize) -> &[S::Entry] {
        &self.entries[self.offsets[i]..self.offsets[i + 1]]
    }

    /// The index of the first of the `N_STAGES` evaluations of an accepted
    /// DOP853 step of size `h` from `t` to `t1` (stages 1..11 at
    /// `t + c_s h`, then `f` at `t1`): the last ones recorded, after any
    /// rejected attempt. Fails if the record does not match the stages (an
    /// internal error).
    pub fn accepted_step(&self, t: f64, h: f64, t1: f64) -> Result<usize, IntegrationError> {
        let n = self.times.len();
        if n < N_STAGES {
            return Err(tape_mismatch("fewer evaluations than stages"));
        }
        let first = n - N_STAGES;
        let times = C[1..N_STAGES].iter().map(|c| t + c * h).chain([t1]);
        if self.times[first..].iter().zip(times).any(|(a, b)| *a != b) {
            return Err(tape_mismatch(
                "an evaluation off the accepted step's stages",
            ));
        }
        Ok(first)
    }
}

fn tape_mismatch(what: &str) -> IntegrationError {
    IntegrationError::InvalidOptions(format!("tangent tape: {what} (internal error)"))
}

/// Work space of [`replay_step`].
#[derive(Clone, Debug, Default)]
pub struct ReplayScratch {
    w_new: Vec<f64>,
    w_stage: Vec<f64>,
    k: Vec<f64>,
}

/// One DOP853 step of size `h` from `t` of a linear recurrence (module
/// docs): `K_s = stage(s, t + c_s h, W_s)` for the stages `s = 0..11`,
/// then `w ← w + h Σ_s b_s K_s`, in place.
pub fn replay_step(
    w: &mut Vec<f64>,
    t: f64,
    h: f64,
    scratch: &mut ReplayScratch,
    mut stage: impl FnMut(usize, f64, &[f64], &mut [f64]),
) {
    let d = w.len();
    let ReplayScratch { w_new, w_stage, k } = scratch;
    w_new.resize(d, 0.0);
    w_stage.resize(d, 0.0);
    k.resize(N_STAGES * d, 0.0);
    stage(0, t, w, &mut k[..d]);
    for s in 1..N_STAGES {
        combine(w, &k[..s * d], A[s], h, w_stage);
        stage(s, t + C[s] * h, w_stage, &mut k[s * d..(s + 1) * d]);
    }
    combine(w, k, &B, h, w_new);
    std::mem::swap(w, w_new);
}

impl<S: RecordedJacobian> OdeSystem for Recorder<S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.sys.rhs(t, y, dydt);
        self.record(t, y);
    }

    fn rhs_reforced(&mut self, source: &Self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.sys.rhs_reforced(&source.sys, t, y, dydt);
        self.record(t, y);
    }

    fn admissible(&self, t: f64, y: &[f64]) -> bool {
        self.sys.admissible(t, y)
    }

    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        self.sys.jacobian_bandwidth()
    }

    fn error_block(&self) -> Option<usize> {
        self.sys.error_block()
    }

    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        self.sys.jacobian(t, y, jac)
    }

    fn jacobian_after_rhs(&mut self, t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        self.sys.jacobian_after_rhs(t, y, jac)
    }
}

/// A source term `q(t, out)` of a replayed linear recurrence: writes
/// `q(t)` into `out`.
pub type Source<'a> = dyn FnMut(f64, &mut [f64]) + 'a;

/// The record of one DOP853 integration: its accepted steps and the
/// Jacobian at every stage, replayed by [`apply`](Self::apply).
#[derive(Clone, Debug)]
pub struct TangentTape<S: RecordedJacobian> {
    sys: S,
    dim: usize,
    /// Accepted step sizes.
    steps: Vec<f64>,
    /// Start time of each accepted step.
    starts: Vec<f64>,
    /// Stage `s` of step `k` is record `N_STAGES k + s`; record
    /// `N_STAGES (k + 1)` is `J` at the step's end, the next step's stage 0.
    offsets: Vec<usize>,
    entries: Vec<S::Entry>,
}

impl<S: RecordedJacobian> TangentTape<S> {
    /// Number of accepted steps recorded.
    pub fn steps(&self) -> usize {
        self.steps.len()
    }

    /// Number of recorded entries (the tape's memory is this times the
    /// entry's size, plus a word per stage).
    pub fn entries(&self) -> usize {
        self.entries.len()
    }

    fn record(&self, i: usize) -> &[S::Entry] {
        &self.entries[self.offsets[i]..self.offsets[i + 1]]
    }

    /// `Φ v`: the sensitivity of the end state to the initial state, in
    /// the direction `v` (state order of the system).
    pub fn apply(&self, v: &[f64]) -> Vec<f64> {
        self.replay(v, |_, _| {})
    }

    /// The solution at the end of `w' = J(y(t)) w + q(t)`, `w(t0) = v`,
    /// replayed on the recorded steps: `q(t, out)` writes the source at
    /// `t`. With `v = 0` and `q = ∂f/∂p` of a parameter that enters the
    /// equations through a function of time alone (a forcing amplitude or
    /// frequency), the sensitivity of the end state to the parameter: the
    /// same recurrence, stage by stage, as the integration of the
    /// parameter's variational column on the state's steps.
    pub fn apply_with_source(&self, v: &[f64], q: &mut Source) -> Vec<f64> {
        let mut source = vec![0.0; self.dim];
        self.replay(v, |t, k| {
            q(t, &mut source);
            k.iter_mut().zip(&source).for_each(|(k, q)| *k += q);
        })
    }

    /// The recurrence with `add(t, k)` adding the source at stage time `t`
    /// to the stage derivative `k` (a no-op for `Φ v`, inlined away).
    fn replay(&self, v: &[f64], mut add: impl FnMut(f64, &mut [f64])) -> Vec<f64> {
        let mut w = v.to_vec();
        let mut scratch = ReplayScratch::default();
        for (step, (&h, &t)) in self.steps.iter().zip(&self.starts).enumerate() {
            let first = N_STAGES * step;
            replay_step(&mut w, t, h, &mut scratch, |s, ts, ws, ks| {
                self.sys.apply_recorded(self.record(first + s), ws, ks);
                add(ts, ks);
            });
        }
        w
    }
}

/// Integrates `sys` from `(t0, y0)` to `t_end` with DOP853, as
/// [`integrate_to`](super::integrate_to), and records the tape of the
/// system that `recorder` reaches inside it (the state of a
/// [`Variational`](crate::dynamics::variational::Variational) extension, say: the
/// state's steps and Jacobians; the extension's columns only ride along).
/// Fails if the record does not match DOP853's stages (an internal error).
pub fn integrate_recorded<V, S>(
    sys: &mut V,
    recorder: fn(&mut V) -> &mut Recorder<S>,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &IntegratorOptions,
) -> Result<(Vec<f64>, Stats, TangentTape<S>), IntegrationError>
where
    V: OdeSystem,
    S: RecordedJacobian + Clone,
{
    if !(t_end > t0 && t_end.is_finite()) {
        return Err(IntegrationError::InvalidOptions(format!(
            "integrate_recorded needs a finite t_end > t0, got t0 = {t0}, t_end = {t_end}"
        )));
    }
    let mut solver = Dop853::new(sys.dim(), opts.clone())?;
    recorder(sys).clear();
    solver.reset(sys, t0, y0)?;
    let rec = recorder(sys);
    if rec.time(0) != Some(t0) {
        return Err(tape_mismatch("no record of f(t0, y0)"));
    }
    let mut tape = TangentTape {
        sys: rec.sys.clone(),
        dim: rec.sys.dim(),
        steps: Vec::new(),
        starts: Vec::new(),
        offsets: vec![0],
        entries: rec.evaluation(0).to_vec(),
    };
    tape.offsets.push(tape.entries.len());
    while solver.t() < t_end {
        let t = solver.t();
        recorder(sys).clear();
        solver.step(sys, t_end)?;
        let h = solver.h_last();
        let rec = recorder(sys);
        let first = rec.accepted_step(t, h, solver.t())?;
        for i in first..first + N_STAGES {
            tape.entries.extend_from_slice(rec.evaluation(i));
            tape.offsets.push(tape.entries.len());
        }
        tape.steps.push(h);
        tape.starts.push(t);
    }
    recorder(sys).clear();
    Ok((solver.y().to_vec(), solver.stats(), tape))
}
