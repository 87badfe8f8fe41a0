//! The adaptive Dormand–Prince 5(4) integrator "DOPRI5" with 4th-order
//! dense output, after E. Hairer's Fortran code `dopri5.f` (Hairer, Nørsett
//! & Wanner, *Solving ODEs I*, Sec. II.4 and II.6; J. R. Dormand and P. J.
//! Prince, J. Comput. Appl. Math. 6 (1980) 19–26).
//!
//! Files: `mod.rs` (the method), `tests.rs` (its order conditions and
//! accuracy).
//!
//! Where it serves: loose tolerances with steps limited by something other
//! than accuracy, above all a recorded ground motion, whose every sample is
//! a breakpoint the integrator must stop at (docs/earthquakes.md). There
//! DOP853's eighth order buys nothing: a step costs DOPRI5 six evaluations
//! of `f` and its dense output none, DOP853 twelve and three
//! (docs/decisions.md records the measurement).
//!
//! * **Stages**: seven, the last `f(t + h, y_new)` ("first same as last"),
//!   evaluated within the attempt because the error estimate needs it: six
//!   new evaluations per attempt.
//! * **Error estimate**: `err = sqrt(1/m Σ (h Σ_j E_j k_j / sk_i)²)`, the
//!   difference of the 5th- and 4th-order solutions; accepted when
//!   `err <= 1`.
//! * **Step-size controller**: the shared [`Driver`]'s with exponent `1/5`
//!   and shrink limited to 0.2 (`dopri5.f`'s `fac1`).
//! * **Dense output**: Hairer's `CONTD5` (Shampine's 4th-order continuous
//!   extension), from the stages already computed: no extra evaluation.
//! * **Stiffness test** (as in `dopri5.f`, after every accepted step):
//!   `h·ρ ≈ h·‖f(t+h, y_new) − k₆‖ / ‖y_new − Y₆‖` with `Y₆` the argument of
//!   the sixth stage (also at `t + h`); above 3.25 a step is suspicious, 15
//!   in a row mean stiff, 6 unsuspicious ones clear the count
//!   ([`StiffnessTest`]).
//! * **Robustness** as [`Dop853`](super::Dop853): a non-finite stage or
//!   state, or an inadmissible state, rejects the attempt with `h/4`.
//!
//! Every buffer is allocated in `Dopri5Method::new`.

use super::driver::{
    all_finite, Attempt, Driver, Point, StepMethod, Trial, NON_FINITE, SHRINK_HARD,
};
use super::explicit::{combine, StiffnessTest};
use super::{OdeSystem, RejectReason, Stats};

/// Number of stages, the last one `f(t + h, y_new)`.
const N_STAGES: usize = 7;
/// Nodes `c_i` (`dopri5.f`).
const C: [f64; N_STAGES] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
/// Coefficients `a_ij`, row `i` of stage `i`; row 6 is the 5th-order
/// weights `b` (the method is "first same as last").
const A: [&[f64]; N_STAGES] = [
    &[],
    &[0.2],
    &[3.0 / 40.0, 9.0 / 40.0],
    &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
    &[
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
    ],
    &[
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
    ],
    &B,
];
/// The 5th-order weights (`dopri5.f`'s `a71 … a76`).
const B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
/// Error coefficients: 5th- minus 4th-order weights (`dopri5.f`'s `e1 … e7`).
const E: [f64; N_STAGES] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
/// Dense-output coefficients (`dopri5.f`'s `d1 … d7`).
const D: [f64; N_STAGES] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];
/// Shrink limit of the controller: `h_new >= 0.2 h` (`dopri5.f`'s `fac1`).
const FAC_MIN: f64 = 0.2;
/// Stiffness test: a step with `h·ρ` above this is suspicious (`dopri5.f`).
const STIFF_H_RHO: f64 = 3.25;

/// Adaptive Dormand–Prince 5(4) integrator with 4th-order dense output: the
/// shared [`Driver`] around the [`Dopri5Method`].
pub type Dopri5 = Driver<Dopri5Method>;

/// The stages, error estimate, dense output and stiffness test of DOPRI5
/// (see the module documentation).
#[derive(Clone, Debug)]
pub struct Dopri5Method {
    stiffness: StiffnessTest,
    /// Argument of the stage being evaluated (after an attempt: of stage 5,
    /// at `t + h`, for the stiffness test).
    y_stage: Vec<f64>,
    /// Stages of the current attempt, stage `s` at `k[s*n..(s+1)*n]`.
    k: Vec<f64>,
    /// Stages of the last accepted step.
    k_acc: Vec<f64>,
    /// The attempt's error estimate per component.
    err: Vec<f64>,
    /// The last accepted step's dense coefficient `Σ_j D_j k_j` per
    /// component (`CONTD5`'s fifth), summed once when the step is accepted.
    c5: Vec<f64>,
    /// Zeros to combine the error estimate and `c5` from.
    zeros: Vec<f64>,
}

impl StepMethod for Dopri5Method {
    const ERROR_EXPONENT: f64 = 1.0 / 5.0;
    const SHRINK_LIMIT: f64 = 1.0 / FAC_MIN;

    fn new(dim: usize) -> Self {
        Self {
            stiffness: StiffnessTest::default(),
            y_stage: vec![0.0; dim],
            k: vec![0.0; N_STAGES * dim],
            k_acc: vec![0.0; N_STAGES * dim],
            err: vec![0.0; dim],
            c5: vec![0.0; dim],
            zeros: vec![0.0; dim],
        }
    }

    fn reset<S: OdeSystem>(&mut self, _sys: &S, _dim: usize) {
        self.stiffness = StiffnessTest::default();
    }

    fn begin_step<S: OdeSystem>(&mut self, _sys: &mut S, at: &Point, _stats: &mut Stats) {
        self.k[..at.dim()].copy_from_slice(&at.dydt);
    }

    /// Stages 1–5, the new state, `f(t + h, y_new)` and the error norm.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, trial: &mut Trial) -> Attempt {
        let (n, h, y_new) = (at.dim(), trial.h, &mut *trial.y_new);
        for s in 1..N_STAGES - 1 {
            combine(&at.y, &self.k[..s * n], A[s], h, &mut self.y_stage);
            let ks = &mut self.k[s * n..(s + 1) * n];
            sys.rhs(at.t + C[s] * h, &self.y_stage, ks);
            trial.stats.rhs_evaluations += 1;
            if !all_finite(ks) {
                return Err(NON_FINITE);
            }
        }
        combine(&at.y, &self.k[..(N_STAGES - 1) * n], &B, h, y_new);
        if !all_finite(y_new) {
            return Err(NON_FINITE);
        }
        if !sys.admissible(trial.t_new, y_new) {
            return Err((RejectReason::NotAdmissible, SHRINK_HARD));
        }
        let last = &mut self.k[(N_STAGES - 1) * n..];
        sys.rhs(trial.t_new, y_new, last);
        trial.stats.rhs_evaluations += 1;
        if !all_finite(last) {
            return Err(NON_FINITE);
        }
        // Combined over contiguous stages (the same order per component
        // as one component at a time: the same bits).
        combine(&self.zeros, &self.k, &E, 1.0, &mut self.err);
        for e in self.err[..at.error_components()].iter_mut() {
            *e *= h;
        }
        Ok(at.error_norm(&self.err, y_new))
    }

    /// `f(t + h, y_new)` was evaluated (and checked) within the attempt.
    fn evaluate_end<S: OdeSystem>(&mut self, _sys: &mut S, _trial: &mut Trial) -> bool {
        true
    }

    fn accept(&mut self, at: &Point, y_new: &[f64], h: f64) {
        if at.options().stiffness_check {
            let n = y_new.len();
            let h_rho = StiffnessTest::h_rho(
                h,
                y_new,
                &self.y_stage,
                &self.k[(N_STAGES - 1) * n..],
                &self.k[(N_STAGES - 2) * n..(N_STAGES - 1) * n],
            );
            self.stiffness.record(h_rho > STIFF_H_RHO);
        }
        std::mem::swap(&mut self.k, &mut self.k_acc);
        combine(&self.zeros, &self.k_acc, &D, 1.0, &mut self.c5);
    }

    fn end_derivative(&self) -> &[f64] {
        let n = self.y_stage.len();
        &self.k_acc[(N_STAGES - 1) * n..]
    }

    /// Hairer's `CONTD5`.
    fn dense<S: OdeSystem>(
        &mut self,
        _sys: &mut S,
        at: &Point,
        i: usize,
        s: f64,
        _stats: &mut Stats,
    ) -> f64 {
        let n = at.dim();
        let h = at.h_last;
        let k = |j: usize| self.k_acc[j * n + i];
        let ydiff = at.y[i] - at.y_prev[i];
        let bspl = h * k(0) - ydiff;
        let c4 = ydiff - h * k(N_STAGES - 1) - bspl;
        let c5 = self.c5[i];
        let s1 = 1.0 - s;
        at.y_prev[i] + s * (ydiff + s1 * (bspl + s * (c4 + s1 * h * c5)))
    }
}

impl Driver<Dopri5Method> {
    /// Whether the problem looks stiff (the test of the module
    /// documentation; cleared by `reset`; always `false` when
    /// [`IntegratorOptions::stiffness_check`](super::IntegratorOptions::stiffness_check)
    /// is off).
    pub fn stiffness_detected(&self) -> bool {
        self.method.stiffness.detected()
    }
}

#[cfg(test)]
mod tests;
