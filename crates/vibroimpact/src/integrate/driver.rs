//! The step driver shared by every one-step method: reset with Hairer's
//! initial-step estimate, the step loop with clipping to the end time, the
//! step-size controller, the step-size floor, the step limit, accept and
//! reject, dense-output end points and statistics.
//!
//! A method ([`StepMethod`]) holds only what differs between integrators:
//! its stages and their buffers, one attempted step with its local error
//! norm, `f` at the new state, and its dense-output polynomial. The driver
//! owns the accepted point ([`Point`]) and passes it to the method.
//!
//! # Step-size control (the same for every method)
//!
//! With `e` the method's error norm of an attempt (weighted RMS, accepted
//! when `e <= 1`) and `E = 1/(q + 1)` its controller exponent:
//!
//! * after an acceptance, `h_new = h / fac` with
//!   `fac = clamp(e^E / 0.9, 1/6, SHRINK_LIMIT)`, combined with Gustafsson's
//!   predictive controller from the second step after a reset on (the
//!   smaller proposal wins): `fac_g = (h_acc / h)·(e² / e_acc)^E / 0.9`,
//!   `h_acc`, `e_acc = max(e, 0.01)` of the previous accepted step. When the
//!   error grows from step to step (an impact approaching: the exponential
//!   force steepens every step) the controller shrinks ahead of the trend
//!   instead of being rejected once per step. After a rejection the step
//!   finally accepted proposes no larger step; a step shortened to reach
//!   `t_bound` and accepted at once proposes no smaller step than planned.
//! * after a rejection by the error estimate, `h ← h · max(1/SHRINK_LIMIT,
//!   0.9 / e^E)`; after a non-finite or non-admissible attempt `h ← h/4`
//!   (or the method's own factor, e.g. RODAS's `h/2` for a singular
//!   iteration matrix).
//! * a step is stretched by up to 1 % to end exactly on `t_bound`; a
//!   rejected attempt that would shrink `h` below
//!   `max(h_min, 16·ε·|t|)`, or no longer advance `t`, ends the step with
//!   [`IntegrationError::StepSizeUnderflow`].
//!
//! The driver allocates in [`Driver::new`] only; stepping, resetting and
//! dense output do not allocate (except for building an error value).

use super::{IntegrationError, IntegratorOptions, OdeSystem, RejectReason, Stats};

/// Safety factor of the step-size prediction.
const SAFETY: f64 = 0.9;
/// Smallest `h / h_new` after an accepted step (growth at most 6).
const FAC_GROW: f64 = 1.0 / 6.0;
/// Factor applied to `h` after a non-finite or non-admissible attempt.
pub(super) const SHRINK_HARD: f64 = 0.25;
/// Relative step-size floor: `h >= MIN_STEP_REL · |t|`.
const MIN_STEP_REL: f64 = 16.0 * f64::EPSILON;
/// A step is stretched by up to this factor to hit `t_bound` exactly.
const STRETCH: f64 = 1.01;

/// The accepted point and the last accepted step, as the driver keeps them
/// and a method reads them.
#[derive(Clone, Debug)]
pub struct Point {
    opts: IntegratorOptions,
    /// Number of leading components entering the error norm.
    n_err: usize,
    /// Size of the blocks whose norms are compared (see
    /// [`OdeSystem::error_block`]); `n_err` for one block.
    block: usize,
    /// Time after the last accepted step.
    pub t: f64,
    /// Time before the last accepted step.
    pub t_prev: f64,
    /// Size of the last accepted step.
    pub h_last: f64,
    /// State at `t`.
    pub y: Vec<f64>,
    /// State at `t_prev`.
    pub y_prev: Vec<f64>,
    /// `f(t, y)`.
    pub dydt: Vec<f64>,
}

impl Point {
    /// Dimension of the system.
    #[inline]
    pub fn dim(&self) -> usize {
        self.y.len()
    }

    /// The options the integrator was created with.
    #[inline]
    pub fn options(&self) -> &IntegratorOptions {
        &self.opts
    }

    /// Number of leading components that enter the error norm (see
    /// [`IntegratorOptions::error_components`]).
    #[inline]
    pub fn error_components(&self) -> usize {
        self.n_err
    }

    /// Error weight `atol + rtol · max(|a|, |b|)`.
    #[inline]
    pub fn weight(&self, a: f64, b: f64) -> f64 {
        self.opts.atol + self.opts.rtol * a.abs().max(b.abs())
    }

    /// Size of the error norm's blocks (see [`OdeSystem::error_block`]):
    /// the error-controlled components in consecutive blocks of this size
    /// (the last may be shorter).
    #[inline]
    pub fn error_block(&self) -> usize {
        self.block
    }

    /// Largest over the blocks of the weighted RMS norm
    /// `sqrt(1/b Σ_block (err_i / sk_i)²)` of `err` over the
    /// error-controlled components, with weights from the current state and
    /// the candidate `y_new` (one block: the RMS norm over all of them).
    #[inline]
    pub fn error_norm(&self, err: &[f64], y_new: &[f64]) -> f64 {
        let m = self.n_err;
        let mut worst = 0.0f64;
        for start in (0..m).step_by(self.block) {
            let end = (start + self.block).min(m);
            let mut sum = 0.0;
            for i in start..end {
                sum += (err[i] / self.weight(self.y[i], y_new[i])).powi(2);
            }
            worst = worst.max(sum / (end - start) as f64);
        }
        worst.sqrt()
    }
}

/// One attempted step as the driver hands it to the method.
#[derive(Debug)]
pub struct Trial<'a> {
    /// Step size.
    pub h: f64,
    /// End time of the step (`t + h`, or exactly `t_bound`).
    pub t_new: f64,
    /// The candidate new state, written by the method.
    pub y_new: &'a mut [f64],
    /// Work counters to update.
    pub stats: &'a mut Stats,
}

/// The outcome of [`StepMethod::attempt`]: the error norm, or a rejection
/// with the factor for the next step size.
pub type Attempt = Result<f64, (RejectReason, f64)>;

/// The rejection of an attempt with a non-finite value: retry with `h/4`.
pub(super) const NON_FINITE: (RejectReason, f64) = (RejectReason::NonFinite, SHRINK_HARD);

/// Whether every value is finite.
#[inline]
pub(super) fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// What a one-step method supplies to the [`Driver`]: its stages, the error
/// norm of an attempt, `f` at the accepted state and its dense output.
pub trait StepMethod: Clone + std::fmt::Debug {
    /// Exponent `1/(q + 1)` of the step-size controller, `q` the order of
    /// the error estimate.
    const ERROR_EXPONENT: f64;
    /// Largest `h / h_new` of the controller (the strongest shrink after
    /// an error-estimate rejection is `1/SHRINK_LIMIT`).
    const SHRINK_LIMIT: f64;

    /// Allocates the method's buffers for dimension `dim`.
    fn new(dim: usize) -> Self;

    /// Called on every reset, before `f(t0, y0)` is evaluated (e.g. to shape
    /// matrices after [`OdeSystem::jacobian_bandwidth`]).
    fn reset<S: OdeSystem>(&mut self, sys: &S, dim: usize);

    /// Called once per step before its first attempt, at the accepted
    /// point (e.g. to evaluate the Jacobian).
    fn begin_step<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, stats: &mut Stats);

    /// One attempt of size `trial.h` from `at`, ending at `trial.t_new`:
    /// writes the new state into `trial.y_new` and returns the error norm
    /// (`<= 1` accepts), or a rejection with the factor for the next try
    /// when a stage or the new state is not finite or not admissible. The
    /// driver checks the norm.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, trial: &mut Trial) -> Attempt;

    /// Evaluates `f(t_new, y_new)` after the error test passed; `false` if
    /// it is not finite (the attempt is then rejected).
    fn evaluate_end<S: OdeSystem>(&mut self, sys: &mut S, trial: &mut Trial) -> bool;

    /// Commits the attempt (still from `at`): e.g. swaps stage buffers,
    /// prepares the dense coefficients, runs a stiffness test.
    fn accept(&mut self, at: &Point, y_new: &[f64], h: f64);

    /// `f(t_new, y_new)` of the attempt just accepted.
    fn end_derivative(&self) -> &[f64];

    /// Dense output of component `i` at the normalised time
    /// `s = (t − t_prev)/h_last` of the last accepted step (`at` is the point
    /// after it).
    fn dense<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        at: &Point,
        i: usize,
        s: f64,
        stats: &mut Stats,
    ) -> f64;

    /// Whether the dense output is the flow itself to rounding (the exact
    /// method), so that a step can be shortened to end where an event lies
    /// ([`Driver::end_step_at`]) instead of being taken again up to it; an
    /// interpolant's is not (the step's end is the method's own).
    const DENSE_IS_FLOW: bool = false;

    /// For a method whose dense output is the flow: the last accepted step
    /// now ends at `(t, y)`, its dense output still reading its first part;
    /// [`end_derivative`](Self::end_derivative) then reads `f(t, y)`.
    fn shorten(&mut self, _t: f64, _y: &[f64]) {}

    /// The first `out.len()` components of the dense output at `s`
    /// (default: one at a time).
    fn dense_all<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        at: &Point,
        s: f64,
        out: &mut [f64],
        stats: &mut Stats,
    ) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.dense(sys, at, i, s, stats);
        }
    }
}

/// A one-step integrator: the shared driver around the method `M`.
///
/// Usage: [`new`](Self::new) once (allocates all buffers), then
/// [`reset`](Self::reset) at an initial point (again after every
/// discontinuity, e.g. an impact), then [`step`](Self::step) repeatedly;
/// after each accepted step [`dense_output`](Self::dense_output) and
/// [`dense_component`](Self::dense_component) interpolate inside
/// `[t_prev(), t()]`. If `step` fails, the integrator keeps the last accepted
/// point and its dense output; it can be reset and reused.
#[derive(Clone, Debug)]
pub struct Driver<M> {
    pub(super) at: Point,
    pub(super) method: M,
    /// Whether `reset` succeeded since construction or the last failed reset.
    initialised: bool,
    /// Whether a step has been accepted since the last reset.
    has_step: bool,
    h_next: f64,
    /// Size and error (`>= 0.01`) of the previous accepted step, for
    /// Gustafsson's controller (None right after a reset).
    previous_accepted: Option<(f64, f64)>,
    steps_since_reset: u64,
    pub(super) stats: Stats,
    /// Candidate state of the current attempt.
    y_new: Vec<f64>,
    /// Scratch for the initial-step estimate.
    scratch: Vec<f64>,
}

impl<M: StepMethod> Driver<M> {
    /// Creates an integrator for systems of dimension `dim` with options
    /// `opts`, allocating all work buffers. Fails with
    /// [`IntegrationError::InvalidOptions`] if the options are invalid (see
    /// [`IntegratorOptions`]) or `dim == 0`. Call [`reset`](Self::reset)
    /// before stepping.
    pub fn new(dim: usize, opts: IntegratorOptions) -> Result<Self, IntegrationError> {
        Self::with_method(dim, opts, M::new(dim))
    }

    pub(super) fn with_method(
        dim: usize,
        opts: IntegratorOptions,
        method: M,
    ) -> Result<Self, IntegrationError> {
        let n_err = opts.validate(dim)?;
        Ok(Self {
            at: Point {
                opts,
                n_err,
                block: n_err,
                t: 0.0,
                t_prev: 0.0,
                h_last: 0.0,
                y: vec![0.0; dim],
                y_prev: vec![0.0; dim],
                dydt: vec![0.0; dim],
            },
            method,
            initialised: false,
            has_step: false,
            h_next: 0.0,
            previous_accepted: None,
            steps_since_reset: 0,
            stats: Stats::default(),
            y_new: vec![0.0; dim],
            scratch: vec![0.0; dim],
        })
    }

    /// Starts (or restarts, e.g. after a discontinuity) at `(t0, y0)`:
    /// evaluates `f(t0, y0)` and chooses the initial step, `min(h_init,
    /// h_max)` if `h_init` is given, else Hairer's `HINIT` estimate (one more
    /// evaluation of `f`, at `t0 + h` with `h` an Euler guess). Statistics are
    /// *not* reset (they accumulate over the integrator's lifetime, see
    /// [`reset_stats`](Self::reset_stats)); the step counter for
    /// [`IntegratorOptions::max_steps`] is.
    ///
    /// Errors: [`IntegrationError::InvalidOptions`] for a dimension mismatch
    /// or non-finite `t0`; [`IntegrationError::NonFiniteInitialState`] if `y0`
    /// or `f(t0, y0)` is not finite. After an error, [`step`](Self::step)
    /// refuses to run until a successful reset.
    pub fn reset<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t0: f64,
        y0: &[f64],
    ) -> Result<(), IntegrationError> {
        let h0 = self.at.opts.h_init;
        self.reset_with_step(sys, t0, y0, h0)
    }

    /// Restarts at the current time with the state `y` (e.g. variational
    /// columns re-orthonormalised, or an impulsive change), keeping the
    /// proposed step size instead of estimating a new one: one evaluation
    /// of `f`. Errors as [`reset`](Self::reset).
    pub fn restart<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        y: &[f64],
    ) -> Result<(), IntegrationError> {
        let (t, h) = (self.at.t, self.h_next);
        self.reset_with_step(sys, t, y, Some(h))
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
        self.check_dim(sys)?;
        let n = self.at.dim();
        if y0.len() != n {
            return Err(IntegrationError::InvalidOptions(format!(
                "initial state has {} components, the integrator {n}",
                y0.len()
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
        self.method.reset(sys, n);
        self.at.block = sys
            .error_block()
            .map_or(self.at.n_err, |b| b.clamp(1, self.at.n_err));
        self.at.y.copy_from_slice(y0);
        self.at.y_prev.copy_from_slice(y0);
        sys.rhs(t0, &self.at.y, &mut self.at.dydt);
        self.stats.rhs_evaluations += 1;
        if !all_finite(&self.at.dydt) {
            return Err(IntegrationError::NonFiniteInitialState { t: t0 });
        }
        self.at.t = t0;
        self.at.t_prev = t0;
        self.at.h_last = 0.0;
        self.steps_since_reset = 0;
        self.previous_accepted = None;
        self.h_next = match h0 {
            Some(h) if h > 0.0 && h.is_finite() => h.min(self.at.opts.h_max),
            _ => self.initial_step(sys),
        };
        self.initialised = true;
        Ok(())
    }

    /// Takes ONE accepted step (internally retrying rejected attempts),
    /// never stepping past `t_bound` (> current t, may be infinite). A step
    /// that ends within 1 % of a step size before `t_bound` is stretched to
    /// end exactly at `t_bound`.
    ///
    /// Errors: [`IntegrationError::InvalidOptions`] if called before a
    /// successful [`reset`](Self::reset), on a dimension mismatch, or if
    /// `t_bound <= t()` (or NaN); [`IntegrationError::TooManySteps`] if
    /// `max_steps` steps were already accepted since the reset;
    /// [`IntegrationError::Interrupted`] if the options' interrupt was
    /// requested; [`IntegrationError::StepSizeUnderflow`] if rejections
    /// shrink the step below the floor described at
    /// [`IntegratorOptions::h_min`]. On error the integrator's point (`t`,
    /// `y`, dense output) is unchanged.
    pub fn step<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        t_bound: f64,
    ) -> Result<(), IntegrationError> {
        self.check_step(sys, t_bound)?;
        self.method.begin_step(sys, &self.at, &mut self.stats);
        let t = self.at.t;
        let opts = &self.at.opts;
        let floor = opts.h_min.max(MIN_STEP_REL * t.abs());
        let h_planned = self.h_next.max(floor).min(opts.h_max);
        let mut h = h_planned;
        let mut rejected = false;
        loop {
            let clipped = t + STRETCH * h >= t_bound;
            let t_new = if clipped {
                h = t_bound - t;
                t_bound
            } else {
                t + h
            };
            match self.try_attempt(sys, h, t_new) {
                Ok(err) => {
                    let mut h_new = h / self.controller_factor(h, err);
                    if rejected {
                        h_new = h_new.min(h);
                    } else if clipped {
                        h_new = h_new.max(h_planned);
                    }
                    self.accept(t_new, h, h_new.min(self.at.opts.h_max));
                    return Ok(());
                }
                Err((reason, factor)) => {
                    self.stats.rejected_steps += 1;
                    rejected = true;
                    let h_new = h * factor;
                    if h_new < floor || t + h_new <= t {
                        return Err(IntegrationError::StepSizeUnderflow {
                            t,
                            h: h_new,
                            y: self.at.y.clone(),
                            reason,
                        });
                    }
                    h = h_new;
                }
            }
        }
    }

    /// The preconditions of [`step`](Self::step).
    fn check_step<S: OdeSystem>(&self, sys: &S, t_bound: f64) -> Result<(), IntegrationError> {
        if !self.initialised {
            return Err(IntegrationError::InvalidOptions(
                "step() called before a successful reset()".into(),
            ));
        }
        self.check_dim(sys)?;
        let t = self.at.t;
        if t_bound.is_nan() || t_bound <= t {
            return Err(IntegrationError::InvalidOptions(format!(
                "t_bound = {t_bound} must be greater than t = {t}"
            )));
        }
        if self.steps_since_reset >= self.at.opts.max_steps {
            return Err(IntegrationError::TooManySteps {
                t,
                steps: self.steps_since_reset,
            });
        }
        if let Some(stop) = &self.at.opts.interrupt {
            stop.check(t)?;
        }
        Ok(())
    }

    /// One attempt with the error test: the error norm if accepted, else the
    /// rejection reason and the factor for the next try.
    fn try_attempt<S: OdeSystem>(&mut self, sys: &mut S, h: f64, t_new: f64) -> Attempt {
        let mut trial = Trial {
            h,
            t_new,
            y_new: &mut self.y_new,
            stats: &mut self.stats,
        };
        let err = self.method.attempt(sys, &self.at, &mut trial)?;
        if !err.is_finite() {
            return Err(NON_FINITE);
        }
        if err > 1.0 {
            let factor = (1.0 / M::SHRINK_LIMIT).max(SAFETY / err.powf(M::ERROR_EXPONENT));
            return Err((RejectReason::ErrorEstimate, factor));
        }
        if !self.method.evaluate_end(sys, &mut trial) {
            return Err(NON_FINITE);
        }
        Ok(err)
    }

    /// `h / h_new` after an accepted attempt of size `h` with error `err`
    /// (both controllers of the module notes); remembers the step for the
    /// next prediction.
    fn controller_factor(&mut self, h: f64, err: f64) -> f64 {
        let e = M::ERROR_EXPONENT;
        let mut fac = (err.powf(e) / SAFETY).clamp(FAC_GROW, M::SHRINK_LIMIT);
        if let Some((h_acc, err_acc)) = self.previous_accepted {
            let gus = (h_acc / h) * (err * err / err_acc).powf(e) / SAFETY;
            fac = fac.max(gus.clamp(FAC_GROW, M::SHRINK_LIMIT));
        }
        self.previous_accepted = Some((h, err.max(1e-2)));
        fac
    }

    /// Commits the accepted attempt.
    fn accept(&mut self, t_new: f64, h: f64, h_next: f64) {
        self.method.accept(&self.at, &self.y_new, h);
        let at = &mut self.at;
        std::mem::swap(&mut at.y_prev, &mut at.y);
        std::mem::swap(&mut at.y, &mut self.y_new);
        at.dydt.copy_from_slice(self.method.end_derivative());
        at.t_prev = at.t;
        at.t = t_new;
        at.h_last = h;
        self.h_next = h_next;
        self.has_step = true;
        self.steps_since_reset += 1;
        self.stats.steps += 1;
    }

    /// Hairer's `HINIT`: initial step size guess from `y0`, `f(t0, y0)` and
    /// one more evaluation of `f` (explicit Euler step). If that evaluation
    /// is not finite, the Euler guess itself is returned (the step loop then
    /// shrinks it as needed).
    fn initial_step<S: OdeSystem>(&mut self, sys: &mut S) -> f64 {
        let at = &self.at;
        let h_max = at.opts.h_max;
        let (mut dnf, mut dny) = (0.0, 0.0);
        for i in 0..at.n_err {
            let sk = at.weight(at.y[i], 0.0);
            dnf += (at.dydt[i] / sk).powi(2);
            dny += (at.y[i] / sk).powi(2);
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
        for ((ys, &y), &f) in self.y_new.iter_mut().zip(&at.y).zip(&at.dydt) {
            *ys = y + h * f;
        }
        sys.rhs(at.t + h, &self.y_new, &mut self.scratch);
        self.stats.rhs_evaluations += 1;
        let mut der2 = 0.0;
        for i in 0..at.n_err {
            let sk = at.weight(at.y[i], 0.0);
            der2 += ((self.scratch[i] - at.dydt[i]) / sk).powi(2);
        }
        let der2 = der2.sqrt() / h;
        if !der2.is_finite() {
            return h;
        }
        let der12 = der2.max(dnf.sqrt());
        let h1 = if der12 <= 1e-15 {
            (h * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(M::ERROR_EXPONENT)
        };
        (100.0 * h).min(h1).min(h_max)
    }

    fn check_dim<S: OdeSystem>(&self, sys: &S) -> Result<(), IntegrationError> {
        if sys.dim() == self.at.dim() {
            Ok(())
        } else {
            Err(IntegrationError::InvalidOptions(format!(
                "system dimension {} differs from the integrator's {}",
                sys.dim(),
                self.at.dim()
            )))
        }
    }

    /// Time after the last accepted step (the initial time right after
    /// [`reset`](Self::reset)).
    pub fn t(&self) -> f64 {
        self.at.t
    }

    /// Time before the last accepted step (equal to [`t`](Self::t) right
    /// after [`reset`](Self::reset)).
    pub fn t_prev(&self) -> f64 {
        self.at.t_prev
    }

    /// Size of the last accepted step (`t − t_prev` before rounding; 0
    /// right after [`reset`](Self::reset)).
    pub fn h_last(&self) -> f64 {
        self.at.h_last
    }

    /// State at [`t`](Self::t).
    pub fn y(&self) -> &[f64] {
        &self.at.y
    }

    /// `f(t, y)` at the current point (the first stage of the next step).
    pub fn dydt(&self) -> &[f64] {
        &self.at.dydt
    }

    /// Caps the size of the next step at `h` (> 0), e.g. so that it does not
    /// run deep into an impact the caller sees coming. Unlike `t_bound`, the
    /// cap is not remembered: the step after it grows from the capped size
    /// as the error allows.
    pub fn limit_next_step(&mut self, h: f64) {
        if h > 0.0 && h < self.h_next {
            self.h_next = h;
        }
    }

    /// Step size proposed for the next step (before limiting it by the
    /// `t_bound` of the next [`step`](Self::step) call).
    pub fn h_next(&self) -> f64 {
        self.h_next
    }

    /// Shortens the last accepted step to end at `t` inside it, where the
    /// method's dense output is the flow itself ([`StepMethod::DENSE_IS_FLOW`]):
    /// the point becomes `(t, y(t))` from the dense output, which keeps
    /// reading the step's first part. An event located inside a step then
    /// ends it there, without the step being taken again up to it. False
    /// (nothing changed) for another method or a `t` not inside the step.
    pub fn end_step_at<S: OdeSystem>(&mut self, sys: &mut S, t: f64) -> bool {
        if !(M::DENSE_IS_FLOW && self.has_step && t > self.at.t_prev && t < self.at.t) {
            return false;
        }
        let mut y = std::mem::take(&mut self.y_new);
        self.dense_output(sys, t, &mut y);
        self.method.shorten(t, &y);
        let at = &mut self.at;
        std::mem::swap(&mut at.y, &mut y);
        at.dydt.copy_from_slice(self.method.end_derivative());
        at.t = t;
        at.h_last = t - at.t_prev;
        self.y_new = y;
        true
    }

    /// Dense output of the last accepted step, valid for `t` in
    /// `[t_prev, t]`: the first `out.len()` components (all of them, or
    /// a leading part: a system's own state ahead of its carried
    /// columns, which is all an event needs). Requests at exactly `t_prev()`
    /// or `t()` return the stored states; outside `[t_prev, t]` the
    /// polynomial is extrapolated (not accurate); before the first step
    /// after a reset the output is the current state. A method may evaluate
    /// `f` lazily here (DOP853's extra stages), hence `&mut self` and the
    /// system.
    ///
    /// # Panics
    /// If `out.len()` exceeds the dimension.
    pub fn dense_output<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        let m = out.len();
        assert!(
            m <= self.at.dim(),
            "dense_output: output longer than the state"
        );
        if !self.has_step || t == self.at.t {
            out.copy_from_slice(&self.at.y[..m]);
        } else if t == self.at.t_prev {
            out.copy_from_slice(&self.at.y_prev[..m]);
        } else {
            let s = (t - self.at.t_prev) / self.at.h_last;
            self.method
                .dense_all(sys, &self.at, s, out, &mut self.stats);
        }
    }

    /// Single component of the dense output (cheap: used inside root
    /// finding); same semantics as [`dense_output`](Self::dense_output).
    ///
    /// # Panics
    /// If `i` is not below the dimension.
    pub fn dense_component<S: OdeSystem>(&mut self, sys: &mut S, i: usize, t: f64) -> f64 {
        assert!(i < self.at.dim(), "dense_component: index {i} out of range");
        if !self.has_step || t == self.at.t {
            self.at.y[i]
        } else if t == self.at.t_prev {
            self.at.y_prev[i]
        } else {
            let s = (t - self.at.t_prev) / self.at.h_last;
            self.method.dense(sys, &self.at, i, s, &mut self.stats)
        }
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
        &self.at.opts
    }

    /// Whether a successful [`reset`](Self::reset) has happened (stepping is
    /// allowed).
    pub(super) fn is_initialised(&self) -> bool {
        self.initialised
    }
}
