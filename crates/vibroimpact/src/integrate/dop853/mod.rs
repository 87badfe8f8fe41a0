//! The adaptive Dormand–Prince 8(5,3) integrator "DOP853" with 7th-order dense
//! output, after E. Hairer's Fortran code `dop853.f` (Hairer, Nørsett & Wanner,
//! *Solving ODEs I*, Sec. II.5 and II.6).
//!
//! Files: `mod.rs` (the method), `tableau.rs` (its coefficients, shared
//! with the tangent replay), `tests.rs` (order, dense output, Hairer's
//! reference problems).
//!
//! Algorithmic choices (all as in `dop853.f` unless stated):
//!
//! * **Error estimate**: the "8(5,3)" combination of the 5th- and 3rd-order
//!   embedded estimators, `err = |h|·e5² / sqrt(m·(e5² + 0.01·e3²))` with
//!   `e5, e3` the weighted 2-norms of `Σ E5_i k_i`, `Σ E3_i k_i` over the `m`
//!   error-controlled components. The step is accepted when `err <= 1`.
//! * **Step-size controller**: the shared [`Driver`]'s, with
//!   exponent `1/8` and shrink limited to 0.333 (`dop853.f`'s `facmin`,
//!   `facmax`; no PI stabilisation, `beta = 0`), plus Gustafsson's
//!   predictive controller (not in `dop853.f`).
//! * **Robustness** (not in `dop853.f`): an attempt with a non-finite stage
//!   derivative, new state, `f(t + h, y_new)` or error estimate, or whose new
//!   state is not [admissible](OdeSystem::admissible), is rejected and
//!   retried with `h/4`. The check order is: stages, new state, admissibility,
//!   error estimate, `f` at the new state. Non-finite values never reach the
//!   error norm's comparisons (checked explicitly with `is_finite`).
//! * **Bounds**: as the driver's (a step is stretched by up to 1 % to land
//!   exactly on `t_bound`).
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
//! Every buffer is allocated in `Dop853::new`; stepping, resetting and dense
//! output do not allocate (except for building an error value).

use super::driver::{
    all_finite, Attempt, Driver, Point, StepMethod, Trial, NON_FINITE, SHRINK_HARD,
};
use super::explicit::{combine, StiffnessTest};
use super::{OdeSystem, RejectReason, Stats};
use tableau::{A, B, C, D, E3, E5, N_STAGES, N_STAGES_EXTENDED};

/// Shrink limit of the controller: `h_new >= 0.333 h` (`dop853.f`'s `facmin`).
const FAC_MIN: f64 = 0.333;
/// Index of the stage `f(t + h, y_new)` in the extended stage list.
const FSAL_STAGE: usize = N_STAGES;
/// Number of dense-output coefficients per component.
const N_CONT: usize = 8;
/// Stiffness test: a step with `h·ρ` above this is suspicious (`dop853.f`).
const STIFF_H_RHO: f64 = 6.1;

/// Adaptive Dormand–Prince 8(5,3) integrator with 7th-order dense output:
/// the shared [`Driver`] around the [`Dop853Method`].
///
/// Usage: `new` once (allocates all buffers), then `reset` at an initial
/// point (again after every discontinuity, e.g. an impact), then `step`
/// repeatedly; after each accepted step, `dense_output` / `dense_component`
/// interpolate inside `[t_prev(), t()]`.
pub type Dop853 = Driver<Dop853Method>;

/// The stages, error estimate, dense output and stiffness test of DOP853
/// (see the module documentation).
#[derive(Clone, Debug)]
pub struct Dop853Method {
    /// Whether `cont` holds the dense output of the last accepted step.
    dense_ready: bool,
    stiffness: StiffnessTest,
    /// Argument of the stage being evaluated.
    y_stage: Vec<f64>,
    /// Stages of the current attempt, stage `s` at `k[s*n..(s+1)*n]`.
    k: Vec<f64>,
    /// Stages of the last accepted step (same layout, incl. the extra dense
    /// stages once computed).
    k_acc: Vec<f64>,
    /// Dense-output coefficients, component `i` at `cont[8*i..8*i+8]`.
    cont: Vec<f64>,
    /// The attempt's error estimates per component, `Σ E5_j k_j` and
    /// `Σ E3_j k_j`, summed stage by stage over contiguous stages (a
    /// component's 12 stages lie `n` apart: read per component, they cost
    /// a tenth of an N = 1000 run), and zeros to combine them from.
    e5: Vec<f64>,
    e3: Vec<f64>,
    zeros: Vec<f64>,
}

/// Hairer's `CONTD8` for one component: `c` are its 8 coefficients, `s` the
/// normalised time `(t − t_prev)/h`.
fn eval_cont(c: &[f64], s: f64) -> f64 {
    let s1 = 1.0 - s;
    let conpar = c[4] + s * (c[5] + s1 * (c[6] + s * c[7]));
    c[0] + s * (c[1] + s1 * (c[2] + s * (c[3] + s1 * conpar)))
}

impl StepMethod for Dop853Method {
    const ERROR_EXPONENT: f64 = 1.0 / 8.0;
    const SHRINK_LIMIT: f64 = 1.0 / FAC_MIN;

    fn new(dim: usize) -> Self {
        Self {
            dense_ready: false,
            stiffness: StiffnessTest::default(),
            y_stage: vec![0.0; dim],
            k: vec![0.0; N_STAGES_EXTENDED * dim],
            k_acc: vec![0.0; N_STAGES_EXTENDED * dim],
            cont: vec![0.0; N_CONT * dim],
            e5: vec![0.0; dim],
            e3: vec![0.0; dim],
            zeros: vec![0.0; dim],
        }
    }

    fn reset<S: OdeSystem>(&mut self, _sys: &S, _dim: usize) {
        self.dense_ready = false;
        self.stiffness = StiffnessTest::default();
    }

    fn begin_step<S: OdeSystem>(&mut self, _sys: &mut S, at: &Point, _stats: &mut Stats) {
        self.k[..at.dim()].copy_from_slice(&at.dydt);
    }

    /// The 11 new stages (stage 0 is the previous step's last evaluation,
    /// "first same as last") and the 8(5,3) error estimate
    /// `|h|·e5² / sqrt(m·(e5² + 0.01·e3²))`, the largest over the error
    /// norm's blocks.
    fn attempt<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, trial: &mut Trial) -> Attempt {
        let (n, h, y_new) = (at.dim(), trial.h, &mut *trial.y_new);
        for s in 1..N_STAGES {
            combine(&at.y, &self.k[..s * n], A[s], h, &mut self.y_stage);
            let ks = &mut self.k[s * n..(s + 1) * n];
            sys.rhs(at.t + C[s] * h, &self.y_stage, ks);
            trial.stats.rhs_evaluations += 1;
            if !all_finite(ks) {
                return Err(NON_FINITE);
            }
        }
        combine(&at.y, &self.k[..N_STAGES * n], &B, h, y_new);
        if !all_finite(y_new) {
            return Err(NON_FINITE);
        }
        if !sys.admissible(trial.t_new, y_new) {
            return Err((RejectReason::NotAdmissible, SHRINK_HARD));
        }
        let (m, block) = (at.error_components(), at.error_block());
        // (Each component's sum in stage order from 0, as per component.)
        let stages = &self.k[..N_STAGES * n];
        combine(&self.zeros, stages, &E5, 1.0, &mut self.e5);
        combine(&self.zeros, stages, &E3, 1.0, &mut self.e3);
        let mut worst = 0.0f64;
        for start in (0..m).step_by(block) {
            let end = (start + block).min(m);
            let (mut err5, mut err3) = (0.0, 0.0);
            let (y, yn) = (&at.y[start..end], &y_new[start..end]);
            let (e5, e3) = (&self.e5[start..end], &self.e3[start..end]);
            for (((&y, &yn), &e5), &e3) in y.iter().zip(yn).zip(e5).zip(e3) {
                let sk = at.weight(y, yn);
                err5 += (e5 / sk).powi(2);
                err3 += (e3 / sk).powi(2);
            }
            let mut deno = err5 + 0.01 * err3;
            if deno <= 0.0 {
                deno = 1.0;
            }
            worst = worst.max(h.abs() * err5 / ((end - start) as f64 * deno).sqrt());
        }
        Ok(worst)
    }

    fn evaluate_end<S: OdeSystem>(&mut self, sys: &mut S, trial: &mut Trial) -> bool {
        let n = trial.y_new.len();
        let f_new = &mut self.k[FSAL_STAGE * n..(FSAL_STAGE + 1) * n];
        sys.rhs(trial.t_new, trial.y_new, f_new);
        trial.stats.rhs_evaluations += 1;
        all_finite(f_new)
    }

    /// Runs the stiffness test, then makes the attempt's stages the accepted
    /// step's (buffer swap, no copy of the stages).
    fn accept(&mut self, at: &Point, y_new: &[f64], h: f64) {
        if at.options().stiffness_check {
            self.test_stiffness(y_new, h);
        }
        std::mem::swap(&mut self.k, &mut self.k_acc);
        self.dense_ready = false;
    }

    fn end_derivative(&self) -> &[f64] {
        let n = self.y_stage.len();
        &self.k_acc[FSAL_STAGE * n..(FSAL_STAGE + 1) * n]
    }

    fn dense<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        at: &Point,
        i: usize,
        s: f64,
        stats: &mut Stats,
    ) -> f64 {
        self.prepare_dense(sys, at, stats);
        eval_cont(&self.cont[N_CONT * i..N_CONT * (i + 1)], s)
    }

    fn dense_all<S: OdeSystem>(
        &mut self,
        sys: &mut S,
        at: &Point,
        s: f64,
        out: &mut [f64],
        stats: &mut Stats,
    ) {
        self.prepare_dense(sys, at, stats);
        for (o, c) in out.iter_mut().zip(self.cont.chunks_exact(N_CONT)) {
            *o = eval_cont(c, s);
        }
    }
}

impl Dop853Method {
    /// Hairer's stiffness test on the attempt just accepted (before the
    /// stage buffers are swapped): `y_stage` holds the argument of stage 11
    /// (`c = 1`), `k` its derivative and `f(t+h, y_new)`.
    fn test_stiffness(&mut self, y_new: &[f64], h: f64) {
        let n = y_new.len();
        let k12 = &self.k[(N_STAGES - 1) * n..N_STAGES * n];
        let f_new = &self.k[FSAL_STAGE * n..(FSAL_STAGE + 1) * n];
        let h_rho = StiffnessTest::h_rho(h, y_new, &self.y_stage, f_new, k12);
        self.stiffness.record(h_rho > STIFF_H_RHO);
    }

    /// Computes the 3 extra stages and the dense-output coefficients of the
    /// last accepted step (`at` is the point after it), once per step.
    fn prepare_dense<S: OdeSystem>(&mut self, sys: &mut S, at: &Point, stats: &mut Stats) {
        if self.dense_ready {
            return;
        }
        let n = at.dim();
        let h = at.h_last;
        for s in FSAL_STAGE + 1..N_STAGES_EXTENDED {
            combine(&at.y_prev, &self.k_acc[..s * n], A[s], h, &mut self.y_stage);
            sys.rhs(
                at.t_prev + C[s] * h,
                &self.y_stage,
                &mut self.k_acc[s * n..(s + 1) * n],
            );
            stats.rhs_evaluations += 1;
        }
        for (i, c) in self.cont.chunks_exact_mut(N_CONT).enumerate() {
            let ydiff = at.y[i] - at.y_prev[i];
            let bspl = h * self.k_acc[i] - ydiff;
            c[0] = at.y_prev[i];
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

impl Driver<Dop853Method> {
    /// Whether the problem looks stiff: the stiffness test (see the module
    /// documentation and [`IntegratorOptions::stiffness_check`](super::IntegratorOptions::stiffness_check))
    /// has counted at least 15 consecutive accepted steps whose size was
    /// limited by stability (`h·ρ > 6.1`), and not 6 consecutive
    /// unsuspicious steps since. Cleared by `reset`; always `false` when the
    /// test is switched off.
    ///
    /// Limit of Hairer's test: at tight tolerances the controller may keep a
    /// stability-limited step below the threshold (measured on
    /// `y' = −1e4 (y − cos t)` at rtol = atol = 1e-10: `h·λ ≈ 4.97`), so
    /// *mildly* stiff problems can go undetected there; strongly stiff ones
    /// (`λ = 1e6`, tolerance 1e-12) are detected within a few dozen steps.
    pub fn stiffness_detected(&self) -> bool {
        self.method.stiffness.detected()
    }

    /// Number of consecutive suspicious steps counted by the stiffness test
    /// (Hairer's `IASTI`; reaching 15 means [`stiffness_detected`](Self::stiffness_detected)).
    pub fn stiff_step_count(&self) -> u32 {
        self.method.stiffness.count()
    }
}

pub(super) mod tableau;

#[cfg(test)]
mod tests;
