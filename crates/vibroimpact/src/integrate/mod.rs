//! Numerical integration of ordinary differential equations `y' = f(t, y)`.
//!
//! ## Files
//! - `driver.rs` — the one step driver and the [`StepMethod`] interface;
//! - `explicit.rs` — what the explicit Runge–Kutta methods share;
//! - `dop853/`, `dopri5/`, `rosenbrock/` — the three methods (DOP853 with
//!   its tableau, DOPRI5, RODAS), each with its tests;
//! - `exact/` — the exact flow of a linear system under harmonic forcing
//!   (a chain whose every contact is rigid, between impacts);
//! - `stepper.rs` — any method behind one interface, automatic switching;
//! - `events.rs` — event location on the dense output;
//! - `tangent.rs` — the tangent tape: products replayed on recorded steps;
//! - `tests/` — the conformance suite and the shared test systems.
//!
//! Three integrators with the same step-by-step interface:
//!
//! * [`Dop853`]: an adaptive explicit Runge–Kutta method of order 8, the
//!   Dormand–Prince 8(5,3) pair "DOP853" of Hairer, Nørsett & Wanner
//!   (*Solving Ordinary Differential Equations I*, Sec. II.5), with its
//!   7th-order dense output and Hairer's stiffness test;
//! * [`Dopri5`]: the Dormand–Prince 5(4) pair of Hairer's `dopri5.f` with
//!   its 4th-order dense output, for loose tolerances where something else
//!   than accuracy limits the step (a record's samples);
//! * [`Rodas`]: the L-stable, stiffly accurate Rosenbrock method RODAS of
//!   order 4(3) (Hairer & Wanner, *Solving Ordinary Differential Equations
//!   II*, Sec. IV.7 and VI.3, code `rodas.f`), for stiff phases such as bodies pressed together by a
//!   very stiff contact force; it needs the Jacobian `∂f/∂y` (analytic via
//!   [`OdeSystem::jacobian`], else by banded finite differences) and solves
//!   linear systems with the band LU of [`crate::linalg::band`].
//!
//! * [`OdeSystem`] is the interface a model implements (right-hand side, an
//!   optional admissibility test of candidate states, optional Jacobian and
//!   its bandwidths).
//! * [`IntegratorOptions`] holds tolerances and step-size limits.
//! * [`Driver`] is the one step driver (reset, step loop, step-size control,
//!   limits, accept/reject, dense-output end points, statistics), generic
//!   over a [`StepMethod`] that holds only what differs between methods;
//!   [`Dop853`], [`Dopri5`] and [`Rodas`] are the driver around
//!   [`Dop853Method`], [`Dopri5Method`] and [`RodasMethod`]. [`Stepper`]
//!   holds any of them behind one interface and can
//!   switch from DOP853 to RODAS when stiffness is detected
//!   ([`Method::Auto`]).
//! * [`events`] detects and locates sign changes of event functions on the
//!   dense output of a step.
//! * [`integrate_to`] is a convenience wrapper integrating over an interval
//!   with DOP853.
//!
//! Integration always runs forward in time (`t_end > t0`).

mod dop853;
mod dopri5;
mod driver;
pub mod events;
mod exact;
mod explicit;
pub mod rosenbrock;
mod stepper;
pub mod tangent;

#[cfg(test)]
mod tests;

pub use crate::linalg::{BandMatrix, Singular};
pub use dop853::{Dop853, Dop853Method};
pub use dopri5::{Dopri5, Dopri5Method};
pub use driver::{Attempt, Driver, Point, StepMethod, Trial};
pub use exact::{Exact, ExactMethod, Harmonic, Linear, LinearForm};
pub use rosenbrock::{Rodas, RodasMethod};
pub use stepper::{Method, Stepper};
pub use tangent::{integrate_recorded, RecordedJacobian, Recorder, TangentTape};

use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;

/// A shared stop request and progress mark: a caller (a Ctrl-C handler, a
/// Python binding watching for KeyboardInterrupt) requests the stop from
/// another thread, and every integrator whose options carry the token stops
/// before its next step with [`IntegrationError::Interrupted`]; each step
/// also marks the time it starts from, for progress reports. Clones share
/// the state.
#[derive(Clone, Debug, Default)]
pub struct Interrupt(Arc<InterruptState>);

#[derive(Debug, Default)]
struct InterruptState {
    stop: AtomicBool,
    /// Bits of the last marked time.
    time: AtomicU64,
}

impl Interrupt {
    /// A new token, not yet requested.
    pub fn new() -> Self {
        Self::default()
    }

    /// Requests the stop.
    pub fn request(&self) {
        self.0.stop.store(true, Ordering::Relaxed);
    }

    /// Whether the stop was requested.
    pub fn requested(&self) -> bool {
        self.0.stop.load(Ordering::Relaxed)
    }

    /// Marks the time an integrator has reached.
    pub fn mark(&self, t: f64) {
        self.0.time.store(t.to_bits(), Ordering::Relaxed);
    }

    /// The last marked time (0 before any step).
    pub fn time(&self) -> f64 {
        f64::from_bits(self.0.time.load(Ordering::Relaxed))
    }

    /// Checks the token before a step from `t`: marks `t`, and fails if the
    /// stop was requested.
    pub fn check(&self, t: f64) -> Result<(), IntegrationError> {
        self.mark(t);
        if self.requested() {
            Err(IntegrationError::Interrupted { t })
        } else {
            Ok(())
        }
    }
}

/// Two tokens are equal when they share the flag.
impl PartialEq for Interrupt {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// A system of first-order ordinary differential equations `y' = f(t, y)`.
pub trait OdeSystem {
    /// Number of state components.
    fn dim(&self) -> usize;

    /// dy/dt = f(t, y), written into `dydt` (same length as y).
    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]);

    /// Whether a candidate state is acceptable to the model (e.g. no absurd
    /// penetration). A step whose new state is not admissible is rejected and
    /// retried smaller.
    ///
    /// Only the end state of each attempted step is tested (not the internal
    /// stage states, and not the initial state given to [`Driver::reset`]).
    fn admissible(&self, _t: f64, _y: &[f64]) -> bool {
        true
    }

    /// Size of the blocks of the error norm (None: one block, the weighted
    /// RMS norm over all error-controlled components). With `Some(b)` the
    /// components form consecutive blocks of `b` (a body's displacement and
    /// velocity: `b = 2`) and a step's error is the largest block's RMS
    /// norm, so that the error of a few moving bodies is not averaged away
    /// by many at rest (docs/theory.md §10). Read when the integrator is
    /// reset.
    fn error_block(&self) -> Option<usize> {
        None
    }

    /// Lower and upper bandwidths of ∂f/∂y, if banded (None: dense).
    ///
    /// `Some((kl, ku))` promises `∂f_i/∂y_j = 0` unless
    /// `j − ku <= i <= j + kl`. [`Rodas`] then stores the Jacobian and its
    /// iteration matrix as band matrices and needs only `kl + ku + 1`
    /// evaluations of `f` for a finite-difference Jacobian. Bandwidths above
    /// `dim − 1` are reduced to `dim − 1`. The value is read when the
    /// integrator is reset.
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        None
    }

    /// Analytic Jacobian ∂f/∂y at (t, y) written into `jac` (already
    /// zeroed, of the shape given by [`jacobian_bandwidth`](Self::jacobian_bandwidth));
    /// return false if not provided (finite differences are then used).
    ///
    /// Write entries with [`BandMatrix::set`] / [`BandMatrix::add`], only
    /// inside the band. Used by [`Rodas`] once per step (at the start point
    /// of the step); the explicit [`Dop853`] never calls it.
    fn jacobian(&mut self, _t: f64, _y: &[f64], _jac: &mut BandMatrix) -> bool {
        false
    }

    /// [`jacobian`](Self::jacobian) at the `(t, y)` of the last
    /// [`rhs`](Self::rhs) call, which a system may take from what that call
    /// computed (the same numbers: a row's contact laws are evaluated once).
    fn jacobian_after_rhs(&mut self, t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        self.jacobian(t, y, jac)
    }

    /// [`rhs`](Self::rhs) at the `(t, y)` of `source`'s last right-hand
    /// side, for a copy of `source` that differs from it in its forcing
    /// alone (functions of time): a system may take the rest from what
    /// `source` computed (the same numbers).
    fn rhs_reforced(&mut self, _source: &Self, t: f64, y: &[f64], dydt: &mut [f64])
    where
        Self: Sized,
    {
        self.rhs(t, y, dydt)
    }

    /// The system as `A y + b(t)` with harmonic `b`, where it is one
    /// ([`LinearForm`]; None by default): [`Method::Exact`] then moves it
    /// exactly.
    fn linear_form(&self) -> Option<LinearForm> {
        None
    }
}

/// Tolerances and step-size limits of the integrator.
///
/// The local error of every step is measured in the weighted RMS norm
/// `sqrt(1/m · Σ_i (err_i / sk_i)²)` over the `m` error-controlled components
/// (see [`error_components`](Self::error_components)), or its largest value
/// over blocks of components (see [`OdeSystem::error_block`]), with the weights
/// `sk_i = atol + rtol · max(|y_old,i|, |y_new,i|)`; a step is accepted when
/// this norm is at most 1.
#[derive(Clone, Debug)]
pub struct IntegratorOptions {
    /// Relative tolerance (`> 0`, finite). Default `1e-9`.
    pub rtol: f64,
    /// Absolute tolerance, a scalar for all components (`> 0`, finite).
    /// Default `1e-12`.
    pub atol: f64,
    /// Initial step size (`> 0`, finite). `None` (default): Hairer's automatic
    /// initial step (`HINIT` of `dop853.f`, one extra evaluation of `f`).
    pub h_init: Option<f64>,
    /// Maximal step size (`> 0`, may be infinite). Default `f64::INFINITY`.
    pub h_max: f64,
    /// Minimal step size (`>= 0`, finite, `<= h_max`). Default `0.0`.
    ///
    /// When a rejected attempt would shrink the step to
    /// `h < max(h_min, 16·ε·|t|)` (ε = `f64::EPSILON`), or to a value that no
    /// longer advances `t` (`t + h == t`), the integrator gives up with
    /// [`IntegrationError::StepSizeUnderflow`]. An accepted step is never
    /// started below that floor, except a final step that is shortened to
    /// reach the bound `t_bound` exactly.
    pub h_min: f64,
    /// Maximal number of accepted steps since the last [`Driver::reset`]
    /// (hence per call of [`integrate_to`]); exceeding it gives
    /// [`IntegrationError::TooManySteps`]. Default `10_000_000`.
    pub max_steps: u64,
    /// `Some(n)`: only the first `n` components (`1 <= n <= dim`) enter the
    /// error norm, so that e.g. variational equations appended after the
    /// state do not control the step size (they are still checked for
    /// finiteness). Default `None`: all components.
    pub error_components: Option<usize>,
    /// Whether [`Dop853`] and [`Dopri5`] run Hairer's stiffness test after every accepted
    /// step (see [`Driver::stiffness_detected`]); it only reports and never
    /// changes the computed solution. Ignored by [`Rodas`]. Default `true`.
    pub stiffness_check: bool,
    /// Stop request checked before every step (see [`Interrupt`]). Default
    /// `None`.
    pub interrupt: Option<Interrupt>,
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-9,
            atol: 1e-12,
            h_init: None,
            h_max: f64::INFINITY,
            h_min: 0.0,
            max_steps: 10_000_000,
            error_components: None,
            stiffness_check: true,
            interrupt: None,
        }
    }
}

impl IntegratorOptions {
    /// Checks the options for a system of dimension `dim`; returns the number
    /// of error-controlled components.
    pub(crate) fn validate(&self, dim: usize) -> Result<usize, IntegrationError> {
        let invalid = |msg: String| Err(IntegrationError::InvalidOptions(msg));
        if dim == 0 {
            return invalid("the system dimension must be positive".into());
        }
        if !(self.rtol > 0.0 && self.rtol.is_finite()) {
            return invalid(format!(
                "rtol must be positive and finite, got {}",
                self.rtol
            ));
        }
        if !(self.atol > 0.0 && self.atol.is_finite()) {
            return invalid(format!(
                "atol must be positive and finite, got {}",
                self.atol
            ));
        }
        if let Some(h) = self.h_init {
            if !(h > 0.0 && h.is_finite()) {
                return invalid(format!("h_init must be positive and finite, got {h}"));
            }
        }
        if self.h_max.is_nan() || self.h_max <= 0.0 {
            return invalid(format!("h_max must be positive, got {}", self.h_max));
        }
        if !(self.h_min >= 0.0 && self.h_min.is_finite() && self.h_min <= self.h_max) {
            return invalid(format!(
                "h_min must be finite and in [0, h_max], got h_min = {}, h_max = {}",
                self.h_min, self.h_max
            ));
        }
        if self.max_steps == 0 {
            return invalid("max_steps must be positive".into());
        }
        match self.error_components {
            None => Ok(dim),
            Some(n) if (1..=dim).contains(&n) => Ok(n),
            Some(n) => invalid(format!("error_components must be in 1..={dim}, got {n}")),
        }
    }
}

/// Work counters of an integrator (accumulated over its lifetime, see
/// [`Driver::reset_stats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Number of evaluations of the right-hand side `f`.
    pub rhs_evaluations: u64,
    /// Number of accepted steps.
    pub steps: u64,
    /// Number of rejected step attempts (error estimate too large, non-finite
    /// values, singular iteration matrix, or state not admissible).
    pub rejected_steps: u64,
    /// Number of Jacobian evaluations (analytic or by finite differences;
    /// [`Rodas`] only). The evaluations of `f` spent on finite differences
    /// are included in [`rhs_evaluations`](Self::rhs_evaluations).
    pub jacobian_evaluations: u64,
    /// Number of LU factorisations of iteration matrices ([`Rodas`] only).
    pub lu_decompositions: u64,
}

impl std::ops::Add for Stats {
    type Output = Stats;

    /// Field-wise sum (e.g. the work of several integrations).
    fn add(self, o: Stats) -> Stats {
        Stats {
            rhs_evaluations: self.rhs_evaluations + o.rhs_evaluations,
            steps: self.steps + o.steps,
            rejected_steps: self.rejected_steps + o.rejected_steps,
            jacobian_evaluations: self.jacobian_evaluations + o.jacobian_evaluations,
            lu_decompositions: self.lu_decompositions + o.lu_decompositions,
        }
    }
}

/// Why an attempted step was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RejectReason {
    /// The local error estimate exceeded the tolerance.
    ErrorEstimate,
    /// A stage derivative, the new state, `f` at the new state or the error
    /// estimate was not finite (NaN or infinite). [`Rodas`] also reports a
    /// singular (or non-finite) iteration matrix `I/(hγ) − J` this way.
    NonFinite,
    /// The model declared the new state not admissible
    /// ([`OdeSystem::admissible`]).
    NotAdmissible,
}

impl fmt::Display for RejectReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::ErrorEstimate => "error estimate too large",
            Self::NonFinite => "non-finite stage, state or error estimate",
            Self::NotAdmissible => "state not admissible",
        })
    }
}

/// Failure of an integration.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IntegrationError {
    /// Repeated rejections shrank the step size below the minimum (see
    /// [`IntegratorOptions::h_min`]). `t` and `y` are the last accepted point,
    /// `h` the step size that would have been tried next, `reason` the cause
    /// of the last rejection.
    #[error("step size underflow at t = {t:e}: h = {h:e} is below the minimum (last rejection: {reason}); state y = {y:?}")]
    StepSizeUnderflow {
        /// Time of the last accepted point.
        t: f64,
        /// The too-small step size.
        h: f64,
        /// State at `t`.
        y: Vec<f64>,
        /// Reason of the last rejected attempt.
        reason: RejectReason,
    },
    /// More than [`IntegratorOptions::max_steps`] accepted steps since the
    /// last reset.
    #[error("maximal number of steps ({steps}) reached at t = {t:e}")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// Number of accepted steps since the last reset.
        steps: u64,
    },
    /// The explicit method's step is limited by stability (its stiffness
    /// test fired) so far below what the remaining interval needs that the
    /// run would take `projected` more steps, beyond the step limit: an
    /// implicit method is the remedy.
    #[error("stiff at t = {t:e}: stability limits the explicit step to h = {h:e}, so {projected:.1e} more steps would be needed (limit {limit}); use the implicit method rodas (or auto)")]
    Stiff {
        /// Time reached.
        t: f64,
        /// The stability-limited step size.
        h: f64,
        /// Steps the rest of the interval would take at that size.
        projected: f64,
        /// The step limit.
        limit: u64,
    },
    /// The run has advanced so little for its steps that finishing would
    /// take far more than the step limit (checked by callers that know the
    /// end time, e.g. simulation).
    #[error("no progress: {steps} steps reached only t = {t:e}; at this pace the run needs {projected:.1e} steps, far beyond the limit {limit}: the model (a contact law or a body) is far stiffer or faster than its motion; check its parameters, or use the implicit method rodas")]
    NoProgress {
        /// Time reached.
        t: f64,
        /// Steps taken.
        steps: u64,
        /// Steps the whole run would take at this pace.
        projected: f64,
        /// The step limit.
        limit: u64,
    },
    /// The local integrator's checks of contacts between exactly moving
    /// bodies advance so little that finishing would take `projected`
    /// checks, beyond `CRAWL_FACTOR` × the step limit (docs/theory.md §10).
    #[error("no progress: {checks} contact checks reached only t = {t:e}; at this pace the run needs {projected:.1e}, far beyond 100 x the step limit {limit}: a body moves far faster than the bound of its motion can follow (check its parameters), or use the global integrator")]
    ChecksCrawl {
        /// Time reached.
        t: f64,
        /// Checks made.
        checks: u64,
        /// Checks the whole run would take at this pace.
        projected: f64,
        /// The step limit.
        limit: u64,
    },
    /// The caller's [`Interrupt`] was requested; `t` is the time reached.
    #[error("interrupted at t = {t:e}")]
    Interrupted {
        /// Time reached.
        t: f64,
    },
    /// Invalid options or arguments (tolerances, step limits, dimension
    /// mismatch, non-finite or out-of-order times, stepping before `reset`).
    #[error("invalid integrator options or arguments: {0}")]
    InvalidOptions(String),
    /// A rigid impact the run cannot take (docs/theory.md §12): impacts
    /// that accumulate into a resting contact, or a law's e(U) that
    /// failed.
    #[error("rigid impact of contact {contact} at t = {t:e}: {reason}")]
    RigidImpact {
        /// Time of the impact.
        t: f64,
        /// The model's contact index.
        contact: usize,
        /// What stopped it.
        reason: String,
    },
    /// The initial state or its derivative `f(t0, y0)` is not finite.
    #[error("non-finite initial state or derivative at t = {t:e}")]
    NonFiniteInitialState {
        /// Initial time.
        t: f64,
    },
}

/// Convenience: integrate from t0 to t_end (t_end > t0), return final state and stats.
///
/// Creates a [`Dop853`] with `opts`, resets it at `(t0, y0)` and steps until
/// `t_end` is reached exactly. The statistics cover this call only.
pub fn integrate_to<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &IntegratorOptions,
) -> Result<(Vec<f64>, Stats), IntegrationError> {
    if !(t_end > t0 && t_end.is_finite()) {
        return Err(IntegrationError::InvalidOptions(format!(
            "integrate_to needs a finite t_end > t0, got t0 = {t0}, t_end = {t_end}"
        )));
    }
    let mut solver = Dop853::new(sys.dim(), opts.clone())?;
    solver.reset(sys, t0, y0)?;
    while solver.t() < t_end {
        solver.step(sys, t_end)?;
    }
    Ok((solver.y().to_vec(), solver.stats()))
}
