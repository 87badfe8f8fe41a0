//! The L-stable, stiffly accurate Rosenbrock method RODAS of order 4 with an
//! embedded method of order 3 and a continuous extension of order 3, after
//! E. Hairer's and G. Wanner's Fortran code `rodas.f` (Hairer & Wanner,
//! *Solving Ordinary Differential Equations II. Stiff and
//! Differential-Algebraic Problems*, 2nd ed., Springer 1996, Sec. IV.7 and
//! VI.3, as cited by `rodas.f`; `γ = 1/4`; often called RODAS4, e.g. in
//! DifferentialEquations.jl).
//!
//! Coefficients: `rodas.f`, subroutine `ROCOE`, `METH = 1` (the default), in
//! Hairer's transformed variables `U_i = Σ_j γ_ij k_j`, digits copied
//! verbatim (trailing zeros dropped). The test
//! `tableau_order_conditions` converts them back to `(α_ij, γ_ij, b_i)` and
//! checks the Rosenbrock order conditions: order 4 for the solution, 3 for
//! the embedded one (residuals ~1e-16).
//!
//! # One step
//!
//! With `J = ∂f/∂y(t, y)`, `f_t = ∂f/∂t(t, y)` and `E = I/(hγ) − J`
//! (factored once per attempt), the six stages solve
//!
//! ```text
//! E·U_i = f(t + c_i·h, y + Σ_{j<i} a_ij U_j) + Σ_{j<i} (c_ij/h)·U_j + h·d_i·f_t
//! ```
//!
//! (`d_5 = d_6 = 0`; stage 6 is evaluated at the embedded solution
//! `ŷ = y + Σ_j a_5j U_j + U_5`), the new state is `y_new = ŷ + U_6` and `U_6`
//! is the error estimate (stiffly accurate pair: both solutions are stage
//! values). Dense output: `y(t_prev + s·h) = (1−s)·y_prev + s·(y_new +
//! (1−s)·(Σ d2_j U_j + s·Σ d3_j U_j))`, Hairer's `CONTRO`.
//!
//! # Algorithmic choices
//!
//! * **Error norm** as for [`Dop853`](super::Dop853): weighted RMS of `U_6`
//!   over the error-controlled components, accepted when `<= 1`.
//! * **Step-size controller** (`rodas.f` defaults): `h_new = h/fac`,
//!   `fac = clamp(err^(1/4)/0.9, 1/6, 5)`, combined with Gustafsson's
//!   predictive controller after the first accepted step (the smaller of
//!   the two proposed steps is taken). After a rejection the accepted step does
//!   not propose a larger step. Initial step: `h_init`, else Hairer's `HINIT`
//!   estimate for order 4 (one extra evaluation of `f`).
//! * **Jacobian**: once per step at its start point (reused by rejected
//!   attempts): [`OdeSystem::jacobian`] if it returns `true`, else forward
//!   differences with increments `δ_j = sqrt(ε·max(1e-5, |y_j|))`
//!   (`rodas.f`), columns grouped after Curtis, Powell & Reid: with
//!   bandwidths `(kl, ku)` the columns `j ≡ g (mod kl + ku + 1)` do not share
//!   rows, so `min(n, kl + ku + 1)` evaluations of `f` give the whole
//!   Jacobian. If a perturbed evaluation is not finite, the group is retried
//!   with `−δ`.
//! * **Time derivative** `f_t`: always by a forward difference with
//!   `δ = sqrt(ε·max(1e-5, |t|))` (`rodas.f`), one evaluation of `f` per
//!   step; a backward difference if the forward one is not finite. For an
//!   autonomous system this yields exactly zero.
//! * **Robustness** (as in [`Dop853`](super::Dop853)): a non-finite stage,
//!   state, `f` at the new state or error estimate, or a non-admissible new
//!   state, rejects the attempt and retries with `h/4`; a singular (or
//!   non-finite) iteration matrix retries with `h/2` (`rodas.f`), reported as
//!   [`RejectReason::NonFinite`]. Step-size floor, `t_bound` handling (1 %
//!   stretch) and [`IntegrationError::StepSizeUnderflow`] as in DOP853.
//! * **Evaluation count**: `f(t0, y0)` on reset (+1 for `HINIT`); per step
//!   the Jacobian (`0` evaluations if analytic, else the number of column
//!   groups) and `f_t` (1); per attempt 5 stages (fewer if stopped early);
//!   `f(t + h, y_new)` once the error test passed (the first stage of the
//!   next step). Dense output is free.
//!
//! All buffers, including the two band matrices, are allocated by
//! [`Rodas::with_bandwidth`]; [`Rodas::new`] defers the matrices to the first
//! [`Rodas::reset`], where they are shaped by
//! [`OdeSystem::jacobian_bandwidth`] (and reallocated only if a later system
//! has a different shape). Stepping and dense output do not allocate.

use super::linalg::BandMatrix;
use super::{IntegrationError, IntegratorOptions, OdeSystem, RejectReason, Stats};

/// Diagonal `γ` of the method.
const GAMMA: f64 = 0.25;
/// Nodes `c_2 … c_5` (`c_1 = 0`, `c_5 = c_6 = 1`).
const NODES: [f64; 4] = [0.386, 0.21, 0.63, 1.0];
/// `d_1 … d_4` (`γ_i = Σ_j γ_ij`, the coefficients of `h·f_t`; `d_5 = d_6 = 0`).
const D: [f64; 4] = [0.25, -0.1043, 0.1035, -0.03620000000000023];
/// `a_ij` of stages 2 … 5 (row `i − 2`, column `j − 1`).
const A: [[f64; 4]; 4] = [
    [1.544, 0.0, 0.0, 0.0],
    [0.9466785280815826, 0.2557011698983284, 0.0, 0.0],
    [
        3.314825187068521,
        2.896124015972201,
        0.9986419139977817,
        0.0,
    ],
    [
        1.221224509226641,
        6.019134481288629,
        12.53708332932087,
        -0.687886036105895,
    ],
];
/// `c_ij` of stages 2 … 6 (row `i − 2`, column `j − 1`).
const CC: [[f64; 5]; 5] = [
    [-5.6688, 0.0, 0.0, 0.0, 0.0],
    [-2.430093356833875, -0.2063599157091915, 0.0, 0.0, 0.0],
    [
        -0.1073529058151375,
        -9.594562251023355,
        -20.47028614809616,
        0.0,
        0.0,
    ],
    [
        7.496443313967647,
        -10.24680431464352,
        -33.99990352819905,
        11.7089089320616,
        0.0,
    ],
    [
        8.083246795921522,
        -7.981132988064893,
        -31.52159432874371,
        16.31930543123136,
        -6.058818238834054,
    ],
];
/// Dense output, `d2_j` (`D21 … D25`).
const D2: [f64; 5] = [
    10.12623508344586,
    -7.487995877610167,
    -34.80091861555747,
    -7.992771707568823,
    1.025137723295662,
];
/// Dense output, `d3_j` (`D31 … D35`).
const D3: [f64; 5] = [
    -0.6762803392801253,
    6.087714651680015,
    16.43084320892478,
    24.76722511418386,
    -6.594389125716872,
];
/// Number of stages.
const N_STAGES: usize = 6;

/// Safety factor of the step-size prediction.
const SAFETY: f64 = 0.9;
/// Smallest `h_old / h_new` (growth at most 6).
const FAC_GROW: f64 = 1.0 / 6.0;
/// Largest `h_old / h_new` (shrink at most to 1/5).
const FAC_SHRINK: f64 = 5.0;
/// Exponent of the step-size controller, `1/(q + 1)` with `q = 3`.
const ERROR_EXPONENT: f64 = 0.25;
/// Factor applied to `h` after a non-finite or non-admissible attempt.
const SHRINK_HARD: f64 = 0.25;
/// Factor applied to `h` after a singular iteration matrix.
const SHRINK_SINGULAR: f64 = 0.5;
/// Relative step-size floor: `h >= MIN_STEP_REL · |t|`.
const MIN_STEP_REL: f64 = 16.0 * f64::EPSILON;
/// A step is stretched by up to this factor to hit `t_bound` exactly.
const STRETCH: f64 = 1.01;

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Finite-difference increment `sqrt(ε·max(1e-5, |x|))` (`rodas.f`).
fn fd_increment(x: f64) -> f64 {
    (f64::EPSILON * x.abs().max(1e-5)).sqrt()
}

/// `out += Σ_j w[j] · u_j` over the stages `u_j = u[j*n..(j+1)*n]`,
/// skipping zero weights.
fn accumulate(out: &mut [f64], u: &[f64], w: &[f64]) {
    let n = out.len();
    for (&c, uj) in w.iter().zip(u.chunks_exact(n)) {
        if c != 0.0 {
            for (o, &v) in out.iter_mut().zip(uj) {
                *o += c * v;
            }
        }
    }
}

/// Adaptive Rosenbrock integrator RODAS (order 4(3), L-stable, stiffly
/// accurate) with 3rd-order dense output, for stiff systems.
///
/// Same interface and semantics as [`Dop853`](super::Dop853):
/// [`new`](Self::new) once, [`reset`](Self::reset) at an initial point (again
/// after every discontinuity), then [`step`](Self::step) repeatedly; after
/// each accepted step [`dense_output`](Self::dense_output) /
/// [`dense_component`](Self::dense_component) interpolate inside
/// `[t_prev(), t()]`. If `step` fails, the integrator keeps the last accepted
/// point and its dense output.
#[derive(Clone, Debug)]
pub struct Rodas {
    opts: IntegratorOptions,
    /// Dimension of the system.
    n: usize,
    /// Number of leading components entering the error norm.
    n_err: usize,
    /// Whether `reset` succeeded since construction or the last failed reset.
    initialised: bool,
    /// Whether a step has been accepted since the last reset.
    has_step: bool,
    /// Whether `jac` and `f_t` belong to the current point `(t, y)`.
    jac_current: bool,
    t: f64,
    t_prev: f64,
    /// Step size actually used by the last accepted step.
    h_last: f64,
    h_next: f64,
    /// Gustafsson controller: step size and error (`>= 0.01`) of the last
    /// accepted step.
    h_acc: f64,
    err_acc: f64,
    steps_since_reset: u64,
    stats: Stats,
    y: Vec<f64>,
    dydt: Vec<f64>,
    /// State at `t_prev`.
    y_prev: Vec<f64>,
    /// Candidate state of the current attempt.
    y_new: Vec<f64>,
    /// Argument of the stage being evaluated (also the perturbed state of
    /// finite differences).
    y_stage: Vec<f64>,
    /// `f` at `y_stage` (after an accepted attempt: `f(t_new, y_new)`).
    f_stage: Vec<f64>,
    /// Right-hand side / solution of the linear systems (also the increments
    /// of finite differences).
    work: Vec<f64>,
    /// `∂f/∂t` at the current point.
    f_t: Vec<f64>,
    /// Stages `U_1 … U_6`, stage `s` at `u[s*n..(s+1)*n]`.
    u: Vec<f64>,
    /// Dense-output coefficients `Σ d2_j U_j`, `Σ d3_j U_j` of the last
    /// accepted step.
    cont2: Vec<f64>,
    cont3: Vec<f64>,
    /// Jacobian at the current point.
    jac: BandMatrix,
    /// Iteration matrix `I/(hγ) − J` and its LU factors.
    lu: BandMatrix,
}

impl Rodas {
    /// Creates an integrator for systems of dimension `dim` with options
    /// `opts`, allocating all work buffers except the Jacobian and iteration
    /// matrices (shaped at the first [`reset`](Self::reset)). Fails with
    /// [`IntegrationError::InvalidOptions`] if the options are invalid or
    /// `dim == 0`.
    pub fn new(dim: usize, opts: IntegratorOptions) -> Result<Self, IntegrationError> {
        Self::with_matrices(dim, opts, BandMatrix::new(0, 0, 0))
    }

    /// As [`new`](Self::new), but also allocates the Jacobian and iteration
    /// matrices for Jacobian bandwidths `bandwidth` (`None`: dense), so that
    /// a [`reset`](Self::reset) with a system of that
    /// [`jacobian_bandwidth`](OdeSystem::jacobian_bandwidth) does not
    /// allocate.
    pub fn with_bandwidth(
        dim: usize,
        opts: IntegratorOptions,
        bandwidth: Option<(usize, usize)>,
    ) -> Result<Self, IntegrationError> {
        let (kl, ku) = bandwidth.unwrap_or((dim, dim));
        Self::with_matrices(dim, opts, BandMatrix::new(dim, kl, ku))
    }

    fn with_matrices(
        dim: usize,
        opts: IntegratorOptions,
        jac: BandMatrix,
    ) -> Result<Self, IntegrationError> {
        let n_err = opts.validate(dim)?;
        Ok(Self {
            opts,
            n: dim,
            n_err,
            initialised: false,
            has_step: false,
            jac_current: false,
            t: 0.0,
            t_prev: 0.0,
            h_last: 0.0,
            h_next: 0.0,
            h_acc: 0.0,
            err_acc: 1.0,
            steps_since_reset: 0,
            stats: Stats::default(),
            y: vec![0.0; dim],
            dydt: vec![0.0; dim],
            y_prev: vec![0.0; dim],
            y_new: vec![0.0; dim],
            y_stage: vec![0.0; dim],
            f_stage: vec![0.0; dim],
            work: vec![0.0; dim],
            f_t: vec![0.0; dim],
            u: vec![0.0; N_STAGES * dim],
            cont2: vec![0.0; dim],
            cont3: vec![0.0; dim],
            lu: jac.clone(),
            jac,
        })
    }

    /// Start (or restart, e.g. after a discontinuity) at `(t0, y0)`:
    /// evaluates `f(t0, y0)`, shapes the matrices after
    /// [`OdeSystem::jacobian_bandwidth`] and chooses the initial step
    /// (`min(h_init, h_max)` if given, else `HINIT`, one more evaluation of
    /// `f`). Statistics are not reset; the step counter for
    /// [`IntegratorOptions::max_steps`] is.
    ///
    /// Errors as [`Dop853::reset`](super::Dop853::reset):
    /// [`IntegrationError::InvalidOptions`] for a dimension mismatch or
    /// non-finite `t0`, [`IntegrationError::NonFiniteInitialState`] if `y0`
    /// or `f(t0, y0)` is not finite; after an error, stepping is refused
    /// until a successful reset.
    pub fn reset<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), IntegrationError> {
        self.reset_with_step(sys, t0, y0, self.opts.h_init)
    }

    /// [`reset`](Self::reset) with the initial step `h0` instead of the
    /// option `h_init` (`None`: `HINIT`).
    pub(super) fn reset_with_step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        h0: Option<f64>,
    ) -> Result<(), IntegrationError> {
        self.initialised = false;
        self.has_step = false;
        self.jac_current = false;
        self.check_dim(sys)?;
        if y0.len() != self.n {
            return Err(IntegrationError::InvalidOptions(format!(
                "initial state has {} components, the integrator {}",
                y0.len(),
                self.n
            )));
        }
        if !t0.is_finite() {
            return Err(IntegrationError::InvalidOptions(format!(
                "initial time must be finite, got {t0}"
            )));
        }
        if !all_finite(y0) {
            return Err(IntegrationError::NonFiniteInitialState { t: t0 });
        }
        let n = self.n;
        let (kl, ku) = sys.jacobian_bandwidth().unwrap_or((n, n));
        let bw = (kl.min(n - 1), ku.min(n - 1));
        if self.jac.n() != n || self.jac.bandwidths() != bw {
            self.jac = BandMatrix::new(n, bw.0, bw.1);
            self.lu = self.jac.clone();
        }
        self.y.copy_from_slice(y0);
        self.y_prev.copy_from_slice(y0);
        sys.rhs(t0, &self.y, &mut self.dydt);
        self.stats.rhs_evaluations += 1;
        if !all_finite(&self.dydt) {
            return Err(IntegrationError::NonFiniteInitialState { t: t0 });
        }
        self.t = t0;
        self.t_prev = t0;
        self.h_last = 0.0;
        self.h_acc = 0.0;
        self.err_acc = 1.0;
        self.steps_since_reset = 0;
        self.h_next = match h0 {
            Some(h) if h > 0.0 && h.is_finite() => h.min(self.opts.h_max),
            _ => self.initial_step(sys),
        };
        self.initialised = true;
        Ok(())
    }

    /// Take ONE accepted step (internally retrying rejected attempts), never
    /// stepping past `t_bound` (> current t); same semantics and errors as
    /// [`Dop853::step`](super::Dop853::step). The Jacobian is evaluated once
    /// per step, at its start point.
    pub fn step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t_bound: f64,
    ) -> Result<(), IntegrationError> {
        if !self.initialised {
            return Err(IntegrationError::InvalidOptions(
                "step() called before a successful reset()".into(),
            ));
        }
        self.check_dim(sys)?;
        if t_bound.is_nan() || t_bound <= self.t {
            return Err(IntegrationError::InvalidOptions(format!(
                "t_bound = {t_bound} must be greater than t = {}",
                self.t
            )));
        }
        if self.steps_since_reset >= self.opts.max_steps {
            return Err(IntegrationError::TooManySteps {
                t: self.t,
                steps: self.steps_since_reset,
            });
        }
        if let Some(stop) = &self.opts.interrupt {
            stop.check(self.t)?;
        }
        if !self.jac_current {
            self.evaluate_jacobian(sys);
            self.jac_current = true;
        }
        let floor = self.opts.h_min.max(MIN_STEP_REL * self.t.abs());
        let h_planned = self.h_next.max(floor).min(self.opts.h_max);
        let mut h = h_planned;
        let mut rejected = false;
        loop {
            let clipped = self.t + STRETCH * h >= t_bound;
            let t_new = if clipped {
                h = t_bound - self.t;
                t_bound
            } else {
                self.t + h
            };
            match self.attempt(sys, h, t_new) {
                Ok(err) => {
                    let mut fac = (err.powf(ERROR_EXPONENT) / SAFETY).clamp(FAC_GROW, FAC_SHRINK);
                    if self.steps_since_reset > 0 {
                        // Gustafsson's predictive controller (rodas.f, PRED).
                        let gus = (self.h_acc / h)
                            * (err * err / self.err_acc).powf(ERROR_EXPONENT)
                            / SAFETY;
                        fac = fac.max(gus.clamp(FAC_GROW, FAC_SHRINK));
                    }
                    self.h_acc = h;
                    self.err_acc = err.max(1e-2);
                    let mut h_new = h / fac;
                    if rejected {
                        h_new = h_new.min(h);
                    } else if clipped {
                        h_new = h_new.max(h_planned);
                    }
                    self.accept(t_new, h, h_new.min(self.opts.h_max));
                    return Ok(());
                }
                Err((reason, factor)) => {
                    self.stats.rejected_steps += 1;
                    rejected = true;
                    let h_new = h * factor;
                    if h_new < floor || self.t + h_new <= self.t {
                        return Err(IntegrationError::StepSizeUnderflow {
                            t: self.t,
                            h: h_new,
                            y: self.y.clone(),
                            reason,
                        });
                    }
                    h = h_new;
                }
            }
        }
    }

    /// Time after the last accepted step (the initial time right after
    /// [`reset`](Self::reset)).
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Time before the last accepted step (equal to [`t`](Self::t) right
    /// after [`reset`](Self::reset)).
    pub fn t_prev(&self) -> f64 {
        self.t_prev
    }

    /// State at [`t`](Self::t).
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// `f(t, y)` at the current point (the first stage of the next step).
    pub fn dydt(&self) -> &[f64] {
        &self.dydt
    }

    /// Step size proposed for the next step (before limiting it by the
    /// `t_bound` of the next [`step`](Self::step) call).
    pub fn h_next(&self) -> f64 {
        self.h_next
    }

    /// Caps the size of the next step at `h` (> 0); not remembered after it
    /// (see [`Dop853::limit_next_step`](super::Dop853::limit_next_step)).
    pub fn limit_next_step(&mut self, h: f64) {
        if h > 0.0 && h < self.h_next {
            self.h_next = h;
        }
    }

    /// Dense output of the last accepted step (3rd order, `rodas.f`'s
    /// `CONTRO`), valid for t in `[t_prev, t]`; writes all components.
    ///
    /// Same signature and end-point behaviour as
    /// [`Dop853::dense_output`](super::Dop853::dense_output); the
    /// coefficients are computed when the step is accepted, so the system is
    /// not evaluated (`sys` is unused). Outside `[t_prev, t]` the
    /// polynomial is extrapolated; before the first step after a reset the
    /// output is the current state.
    ///
    /// # Panics
    /// If `out.len()` differs from the dimension.
    pub fn dense_output<S: OdeSystem>(&mut self, _sys: &mut S, t: f64, out: &mut [f64]) {
        assert_eq!(out.len(), self.n, "dense_output: wrong output length");
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.interpolate(i, t);
        }
    }

    /// Single component of the dense output; same semantics as
    /// [`dense_output`](Self::dense_output).
    ///
    /// # Panics
    /// If `i` is not below the dimension.
    pub fn dense_component<S: OdeSystem>(&mut self, _sys: &mut S, i: usize, t: f64) -> f64 {
        assert!(i < self.n, "dense_component: index {i} out of range");
        self.interpolate(i, t)
    }

    /// Work counters accumulated since construction or the last
    /// [`reset_stats`](Self::reset_stats).
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Sets all work counters to zero.
    pub fn reset_stats(&mut self) {
        self.stats = Stats::default();
    }

    /// The options the integrator was created with.
    pub fn options(&self) -> &IntegratorOptions {
        &self.opts
    }

    fn interpolate(&self, i: usize, t: f64) -> f64 {
        if !self.has_step || t == self.t {
            self.y[i]
        } else if t == self.t_prev {
            self.y_prev[i]
        } else {
            let s = (t - self.t_prev) / self.h_last;
            let s1 = 1.0 - s;
            s1 * self.y_prev[i] + s * (self.y[i] + s1 * (self.cont2[i] + s * self.cont3[i]))
        }
    }

    fn check_dim<S: OdeSystem>(&self, sys: &S) -> Result<(), IntegrationError> {
        if sys.dim() == self.n {
            Ok(())
        } else {
            Err(IntegrationError::InvalidOptions(format!(
                "system dimension {} differs from the integrator's {}",
                sys.dim(),
                self.n
            )))
        }
    }

    /// Error weight `atol + rtol · max(|a|, |b|)`.
    fn weight(&self, a: f64, b: f64) -> f64 {
        self.opts.atol + self.opts.rtol * a.abs().max(b.abs())
    }

    /// Hairer's `HINIT` for a method of order 4 (see
    /// [`Dop853`](super::Dop853)'s): one evaluation of `f` after an explicit
    /// Euler step; a non-finite result returns the Euler guess itself.
    fn initial_step<S: OdeSystem>(&mut self, sys: &mut S) -> f64 {
        let h_max = self.opts.h_max;
        let (mut dnf, mut dny) = (0.0, 0.0);
        for i in 0..self.n_err {
            let sk = self.weight(self.y[i], 0.0);
            dnf += (self.dydt[i] / sk).powi(2);
            dny += (self.y[i] / sk).powi(2);
        }
        let mut h = if dnf <= 1e-10 || dny <= 1e-10 {
            1e-6
        } else {
            0.01 * (dny / dnf).sqrt()
        };
        h = h.min(h_max);
        if !h.is_finite() {
            h = 1e-6_f64.min(h_max);
        }
        for ((ys, &y), &f) in self.y_stage.iter_mut().zip(&self.y).zip(&self.dydt) {
            *ys = y + h * f;
        }
        sys.rhs(self.t + h, &self.y_stage, &mut self.f_stage);
        self.stats.rhs_evaluations += 1;
        let mut der2 = 0.0;
        for i in 0..self.n_err {
            let sk = self.weight(self.y[i], 0.0);
            der2 += ((self.f_stage[i] - self.dydt[i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        if !der2.is_finite() {
            return h;
        }
        let der12 = der2.max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(ERROR_EXPONENT)
        };
        (100.0 * h).min(h1).min(h_max)
    }

    /// Jacobian `J` (analytic or banded finite differences) and `f_t` at the
    /// current point `(t, y)`, with `f(t, y) = dydt`.
    fn evaluate_jacobian<S: OdeSystem>(&mut self, sys: &mut S) {
        self.stats.jacobian_evaluations += 1;
        self.jac.zero();
        if !sys.jacobian(self.t, &self.y, &mut self.jac) {
            self.jac.zero();
            self.fd_jacobian(sys);
        }
        // ∂f/∂t: forward difference, backward if that is not finite.
        let t = self.t;
        for sign in [1.0, -1.0] {
            let tp = t + sign * fd_increment(t);
            let delta = tp - t;
            sys.rhs(tp, &self.y, &mut self.f_stage);
            self.stats.rhs_evaluations += 1;
            for ((ft, &fp), &f0) in self.f_t.iter_mut().zip(&self.f_stage).zip(&self.dydt) {
                *ft = (fp - f0) / delta;
            }
            if all_finite(&self.f_t) {
                break;
            }
        }
    }

    /// Finite-difference Jacobian with Curtis–Powell–Reid column groups:
    /// `min(n, kl + ku + 1)` evaluations of `f` (twice for a group whose
    /// forward difference is not finite).
    fn fd_jacobian<S: OdeSystem>(&mut self, sys: &mut S) {
        let n = self.n;
        let (kl, ku) = self.jac.bandwidths();
        let width = (kl + ku + 1).min(n);
        for g in 0..width {
            for sign in [1.0, -1.0] {
                self.y_stage.copy_from_slice(&self.y);
                for j in (g..n).step_by(width) {
                    let yj = self.y[j];
                    let yp = yj + sign * fd_increment(yj);
                    self.y_stage[j] = yp;
                    self.work[j] = yp - yj;
                }
                sys.rhs(self.t, &self.y_stage, &mut self.f_stage);
                self.stats.rhs_evaluations += 1;
                let mut finite = true;
                for j in (g..n).step_by(width) {
                    for i in j.saturating_sub(ku)..=(j + kl).min(n - 1) {
                        let d = (self.f_stage[i] - self.dydt[i]) / self.work[j];
                        finite &= d.is_finite();
                        self.jac.set(i, j, d);
                    }
                }
                if finite {
                    break;
                }
            }
        }
    }

    /// Solves `E·x = work` in place (`work` becomes `x`) and stores it as
    /// stage `s`; returns whether it is finite.
    fn solve_stage(&mut self, s: usize) -> bool {
        let n = self.n;
        self.lu.solve(&mut self.work);
        self.u[s * n..(s + 1) * n].copy_from_slice(&self.work);
        all_finite(&self.work)
    }

    /// `work = f_stage + Σ_{j<s} (cc[j]/h)·U_j + h·d·f_t`, the right-hand
    /// side of stage `s` (0-based).
    fn stage_rhs(&mut self, s: usize, cc: &[f64], h: f64, d: f64) {
        let n = self.n;
        self.work.copy_from_slice(&self.f_stage);
        for (j, &c) in cc.iter().enumerate().take(s) {
            let w = c / h;
            for (x, &v) in self.work.iter_mut().zip(&self.u[j * n..(j + 1) * n]) {
                *x += w * v;
            }
        }
        if d != 0.0 {
            for (x, &ft) in self.work.iter_mut().zip(&self.f_t) {
                *x += h * d * ft;
            }
        }
    }

    /// One attempt of size `h` from the current point, ending at `t_new`.
    /// Returns the error norm (`<= 1`) if the attempt is acceptable (then
    /// `y_new`, the stages `u` and `f(t_new, y_new)` in `f_stage` are
    /// ready), else the reason and the factor for the next step size.
    fn attempt<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
    ) -> Result<f64, (RejectReason, f64)> {
        let n = self.n;
        let hard = (RejectReason::NonFinite, SHRINK_HARD);
        self.lu.assign_shifted(&self.jac, -1.0, 1.0 / (h * GAMMA));
        self.stats.lu_decompositions += 1;
        if self.lu.factor().is_err() {
            return Err((RejectReason::NonFinite, SHRINK_SINGULAR));
        }
        // Stage 1 at (t, y): f = dydt.
        self.f_stage.copy_from_slice(&self.dydt);
        self.stage_rhs(0, &[], h, D[0]);
        if !self.solve_stage(0) {
            return Err(hard);
        }
        // Stages 2 … 5.
        for s in 1..5 {
            self.y_stage.copy_from_slice(&self.y);
            accumulate(&mut self.y_stage, &self.u[..s * n], &A[s - 1][..s]);
            let ts = if s == 4 {
                t_new
            } else {
                self.t + NODES[s - 1] * h
            };
            sys.rhs(ts, &self.y_stage, &mut self.f_stage);
            self.stats.rhs_evaluations += 1;
            if !all_finite(&self.f_stage) {
                return Err(hard);
            }
            let d = if s < 4 { D[s] } else { 0.0 };
            self.stage_rhs(s, &CC[s - 1], h, d);
            if !self.solve_stage(s) {
                return Err(hard);
            }
        }
        // Embedded solution ŷ = (argument of stage 5) + U_5, stage 6 there.
        for (yn, (&ys, &u5)) in self
            .y_new
            .iter_mut()
            .zip(self.y_stage.iter().zip(&self.u[4 * n..5 * n]))
        {
            *yn = ys + u5;
        }
        sys.rhs(t_new, &self.y_new, &mut self.f_stage);
        self.stats.rhs_evaluations += 1;
        if !all_finite(&self.f_stage) {
            return Err(hard);
        }
        self.stage_rhs(5, &CC[4], h, 0.0);
        if !self.solve_stage(5) {
            return Err(hard);
        }
        for (yn, &u6) in self.y_new.iter_mut().zip(&self.u[5 * n..]) {
            *yn += u6;
        }
        if !all_finite(&self.y_new) {
            return Err(hard);
        }
        if !sys.admissible(t_new, &self.y_new) {
            return Err((RejectReason::NotAdmissible, SHRINK_HARD));
        }
        let mut err = 0.0;
        for i in 0..self.n_err {
            let sk = self.weight(self.y[i], self.y_new[i]);
            err += (self.u[5 * n + i] / sk).powi(2);
        }
        let err = (err / self.n_err as f64).sqrt();
        if !err.is_finite() {
            return Err(hard);
        }
        if err > 1.0 {
            let fac = (err.powf(ERROR_EXPONENT) / SAFETY).clamp(FAC_GROW, FAC_SHRINK);
            return Err((RejectReason::ErrorEstimate, 1.0 / fac));
        }
        sys.rhs(t_new, &self.y_new, &mut self.f_stage);
        self.stats.rhs_evaluations += 1;
        if !all_finite(&self.f_stage) {
            return Err(hard);
        }
        Ok(err)
    }

    /// Commits the successful attempt and computes the dense-output
    /// coefficients from its stages.
    fn accept(&mut self, t_new: f64, h: f64, h_next: f64) {
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, &mut self.y_new);
        std::mem::swap(&mut self.dydt, &mut self.f_stage);
        self.cont2.fill(0.0);
        accumulate(&mut self.cont2, &self.u, &D2);
        self.cont3.fill(0.0);
        accumulate(&mut self.cont3, &self.u, &D3);
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.h_next = h_next;
        self.has_step = true;
        self.jac_current = false;
        self.steps_since_reset += 1;
        self.stats.steps += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::Dop853;
    use std::cell::Cell;

    // ---------------------------------------------------------------------
    // Test systems.
    // ---------------------------------------------------------------------

    /// Harmonic oscillator y1' = y2, y2' = -y1; from (1, 0): (cos t, -sin t).
    struct Harmonic {
        analytic: bool,
    }
    impl OdeSystem for Harmonic {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[1];
            d[1] = -y[0];
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
            if self.analytic {
                jac.set(0, 1, 1.0);
                jac.set(1, 0, -1.0);
            }
            self.analytic
        }
    }

    /// Nonlinear, non-autonomous, diagonal Jacobian: y1' = -2 t y1²,
    /// y2' = y2 cos t; from (1, 1): (1/(1+t²), exp(sin t)).
    struct Nonlinear {
        analytic: bool,
    }
    impl OdeSystem for Nonlinear {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -2.0 * t * y[0] * y[0];
            d[1] = y[1] * t.cos();
        }
        fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
            Some((0, 0))
        }
        fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
            if self.analytic {
                jac.set(0, 0, -4.0 * t * y[0]);
                jac.set(1, 1, t.cos());
            }
            self.analytic
        }
    }
    fn nonlinear_exact(t: f64) -> [f64; 2] {
        [1.0 / (1.0 + t * t), t.sin().exp()]
    }

    /// Van der Pol oscillator y1' = y2, y2' = μ (1 − y1²) y2 − y1.
    struct VanDerPol {
        mu: f64,
        analytic: bool,
    }
    impl OdeSystem for VanDerPol {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[1];
            d[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
        }
        fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
            if self.analytic {
                jac.set(0, 1, 1.0);
                jac.set(1, 0, -2.0 * self.mu * y[0] * y[1] - 1.0);
                jac.set(1, 1, self.mu * (1.0 - y[0] * y[0]));
            }
            self.analytic
        }
    }

    /// Stiff linear, non-autonomous: y' = −λ (y − cos t).
    struct StiffLinear {
        lambda: f64,
    }
    impl OdeSystem for StiffLinear {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -self.lambda * (y[0] - t.cos());
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
            jac.set(0, 0, -self.lambda);
            true
        }
    }
    /// Exact solution of [`StiffLinear`] from y(0) = y0.
    fn stiff_linear_exact(lambda: f64, y0: f64, t: f64) -> f64 {
        let a = lambda * lambda / (1.0 + lambda * lambda);
        let b = lambda / (1.0 + lambda * lambda);
        a * t.cos() + b * t.sin() + (y0 - a) * (-lambda * t).exp()
    }

    /// y' = −y with traps: `f` is NaN where y < `nan_below` or t >
    /// `nan_after`; states are admissible only in [`admissible_min`, ∞).
    struct Decay {
        nan_below: f64,
        nan_after: f64,
        admissible_min: f64,
        nan_returns: u64,
        inadmissible: Cell<u64>,
    }
    impl Decay {
        fn new() -> Self {
            Self {
                nan_below: f64::NEG_INFINITY,
                nan_after: f64::INFINITY,
                admissible_min: f64::NEG_INFINITY,
                nan_returns: 0,
                inadmissible: Cell::new(0),
            }
        }
    }
    impl OdeSystem for Decay {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            if y[0] < self.nan_below || t > self.nan_after {
                self.nan_returns += 1;
                d[0] = f64::NAN;
            } else {
                d[0] = -y[0];
            }
        }
        fn admissible(&self, _t: f64, y: &[f64]) -> bool {
            let ok = y[0] >= self.admissible_min;
            if !ok {
                self.inadmissible.set(self.inadmissible.get() + 1);
            }
            ok
        }
    }

    /// Nonlinear chain with a banded Jacobian (kl = 2, ku = 1):
    /// f_i = −y_i³ + ½ sin(y_{i−1}) y_{i−2} + exp(y_{i+1}/10) + cos t
    /// (terms with indices outside 0..n dropped).
    struct Chain {
        n: usize,
        banded: bool,
        analytic: bool,
    }
    impl OdeSystem for Chain {
        fn dim(&self) -> usize {
            self.n
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            let n = self.n;
            for i in 0..n {
                let mut v = -y[i].powi(3) + t.cos();
                if i >= 2 {
                    v += 0.5 * y[i - 1].sin() * y[i - 2];
                }
                if i + 1 < n {
                    v += (0.1 * y[i + 1]).exp();
                }
                d[i] = v;
            }
        }
        fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
            self.banded.then_some((2, 1))
        }
        fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
            if !self.analytic {
                return false;
            }
            let n = self.n;
            for i in 0..n {
                jac.set(i, i, -3.0 * y[i] * y[i]);
                if i >= 2 {
                    jac.set(i, i - 1, 0.5 * y[i - 1].cos() * y[i - 2]);
                    jac.set(i, i - 2, 0.5 * y[i - 1].sin());
                }
                if i + 1 < n {
                    jac.set(i, i + 1, 0.1 * (0.1 * y[i + 1]).exp());
                }
            }
            true
        }
    }

    /// Heat equation u_t = u_xx on (0, 1), u = 0 at both ends, central
    /// differences on `n` interior points (tridiagonal, stiff: eigenvalues
    /// down to ≈ −4(n+1)²).
    struct Heat {
        n: usize,
        analytic: bool,
    }
    impl Heat {
        fn inv_dx2(&self) -> f64 {
            ((self.n + 1) * (self.n + 1)) as f64
        }
        /// Exact solution from the first discrete eigenmode sin(π x_i).
        fn exact(&self, t: f64, out: &mut [f64]) {
            let dx = 1.0 / (self.n + 1) as f64;
            let lambda = -4.0 * self.inv_dx2() * (0.5 * std::f64::consts::PI * dx).sin().powi(2);
            for (i, o) in out.iter_mut().enumerate() {
                *o = (lambda * t).exp() * (std::f64::consts::PI * (i + 1) as f64 * dx).sin();
            }
        }
    }
    impl OdeSystem for Heat {
        fn dim(&self) -> usize {
            self.n
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            let n = self.n;
            let c = self.inv_dx2();
            for i in 0..n {
                let l = if i > 0 { y[i - 1] } else { 0.0 };
                let r = if i + 1 < n { y[i + 1] } else { 0.0 };
                d[i] = c * (l - 2.0 * y[i] + r);
            }
        }
        fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
            Some((1, 1))
        }
        fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
            if self.analytic {
                let c = self.inv_dx2();
                for i in 0..self.n {
                    jac.set(i, i, -2.0 * c);
                    if i > 0 {
                        jac.set(i, i - 1, c);
                        jac.set(i - 1, i, c);
                    }
                }
            }
            self.analytic
        }
    }

    /// Options for fixed steps `h`: every step accepted (huge tolerances),
    /// never grown (`h_max = h`).
    fn fixed(h: f64) -> IntegratorOptions {
        IntegratorOptions {
            rtol: 1e6,
            atol: 1e6,
            h_init: Some(h),
            h_max: h,
            ..Default::default()
        }
    }

    fn tol(tol: f64) -> IntegratorOptions {
        IntegratorOptions {
            rtol: tol,
            atol: tol,
            ..Default::default()
        }
    }

    fn observed_order(e_coarse: f64, e_fine: f64) -> f64 {
        (e_coarse / e_fine).log2()
    }

    /// Integrates with RODAS from (t0, y0) to t_end; final state and stats.
    fn run<S: OdeSystem>(
        sys: &mut S,
        t0: f64,
        y0: &[f64],
        t_end: f64,
        opts: IntegratorOptions,
    ) -> (Vec<f64>, Stats) {
        let mut s = Rodas::new(sys.dim(), opts).unwrap();
        s.reset(sys, t0, y0).unwrap();
        while s.t() < t_end {
            s.step(sys, t_end).unwrap();
        }
        assert_eq!(s.t(), t_end);
        (s.y().to_vec(), s.stats())
    }

    // ---------------------------------------------------------------------
    // 1. Tableau.
    // ---------------------------------------------------------------------

    #[test]
    // Small dense matrix algebra reads best with explicit indices.
    #[allow(clippy::needless_range_loop)]
    fn tableau_order_conditions() {
        // Back to Hairer–Wanner's standard form: Γ⁻¹ = diag(1/γ) − (c_ij),
        // α = (a_ij)·Γ, b = m·Γ with m = (a_51 … a_54, 1, 1) (stiffly
        // accurate: y_new is the argument of stage 6 plus U_6), embedded
        // m̂ = (a_51 … a_54, 1, 0).
        const S: usize = N_STAGES;
        let mut a = [[0.0; S]; S];
        let mut gi = [[0.0; S]; S];
        for i in 0..S {
            gi[i][i] = 1.0 / GAMMA;
            for j in 0..i {
                gi[i][j] = -CC[i - 1][j];
                if i < 5 {
                    a[i][j] = A[i - 1][j];
                } else if j < 4 {
                    a[i][j] = A[3][j];
                }
            }
        }
        a[5][4] = 1.0;
        // Γ = (Γ⁻¹)⁻¹ by forward substitution, column by column.
        let mut g = [[0.0; S]; S];
        for j in 0..S {
            for i in 0..S {
                let e = if i == j { 1.0 } else { 0.0 };
                let s: f64 = (0..i).map(|k| gi[i][k] * g[k][j]).sum();
                g[i][j] = (e - s) / gi[i][i];
            }
        }
        let mul = |x: &[[f64; S]; S], y: &[[f64; S]; S]| {
            let mut r = [[0.0; S]; S];
            for i in 0..S {
                for j in 0..S {
                    r[i][j] = (0..S).map(|k| x[i][k] * y[k][j]).sum();
                }
            }
            r
        };
        let alpha = mul(&a, &g);
        let mut beta = alpha;
        for i in 0..S {
            for j in 0..i {
                beta[i][j] += g[i][j];
            }
        }
        let c: Vec<f64> = (0..S).map(|i| alpha[i].iter().sum()).collect();
        let bp: Vec<f64> = (0..S).map(|i| beta[i][..i].iter().sum()).collect();
        // Nodes and d_i = Σ_j γ_ij against the tabulated ones.
        let nodes = [0.0, NODES[0], NODES[1], NODES[2], NODES[3], 1.0];
        let d = [D[0], D[1], D[2], D[3], 0.0, 0.0];
        for i in 0..S {
            assert!((c[i] - nodes[i]).abs() < 1e-14, "c_{i}: {}", c[i]);
            let gs: f64 = g[i][..=i].iter().sum();
            assert!((gs - d[i]).abs() < 1e-14, "d_{i}: {gs}");
        }
        let gam = GAMMA;
        let residuals = |m: [f64; S]| {
            let b: Vec<f64> = (0..S)
                .map(|j| (0..S).map(|k| m[k] * g[k][j]).sum())
                .collect();
            let s1 = |f: &dyn Fn(usize) -> f64| (0..S).map(|i| b[i] * f(i)).sum::<f64>();
            let bb = |i: usize, v: &[f64]| (0..S).map(|j| beta[i][j] * v[j]).sum::<f64>();
            let c2: Vec<f64> = c.iter().map(|x| x * x).collect();
            let bbp: Vec<f64> = (0..S).map(|j| bb(j, &bp)).collect();
            let abp: Vec<f64> = (0..S)
                .map(|i| (0..S).map(|j| alpha[i][j] * bp[j]).sum())
                .collect();
            [
                s1(&|_| 1.0) - 1.0,
                s1(&|i| bp[i]) - (0.5 - gam),
                s1(&|i| c[i] * c[i]) - 1.0 / 3.0,
                s1(&|i| bbp[i]) - (1.0 / 6.0 - gam + gam * gam),
                s1(&|i| c[i].powi(3)) - 0.25,
                s1(&|i| c[i] * abp[i]) - (1.0 / 8.0 - gam / 3.0),
                s1(&|i| bb(i, &c2)) - (1.0 / 12.0 - gam / 3.0),
                s1(&|i| bb(i, &bbp)) - (1.0 / 24.0 - gam / 2.0 + 1.5 * gam * gam - gam.powi(3)),
            ]
        };
        let m = [A[3][0], A[3][1], A[3][2], A[3][3], 1.0, 1.0];
        let mut m_hat = m;
        m_hat[5] = 0.0;
        let r = residuals(m);
        let r_hat = residuals(m_hat);
        // Order 4 (all 8 conditions), measured |residual| <= 2.3e-16.
        for (k, x) in r.iter().enumerate() {
            assert!(x.abs() < 1e-13, "solution, condition {k}: {x:e}");
        }
        // Embedded: order 3 (first 4 conditions) and not 4 (measured
        // residuals 0.10, 0.034, −0.0039, −0.0048 for the order-4 ones).
        for (k, x) in r_hat.iter().enumerate().take(4) {
            assert!(x.abs() < 1e-13, "embedded, condition {k}: {x:e}");
        }
        assert!(r_hat[4].abs() > 1e-2);
    }

    // ---------------------------------------------------------------------
    // 2. Convergence order with fixed steps.
    // ---------------------------------------------------------------------

    #[test]
    fn convergence_order_is_4() {
        let hs = [0.5, 0.25, 0.125, 0.0625];
        for analytic in [true, false] {
            let errs: Vec<f64> = hs
                .iter()
                .map(|&h| {
                    let (y, st) = run(&mut Harmonic { analytic }, 0.0, &[1.0, 0.0], 10.0, fixed(h));
                    assert_eq!(st.rejected_steps, 0);
                    assert_eq!(st.steps, (10.0 / h).round() as u64);
                    (y[0] - 10f64.cos()).hypot(y[1] + 10f64.sin())
                })
                .collect();
            // Measured (analytic and FD Jacobian alike): 4.56e-4, 2.84e-5,
            // 1.77e-6, 1.11e-7, orders 4.00, 4.00, 4.00.
            for w in errs.windows(2) {
                let p = observed_order(w[0], w[1]);
                assert!((3.5..=4.5).contains(&p), "order {p} from {errs:?}");
            }
            // Non-autonomous (exercises the h·d_i·f_t terms): worst error
            // along [0, 5].
            let errs: Vec<f64> = [0.1, 0.05, 0.025, 0.0125]
                .iter()
                .map(|&h| {
                    let mut sys = Nonlinear { analytic };
                    let mut s = Rodas::new(2, fixed(h)).unwrap();
                    s.reset(&mut sys, 0.0, &[1.0, 1.0]).unwrap();
                    let mut worst = 0.0f64;
                    while s.t() < 5.0 {
                        s.step(&mut sys, 5.0).unwrap();
                        let ex = nonlinear_exact(s.t());
                        worst = worst.max((s.y()[0] - ex[0]).abs().max((s.y()[1] - ex[1]).abs()));
                    }
                    worst
                })
                .collect();
            // Measured: 1.52e-6, 7.32e-8, 3.95e-9, 2.29e-10, orders 4.37,
            // 4.21, 4.11 (approaching 4 from above).
            for w in errs.windows(2) {
                let p = observed_order(w[0], w[1]);
                assert!((3.5..=4.5).contains(&p), "order {p} from {errs:?}");
            }
        }
    }

    // ---------------------------------------------------------------------
    // 3. Dense output.
    // ---------------------------------------------------------------------

    #[test]
    fn dense_output_is_3rd_order() {
        // Fixed steps on the harmonic oscillator; at 1/4, 1/2, 3/4 of every
        // step compare with the exact solution through (t_prev, y_prev):
        // local interpolation error O(h^4) for a 3rd-order extension.
        let run_dense = |h: f64| {
            let mut sys = Harmonic { analytic: true };
            let mut s = Rodas::new(2, fixed(h)).unwrap();
            s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
            let mut worst = 0.0f64;
            let mut out = [0.0; 2];
            let mut prev = [1.0, 0.0];
            while s.t() < 10.0 {
                s.step(&mut sys, 10.0).unwrap();
                for q in [0.25, 0.5, 0.75] {
                    let tq = s.t_prev() + q * (s.t() - s.t_prev());
                    s.dense_output(&mut sys, tq, &mut out);
                    assert_eq!(s.dense_component(&mut sys, 1, tq), out[1]);
                    let dt = tq - s.t_prev();
                    let loc = [
                        prev[0] * dt.cos() + prev[1] * dt.sin(),
                        prev[1] * dt.cos() - prev[0] * dt.sin(),
                    ];
                    worst = worst.max((out[0] - loc[0]).abs().max((out[1] - loc[1]).abs()));
                }
                prev = [s.y()[0], s.y()[1]];
            }
            worst
        };
        // Measured: 3.39e-5, 2.21e-6, 1.39e-7, 8.74e-9 (orders 3.94, 3.99,
        // 4.00).
        let errs: Vec<f64> = [0.4, 0.2, 0.1, 0.05]
            .iter()
            .map(|&h| run_dense(h))
            .collect();
        for w in errs.windows(2) {
            let p = observed_order(w[0], w[1]);
            assert!((3.5..=4.5).contains(&p), "dense order {p} from {errs:?}");
        }
    }

    #[test]
    fn dense_output_adaptive_accuracy_and_end_points() {
        // Nonlinear problem at rtol = atol = 1e-8: dense output at 7 interior
        // points per step against the exact solution.
        let mut sys = Nonlinear { analytic: true };
        let mut s = Rodas::new(2, tol(1e-8)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 1.0]).unwrap();
        let mut out = [0.0; 2];
        s.dense_output(&mut sys, 0.0, &mut out);
        assert_eq!(out, [1.0, 1.0], "before the first step: current state");
        let (mut worst_dense, mut worst_end) = (0.0f64, 0.0f64);
        while s.t() < 10.0 {
            let y_prev = s.y().to_vec();
            s.step(&mut sys, 10.0).unwrap();
            s.dense_output(&mut sys, s.t_prev(), &mut out);
            assert_eq!(out.as_slice(), y_prev.as_slice());
            s.dense_output(&mut sys, s.t(), &mut out);
            assert_eq!(out, s.y());
            let ex = nonlinear_exact(s.t());
            worst_end = worst_end.max((s.y()[0] - ex[0]).abs().max((s.y()[1] - ex[1]).abs()));
            for j in 1..8 {
                let tt = s.t_prev() + (s.t() - s.t_prev()) * f64::from(j) / 8.0;
                s.dense_output(&mut sys, tt, &mut out);
                let ex = nonlinear_exact(tt);
                worst_dense = worst_dense.max((out[0] - ex[0]).abs().max((out[1] - ex[1]).abs()));
            }
        }
        // Measured: worst step-end error 4.2e-9, worst dense error 4.8e-8
        // (3rd-order interpolant), 372 steps.
        assert!(worst_end < 2e-8, "{worst_end:e}");
        assert!(worst_dense < 2e-7, "{worst_dense:e}");
    }

    // ---------------------------------------------------------------------
    // 4. Stiff problems.
    // ---------------------------------------------------------------------

    #[test]
    fn van_der_pol_stiff_against_dop853_reference() {
        // μ = 1000 over [0, 3000] from (2, 0): relaxation oscillations with
        // period ≈ 1614, fast jumps near t ≈ 807, 1614, 2421; t = 3000 lies
        // on a slow branch. Reference: DOP853 at rtol = atol = 1e-12.
        let t_end = 3000.0;
        let mut reference = VanDerPol {
            mu: 1000.0,
            analytic: false,
        };
        let mut d = Dop853::new(2, tol(1e-12)).unwrap();
        d.reset(&mut reference, 0.0, &[2.0, 0.0]).unwrap();
        while d.t() < t_end {
            d.step(&mut reference, t_end).unwrap();
        }
        let y_ref = d.y().to_vec();
        let dop_steps = d.stats().steps;
        // Measured: 879 241 DOP853 steps, the stiffness test has fired.
        assert!(d.stiffness_detected());
        assert!(dop_steps > 500_000, "{dop_steps}");
        // Measured (tol: rel. errors y1, y2; steps):
        // 1e-5: 6.6e-5, 1.7e-4, 516;  1e-7: 6.3e-7, 1.6e-6, 1605;
        // 1e-9: 5.8e-9, 1.5e-8, 5636;  1e-7 with FD Jacobian: the same
        // errors to 2 digits, 1605 steps.
        let mut last = f64::INFINITY;
        let mut steps_1e7 = 0;
        for (tl, analytic) in [(1e-5, true), (1e-7, true), (1e-9, true), (1e-7, false)] {
            let (y, st) = run(
                &mut VanDerPol {
                    mu: 1000.0,
                    analytic,
                },
                0.0,
                &[2.0, 0.0],
                t_end,
                tol(tl),
            );
            let e1 = ((y[0] - y_ref[0]) / y_ref[0]).abs();
            let e2 = ((y[1] - y_ref[1]) / y_ref[1]).abs();
            assert!(
                e1 < 30.0 * tl && e2 < 50.0 * tl,
                "tol {tl:e}: {e1:e}, {e2:e}"
            );
            assert!(st.steps * 100 < dop_steps, "tol {tl:e}: {st:?}");
            assert_eq!(st.jacobian_evaluations, st.steps);
            assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
            if analytic {
                assert!(e1 < 0.1 * last, "error must decrease with tol");
                last = e1;
                if tl == 1e-7 {
                    steps_1e7 = st.steps;
                }
            } else {
                // Same steps with finite differences (2 more f per step).
                assert_eq!(st.steps, steps_1e7);
            }
        }
    }

    #[test]
    fn stiff_linear_in_few_steps() {
        // y' = −1e6 (y − cos t), y(0) = 0 (initial layer of width 1e-6),
        // over [0, 10] at rtol = atol = 1e-6.
        let lambda = 1e6;
        let t_end = 10.0;
        let ex = stiff_linear_exact(lambda, 0.0, t_end);
        let (y, st) = run(&mut StiffLinear { lambda }, 0.0, &[0.0], t_end, tol(1e-6));
        let mut d = Dop853::new(1, tol(1e-6)).unwrap();
        let mut sys = StiffLinear { lambda };
        d.reset(&mut sys, 0.0, &[0.0]).unwrap();
        while d.t() < t_end {
            d.step(&mut sys, t_end).unwrap();
        }
        let sd = d.stats();
        // Measured: RODAS 46 steps (4 rejected), error 3.0e-7; DOP853
        // 1 564 058 steps, error 1.9e-8.
        assert!(
            (y[0] - ex).abs() < 1e-6,
            "RODAS error {:e}",
            (y[0] - ex).abs()
        );
        assert!(st.steps < 100, "{st:?}");
        assert!(st.steps * 10_000 < sd.steps, "{st:?} vs {sd:?}");
    }

    #[test]
    fn l_stable_and_stiffly_accurate() {
        // Single steps far outside any explicit stability region on
        // y' = −1e12 (y − cos t) from y = 1: an L-stable, stiffly accurate
        // method (R(∞) = 0) lands on the slow solution.
        let lambda = 1e12;
        for h in [1e-3, 1.0] {
            let (y, st) = run(&mut StiffLinear { lambda }, 0.0, &[1.0], h, fixed(h));
            assert_eq!(st.steps, 1);
            let err = (y[0] - stiff_linear_exact(lambda, 1.0, h)).abs();
            // Measured: 0 (h = 1e-3) and 2.4e-15 (h = 1).
            assert!(err < 1e-10, "h = {h}: {y:?}, error {err:e}");
        }
    }

    // ---------------------------------------------------------------------
    // 5. Jacobians.
    // ---------------------------------------------------------------------

    /// Jacobian evaluated by `evaluate_jacobian` at (t, y) and the number of
    /// evaluations of f it cost.
    fn jacobian_of<S: OdeSystem>(sys: &mut S, t: f64, y: &[f64]) -> (BandMatrix, u64) {
        let mut s = Rodas::new(sys.dim(), tol(1e-8)).unwrap();
        s.reset(sys, t, y).unwrap();
        let before = s.stats().rhs_evaluations;
        s.evaluate_jacobian(sys);
        assert_eq!(s.stats().jacobian_evaluations, 1);
        (s.jac.clone(), s.stats().rhs_evaluations - before)
    }

    #[test]
    fn banded_fd_jacobian_equals_analytic() {
        let n = 12;
        let y: Vec<f64> = (0..n).map(|i| 0.5 + 0.3 * (i as f64).sin()).collect();
        let (ja, evals_a) = jacobian_of(
            &mut Chain {
                n,
                banded: true,
                analytic: true,
            },
            0.4,
            &y,
        );
        let (jf, evals_f) = jacobian_of(
            &mut Chain {
                n,
                banded: true,
                analytic: false,
            },
            0.4,
            &y,
        );
        let (jd, evals_d) = jacobian_of(
            &mut Chain {
                n,
                banded: false,
                analytic: false,
            },
            0.4,
            &y,
        );
        assert_eq!(ja.bandwidths(), (2, 1));
        assert_eq!(jd.bandwidths(), (n - 1, n - 1));
        // Analytic: only ∂f/∂t costs an evaluation; banded FD: kl + ku + 1
        // = 4 grouped evaluations (instead of n = 12) plus ∂f/∂t.
        assert_eq!(evals_a, 1);
        assert_eq!(evals_f, 4 + 1);
        assert_eq!(evals_d, n as u64 + 1);
        let mut worst = 0.0f64;
        for i in 0..n {
            for j in 0..n {
                let a = ja.get(i, j);
                let scale = a.abs().max(1.0);
                worst = worst.max((jf.get(i, j) - a).abs() / scale);
                worst = worst.max((jd.get(i, j) - a).abs() / scale);
                if !ja.in_band(i, j) {
                    assert_eq!(jd.get(i, j), 0.0, "({i}, {j}) outside the band");
                }
            }
        }
        // Measured: 6.2e-8 (forward differences, δ ≈ 1.5e-8·sqrt|y|).
        assert!(worst < 1e-6, "worst relative deviation {worst:e}");
    }

    #[test]
    fn banded_stiff_heat_equation() {
        // n = 50: eigenvalues from −9.9 to −1.04e4. Exact solution: the
        // first discrete mode, decaying as exp(−9.87 t). RODAS with the
        // analytic and the banded FD Jacobian (3 grouped evaluations).
        let n = 50;
        let heat = Heat { n, analytic: true };
        let mut y0 = vec![0.0; n];
        heat.exact(0.0, &mut y0);
        let mut ex = vec![0.0; n];
        heat.exact(0.5, &mut ex);
        let mut results = Vec::new();
        for analytic in [true, false] {
            let mut sys = Heat { n, analytic };
            let opts = tol(1e-8);
            let mut s = Rodas::with_bandwidth(n, opts, Some((1, 1))).unwrap();
            s.reset(&mut sys, 0.0, &y0).unwrap();
            while s.t() < 0.5 {
                s.step(&mut sys, 0.5).unwrap();
            }
            let err = s
                .y()
                .iter()
                .zip(&ex)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let st = s.stats();
            // Measured: error 1.3e-9, 74 steps (no rejection), both variants.
            assert!(err < 5e-8, "analytic {analytic}: error {err:e}");
            assert!(st.steps < 150, "{st:?}");
            let per_jac = if analytic { 1 } else { 3 + 1 };
            assert_eq!(
                st.rhs_evaluations,
                1 + 1 + per_jac * st.jacobian_evaluations + 5 * st.lu_decompositions + st.steps,
                "{st:?}"
            );
            results.push((s.y().to_vec(), st));
        }
        let diff = results[0]
            .0
            .iter()
            .zip(&results[1].0)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        // Measured: 3.8e-12.
        assert!(diff < 1e-10, "analytic vs FD {diff:e}");
        // An explicit method is limited by stability: DOP853 takes 809 steps
        // (measured).
        let mut d = Dop853::new(n, tol(1e-8)).unwrap();
        let mut sys = Heat { n, analytic: true };
        d.reset(&mut sys, 0.0, &y0).unwrap();
        while d.t() < 0.5 {
            d.step(&mut sys, 0.5).unwrap();
        }
        assert!(d.stats().steps > 5 * results[0].1.steps, "{:?}", d.stats());
    }

    // ---------------------------------------------------------------------
    // 6. NaN safety and admissibility.
    // ---------------------------------------------------------------------

    #[test]
    fn nan_in_stages_is_rejected_and_recovered() {
        // y' = −y, y(0) = 1, but f = NaN for y < 0 (never on the exact
        // solution). A first step of 10 puts the argument of stage 2 at
        // y·(1 − 1.544·hγ/(1 + hγ)) < 0; the attempt must be rejected and
        // retried, the solution stays finite and accurate.
        let mut sys = Decay::new();
        sys.nan_below = 0.0;
        let opts = IntegratorOptions {
            h_init: Some(10.0),
            ..tol(1e-10)
        };
        let mut s = Rodas::new(1, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0]).unwrap();
        s.step(&mut sys, 10.0).unwrap();
        assert!(sys.nan_returns > 0, "the trap must fire");
        assert!(s.stats().rejected_steps > 0);
        assert!(s.t() < 10.0);
        assert!(s.h_next() <= s.t() - s.t_prev());
        while s.t() < 10.0 {
            s.step(&mut sys, 10.0).unwrap();
            assert!(s.y()[0].is_finite());
        }
        let err = (s.y()[0] - (-10f64).exp()).abs();
        assert!(err < 1e-10, "final error {err:e}");
    }

    #[test]
    fn nan_beyond_time_gives_underflow_there() {
        // f = NaN for t > 0.7: RODAS creeps up to 0.7 (∂f/∂t falls back to
        // a backward difference there) and gives up with StepSizeUnderflow,
        // reason NonFinite.
        let mut sys = Decay::new();
        sys.nan_after = 0.7;
        let mut s = Rodas::new(1, tol(1e-10)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0]).unwrap();
        let err = loop {
            if let Err(e) = s.step(&mut sys, 2.0) {
                break e;
            }
        };
        match &err {
            IntegrationError::StepSizeUnderflow { t, h, y, reason } => {
                assert_eq!(*reason, RejectReason::NonFinite);
                assert!(*t <= 0.7 && 0.7 - t < 1e-12, "t = {t}");
                assert!(*h < 16.0 * f64::EPSILON * t);
                assert!((y[0] - (-t).exp()).abs() < 1e-9, "y = {y:?}");
            }
            other => panic!("unexpected error {other:?}"),
        }
        // The integrator keeps its last point and can be reset.
        assert!(s.t() <= 0.7);
        s.reset(&mut Decay::new(), 0.0, &[1.0]).unwrap();
        s.step(&mut Decay::new(), 1.0).unwrap();
    }

    #[test]
    fn inadmissible_state_is_rejected_and_recovered() {
        // Admissible only for y >= 0.3: integration stops at t* = ln(1/0.3)
        // with reason NotAdmissible, after rejecting every step beyond.
        let mut sys = Decay::new();
        sys.admissible_min = 0.3;
        let t_star = (1.0f64 / 0.3).ln();
        let mut s = Rodas::new(1, tol(1e-10)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0]).unwrap();
        let err = loop {
            if let Err(e) = s.step(&mut sys, 3.0) {
                break e;
            }
        };
        match err {
            IntegrationError::StepSizeUnderflow { t, y, reason, .. } => {
                assert_eq!(reason, RejectReason::NotAdmissible);
                assert!((t - t_star).abs() < 1e-8, "t = {t}, t* = {t_star}");
                assert!(y[0] >= 0.3);
            }
            other => panic!("unexpected result {other:?}"),
        }
        assert!(sys.inadmissible.get() > 0);
    }

    #[test]
    fn singular_iteration_matrix_is_rejected() {
        // y' = y with h·γ = 1: I/(hγ) − J = 0 is singular; the attempt is
        // rejected (reason NonFinite, h halved) and the integration goes on.
        struct Growth;
        impl OdeSystem for Growth {
            fn dim(&self) -> usize {
                1
            }
            fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
                d[0] = y[0];
            }
        }
        let opts = IntegratorOptions {
            h_init: Some(4.0),
            ..tol(1e-8)
        };
        let mut s = Rodas::new(1, opts).unwrap();
        s.reset(&mut Growth, 0.0, &[1.0]).unwrap();
        s.step(&mut Growth, 1.0).unwrap();
        let st = s.stats();
        assert!(st.rejected_steps > 0);
        // The singular attempt counts as a factorisation.
        assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
        while s.t() < 1.0 {
            s.step(&mut Growth, 1.0).unwrap();
        }
        assert!((s.y()[0] - 1f64.exp()).abs() < 1e-7);
    }

    // ---------------------------------------------------------------------
    // 7. Statistics, options, misuse.
    // ---------------------------------------------------------------------

    #[test]
    fn stats_count_every_evaluation() {
        // Per step: ∂f/∂t (1) + FD Jacobian (2 groups for the dense 2×2
        // harmonic oscillator) + f at the new point (1); per attempt: 5
        // stages; reset: 1 (+1 for HINIT).
        let mut sys = Harmonic { analytic: false };
        let mut s = Rodas::new(2, tol(1e-8)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        assert_eq!(s.stats().rhs_evaluations, 2, "f(t0, y0) + HINIT");
        let opts = IntegratorOptions {
            h_init: Some(3.0),
            ..tol(1e-8)
        };
        let mut s = Rodas::new(2, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        let mut out = [0.0; 2];
        while s.t() < 10.0 {
            s.step(&mut sys, 10.0).unwrap();
            s.dense_output(&mut sys, 0.5 * (s.t() + s.t_prev()), &mut out);
        }
        let st = s.stats();
        assert!(st.rejected_steps > 0, "h_init = 3 must be rejected");
        assert_eq!(st.jacobian_evaluations, st.steps);
        assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
        assert_eq!(
            st.rhs_evaluations,
            1 + (1 + 2 + 1) * st.steps + 5 * st.lu_decompositions,
            "{st:?}"
        );
        // Analytic Jacobian: no FD evaluations.
        let mut sys = Harmonic { analytic: true };
        let mut s = Rodas::new(2, tol(1e-8)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        s.reset_stats();
        s.step(&mut sys, 10.0).unwrap();
        let st = s.stats();
        assert_eq!(st.rhs_evaluations, 2 + 5 * st.lu_decompositions);
        // Stats survive reset(), not reset_stats().
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        assert_eq!(s.stats().steps, 1);
        s.reset_stats();
        assert_eq!(s.stats(), Stats::default());
        assert_eq!(s.options().rtol, 1e-8);
    }

    #[test]
    fn bounds_error_components_and_too_many_steps() {
        let opts = IntegratorOptions {
            h_max: 0.3,
            ..tol(1e-6)
        };
        let mut sys = Harmonic { analytic: true };
        let mut s = Rodas::new(2, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        s.step(&mut sys, 1e-3).unwrap();
        assert_eq!(s.t(), 1e-3);
        let mut t_old = s.t();
        while s.t() < 5.0 {
            s.step(&mut sys, 5.0).unwrap();
            assert!(s.t() - t_old <= 0.3 * (1.0 + 1e-12));
            t_old = s.t();
        }
        assert_eq!(s.t(), 5.0);
        assert_eq!(s.dydt(), [s.y()[1], -s.y()[0]]);
        assert!(matches!(
            s.step(&mut sys, 5.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
        s.step(&mut sys, f64::INFINITY).unwrap();
        assert!(s.t() > 5.0);
        // max_steps.
        let opts = IntegratorOptions {
            max_steps: 3,
            h_init: Some(0.1),
            h_max: 0.1,
            ..tol(1e-6)
        };
        let mut s = Rodas::new(2, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        let err = loop {
            if let Err(e) = s.step(&mut sys, 1.0) {
                break e;
            }
        };
        assert!(matches!(
            err,
            IntegrationError::TooManySteps { steps: 3, .. }
        ));
        // error_components: a fast oscillating appended equation does not
        // influence the steps.
        struct WithOscillation;
        impl OdeSystem for WithOscillation {
            fn dim(&self) -> usize {
                2
            }
            fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
                d[0] = -y[0];
                d[1] = (30.0 * t).cos();
            }
        }
        let opts = IntegratorOptions {
            error_components: Some(1),
            ..tol(1e-8)
        };
        let (y2, st2) = run(&mut WithOscillation, 0.0, &[1.0, 1.0], 2.0, opts);
        let (y1, st1) = run(&mut Decay::new(), 0.0, &[1.0], 2.0, tol(1e-8));
        assert_eq!(y1[0], y2[0]);
        assert_eq!(st1.steps, st2.steps);
        let (_, st_all) = run(&mut WithOscillation, 0.0, &[1.0, 1.0], 2.0, tol(1e-8));
        assert!(st_all.steps > 2 * st2.steps, "{st_all:?} vs {st2:?}");
    }

    #[test]
    fn misuse_and_invalid_states() {
        assert!(matches!(
            Rodas::new(2, tol(0.0)),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            Rodas::new(0, IntegratorOptions::default()),
            Err(IntegrationError::InvalidOptions(_))
        ));
        let mut sys = Harmonic { analytic: true };
        let mut s = Rodas::new(2, IntegratorOptions::default()).unwrap();
        assert!(matches!(
            s.step(&mut sys, 1.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            s.reset(&mut sys, 0.0, &[1.0]),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            s.reset(&mut Decay::new(), 0.0, &[1.0]),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            s.reset(&mut sys, f64::NAN, &[1.0, 0.0]),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            s.reset(&mut sys, 2.0, &[f64::NAN, 0.0]),
            Err(IntegrationError::NonFiniteInitialState { t }) if t == 2.0
        ));
        let mut nan_sys = Decay::new();
        nan_sys.nan_below = 2.0;
        let mut s1 = Rodas::new(1, IntegratorOptions::default()).unwrap();
        assert!(matches!(
            s1.reset(&mut nan_sys, 0.0, &[1.0]),
            Err(IntegrationError::NonFiniteInitialState { .. })
        ));
        assert!(matches!(
            s1.step(&mut nan_sys, 1.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
    }

    #[test]
    fn matrices_are_shaped_at_reset_only_when_needed() {
        // with_bandwidth preallocates; reset with the same shape keeps the
        // allocation, another shape replaces it.
        let mut s = Rodas::with_bandwidth(50, tol(1e-6), Some((1, 1))).unwrap();
        let shape = s.jac.bandwidths();
        let mut heat = Heat {
            n: 50,
            analytic: true,
        };
        let y0 = vec![0.1; 50];
        s.reset(&mut heat, 0.0, &y0).unwrap();
        assert_eq!(s.jac.bandwidths(), shape);
        let mut chain = Chain {
            n: 50,
            banded: false,
            analytic: true,
        };
        s.reset(&mut chain, 0.0, &y0).unwrap();
        assert_eq!(s.jac.bandwidths(), (49, 49));
        let mut fresh = Rodas::new(50, tol(1e-6)).unwrap();
        assert_eq!(fresh.jac.n(), 0);
        fresh.reset(&mut heat, 0.0, &y0).unwrap();
        assert_eq!(fresh.jac.bandwidths(), (1, 1));
        assert_eq!(fresh.lu.bandwidths(), (1, 1));
    }
}
