//! Numerical integration of ordinary differential equations `y' = f(t, y)`.
//!
//! Two integrators with the same step-by-step interface:
//!
//! * [`Dop853`]: an adaptive explicit Runge–Kutta method of order 8, the
//!   Dormand–Prince 8(5,3) pair "DOP853" of Hairer, Nørsett & Wanner
//!   (*Solving Ordinary Differential Equations I*, Sec. II.5), with its
//!   7th-order dense output and Hairer's stiffness test;
//! * [`Rodas`]: the L-stable, stiffly accurate Rosenbrock method RODAS of
//!   order 4(3) (Hairer & Wanner, *Solving Ordinary Differential Equations
//!   II*, Sec. IV.7 and VI.3, code `rodas.f`), for stiff phases such as bodies pressed together by a
//!   very stiff contact force; it needs the Jacobian `∂f/∂y` (analytic via
//!   [`OdeSystem::jacobian`], else by banded finite differences) and solves
//!   linear systems with the band LU of [`linalg`].
//!
//! * [`OdeSystem`] is the interface a model implements (right-hand side, an
//!   optional admissibility test of candidate states, optional Jacobian and
//!   its bandwidths).
//! * [`IntegratorOptions`] holds tolerances and step-size limits.
//! * [`Dop853`] and [`Rodas`] are the step-by-step drivers (one accepted step
//!   per call, dense output of the last step, restart after
//!   discontinuities); [`Stepper`] holds either behind one interface and can
//!   switch from DOP853 to RODAS when stiffness is detected
//!   ([`Method::Auto`]).
//! * [`integrate_to`] is a convenience wrapper integrating over an interval
//!   with DOP853.
//!
//! Integration always runs forward in time (`t_end > t0`).

mod dop853;
mod dop853_tableau;
pub mod linalg;
pub mod rosenbrock;

pub use dop853::Dop853;
pub use linalg::{BandMatrix, Singular};
pub use rosenbrock::Rodas;

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
    /// stage states, and not the initial state given to [`Dop853::reset`]).
    fn admissible(&self, _t: f64, _y: &[f64]) -> bool {
        true
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
    /// Whether [`Dop853`] runs Hairer's stiffness test after every accepted
    /// step (see [`Dop853::stiffness_detected`]); it only reports and never
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

/// Integration method of a [`Stepper`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The explicit [`Dop853`] (non-stiff problems).
    Dop853,
    /// The linearly implicit [`Rodas`] (stiff problems).
    Rodas,
    /// Start every integration (every [`Stepper::reset`]) with DOP853 and
    /// switch to RODAS for the rest of it as soon as DOP853's stiffness test
    /// fires ([`Dop853::stiffness_detected`]; needs
    /// [`IntegratorOptions::stiffness_check`], else this is plain DOP853).
    Auto,
}

/// Either integrator behind one interface, with optional automatic switching
/// from DOP853 to RODAS ([`Method::Auto`]).
///
/// The methods have the semantics of the same-named methods of [`Dop853`] and
/// [`Rodas`] and act on the *active* integrator ([`active`](Self::active)).
///
/// With [`Method::Auto`], [`step`](Self::step) checks, *before* taking a
/// step, whether DOP853 has detected stiffness; if so it calls
/// [`switch_to_rodas`](Self::switch_to_rodas) and takes the step with RODAS.
/// Dense output therefore always refers to the last step taken. There is no
/// switch back within an integration: the next [`reset`](Self::reset) (e.g.
/// after an impact) starts with DOP853 again.
///
/// Both integrators are allocated by [`new`](Self::new) for [`Method::Auto`];
/// for [`Method::Dop853`] a RODAS integrator is allocated on the first manual
/// switch only.
#[derive(Clone, Debug)]
pub struct Stepper {
    method: Method,
    dim: usize,
    opts: IntegratorOptions,
    dop853: Option<Dop853>,
    rodas: Option<Rodas>,
    /// Whether RODAS is the active integrator.
    on_rodas: bool,
}

impl Stepper {
    /// Creates a stepper for systems of dimension `dim`. Fails with
    /// [`IntegrationError::InvalidOptions`] as [`Dop853::new`] /
    /// [`Rodas::new`] do.
    pub fn new(
        method: Method,
        dim: usize,
        opts: IntegratorOptions,
    ) -> Result<Self, IntegrationError> {
        let dop853 = match method {
            Method::Dop853 | Method::Auto => Some(Dop853::new(dim, opts.clone())?),
            Method::Rodas => None,
        };
        let rodas = match method {
            Method::Rodas | Method::Auto => Some(Rodas::new(dim, opts.clone())?),
            Method::Dop853 => None,
        };
        Ok(Self {
            method,
            dim,
            opts,
            dop853,
            rodas,
            on_rodas: method == Method::Rodas,
        })
    }

    /// The method the stepper was created with.
    pub fn method(&self) -> Method {
        self.method
    }

    /// The integrator in use: [`Method::Dop853`] or [`Method::Rodas`].
    pub fn active(&self) -> Method {
        if self.on_rodas {
            Method::Rodas
        } else {
            Method::Dop853
        }
    }

    fn dop(&self) -> &Dop853 {
        self.dop853
            .as_ref()
            .expect("DOP853 is allocated while active")
    }

    fn dop_mut(&mut self) -> &mut Dop853 {
        self.dop853
            .as_mut()
            .expect("DOP853 is allocated while active")
    }

    fn ros(&self) -> &Rodas {
        self.rodas
            .as_ref()
            .expect("RODAS is allocated while active")
    }

    fn ros_mut(&mut self) -> &mut Rodas {
        self.rodas
            .as_mut()
            .expect("RODAS is allocated while active")
    }

    /// Start (or restart) at `(t0, y0)` with the method of construction
    /// (DOP853 for [`Method::Auto`], also after an earlier switch); see
    /// [`Dop853::reset`] and [`Rodas::reset`].
    pub fn reset<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), IntegrationError> {
        self.on_rodas = self.method == Method::Rodas;
        if self.on_rodas {
            self.ros_mut().reset(sys, t0, y0)
        } else {
            self.dop_mut().reset(sys, t0, y0)
        }
    }

    /// Restarts RODAS at the current point `(t, y)` of DOP853 and makes it
    /// the active integrator until the next [`reset`](Self::reset). The
    /// initial RODAS step is DOP853's proposed next step (under stiffness
    /// limited by stability, which is safe; RODAS then grows it up to 6× per
    /// step). Costs one evaluation of `f`; allocates a RODAS integrator if
    /// the stepper was created with [`Method::Dop853`] and has none yet.
    /// RODAS's step counter for [`IntegratorOptions::max_steps`] starts
    /// from zero. Dense output of the last DOP853 step is no longer
    /// available afterwards. A no-op if RODAS is already active.
    ///
    /// Errors: [`IntegrationError::InvalidOptions`] before a successful
    /// [`reset`](Self::reset); errors of [`Rodas::reset`].
    pub fn switch_to_rodas<S: OdeSystem>(&mut self, sys: &mut S) -> Result<(), IntegrationError> {
        if self.on_rodas {
            return Ok(());
        }
        if !self.dop().is_initialised() {
            return Err(IntegrationError::InvalidOptions(
                "switch_to_rodas() called before a successful reset()".into(),
            ));
        }
        if self.rodas.is_none() {
            self.rodas = Some(Rodas::new(self.dim, self.opts.clone())?);
        }
        let (Some(dop), Some(ros)) = (self.dop853.as_ref(), self.rodas.as_mut()) else {
            unreachable!("both integrators are allocated here");
        };
        ros.reset_with_step(sys, dop.t(), dop.y(), Some(dop.h_next()))?;
        self.on_rodas = true;
        Ok(())
    }

    /// Takes one accepted step (see [`Dop853::step`] / [`Rodas::step`]);
    /// with [`Method::Auto`], first switches to RODAS if DOP853 has detected
    /// stiffness.
    pub fn step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t_bound: f64,
    ) -> Result<(), IntegrationError> {
        if self.method == Method::Auto && !self.on_rodas && self.dop().stiffness_detected() {
            self.switch_to_rodas(sys)?;
        }
        if self.on_rodas {
            self.ros_mut().step(sys, t_bound)
        } else {
            self.dop_mut().step(sys, t_bound)
        }
    }

    /// Time after the last accepted step.
    pub fn t(&self) -> f64 {
        if self.on_rodas {
            self.ros().t()
        } else {
            self.dop().t()
        }
    }

    /// Time before the last accepted step.
    pub fn t_prev(&self) -> f64 {
        if self.on_rodas {
            self.ros().t_prev()
        } else {
            self.dop().t_prev()
        }
    }

    /// State at [`t`](Self::t).
    pub fn y(&self) -> &[f64] {
        if self.on_rodas {
            self.ros().y()
        } else {
            self.dop().y()
        }
    }

    /// `f(t, y)` at the current point.
    pub fn dydt(&self) -> &[f64] {
        if self.on_rodas {
            self.ros().dydt()
        } else {
            self.dop().dydt()
        }
    }

    /// Step size proposed for the next step.
    pub fn h_next(&self) -> f64 {
        if self.on_rodas {
            self.ros().h_next()
        } else {
            self.dop().h_next()
        }
    }

    /// Caps the size of the next step of the active integrator at `h`.
    pub fn limit_next_step(&mut self, h: f64) {
        if self.on_rodas {
            self.ros_mut().limit_next_step(h);
        } else {
            self.dop_mut().limit_next_step(h);
        }
    }

    /// Dense output of the last accepted step, valid in `[t_prev, t]`: 7th
    /// order for DOP853, 3rd order for RODAS.
    ///
    /// # Panics
    /// If `out.len()` differs from the dimension.
    pub fn dense_output<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        if self.on_rodas {
            self.ros_mut().dense_output(sys, t, out);
        } else {
            self.dop_mut().dense_output(sys, t, out);
        }
    }

    /// Single component of the dense output.
    ///
    /// # Panics
    /// If `i` is not below the dimension.
    pub fn dense_component<S: OdeSystem>(&mut self, sys: &mut S, i: usize, t: f64) -> f64 {
        if self.on_rodas {
            self.ros_mut().dense_component(sys, i, t)
        } else {
            self.dop_mut().dense_component(sys, i, t)
        }
    }

    /// Work counters of both integrators together.
    pub fn stats(&self) -> Stats {
        let d = self.dop853.as_ref().map(Dop853::stats).unwrap_or_default();
        let r = self.rodas.as_ref().map(Rodas::stats).unwrap_or_default();
        d + r
    }

    /// Sets the work counters of both integrators to zero.
    pub fn reset_stats(&mut self) {
        if let Some(d) = self.dop853.as_mut() {
            d.reset_stats();
        }
        if let Some(r) = self.rodas.as_mut() {
            r.reset_stats();
        }
    }

    /// The options the stepper was created with.
    pub fn options(&self) -> &IntegratorOptions {
        &self.opts
    }

    /// Whether DOP853 is active and its stiffness test currently reports
    /// stiffness ([`Dop853::stiffness_detected`]); `false` while RODAS is
    /// active.
    pub fn stiffness_detected(&self) -> bool {
        !self.on_rodas && self.dop().stiffness_detected()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y' = −λ (y − cos t), with analytic Jacobian.
    struct StiffLinear(f64);
    impl OdeSystem for StiffLinear {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -self.0 * (y[0] - t.cos());
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
            jac.set(0, 0, -self.0);
            true
        }
    }
    fn stiff_exact(lambda: f64, t: f64) -> f64 {
        let a = lambda * lambda / (1.0 + lambda * lambda);
        let b = lambda / (1.0 + lambda * lambda);
        a * t.cos() + b * t.sin() - a * (-lambda * t).exp()
    }

    /// Harmonic oscillator (non-stiff).
    struct Harmonic;
    impl OdeSystem for Harmonic {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[1];
            d[1] = -y[0];
        }
    }

    fn tol(tol: f64) -> IntegratorOptions {
        IntegratorOptions {
            rtol: tol,
            atol: tol,
            ..Default::default()
        }
    }

    fn run_to<S: OdeSystem>(st: &mut Stepper, sys: &mut S, t_end: f64) {
        while st.t() < t_end {
            st.step(sys, t_end).unwrap();
        }
    }

    #[test]
    fn auto_switches_to_rodas_on_stiff_problem() {
        // y' = −1e6 (y − cos t), y(0) = 0, over [0, 10] at tol 1e-8:
        // DOP853 alone needs ~1.56 million steps; Auto detects stiffness
        // after a few dozen DOP853 steps and finishes with RODAS.
        let lambda = 1e6;
        let mut sys = StiffLinear(lambda);
        let mut st = Stepper::new(Method::Auto, 1, tol(1e-8)).unwrap();
        assert_eq!(st.method(), Method::Auto);
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
        let mut switched_at = None;
        while st.t() < 10.0 {
            st.step(&mut sys, 10.0).unwrap();
            if switched_at.is_none() && st.active() == Method::Rodas {
                switched_at = Some(st.t_prev());
            }
        }
        let stats = st.stats();
        let err = (st.y()[0] - stiff_exact(lambda, 10.0)).abs();
        // Measured: switch after 34 DOP853 steps (t = 1.4e-4), then 80 RODAS
        // steps; 114 steps, 25 rejected, error 1.0e-9.
        assert!(switched_at.is_some());
        assert!(!st.stiffness_detected(), "false while RODAS is active");
        assert!(err < 1e-7, "error {err:e}");
        assert!(stats.steps < 500, "{stats:?}");
        assert!(stats.jacobian_evaluations > 0 && stats.lu_decompositions > 0);
        // Dense output works across the switch.
        let tm = 0.5 * (st.t_prev() + st.t());
        let v = st.dense_component(&mut sys, 0, tm);
        assert!((v - stiff_exact(lambda, tm)).abs() < 1e-6);
        // reset() starts with DOP853 again.
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
        st.reset_stats();
        assert_eq!(st.stats(), Stats::default());
    }

    #[test]
    fn auto_stays_on_dop853_for_non_stiff_problem() {
        let mut st = Stepper::new(Method::Auto, 2, tol(1e-9)).unwrap();
        let mut d = Dop853::new(2, tol(1e-9)).unwrap();
        st.reset(&mut Harmonic, 0.0, &[1.0, 0.0]).unwrap();
        d.reset(&mut Harmonic, 0.0, &[1.0, 0.0]).unwrap();
        run_to(&mut st, &mut Harmonic, 50.0);
        while d.t() < 50.0 {
            d.step(&mut Harmonic, 50.0).unwrap();
        }
        assert_eq!(st.active(), Method::Dop853);
        assert_eq!(st.y(), d.y(), "identical to plain DOP853");
        assert_eq!(st.stats(), d.stats());
        assert_eq!(st.dydt(), d.dydt());
        assert_eq!(st.h_next(), d.h_next());
    }

    #[test]
    fn fixed_methods_and_manual_switch() {
        // Method::Rodas behaves exactly like a standalone Rodas.
        let lambda = 1e6;
        let mut sys = StiffLinear(lambda);
        let mut st = Stepper::new(Method::Rodas, 1, tol(1e-6)).unwrap();
        let mut r = Rodas::new(1, tol(1e-6)).unwrap();
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        r.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Rodas);
        run_to(&mut st, &mut sys, 1.0);
        while r.t() < 1.0 {
            r.step(&mut sys, 1.0).unwrap();
        }
        assert_eq!(st.y(), r.y());
        assert_eq!(st.stats(), r.stats());
        assert_eq!(st.t_prev(), r.t_prev());
        let mut out = [0.0];
        st.dense_output(&mut sys, 0.5 * (st.t() + st.t_prev()), &mut out);
        assert_eq!(
            out[0],
            r.dense_component(&mut sys, 0, 0.5 * (r.t() + r.t_prev()))
        );

        // Method::Dop853 never switches by itself, but can be switched.
        let mut st = Stepper::new(Method::Dop853, 1, tol(1e-6)).unwrap();
        assert!(matches!(
            st.switch_to_rodas(&mut sys),
            Err(IntegrationError::InvalidOptions(_))
        ));
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        for _ in 0..200 {
            st.step(&mut sys, 1.0).unwrap();
        }
        assert!(st.stiffness_detected());
        assert_eq!(st.active(), Method::Dop853);
        let (t, y) = (st.t(), st.y()[0]);
        st.switch_to_rodas(&mut sys).unwrap();
        assert_eq!(st.active(), Method::Rodas);
        assert_eq!(
            (st.t(), st.y()[0]),
            (t, y),
            "restarted at the current point"
        );
        st.switch_to_rodas(&mut sys).unwrap();
        run_to(&mut st, &mut sys, 1.0);
        assert!((st.y()[0] - stiff_exact(lambda, 1.0)).abs() < 1e-5);
        assert_eq!(st.options().rtol, 1e-6);
        st.reset(&mut sys, 0.0, &[0.0]).unwrap();
        assert_eq!(st.active(), Method::Dop853);
    }

    #[test]
    fn stats_add_field_wise() {
        let a = Stats {
            rhs_evaluations: 1,
            steps: 2,
            rejected_steps: 3,
            jacobian_evaluations: 4,
            lu_decompositions: 5,
        };
        let b = a + a;
        assert_eq!(
            b,
            Stats {
                rhs_evaluations: 2,
                steps: 4,
                rejected_steps: 6,
                jacobian_evaluations: 8,
                lu_decompositions: 10,
            }
        );
    }
}
