//! The adaptive Dormand–Prince 8(5,3) integrator "DOP853" with 7th-order dense
//! output, after E. Hairer's Fortran code `dop853.f` (Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, Sec. II.5 and II.6).
//!
//! Algorithmic choices (all as in `dop853.f` unless stated):
//!
//! * **Error estimate**: the "8(5,3)" combination of the 5th- and 3rd-order
//!   embedded estimators, `err = |h|·e5² / sqrt(m·(e5² + 0.01·e3²))` with
//!   `e5, e3` the weighted 2-norms of `Σ E5_i k_i`, `Σ E3_i k_i` over the `m`
//!   error-controlled components. The step is accepted when `err <= 1`.
//! * **Step-size controller**: `h_new = h / clamp(err^(1/8) / 0.9, 1/6, 1/0.333)`,
//!   i.e. safety factor 0.9, growth limited to 6, shrink limited to 0.333
//!   (`facmin`, `facmax`), with Hairer's default `beta = 0` (no PI
//!   stabilisation: DOP853's default). After a rejection, the step that is
//!   finally accepted does not propose a larger step (`h_new <= h`).
//! * **Robustness** (not in `dop853.f`): an attempt with a non-finite stage
//!   derivative, new state, `f(t + h, y_new)` or error estimate, or whose new
//!   state is not [admissible](OdeSystem::admissible), is rejected and
//!   retried with `h/4`. The check order is: stages, new state, admissibility,
//!   error estimate, `f` at the new state. Non-finite values never reach the
//!   error norm's comparisons (checked explicitly with `is_finite`).
//! * **Bounds**: a step is stretched by up to 1 % to land exactly on
//!   `t_bound` (then `t == t_bound` exactly). When the step was shortened to
//!   reach `t_bound` and accepted without rejection, the proposed next step is
//!   not smaller than the step size that was planned before shortening.
//! * **Stiffness detection** (as in `dop853.f`, but tested after *every*
//!   accepted step instead of every `NSTIFF = 1000`-th): after an accepted
//!   step, `h·ρ ≈ h·‖f(t+h, y_new) − f(t+h, Y₁₂)‖ / ‖y_new − Y₁₂‖` (Hairer's
//!   `STNUM/STDEN`, `Y₁₂` the argument of the 12th stage, also at `t + h`)
//!   estimates `h` times the dominant eigenvalue of the Jacobian. A step with
//!   `h·ρ > 6.1` (the step size is then limited by the stability region, not
//!   by accuracy) counts as suspicious; 6 consecutive non-suspicious steps
//!   clear the count; 15 consecutive suspicious steps mean "stiff" (see
//!   [`Dop853::stiffness_detected`]). The test only reports: it never changes
//!   the computed solution. Switched off by
//!   [`IntegratorOptions::stiffness_check`].
//! * **Evaluation count**: `f(t0, y0)` on reset (+1 for the automatic
//!   initial step); per attempt, 11 new stages (stage 0 is the previous
//!   step's last evaluation, "first same as last"); `f(t + h, y_new)` once
//!   the error test passed; fewer when an attempt stops early at a non-finite
//!   stage. The 3 extra dense-output stages are evaluated lazily, at most once
//!   per accepted step.
//!
//! Every buffer is allocated in [`Dop853::new`]; stepping, resetting and dense
//! output do not allocate (except for building an error value).

use super::dop853_tableau::{A, B, C, D, E3, E5, N_STAGES, N_STAGES_EXTENDED};
use super::{IntegrationError, IntegratorOptions, OdeSystem, RejectReason, Stats};

/// Safety factor of the step-size prediction.
const SAFETY: f64 = 0.9;
/// Smallest factor `h_new / h` after an error-estimate rejection.
const FAC_MIN: f64 = 0.333;
/// Largest factor `h_new / h`.
const FAC_MAX: f64 = 6.0;
/// Exponent of the step-size controller, `1/(q + 1)` with `q = 7`.
const ERROR_EXPONENT: f64 = 1.0 / 8.0;
/// Factor applied to `h` after a non-finite or non-admissible attempt.
const SHRINK_HARD: f64 = 0.25;
/// Relative step-size floor: `h >= MIN_STEP_REL · |t|`.
const MIN_STEP_REL: f64 = 16.0 * f64::EPSILON;
/// A step is stretched by up to this factor to hit `t_bound` exactly.
const STRETCH: f64 = 1.01;
/// Index of the stage `f(t + h, y_new)` in the extended stage list.
const FSAL_STAGE: usize = N_STAGES;
/// Number of dense-output coefficients per component.
const N_CONT: usize = 8;
/// Stiffness test: a step with `h·ρ` above this is suspicious (`dop853.f`).
const STIFF_H_RHO: f64 = 6.1;
/// Stiffness test: this many consecutive suspicious steps mean "stiff".
const STIFF_STEPS: u32 = 15;
/// Stiffness test: this many consecutive non-suspicious steps clear the
/// count of suspicious ones.
const NONSTIFF_STEPS: u32 = 6;

/// Adaptive Dormand–Prince 8(5,3) integrator with 7th-order dense output.
///
/// Usage: [`new`](Self::new) once (allocates all buffers), then
/// [`reset`](Self::reset) at an initial point (again after every
/// discontinuity, e.g. an impact), then [`step`](Self::step) repeatedly; after
/// each accepted step, [`dense_output`](Self::dense_output) /
/// [`dense_component`](Self::dense_component) interpolate inside
/// `[t_prev(), t()]`.
///
/// If `step` fails, the integrator keeps the last accepted point and the dense
/// output of the last accepted step; it can be reset and reused.
#[derive(Clone, Debug)]
pub struct Dop853 {
    opts: IntegratorOptions,
    /// Dimension of the system.
    n: usize,
    /// Number of leading components entering the error norm.
    n_err: usize,
    /// Whether `reset` succeeded since construction or the last failed reset.
    initialised: bool,
    /// Whether a step has been accepted since the last reset.
    has_step: bool,
    /// Whether `cont` holds the dense output of the last accepted step.
    dense_ready: bool,
    t: f64,
    t_prev: f64,
    /// Step size actually used by the last accepted step.
    h_last: f64,
    h_next: f64,
    /// Gustafsson's predictive controller: size and error of the previous
    /// accepted step (None right after a reset).
    previous_accepted: Option<(f64, f64)>,
    steps_since_reset: u64,
    stats: Stats,
    /// Consecutive suspicious steps of the stiffness test (Hairer's `IASTI`).
    stiff_count: u32,
    /// Consecutive non-suspicious steps since the last suspicious one
    /// (Hairer's `NONSTI`).
    nonstiff_count: u32,
    y: Vec<f64>,
    dydt: Vec<f64>,
    /// State at `t_prev`.
    y_prev: Vec<f64>,
    /// Candidate state of the current attempt.
    y_new: Vec<f64>,
    /// Argument of the stage being evaluated.
    y_stage: Vec<f64>,
    /// Stages of the current attempt, stage `s` at `k[s*n..(s+1)*n]`.
    k: Vec<f64>,
    /// Stages of the last accepted step (same layout, incl. the extra dense
    /// stages once computed).
    k_acc: Vec<f64>,
    /// Dense-output coefficients, component `i` at `cont[8*i..8*i+8]`.
    cont: Vec<f64>,
}

/// `out = y + h · Σ_j row[j] · k_j`, skipping zero coefficients.
fn combine(y: &[f64], k: &[f64], row: &[f64], h: f64, out: &mut [f64]) {
    // One pass over the output: each block of 8 components accumulates all
    // stages in registers (measured 2x faster at n = 2000 than one axpy pass
    // per stage, which loads and stores the output once per stage).
    const B: usize = 8;
    let n = y.len();
    let stages = row.len().min(k.len() / n.max(1));
    let mut i = 0;
    while i + B <= n {
        let mut acc = [0.0; B];
        for (j, &a) in row[..stages].iter().enumerate() {
            if a != 0.0 {
                let kj = &k[j * n + i..j * n + i + B];
                for l in 0..B {
                    acc[l] += a * kj[l];
                }
            }
        }
        for l in 0..B {
            out[i + l] = y[i + l] + h * acc[l];
        }
        i += B;
    }
    let rest = n - i;
    if rest > 0 {
        let mut acc = [0.0; B];
        for (j, &a) in row[..stages].iter().enumerate() {
            if a != 0.0 {
                let kj = &k[j * n + i..j * n + n];
                for l in 0..rest {
                    acc[l] += a * kj[l];
                }
            }
        }
        for l in 0..rest {
            out[i + l] = y[i + l] + h * acc[l];
        }
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|x| x.is_finite())
}

/// Hairer's `CONTD8` for one component: `c` are its 8 coefficients, `s` the
/// normalised time `(t − t_prev)/h`.
fn eval_cont(c: &[f64], s: f64) -> f64 {
    let s1 = 1.0 - s;
    let conpar = c[4] + s * (c[5] + s1 * (c[6] + s * c[7]));
    c[0] + s * (c[1] + s1 * (c[2] + s * (c[3] + s1 * conpar)))
}

impl Dop853 {
    /// Creates an integrator for systems of dimension `dim` with options
    /// `opts`, allocating all work buffers. Fails with
    /// [`IntegrationError::InvalidOptions`] if the options are invalid (see
    /// [`IntegratorOptions`]) or `dim == 0`. Call [`reset`](Self::reset)
    /// before stepping.
    pub fn new(dim: usize, opts: IntegratorOptions) -> Result<Self, IntegrationError> {
        let n_err = opts.validate(dim)?;
        Ok(Self {
            opts,
            n: dim,
            n_err,
            initialised: false,
            has_step: false,
            dense_ready: false,
            t: 0.0,
            t_prev: 0.0,
            h_last: 0.0,
            h_next: 0.0,
            previous_accepted: None,
            steps_since_reset: 0,
            stats: Stats::default(),
            stiff_count: 0,
            nonstiff_count: 0,
            y: vec![0.0; dim],
            dydt: vec![0.0; dim],
            y_prev: vec![0.0; dim],
            y_new: vec![0.0; dim],
            y_stage: vec![0.0; dim],
            k: vec![0.0; N_STAGES_EXTENDED * dim],
            k_acc: vec![0.0; N_STAGES_EXTENDED * dim],
            cont: vec![0.0; N_CONT * dim],
        })
    }

    /// Start (or restart, e.g. after a discontinuity) at (t0, y0): evaluates f(t0,y0), chooses h0.
    ///
    /// The initial step is `min(h_init, h_max)` if `h_init` is given, else
    /// Hairer's `HINIT` estimate (one more evaluation of `f`, at `t0 + h`
    /// with `h` an Euler guess). Statistics are *not* reset (they accumulate
    /// over the integrator's lifetime, see [`reset_stats`](Self::reset_stats));
    /// the step counter for [`IntegratorOptions::max_steps`] and the counters
    /// of the stiffness test are.
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
        self.initialised = false;
        self.has_step = false;
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
        self.has_step = false;
        self.dense_ready = false;
        self.steps_since_reset = 0;
        self.stiff_count = 0;
        self.nonstiff_count = 0;
        self.previous_accepted = None;
        self.h_next = match self.opts.h_init {
            Some(h) => h.min(self.opts.h_max),
            None => self.initial_step(sys),
        };
        self.initialised = true;
        Ok(())
    }

    /// Take ONE accepted step (internally retrying rejected attempts), never stepping past t_bound (> current t).
    ///
    /// `t_bound` may be `f64::INFINITY`. A step that ends within 1 % of a step
    /// size before `t_bound` is stretched to end exactly at `t_bound`.
    ///
    /// Errors: [`IntegrationError::InvalidOptions`] if called before a
    /// successful [`reset`](Self::reset), on a dimension mismatch, or if
    /// `t_bound <= t()` (or NaN); [`IntegrationError::TooManySteps`] if
    /// `max_steps` steps were already accepted since the reset;
    /// [`IntegrationError::StepSizeUnderflow`] if rejections shrink the step
    /// below the floor described at [`IntegratorOptions::h_min`]. On error the
    /// integrator's point (`t`, `y`, dense output) is unchanged.
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
        let n = self.n;
        self.k[..n].copy_from_slice(&self.dydt);
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
                    let mut fac =
                        (err.powf(ERROR_EXPONENT) / SAFETY).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                    // Gustafsson's predictive controller (as in Hairer's
                    // RADAU5/RODAS): when the error grows from step to step
                    // (an impact approaching: the exponential force steepens
                    // every step), shrink ahead of the trend instead of
                    // being rejected once per step.
                    if let Some((h_acc, err_acc)) = self.previous_accepted {
                        let gus = (h_acc / h) * (err * err / err_acc).powf(ERROR_EXPONENT) / SAFETY;
                        fac = fac.max(gus.clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN));
                    }
                    self.previous_accepted = Some((h, err.max(1e-2)));
                    let mut h_new = h / fac;
                    if rejected {
                        h_new = h_new.min(h);
                    } else if clipped {
                        h_new = h_new.max(h_planned);
                    }
                    if self.opts.stiffness_check {
                        self.test_stiffness(h);
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

    /// `f(t, y)` at the current point (reused as the first stage of the next
    /// step).
    pub fn dydt(&self) -> &[f64] {
        &self.dydt
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

    /// Dense output of the last accepted step (7th order), valid for t in [t_prev, t]; writes all components.
    ///
    /// Takes `&mut self` and the system because the three extra stages of
    /// the continuous extension are computed lazily: on the first dense
    /// request after a step (3 evaluations of `f`, counted in the stats),
    /// never for callers that do not interpolate. Later requests for the same
    /// step cost one polynomial evaluation per component. Requests at exactly
    /// `t_prev()` or `t()` return the stored states without evaluating `f`.
    /// Outside `[t_prev, t]` the polynomial is extrapolated (not accurate).
    /// Before the first step after a reset, the output is the current state.
    ///
    /// # Panics
    /// If `out.len()` differs from the dimension.
    pub fn dense_output<S: OdeSystem>(&mut self, sys: &mut S, t: f64, out: &mut [f64]) {
        assert_eq!(out.len(), self.n, "dense_output: wrong output length");
        if !self.has_step || t == self.t {
            out.copy_from_slice(&self.y);
        } else if t == self.t_prev {
            out.copy_from_slice(&self.y_prev);
        } else {
            self.prepare_dense(sys);
            let s = (t - self.t_prev) / self.h_last;
            for (o, c) in out.iter_mut().zip(self.cont.chunks_exact(N_CONT)) {
                *o = eval_cont(c, s);
            }
        }
    }

    /// Single component of the dense output (cheap: used inside root finding).
    ///
    /// Same semantics and laziness as [`dense_output`](Self::dense_output).
    ///
    /// # Panics
    /// If `i` is not below the dimension.
    pub fn dense_component<S: OdeSystem>(&mut self, sys: &mut S, i: usize, t: f64) -> f64 {
        assert!(i < self.n, "dense_component: index {i} out of range");
        if !self.has_step || t == self.t {
            self.y[i]
        } else if t == self.t_prev {
            self.y_prev[i]
        } else {
            self.prepare_dense(sys);
            let s = (t - self.t_prev) / self.h_last;
            eval_cont(&self.cont[N_CONT * i..N_CONT * (i + 1)], s)
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
        &self.opts
    }

    /// Whether the problem looks stiff: the stiffness test (see the module
    /// documentation and [`IntegratorOptions::stiffness_check`]) has counted
    /// at least 15 consecutive accepted steps whose size was limited by
    /// stability (`h·ρ > 6.1`), and not 6 consecutive unsuspicious steps
    /// since. Cleared by [`reset`](Self::reset); always `false` when the test
    /// is switched off.
    ///
    /// Limit of Hairer's test: at tight tolerances the controller may keep a
    /// stability-limited step below the threshold (measured on
    /// `y' = −1e4 (y − cos t)` at rtol = atol = 1e-10: `h·λ ≈ 4.97`), so
    /// *mildly* stiff problems can go undetected there; strongly stiff ones
    /// (`λ = 1e6`, tolerance 1e-12) are detected within a few dozen steps.
    pub fn stiffness_detected(&self) -> bool {
        self.stiff_count >= STIFF_STEPS
    }

    /// Number of consecutive suspicious steps counted by the stiffness test
    /// (Hairer's `IASTI`; reaching 15 means [`stiffness_detected`](Self::stiffness_detected)).
    pub fn stiff_step_count(&self) -> u32 {
        self.stiff_count
    }

    /// Whether a successful [`reset`](Self::reset) has happened (stepping is
    /// allowed).
    pub(super) fn is_initialised(&self) -> bool {
        self.initialised
    }

    /// Hairer's stiffness test on the attempt just accepted (before
    /// [`accept`](Self::accept) swaps the buffers): `y_stage` holds the
    /// argument of stage 11 (`c = 1`), `k` its derivative and `f(t+h, y_new)`.
    fn test_stiffness(&mut self, h: f64) {
        let n = self.n;
        let k12 = &self.k[(N_STAGES - 1) * n..N_STAGES * n];
        let f_new = &self.k[FSAL_STAGE * n..(FSAL_STAGE + 1) * n];
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..n {
            num += (f_new[i] - k12[i]).powi(2);
            den += (self.y_new[i] - self.y_stage[i]).powi(2);
        }
        if den > 0.0 && h * (num / den).sqrt() > STIFF_H_RHO {
            self.nonstiff_count = 0;
            self.stiff_count = self.stiff_count.saturating_add(1);
        } else {
            self.nonstiff_count = self.nonstiff_count.saturating_add(1);
            if self.nonstiff_count >= NONSTIFF_STEPS {
                self.stiff_count = 0;
            }
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

    /// Hairer's `HINIT`: initial step size guess from `y0`, `f(t0, y0)` and
    /// one more evaluation of `f` (explicit Euler step). If that evaluation
    /// is not finite, the Euler guess itself is returned (the step loop then
    /// shrinks it as needed).
    fn initial_step<S: OdeSystem>(&mut self, sys: &mut S) -> f64 {
        let n = self.n;
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
        let f1 = &mut self.k[n..2 * n];
        sys.rhs(self.t + h, &self.y_stage, f1);
        self.stats.rhs_evaluations += 1;
        let mut der2 = 0.0;
        for i in 0..self.n_err {
            let sk = self.weight(self.y[i], 0.0);
            der2 += ((self.k[n + i] - self.dydt[i]) / sk).powi(2);
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

    /// One attempt of size `h` from the current point, ending at `t_new`.
    /// Returns the error norm (`<= 1`) if the attempt is acceptable (then
    /// `y_new` and all 13 stages, incl. `f(t_new, y_new)`, are in `y_new`,
    /// `k`), else the reason and the factor for the next step size.
    fn attempt<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        h: f64,
        t_new: f64,
    ) -> Result<f64, (RejectReason, f64)> {
        let n = self.n;
        let hard = (RejectReason::NonFinite, SHRINK_HARD);
        for s in 1..N_STAGES {
            combine(&self.y, &self.k[..s * n], A[s], h, &mut self.y_stage);
            let ks = &mut self.k[s * n..(s + 1) * n];
            sys.rhs(self.t + C[s] * h, &self.y_stage, ks);
            self.stats.rhs_evaluations += 1;
            if !all_finite(ks) {
                return Err(hard);
            }
        }
        combine(&self.y, &self.k[..N_STAGES * n], &B, h, &mut self.y_new);
        if !all_finite(&self.y_new) {
            return Err(hard);
        }
        if !sys.admissible(t_new, &self.y_new) {
            return Err((RejectReason::NotAdmissible, SHRINK_HARD));
        }
        let (mut err5, mut err3) = (0.0, 0.0);
        for i in 0..self.n_err {
            let sk = self.weight(self.y[i], self.y_new[i]);
            let (mut e5, mut e3) = (0.0, 0.0);
            for j in 0..N_STAGES {
                let kj = self.k[j * n + i];
                e5 += E5[j] * kj;
                e3 += E3[j] * kj;
            }
            err5 += (e5 / sk).powi(2);
            err3 += (e3 / sk).powi(2);
        }
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        let err = h.abs() * err5 / (self.n_err as f64 * deno).sqrt();
        if !err.is_finite() {
            return Err(hard);
        }
        if err > 1.0 {
            let factor = FAC_MIN.max(SAFETY / err.powf(ERROR_EXPONENT));
            return Err((RejectReason::ErrorEstimate, factor));
        }
        let f_new = &mut self.k[FSAL_STAGE * n..(FSAL_STAGE + 1) * n];
        sys.rhs(t_new, &self.y_new, f_new);
        self.stats.rhs_evaluations += 1;
        if !all_finite(f_new) {
            return Err(hard);
        }
        Ok(err)
    }

    /// Commits the successful attempt: the attempt's stages become the
    /// accepted step's (buffer swap, no copy of the stages).
    fn accept(&mut self, t_new: f64, h: f64, h_next: f64) {
        let n = self.n;
        std::mem::swap(&mut self.k, &mut self.k_acc);
        std::mem::swap(&mut self.y_prev, &mut self.y);
        std::mem::swap(&mut self.y, &mut self.y_new);
        self.dydt
            .copy_from_slice(&self.k_acc[FSAL_STAGE * n..(FSAL_STAGE + 1) * n]);
        self.t_prev = self.t;
        self.t = t_new;
        self.h_last = h;
        self.h_next = h_next;
        self.has_step = true;
        self.dense_ready = false;
        self.steps_since_reset += 1;
        self.stats.steps += 1;
    }

    /// Computes the 3 extra stages and the dense-output coefficients of the
    /// last accepted step, once per step.
    fn prepare_dense<S: OdeSystem>(&mut self, sys: &mut S) {
        if self.dense_ready {
            return;
        }
        let n = self.n;
        let h = self.h_last;
        for s in FSAL_STAGE + 1..N_STAGES_EXTENDED {
            combine(
                &self.y_prev,
                &self.k_acc[..s * n],
                A[s],
                h,
                &mut self.y_stage,
            );
            sys.rhs(
                self.t_prev + C[s] * h,
                &self.y_stage,
                &mut self.k_acc[s * n..(s + 1) * n],
            );
            self.stats.rhs_evaluations += 1;
        }
        for (i, c) in self.cont.chunks_exact_mut(N_CONT).enumerate() {
            let ydiff = self.y[i] - self.y_prev[i];
            let bspl = h * self.k_acc[i] - ydiff;
            c[0] = self.y_prev[i];
            c[1] = ydiff;
            c[2] = bspl;
            c[3] = ydiff - h * self.k_acc[FSAL_STAGE * n + i] - bspl;
            for (cm, d) in c[4..].iter_mut().zip(&D) {
                let mut acc = 0.0;
                for (j, &dj) in d.iter().enumerate() {
                    if dj != 0.0 {
                        acc += dj * self.k_acc[j * n + i];
                    }
                }
                *cm = h * acc;
            }
        }
        self.dense_ready = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::integrate_to;
    use std::cell::Cell;

    // ---------------------------------------------------------------------
    // Test systems.
    // ---------------------------------------------------------------------

    /// Harmonic oscillator y1' = y2, y2' = -y1; from (1, 0): (cos t, -sin t).
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

    /// Nonlinear, non-autonomous: y1' = -2 t y1², y2' = y2 cos t; from (1, 1):
    /// (1/(1+t²), exp(sin t)).
    struct Nonlinear;
    impl OdeSystem for Nonlinear {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -2.0 * t * y[0] * y[0];
            d[1] = y[1] * t.cos();
        }
    }

    const ZETA: f64 = 0.1;
    /// Damped oscillator x'' + 2ζx' + x = 0.
    struct Damped;
    impl OdeSystem for Damped {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[1];
            d[1] = -y[0] - 2.0 * ZETA * y[1];
        }
    }
    /// Exact solution of [`Damped`] from (1, 0).
    fn damped_exact(t: f64) -> [f64; 2] {
        let w = (1.0 - ZETA * ZETA).sqrt();
        let e = (-ZETA * t).exp();
        [
            e * ((w * t).cos() + ZETA / w * (w * t).sin()),
            -e * (w * t).sin() / w,
        ]
    }

    /// y' = -y (exact: y0·e^{-t}) with traps: `f` is NaN where |y| > `nan_above`
    /// or t > `nan_after`; states are admissible only in
    /// [`admissible_min`, `admissible_max`]. Counts the traps that fired.
    struct Decay {
        nan_above: f64,
        nan_after: f64,
        admissible_min: f64,
        admissible_max: f64,
        nan_returns: u64,
        inadmissible: Cell<u64>,
    }
    impl Decay {
        fn new() -> Self {
            Self {
                nan_above: f64::INFINITY,
                nan_after: f64::INFINITY,
                admissible_min: f64::NEG_INFINITY,
                admissible_max: f64::INFINITY,
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
            if y[0].abs() > self.nan_above || t > self.nan_after {
                self.nan_returns += 1;
                d[0] = f64::NAN;
            } else {
                d[0] = -y[0];
            }
        }
        fn admissible(&self, _t: f64, y: &[f64]) -> bool {
            let ok = (self.admissible_min..=self.admissible_max).contains(&y[0]);
            if !ok {
                self.inadmissible.set(self.inadmissible.get() + 1);
            }
            ok
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

    // ---------------------------------------------------------------------
    // 1. Tableau.
    // ---------------------------------------------------------------------

    /// All rooted trees up to `max_order`, as (order, children): children are
    /// indices of earlier trees, non-increasing, so each tree appears once.
    fn rooted_trees(max_order: usize) -> Vec<(usize, Vec<usize>)> {
        fn multisets(
            trees: &[(usize, Vec<usize>)],
            remaining: usize,
            max_idx: usize,
            current: &mut Vec<usize>,
            out: &mut Vec<Vec<usize>>,
        ) {
            if remaining == 0 {
                out.push(current.clone());
                return;
            }
            for idx in (0..=max_idx).rev() {
                if trees[idx].0 <= remaining {
                    current.push(idx);
                    multisets(trees, remaining - trees[idx].0, idx, current, out);
                    current.pop();
                }
            }
        }
        let mut trees: Vec<(usize, Vec<usize>)> = vec![(1, vec![])];
        for order in 2..=max_order {
            let existing = trees.len();
            let mut children = Vec::new();
            multisets(
                &trees[..existing],
                order - 1,
                existing - 1,
                &mut Vec::new(),
                &mut children,
            );
            trees.extend(children.into_iter().map(|c| (order, c)));
        }
        trees
    }

    /// Per tree: density γ(t) and the stage vector Φ_i(t) of the extended
    /// 16-stage tableau (`Φ_i(•) = 1`, `Φ_i([t1..tm]) = Π_k Σ_j a_ij Φ_j(t_k)`).
    fn tree_data(trees: &[(usize, Vec<usize>)]) -> Vec<(f64, [f64; N_STAGES_EXTENDED])> {
        let mut data: Vec<(f64, [f64; N_STAGES_EXTENDED])> = Vec::new();
        for (order, children) in trees {
            let mut gamma = *order as f64;
            let mut phi = [1.0; N_STAGES_EXTENDED];
            for &c in children {
                let (g, pc) = data[c];
                gamma *= g;
                for (i, p) in phi.iter_mut().enumerate() {
                    let a_phi: f64 = A[i].iter().zip(&pc).map(|(a, x)| a * x).sum();
                    *p *= a_phi;
                }
            }
            data.push((gamma, phi));
        }
        data
    }

    fn dot(w: &[f64], phi: &[f64]) -> f64 {
        w.iter().zip(phi).map(|(a, b)| a * b).sum()
    }

    /// Weights b_i(θ) of the continuous extension (per unit h), built from
    /// the same Horner form as the code ([`eval_cont`]).
    fn dense_weights(theta: f64) -> [f64; N_STAGES_EXTENDED] {
        let mut r = [[0.0; N_STAGES_EXTENDED]; N_CONT];
        for (i, &b) in B.iter().enumerate() {
            r[1][i] = b;
            r[2][i] = -b;
            r[3][i] = 2.0 * b;
        }
        r[2][0] += 1.0;
        r[3][0] -= 1.0;
        r[3][FSAL_STAGE] -= 1.0;
        r[4..].copy_from_slice(&D);
        let mut w = [0.0; N_STAGES_EXTENDED];
        for (i, wi) in w.iter_mut().enumerate() {
            let c: Vec<f64> = (0..N_CONT).map(|m| r[m][i]).collect();
            *wi = eval_cont(&c, theta);
        }
        w
    }

    #[test]
    fn tableau_row_sums_and_shape() {
        for s in 0..N_STAGES_EXTENDED {
            assert_eq!(A[s].len(), s, "row {s} must have {s} entries");
            let sum: f64 = A[s].iter().sum();
            assert!(
                (sum - C[s]).abs() < 1e-14,
                "c_{s} = {} but row sum {sum}",
                C[s]
            );
        }
        let sum_b: f64 = B.iter().sum();
        assert!((sum_b - 1.0).abs() < 1e-14, "sum b = {sum_b}");
        assert_eq!(A[FSAL_STAGE], &B[..]);
        // Row sums: measured residual 6.1e-15 at worst.
    }

    #[test]
    fn tableau_order_conditions() {
        let trees = rooted_trees(8);
        let mut counts = [0usize; 9];
        for t in &trees {
            counts[t.0] += 1;
        }
        // Number of rooted trees (OEIS A000081): checks the enumeration.
        assert_eq!(counts, [0, 1, 1, 2, 4, 9, 20, 48, 115]);
        let data = tree_data(&trees);
        for ((order, _), (gamma, phi)) in trees.iter().zip(&data) {
            // 8th-order solution: all 200 conditions of orders 1..=8
            // (measured residual <= 2.2e-15).
            let r = dot(&B, phi) - 1.0 / gamma;
            assert!(r.abs() < 1e-14, "b: order {order}, residual {r:e}");
            // Embedded estimators vanish on trees up to order 5 resp. 3
            // (measured <= 4.5e-15) and not beyond (measured >= 4.5e-4 at
            // order 6 resp. 0.025 at order 4 for some tree).
            let e5 = dot(&E5, phi);
            let e3 = dot(&E3, phi);
            if *order <= 5 {
                assert!(e5.abs() < 1e-14, "E5: order {order}, {e5:e}");
            }
            if *order <= 3 {
                assert!(e3.abs() < 1e-14, "E3: order {order}, {e3:e}");
            }
        }
        let max_at = |w: &[f64], o: usize| {
            trees
                .iter()
                .zip(&data)
                .filter(|(t, _)| t.0 == o)
                .map(|(_, (_, phi))| dot(w, phi).abs())
                .fold(0.0, f64::max)
        };
        assert!(max_at(&E5, 6) > 1e-4);
        assert!(max_at(&E3, 4) > 1e-2);
    }

    #[test]
    fn dense_output_order_conditions() {
        let trees = rooted_trees(8);
        let data = tree_data(&trees);
        for theta in [0.1, 0.3, 0.5, 0.77, 0.9, 1.0] {
            let w = dense_weights(theta);
            let mut worst8 = 0.0f64;
            for ((order, _), (gamma, phi)) in trees.iter().zip(&data) {
                let r = dot(&w, phi) - theta.powi(*order as i32) / gamma;
                if *order <= 7 {
                    // Continuous extension of order 7 (measured <= 2.9e-15).
                    assert!(r.abs() < 1e-14, "θ = {theta}, order {order}: {r:e}");
                } else {
                    worst8 = worst8.max(r.abs());
                }
            }
            // ... and not of order 8 inside the step (measured >= 7e-6).
            if theta < 1.0 {
                assert!(worst8 > 1e-6, "θ = {theta}: {worst8:e}");
            }
        }
    }

    // ---------------------------------------------------------------------
    // 2. Convergence order with fixed steps.
    // ---------------------------------------------------------------------

    fn harmonic_error(h: f64) -> f64 {
        let (y, st) = integrate_to(&mut Harmonic, 0.0, &[1.0, 0.0], 10.0, &fixed(h)).unwrap();
        assert_eq!(st.rejected_steps, 0);
        assert_eq!(st.steps, (10.0 / h).round() as u64);
        (y[0] - 10f64.cos()).hypot(y[1] + 10f64.sin())
    }

    #[test]
    fn convergence_order_is_8() {
        // Harmonic oscillator over [0, 10], h = 1.25 … 0.15625.
        // Measured errors: 4.09e-6, 1.52e-8, 5.85e-11, 2.28e-13, i.e. observed
        // orders 8.07, 8.02, 8.01. Below h ≈ 0.08 round-off (1e-15) dominates.
        let hs = [1.25, 0.625, 0.3125, 0.15625];
        let errs: Vec<f64> = hs.iter().map(|&h| harmonic_error(h)).collect();
        for w in errs.windows(2) {
            let p = observed_order(w[0], w[1]);
            assert!((7.5..=8.5).contains(&p), "order {p} from errors {errs:?}");
        }
        // Nonlinear, non-autonomous problem, h = 0.625 → 0.3125: errors
        // 4.29e-8 → 1.35e-10, order 8.3.
        let err = |h: f64| {
            let (y, _) = integrate_to(&mut Nonlinear, 0.0, &[1.0, 1.0], 10.0, &fixed(h)).unwrap();
            (y[0] - 1.0 / 101.0)
                .abs()
                .max((y[1] - 10f64.sin().exp()).abs())
        };
        let p = observed_order(err(0.625), err(0.3125));
        assert!((7.5..=8.5).contains(&p), "nonlinear order {p}");
    }

    // ---------------------------------------------------------------------
    // 3. Adaptive accuracy.
    // ---------------------------------------------------------------------

    /// Damped oscillator over [0, 20] at rtol = atol = `tol`: relative final
    /// error, worst dense-output error at 7 interior points per step, stats.
    fn damped_run(tol_: f64) -> (f64, f64, Stats) {
        let mut s = Dop853::new(2, tol(tol_)).unwrap();
        s.reset(&mut Damped, 0.0, &[1.0, 0.0]).unwrap();
        let mut worst_dense = 0.0f64;
        let mut out = [0.0; 2];
        while s.t() < 20.0 {
            s.step(&mut Damped, 20.0).unwrap();
            for j in 1..8 {
                let tt = s.t_prev() + (s.t() - s.t_prev()) * f64::from(j) / 8.0;
                s.dense_output(&mut Damped, tt, &mut out);
                let ex = damped_exact(tt);
                worst_dense = worst_dense.max((out[0] - ex[0]).abs().max((out[1] - ex[1]).abs()));
            }
        }
        assert_eq!(s.t(), 20.0);
        let ex = damped_exact(20.0);
        let y = s.y();
        let rel = (y[0] - ex[0]).hypot(y[1] - ex[1]) / ex[0].hypot(ex[1]);
        (rel, worst_dense, s.stats())
    }

    #[test]
    fn adaptive_accuracy_damped_oscillator() {
        // Measured (rel. final error, dense error, steps):
        // 1e-6: 5.8e-6, 2.4e-6, 19;  1e-8: 6.2e-8, 2.4e-8, 31;
        // 1e-10: 6.5e-10, 2.3e-10, 54;  1e-12: 6.7e-12, 2.4e-12, 95.
        let runs: Vec<_> = [1e-6, 1e-8, 1e-10, 1e-12]
            .iter()
            .map(|&t| (t, damped_run(t)))
            .collect();
        for (t, (rel, dense, _)) in &runs {
            // Global error within a small multiple of the tolerance, dense
            // output as accurate as the step end points.
            assert!(*rel < 50.0 * t, "tol {t:e}: rel error {rel:e}");
            assert!(*dense < 20.0 * t, "tol {t:e}: dense error {dense:e}");
        }
        assert!(
            runs[2].1 .0 < 1e-8,
            "rtol 1e-10: rel error {:e}",
            runs[2].1 .0
        );
        for w in runs.windows(2) {
            assert!(w[1].1 .0 < 0.1 * w[0].1 .0, "error must decrease with rtol");
            assert!(w[1].1 .2.steps > w[0].1 .2.steps);
        }
    }

    // ---------------------------------------------------------------------
    // 4. Dense output.
    // ---------------------------------------------------------------------

    #[test]
    fn dense_output_is_7th_order() {
        // Fixed steps on the harmonic oscillator; at mid-step compare the dense
        // output with the exact solution through (t_prev, y_prev) (local
        // interpolation error, O(h^8) for a 7th-order extension) and with the
        // exact solution (global, also O(h^8)).
        // Measured local errors: h = 1.25: 4.99e-6, 0.625: 1.83e-8,
        // 0.3125: 7.05e-11, 0.15625: 2.74e-13 (orders 8.09, 8.02, 8.01).
        let run = |h: f64| {
            let mut s = Dop853::new(2, fixed(h)).unwrap();
            s.reset(&mut Harmonic, 0.0, &[1.0, 0.0]).unwrap();
            let (mut local, mut global) = (0.0f64, 0.0f64);
            let mut out = [0.0; 2];
            while s.t() < 10.0 {
                s.step(&mut Harmonic, 10.0).unwrap();
                let tm = 0.5 * (s.t_prev() + s.t());
                s.dense_output(&mut Harmonic, tm, &mut out);
                let c1 = s.dense_component(&mut Harmonic, 1, tm);
                assert_eq!(c1, out[1], "component and full dense output agree");
                let (yp0, yp1) = (s.y_prev[0], s.y_prev[1]);
                let dt = tm - s.t_prev();
                let loc = [
                    yp0 * dt.cos() + yp1 * dt.sin(),
                    yp1 * dt.cos() - yp0 * dt.sin(),
                ];
                local = local.max((out[0] - loc[0]).abs().max((out[1] - loc[1]).abs()));
                global = global.max((out[0] - tm.cos()).abs().max((out[1] + tm.sin()).abs()));
            }
            (local, global)
        };
        let res: Vec<(f64, f64)> = [1.25, 0.625, 0.3125, 0.15625]
            .iter()
            .map(|&h| run(h))
            .collect();
        for w in res.windows(2) {
            let p_local = observed_order(w[0].0, w[1].0);
            let p_global = observed_order(w[0].1, w[1].1);
            assert!(
                (7.5..=8.5).contains(&p_local),
                "local dense order {p_local}: {res:?}"
            );
            assert!(
                (7.5..=8.5).contains(&p_global),
                "global dense order {p_global}: {res:?}"
            );
        }
    }

    #[test]
    fn dense_output_end_points_and_before_first_step() {
        let mut sys = Damped;
        let mut s = Dop853::new(2, tol(1e-9)).unwrap();
        s.reset(&mut sys, 1.0, &[0.5, -0.25]).unwrap();
        let mut out = [0.0; 2];
        // Before the first step: the current state, no evaluation.
        let before = s.stats().rhs_evaluations;
        s.dense_output(&mut sys, 1.0, &mut out);
        assert_eq!(out, [0.5, -0.25]);
        s.step(&mut sys, 10.0).unwrap();
        let y_prev = [0.5, -0.25];
        let y = [s.y()[0], s.y()[1]];
        let after_step = s.stats().rhs_evaluations;
        s.dense_output(&mut sys, s.t(), &mut out);
        assert_eq!(out, y);
        s.dense_output(&mut sys, s.t_prev(), &mut out);
        assert_eq!(out, y_prev);
        assert_eq!(s.stats().rhs_evaluations, after_step, "end points are free");
        // Interior points near the ends are continuous with them.
        let h = s.t() - s.t_prev();
        for i in 0..2 {
            let near_end = s.dense_component(&mut sys, i, s.t() - 1e-9 * h);
            let near_start = s.dense_component(&mut sys, i, s.t_prev() + 1e-9 * h);
            assert!((near_end - y[i]).abs() < 1e-9 * h, "{near_end} vs {}", y[i]);
            assert!((near_start - y_prev[i]).abs() < 1e-9 * h);
        }
        assert!(before > 0);
    }

    // ---------------------------------------------------------------------
    // 5. NaN safety.
    // ---------------------------------------------------------------------

    #[test]
    fn nan_in_stages_is_rejected_and_recovered() {
        // y' = -y, y(0) = 1, but f = NaN for |y| > 1.5. A first step of 10
        // (far outside the stability region) produces stage values beyond
        // 1.5; the step must be rejected and retried, the solution stays
        // finite and accurate.
        let mut sys = Decay::new();
        sys.nan_above = 1.5;
        let opts = IntegratorOptions {
            h_init: Some(10.0),
            ..tol(1e-10)
        };
        let mut s = Dop853::new(1, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0]).unwrap();
        s.step(&mut sys, 10.0).unwrap();
        let first = s.stats();
        assert!(sys.nan_returns > 0, "the trap must fire");
        assert!(first.rejected_steps > 0);
        assert!(s.t() < 10.0);
        // After rejections the accepted step does not propose a larger step.
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
        // f = NaN for t > 0.7: the integrator creeps up to 0.7 and gives up
        // with StepSizeUnderflow at t ≈ 0.7, reason NonFinite.
        let mut sys = Decay::new();
        sys.nan_after = 0.7;
        let err = integrate_to(&mut sys, 0.0, &[1.0], 2.0, &tol(1e-10)).unwrap_err();
        match &err {
            IntegrationError::StepSizeUnderflow { t, h, y, reason } => {
                assert_eq!(*reason, RejectReason::NonFinite);
                assert!(*t <= 0.7 && 0.7 - t < 1e-12, "t = {t}");
                assert!(*h < 16.0 * f64::EPSILON * t);
                assert!((y[0] - (-t).exp()).abs() < 1e-10, "y = {y:?}");
                // The message carries t, h, y and the reason.
                let msg = err.to_string();
                for part in [
                    "underflow".to_string(),
                    format!("t = {t:e}"),
                    format!("h = {h:e}"),
                    format!("{y:?}"),
                    RejectReason::NonFinite.to_string(),
                ] {
                    assert!(msg.contains(&part), "{msg:?} lacks {part:?}");
                }
            }
            other => panic!("unexpected error {other:?}"),
        }
    }

    // ---------------------------------------------------------------------
    // 6. Admissibility.
    // ---------------------------------------------------------------------

    #[test]
    fn inadmissible_state_is_rejected_and_recovered() {
        // Exact solution e^{-t} stays in (0, 1]; a first step of 10 lands
        // outside and must be rejected as not admissible.
        let mut sys = Decay::new();
        sys.admissible_min = 0.0;
        sys.admissible_max = 1.0;
        let opts = IntegratorOptions {
            h_init: Some(10.0),
            ..tol(1e-10)
        };
        let mut s = Dop853::new(1, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0]).unwrap();
        while s.t() < 10.0 {
            s.step(&mut sys, 10.0).unwrap();
        }
        assert!(
            sys.inadmissible.get() > 0,
            "the admissibility test must fire"
        );
        assert!(s.stats().rejected_steps >= sys.inadmissible.get());
        let err = (s.y()[0] - (-10f64).exp()).abs();
        assert!(err < 1e-10, "final error {err:e}");
    }

    #[test]
    fn inadmissible_region_gives_underflow_at_boundary() {
        // Admissible only while y >= 0.3: integration stops at t* = ln(1/0.3).
        let mut sys = Decay::new();
        sys.admissible_min = 0.3;
        let t_star = (1.0f64 / 0.3).ln();
        match integrate_to(&mut sys, 0.0, &[1.0], 3.0, &tol(1e-10)) {
            Err(IntegrationError::StepSizeUnderflow { t, y, reason, .. }) => {
                assert_eq!(reason, RejectReason::NotAdmissible);
                assert!((t - t_star).abs() < 1e-9, "t = {t}, t* = {t_star}");
                assert!(y[0] >= 0.3);
            }
            other => panic!("unexpected result {other:?}"),
        }
    }

    // ---------------------------------------------------------------------
    // 7. Statistics.
    // ---------------------------------------------------------------------

    #[test]
    fn stats_count_every_evaluation() {
        // Accounting: reset = 1 evaluation (+1 for the automatic initial
        // step); every attempt = 11 stages; every accepted step + 1
        // (f at the new point); dense output = 3 per step, once.
        let mut sys = Harmonic;
        let mut s = Dop853::new(2, tol(1e-10)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        assert_eq!(s.stats().rhs_evaluations, 2, "f(t0, y0) + HINIT");
        let opts = IntegratorOptions {
            h_init: Some(5.0),
            ..tol(1e-10)
        };
        let mut s = Dop853::new(2, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        assert_eq!(s.stats().rhs_evaluations, 1, "f(t0, y0) only");
        let mut dense_steps = 0;
        let mut interpolate = false;
        let mut out = [0.0; 2];
        while s.t() < 10.0 {
            s.step(&mut sys, 10.0).unwrap();
            // Interpolate in every other step only.
            interpolate = !interpolate;
            if interpolate {
                dense_steps += 1;
                let tm = 0.5 * (s.t_prev() + s.t());
                s.dense_output(&mut sys, tm, &mut out);
                s.dense_component(&mut sys, 0, 0.25 * s.t_prev() + 0.75 * s.t());
            }
        }
        let st = s.stats();
        assert!(st.rejected_steps > 0, "h_init = 5 must be rejected");
        assert!(dense_steps > 5);
        assert_eq!(
            st.rhs_evaluations,
            1 + 11 * (st.steps + st.rejected_steps) + st.steps + 3 * dense_steps
        );
        // Stats survive reset(), not reset_stats().
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        assert_eq!(s.stats().steps, st.steps);
        assert_eq!(s.stats().rhs_evaluations, st.rhs_evaluations + 1);
        s.reset_stats();
        assert_eq!(s.stats(), Stats::default());
    }

    // ---------------------------------------------------------------------
    // Further behaviour.
    // ---------------------------------------------------------------------

    #[test]
    fn error_components_exclude_trailing_equations() {
        // y' = -y with an appended wildly growing z' = 50 z: with
        // error_components = Some(1), z does not influence the step sizes.
        struct WithGrowth;
        impl OdeSystem for WithGrowth {
            fn dim(&self) -> usize {
                2
            }
            fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
                d[0] = -y[0];
                d[1] = 50.0 * y[1];
            }
        }
        let opts = IntegratorOptions {
            error_components: Some(1),
            ..tol(1e-8)
        };
        let (y2, st2) = integrate_to(&mut WithGrowth, 0.0, &[1.0, 1.0], 2.0, &opts).unwrap();
        let (y1, st1) = integrate_to(&mut Decay::new(), 0.0, &[1.0], 2.0, &tol(1e-8)).unwrap();
        assert_eq!(y1[0], y2[0]);
        assert_eq!(st1.steps, st2.steps);
        let (_, st_all) = integrate_to(&mut WithGrowth, 0.0, &[1.0, 1.0], 2.0, &tol(1e-8)).unwrap();
        assert!(st_all.steps > 2 * st2.steps, "{st_all:?} vs {st2:?}");
    }

    #[test]
    fn bounds_and_step_limits() {
        let opts = IntegratorOptions {
            h_max: 0.3,
            ..tol(1e-6)
        };
        let mut sys = Harmonic;
        let mut s = Dop853::new(2, opts).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        let h0 = s.h_next();
        assert!(h0 > 1e-2 && h0 <= 0.3, "h0 = {h0}");
        // Hitting a close bound exactly does not spoil the next step size.
        s.step(&mut sys, 1e-3).unwrap();
        assert_eq!(s.t(), 1e-3);
        assert!(s.h_next() >= h0, "h_next = {}, h0 = {h0}", s.h_next());
        let mut t_old = s.t();
        while s.t() < 5.0 {
            s.step(&mut sys, 5.0).unwrap();
            assert!(s.t() - t_old <= 0.3 * (1.0 + 1e-12));
            assert!(s.t() <= 5.0);
            t_old = s.t();
        }
        assert_eq!(s.t(), 5.0);
        assert!((s.y()[0] - 5f64.cos()).abs() < 1e-5);
        let d = s.dydt();
        assert_eq!(d, [s.y()[1], -s.y()[0]]);
        assert!(matches!(
            s.step(&mut sys, 5.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
        // Unbounded stepping is allowed.
        s.step(&mut sys, f64::INFINITY).unwrap();
        assert!(s.t() > 5.0);
    }

    #[test]
    fn too_many_steps() {
        let opts = IntegratorOptions {
            max_steps: 5,
            h_init: Some(0.1),
            h_max: 0.1,
            ..tol(1e-8)
        };
        match integrate_to(&mut Harmonic, 0.0, &[1.0, 0.0], 1.0, &opts) {
            Err(IntegrationError::TooManySteps { t, steps }) => {
                assert_eq!(steps, 5);
                assert!((t - 0.5).abs() < 1e-12, "t = {t}");
            }
            other => panic!("unexpected result {other:?}"),
        }
    }

    #[test]
    fn invalid_options_and_initial_states() {
        let bad = |o: IntegratorOptions| {
            matches!(Dop853::new(2, o), Err(IntegrationError::InvalidOptions(_)))
        };
        assert!(bad(tol(0.0)));
        assert!(bad(IntegratorOptions {
            atol: -1.0,
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            rtol: f64::NAN,
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            h_init: Some(0.0),
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            h_max: 0.0,
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            h_min: 2.0,
            h_max: 1.0,
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            max_steps: 0,
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            error_components: Some(0),
            ..Default::default()
        }));
        assert!(bad(IntegratorOptions {
            error_components: Some(3),
            ..Default::default()
        }));
        assert!(matches!(
            Dop853::new(0, IntegratorOptions::default()),
            Err(IntegrationError::InvalidOptions(_))
        ));

        let mut s = Dop853::new(2, IntegratorOptions::default()).unwrap();
        let mut sys = Harmonic;
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
        nan_sys.nan_above = 0.5;
        let mut s1 = Dop853::new(1, IntegratorOptions::default()).unwrap();
        assert!(matches!(
            s1.reset(&mut nan_sys, 0.0, &[1.0]),
            Err(IntegrationError::NonFiniteInitialState { .. })
        ));
        assert!(matches!(
            s1.step(&mut nan_sys, 1.0),
            Err(IntegrationError::InvalidOptions(_))
        ));
        assert!(matches!(
            integrate_to(
                &mut sys,
                1.0,
                &[1.0, 0.0],
                1.0,
                &IntegratorOptions::default()
            ),
            Err(IntegrationError::InvalidOptions(_))
        ));
    }

    // ---------------------------------------------------------------------
    // 8. Stiffness test.
    // ---------------------------------------------------------------------

    /// y' = −λ (y − cos t).
    struct StiffLinear(f64);
    impl OdeSystem for StiffLinear {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -self.0 * (y[0] - t.cos());
        }
    }

    /// Steps over [0, t_end]; returns the first step number at which
    /// stiffness was reported, the largest suspicious-step count seen, and
    /// the final state.
    fn stiffness_run<S: OdeSystem>(
        sys: &mut S,
        y0: &[f64],
        t_end: f64,
        opts: IntegratorOptions,
    ) -> (Option<u64>, u32, Vec<f64>) {
        let mut s = Dop853::new(sys.dim(), opts).unwrap();
        s.reset(sys, 0.0, y0).unwrap();
        let (mut first, mut max_count) = (None, 0);
        while s.t() < t_end {
            s.step(sys, t_end).unwrap();
            max_count = max_count.max(s.stiff_step_count());
            if first.is_none() && s.stiffness_detected() {
                first = Some(s.stats().steps);
            }
        }
        (first, max_count, s.y().to_vec())
    }

    #[test]
    fn stiffness_test_fires_on_stiff_problems_only() {
        // y' = −λ (y − cos t) from y = 0 over [0, 0.1] or [0, 1]: after the
        // initial layer the step size is limited by stability, h·λ ≈ 6.39
        // (measured), and the test fires after a few dozen steps (measured
        // first detection at step 27, 28, 46, 212; the predictive controller
        // approaches the stability limit more cautiously at tol 1e-12).
        for (lambda, tl, t_end) in [
            (1e4, 1e-3, 1.0),
            (1e4, 1e-6, 1.0),
            (1e6, 1e-10, 0.1),
            (1e6, 1e-12, 0.1),
        ] {
            let (first, _, _) = stiffness_run(&mut StiffLinear(lambda), &[0.0], t_end, tol(tl));
            let first = first.unwrap_or_else(|| panic!("λ = {lambda:e}, tol {tl:e}: not detected"));
            assert!(
                first < 300,
                "λ = {lambda:e}, tol {tl:e}: detected at step {first}"
            );
        }
        // Mildly stiff at a tight tolerance: the controller keeps h·λ ≈ 4.97
        // < 6.1 (measured), Hairer's test does not fire (a known limit of
        // the test, documented at `stiffness_detected`).
        let (first, _, _) = stiffness_run(&mut StiffLinear(1e4), &[0.0], 1.0, tol(1e-10));
        assert_eq!(first, None);
        // Non-stiff problems never come close (measured: at most 2
        // consecutive suspicious steps, damped oscillator at tol 1e-3).
        for tl in [1e-3, 1e-6, 1e-9, 1e-12] {
            for (name, run) in [
                (
                    "harmonic",
                    stiffness_run(&mut Harmonic, &[1.0, 0.0], 100.0, tol(tl)),
                ),
                (
                    "damped",
                    stiffness_run(&mut Damped, &[1.0, 0.0], 100.0, tol(tl)),
                ),
            ] {
                assert_eq!(run.0, None, "{name}, tol {tl:e}");
                assert!(run.1 <= 3, "{name}, tol {tl:e}: {} suspicious steps", run.1);
            }
        }
    }

    #[test]
    fn stiffness_test_never_changes_the_solution() {
        for (lambda, tl) in [(1e4, 1e-6), (1e2, 1e-9)] {
            let off = IntegratorOptions {
                stiffness_check: false,
                ..tol(tl)
            };
            let (f_on, m_on, y_on) = stiffness_run(&mut StiffLinear(lambda), &[0.0], 1.0, tol(tl));
            let (f_off, m_off, y_off) = stiffness_run(&mut StiffLinear(lambda), &[0.0], 1.0, off);
            assert_eq!(y_on, y_off, "bitwise identical");
            assert_eq!((f_off, m_off), (None, 0));
            if lambda > 1e3 {
                assert!(f_on.is_some() && m_on >= 15);
            }
        }
        // Reset clears the counters.
        let mut s = Dop853::new(1, tol(1e-6)).unwrap();
        let mut sys = StiffLinear(1e4);
        s.reset(&mut sys, 0.0, &[0.0]).unwrap();
        while !s.stiffness_detected() {
            s.step(&mut sys, 1.0).unwrap();
        }
        let (t, y) = (s.t(), s.y().to_vec());
        s.reset(&mut sys, t, &y).unwrap();
        assert!(!s.stiffness_detected());
        assert_eq!(s.stiff_step_count(), 0);
    }
}
