//! The L-stable, stiffly accurate Rosenbrock method RODAS of order 4 with an
//! embedded method of order 3 and a continuous extension of order 3, after
//! E. Hairer's and G. Wanner's Fortran code `rodas.f` (Hairer & Wanner,
//! *Solving Ordinary Differential Equations II. Stiff and
//! Differential-Algebraic Problems*, 2nd ed., Springer 1996, Sec. IV.7 and
//! VI.3, as cited by `rodas.f`; `γ = 1/4`; often called RODAS4, e.g. in
//! DifferentialEquations.jl).
//!
//! Files: `mod.rs` (the method), `tests.rs` (order conditions, stiff
//! problems).
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
//! * **Step-size controller**: the shared [`Driver`]'s with
//!   `rodas.f`'s defaults, exponent `1/4` and `h_new >= h/5`, Gustafsson's
//!   predictive controller included. Initial step: `h_init`, else Hairer's
//!   `HINIT` estimate for order 4 (one extra evaluation of `f`).
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
//!   stretch) and [`IntegrationError::StepSizeUnderflow`] are the driver's.
//! * **Evaluation count**: `f(t0, y0)` on reset (+1 for `HINIT`); per step
//!   the Jacobian (`0` evaluations if analytic, else the number of column
//!   groups) and `f_t` (1); per attempt 5 stages (fewer if stopped early);
//!   `f(t + h, y_new)` once the error test passed (the first stage of the
//!   next step). Dense output is free.
//!
//! All buffers, including the two band matrices, are allocated by
//! `Rodas::with_bandwidth`; `Rodas::new` defers the matrices to the first
//! `Rodas::reset`, where they are shaped by
//! [`OdeSystem::jacobian_bandwidth`] (and reallocated only if a later system
//! has a different shape). Stepping and dense output do not allocate.

use super::driver::{
    all_finite, Attempt, Driver, Point, StepMethod, Trial, NON_FINITE, SHRINK_HARD,
};
use super::{IntegrationError, IntegratorOptions, OdeSystem, RejectReason, Stats};
use crate::linalg::BandMatrix;

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

/// Factor applied to `h` after a singular iteration matrix.
const SHRINK_SINGULAR: f64 = 0.5;

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
/// accurate) with 3rd-order dense output, for stiff systems: the shared
/// [`Driver`] around the [`RodasMethod`], with the same interface and
/// semantics as [`Dop853`](super::Dop853).
pub type Rodas = Driver<RodasMethod>;

/// The stages, Jacobian, error estimate and dense output of RODAS (see the
/// module documentation).
#[derive(Clone, Debug)]
pub struct RodasMethod {
    /// Whether `jac` and `f_t` belong to the current point `(t, y)`.
    jac_current: bool,
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

impl Driver<RodasMethod> {
    /// As `new`, but also allocates the Jacobian and iteration matrices for
    /// Jacobian bandwidths `bandwidth` (`None`: dense), so that a `reset`
    /// with a system of that
    /// [`jacobian_bandwidth`](OdeSystem::jacobian_bandwidth) does not
    /// allocate.
    pub fn with_bandwidth(
        dim: usize,
        opts: IntegratorOptions,
        bandwidth: Option<(usize, usize)>,
    ) -> Result<Self, IntegrationError> {
        let (kl, ku) = bandwidth.unwrap_or((dim, dim));
        let mut method = RodasMethod::new(dim);
        method.jac = BandMatrix::new(dim, kl, ku);
        method.lu = method.jac.clone();
        Self::with_method(dim, opts, method)
    }
}

impl Driver<RodasMethod> {
    /// Gershgorin bound `max_i Σ_j |J_ij|` of the Jacobian of the last step
    /// (an upper bound of its spectral radius; 0 before the first step).
    /// `h · bound` well below the explicit methods' stability limit (about
    /// 6) says an explicit method could take this step too.
    pub fn jacobian_bound(&self) -> f64 {
        let jac = &self.method.jac;
        let n = jac.n();
        let (kl, ku) = jac.bandwidths();
        (0..n)
            .map(|i| {
                (i.saturating_sub(kl)..=(i + ku).min(n.saturating_sub(1)))
                    .map(|j| jac.get(i, j).abs())
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }
}

impl StepMethod for RodasMethod {
    const ERROR_EXPONENT: f64 = 0.25;
    const SHRINK_LIMIT: f64 = 5.0;

    /// All buffers except the Jacobian and iteration matrices (shaped at the
    /// first reset).
    fn new(dim: usize) -> Self {
        Self {
            jac_current: false,
            y_stage: vec![0.0; dim],
            f_stage: vec![0.0; dim],
            work: vec![0.0; dim],
            f_t: vec![0.0; dim],
            u: vec![0.0; N_STAGES * dim],
            cont2: vec![0.0; dim],
            cont3: vec![0.0; dim],
            jac: BandMatrix::new(0, 0, 0),
            lu: BandMatrix::new(0, 0, 0),
        }
    }

    /// Shapes the matrices after [`OdeSystem::jacobian_bandwidth`]
    /// (reallocated only if the shape changed).
    fn reset<S: OdeSystem>(&mut self, sys: &S, n: usize) {
        self.jac_current = false;
        let (kl, ku) = sys.jacobian_bandwidth().unwrap_or((n, n));
        let bw = (kl.min(n - 1), ku.min(n - 1));
        if self.jac.n() != n || self.jac.bandwidths() != bw {
            self.jac = BandMatrix::new(n, bw.0, bw.1);
            self.lu = self.jac.clone();
        }
    }

    /// The Jacobian, once per step at its start point (reused by rejected
    /// attempts).
    fn begin_step<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, stats: &mut Stats) {
        if !self.jac_current {
            self.evaluate_jacobian(sys, at, stats);
            self.jac_current = true;
        }
    }

    /// The six stages; the error norm is that of `U_6`.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, trial: &mut Trial) -> Attempt {
        let (h, t_new, y_new) = (trial.h, trial.t_new, &mut *trial.y_new);
        let stats = &mut *trial.stats;
        let n = y_new.len();
        self.lu.assign_shifted(&self.jac, -1.0, 1.0 / (h * GAMMA));
        stats.lu_decompositions += 1;
        if self.lu.factor().is_err() {
            return Err((RejectReason::NonFinite, SHRINK_SINGULAR));
        }
        // Stage 1 at (t, y): f = dydt.
        self.f_stage.copy_from_slice(&at.dydt);
        self.stage_rhs(0, &[], h, D[0]);
        if !self.solve_stage(0) {
            return Err(NON_FINITE);
        }
        // Stages 2 … 5.
        for s in 1..5 {
            self.y_stage.copy_from_slice(&at.y);
            accumulate(&mut self.y_stage, &self.u[..s * n], &A[s - 1][..s]);
            let ts = if s == 4 {
                t_new
            } else {
                at.t + NODES[s - 1] * h
            };
            sys.rhs(ts, &self.y_stage, &mut self.f_stage);
            stats.rhs_evaluations += 1;
            if !all_finite(&self.f_stage) {
                return Err(NON_FINITE);
            }
            let d = if s < 4 { D[s] } else { 0.0 };
            self.stage_rhs(s, &CC[s - 1], h, d);
            if !self.solve_stage(s) {
                return Err(NON_FINITE);
            }
        }
        // Embedded solution ŷ = (argument of stage 5) + U_5, stage 6 there.
        for (yn, (&ys, &u5)) in y_new
            .iter_mut()
            .zip(self.y_stage.iter().zip(&self.u[4 * n..5 * n]))
        {
            *yn = ys + u5;
        }
        sys.rhs(t_new, y_new, &mut self.f_stage);
        stats.rhs_evaluations += 1;
        if !all_finite(&self.f_stage) {
            return Err(NON_FINITE);
        }
        self.stage_rhs(5, &CC[4], h, 0.0);
        if !self.solve_stage(5) {
            return Err(NON_FINITE);
        }
        for (yn, &u6) in y_new.iter_mut().zip(&self.u[5 * n..]) {
            *yn += u6;
        }
        if !all_finite(y_new) {
            return Err(NON_FINITE);
        }
        if !sys.admissible(t_new, y_new) {
            return Err((RejectReason::NotAdmissible, SHRINK_HARD));
        }
        Ok(at.error_norm(&self.u[5 * n..], y_new))
    }

    fn evaluate_end<S: OdeSystem>(&mut self, sys: &mut S, trial: &mut Trial) -> bool {
        sys.rhs(trial.t_new, trial.y_new, &mut self.f_stage);
        trial.stats.rhs_evaluations += 1;
        all_finite(&self.f_stage)
    }

    /// Computes the dense-output coefficients from the stages.
    fn accept(&mut self, _at: &Point, _y_new: &[f64], _h: f64) {
        self.cont2.fill(0.0);
        accumulate(&mut self.cont2, &self.u, &D2);
        self.cont3.fill(0.0);
        accumulate(&mut self.cont3, &self.u, &D3);
        self.jac_current = false;
    }

    fn end_derivative(&self) -> &[f64] {
        &self.f_stage
    }

    /// `rodas.f`'s `CONTRO`; free (no evaluation of `f`).
    fn dense<S: OdeSystem>(
        &mut self,
        _sys: &mut S,
        at: &Point,
        i: usize,
        s: f64,
        _stats: &mut Stats,
    ) -> f64 {
        let s1 = 1.0 - s;
        s1 * at.y_prev[i] + s * (at.y[i] + s1 * (self.cont2[i] + s * self.cont3[i]))
    }
}

impl RodasMethod {
    /// Jacobian `J` (analytic or banded finite differences) and `f_t` at the
    /// current point `(t, y)`, with `f(t, y) = dydt`.
    fn evaluate_jacobian<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, stats: &mut Stats) {
        stats.jacobian_evaluations += 1;
        self.jac.zero();
        if !sys.jacobian(at.t, &at.y, &mut self.jac) {
            self.jac.zero();
            self.fd_jacobian(sys, at, stats);
        }
        // ∂f/∂t: forward difference, backward if that is not finite.
        let t = at.t;
        for sign in [1.0, -1.0] {
            let tp = t + sign * fd_increment(t);
            let delta = tp - t;
            sys.rhs(tp, &at.y, &mut self.f_stage);
            stats.rhs_evaluations += 1;
            for ((ft, &fp), &f0) in self.f_t.iter_mut().zip(&self.f_stage).zip(&at.dydt) {
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
    fn fd_jacobian<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, stats: &mut Stats) {
        let n = at.dim();
        let (kl, ku) = self.jac.bandwidths();
        let width = (kl + ku + 1).min(n);
        for g in 0..width {
            for sign in [1.0, -1.0] {
                self.y_stage.copy_from_slice(&at.y);
                for j in (g..n).step_by(width) {
                    let yj = at.y[j];
                    let yp = yj + sign * fd_increment(yj);
                    self.y_stage[j] = yp;
                    self.work[j] = yp - yj;
                }
                sys.rhs(at.t, &self.y_stage, &mut self.f_stage);
                stats.rhs_evaluations += 1;
                let mut finite = true;
                for j in (g..n).step_by(width) {
                    for i in j.saturating_sub(ku)..=(j + kl).min(n - 1) {
                        let d = (self.f_stage[i] - at.dydt[i]) / self.work[j];
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
        let n = self.work.len();
        self.lu.solve(&mut self.work);
        self.u[s * n..(s + 1) * n].copy_from_slice(&self.work);
        all_finite(&self.work)
    }

    /// `work = f_stage + Σ_{j<s} (cc[j]/h)·U_j + h·d·f_t`, the right-hand
    /// side of stage `s` (0-based).
    fn stage_rhs(&mut self, s: usize, cc: &[f64], h: f64, d: f64) {
        let n = self.work.len();
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
}

#[cfg(test)]
mod tests;
