//! Numerical integration of ordinary differential equations `y' = f(t, y)`.
//!
//! The integrator is an adaptive explicit Runge–Kutta method of order 8, the
//! Dormand–Prince 8(5,3) pair "DOP853" of Hairer, Nørsett & Wanner (*Solving
//! Ordinary Differential Equations I*, Sec. II.5), with its 7th-order dense
//! output; see [`Dop853`].
//!
//! * [`OdeSystem`] is the interface a model implements (right-hand side and an
//!   optional admissibility test of candidate states).
//! * [`IntegratorOptions`] holds tolerances and step-size limits.
//! * [`Dop853`] is the step-by-step driver (one accepted step per call, dense
//!   output of the last step, restart after discontinuities).
//! * [`integrate_to`] is a convenience wrapper integrating over an interval.
//!
//! Integration always runs forward in time (`t_end > t0`).

mod dop853;
mod dop853_tableau;

pub use dop853::Dop853;

use std::fmt;

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
    /// stage states, and not the initial state given to [`Dop853::reset`]).
    fn admissible(&self, _t: f64, _y: &[f64]) -> bool {
        true
    }
}

/// Tolerances and step-size limits of the integrator.
///
/// The local error of every step is measured in the weighted RMS norm
/// `sqrt(1/m · Σ_i (err_i / sk_i)²)` over the `m` error-controlled components
/// (see [`error_components`](Self::error_components)), with the weights
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
    /// Maximal number of accepted steps since the last [`Dop853::reset`]
    /// (hence per call of [`integrate_to`]); exceeding it gives
    /// [`IntegrationError::TooManySteps`]. Default `10_000_000`.
    pub max_steps: u64,
    /// `Some(n)`: only the first `n` components (`1 <= n <= dim`) enter the
    /// error norm, so that e.g. variational equations appended after the
    /// state do not control the step size (they are still checked for
    /// finiteness). Default `None`: all components.
    pub error_components: Option<usize>,
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
        }
    }
}

impl IntegratorOptions {
    /// Checks the options for a system of dimension `dim`; returns the number
    /// of error-controlled components.
    fn validate(&self, dim: usize) -> Result<usize, IntegrationError> {
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
/// [`Dop853::reset_stats`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Number of evaluations of the right-hand side `f`.
    pub rhs_evaluations: u64,
    /// Number of accepted steps.
    pub steps: u64,
    /// Number of rejected step attempts (error estimate too large, non-finite
    /// values, or state not admissible).
    pub rejected_steps: u64,
}

/// Why an attempted step was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RejectReason {
    /// The local error estimate exceeded the tolerance.
    ErrorEstimate,
    /// A stage derivative, the new state, `f` at the new state or the error
    /// estimate was not finite (NaN or infinite).
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
#[derive(Debug, Clone, thiserror::Error)]
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
    /// Invalid options or arguments (tolerances, step limits, dimension
    /// mismatch, non-finite or out-of-order times, stepping before `reset`).
    #[error("invalid integrator options or arguments: {0}")]
    InvalidOptions(String),
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
