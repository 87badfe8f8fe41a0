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

use super::dop853_tableau::{A, B, C, N_STAGES};
use super::explicit::combine;
use super::{BandMatrix, Dop853, IntegrationError, IntegratorOptions, OdeSystem, Stats};

/// A system whose Jacobian `∂f/∂y` depends on the state alone and can be
/// recorded compactly at a state and applied to vectors later.
pub trait RecordedJacobian: OdeSystem {
    /// One recorded item (e.g. a contact and its force's two partial
    /// derivatives).
    type Entry: Copy + std::fmt::Debug;

    /// Appends to `out` what [`apply_recorded`](Self::apply_recorded) needs
    /// of the Jacobian at `y`.
    fn record_jacobian(&self, y: &[f64], out: &mut Vec<Self::Entry>);

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

    fn clear(&mut self) {
        self.times.clear();
        self.offsets.truncate(1);
        self.entries.clear();
    }

    /// Evaluation `i`'s entries.
    fn evaluation(&self, i: usize) -> &[S::Entry] {
        &self.entries[self.offsets[i]..self.offsets[i + 1]]
    }
}

impl<S: RecordedJacobian> OdeSystem for Recorder<S> {
    fn dim(&self) -> usize {
        self.sys.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.sys.rhs(t, y, dydt);
        if self.on {
            self.times.push(t);
            self.sys.record_jacobian(y, &mut self.entries);
            self.offsets.push(self.entries.len());
        }
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
        let d = self.dim;
        let mut w = v.to_vec();
        let mut w_new = vec![0.0; d];
        let mut w_stage = vec![0.0; d];
        let mut k = vec![0.0; N_STAGES * d];
        for (step, (&h, &t)) in self.steps.iter().zip(&self.starts).enumerate() {
            let first = N_STAGES * step;
            self.sys.apply_recorded(self.record(first), &w, &mut k[..d]);
            add(t, &mut k[..d]);
            for s in 1..N_STAGES {
                combine(&w, &k[..s * d], A[s], h, &mut w_stage);
                let k_s = &mut k[s * d..(s + 1) * d];
                self.sys
                    .apply_recorded(self.record(first + s), &w_stage, k_s);
                add(t + C[s] * h, k_s);
            }
            combine(&w, &k, &B, h, &mut w_new);
            std::mem::swap(&mut w, &mut w_new);
        }
        w
    }
}

/// Integrates `sys` from `(t0, y0)` to `t_end` with DOP853, as
/// [`integrate_to`](super::integrate_to), and records the tape of the
/// system that `recorder` reaches inside it (the state of a
/// [`Variational`](crate::variational::Variational) extension, say: the
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
    let mismatch = |what: &str| {
        IntegrationError::InvalidOptions(format!("tangent tape: {what} (internal error)"))
    };
    let mut solver = Dop853::new(sys.dim(), opts.clone())?;
    recorder(sys).clear();
    solver.reset(sys, t0, y0)?;
    let rec = recorder(sys);
    if rec.times.first() != Some(&t0) {
        return Err(mismatch("no record of f(t0, y0)"));
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
        // The accepted attempt's 11 new stages and f at its end are the
        // last 12 evaluations (rejected attempts come before them).
        let n = rec.times.len();
        if n < N_STAGES {
            return Err(mismatch("fewer evaluations than stages"));
        }
        let first = n - N_STAGES;
        // Stages 1..11 at t + c_s h, then the end: f(t + h, y_new).
        let times = C[1..N_STAGES].iter().map(|c| t + c * h).chain([solver.t()]);
        for (i, expected) in (first..n).zip(times) {
            if rec.times[i] != expected {
                return Err(mismatch("an evaluation off the accepted step's stages"));
            }
            tape.entries.extend_from_slice(rec.evaluation(i));
            tape.offsets.push(tape.entries.len());
        }
        tape.steps.push(h);
        tape.starts.push(t);
    }
    recorder(sys).clear();
    Ok((solver.y().to_vec(), solver.stats(), tape))
}
