//! Identification of the exponential law's a/b and α from measured impacts
//! (seed §3, docs/theory.md §3).
//!
//! ## Files
//! - `mod.rs` — the fits of a/b and α;
//! - `measured.rs` — measured data as CSV tables;
//! - `tests.rs` — the fits against synthetic data of known parameters.
//!
//! The seed fits by eye: measured (impact velocity U, restitution e) pairs
//! fix a/b through e(U/(a/b)) (eqs. 9–10, its figure 4); measured
//! (U, peak acceleration A) pairs then fix α through
//! `A = F_max/m1 = f_max(U/(a/b)) μ α (a/b)² / m1` (eqs. 14, 16–17, its
//! figure 5). Here both are least-squares fits with standard errors:
//!
//! - **a/b** ([`fit_a_over_b`]): minimises `Σ (e_i - e(U_i/q))²` over
//!   `θ = ln q` (absolute errors in e; measurement noise on e does not grow
//!   with e). Start from a log grid over q, then Levenberg–Marquardt.
//! - **α given a/b** ([`fit_alpha`]): accelerations span decades with roughly
//!   relative noise, so the fit is on `ln A`: `ln α = mean(ln A_i - ln g_i)`
//!   with `g_i = f_max(U_i/q) μ q² / m1`; exact, no iteration.
//! - **Joint** ([`fit_joint`]): `θ = (ln q, ln α)` from both data sets,
//!   each residual divided by the residual standard deviation of its data
//!   set's separate fit (two-stage weighted least squares), or from the
//!   accelerations alone (possible only when the data reach V = U/q ~ 1,
//!   where f_max(V) bends away from V²/2; otherwise a/b is not identified).
//!
//! Standard errors are the usual asymptotic ones, `cov(θ) = s² (JᵀJ)⁻¹`,
//! `s² = SSR/(n - p)`, mapped to q and α by the delta method
//! (`σ_q = q σ_{ln q}`).

use serde::Serialize;

use crate::impact::closed_form::{
    peak_force_dimensionless_derivative, peak_velocity, restitution, restitution_derivative,
};
use crate::impact::{ImpactError, TwoBodies};

/// A measured (impact velocity, coefficient of restitution) pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RestitutionSample {
    /// Impact velocity U (m/s), > 0.
    pub impact_velocity: f64,
    /// Coefficient of restitution e, in (0, 1.5) (noisy measurements may
    /// exceed 1 a little).
    pub restitution: f64,
}

/// A measured (impact velocity, peak acceleration of body 1) pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AccelerationSample {
    /// Impact velocity U (m/s), > 0.
    pub impact_velocity: f64,
    /// Peak acceleration of body 1, F_max/m1 (m/s²), > 0.
    pub peak_acceleration: f64,
}

/// An estimated parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Estimate {
    /// Best estimate.
    pub value: f64,
    /// Asymptotic standard error (0 for a parameter held fixed).
    pub std_error: f64,
}

/// One data point against the fitted model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Residual {
    /// Impact velocity (m/s).
    pub impact_velocity: f64,
    /// Measured value.
    pub measured: f64,
    /// Model value at the estimate.
    pub fitted: f64,
    /// `measured - fitted` for restitution; `ln(measured/fitted)` for
    /// acceleration.
    pub residual: f64,
}

/// Result of [`fit_a_over_b`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RestitutionFit {
    /// a/b (m/s).
    pub a_over_b: Estimate,
    /// Residuals in data order.
    pub residuals: Vec<Residual>,
    /// Residual standard deviation `sqrt(SSR/(n - 1))`.
    pub residual_std: f64,
}

/// Result of [`fit_alpha`] and [`fit_joint`].
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ExponentialLawFit {
    /// How the fit was made: `alpha-given-a-over-b`, `joint` or
    /// `joint-acceleration-only`.
    pub method: &'static str,
    /// a/b (m/s); std_error 0 when it was given.
    pub a_over_b: Estimate,
    /// α (1/m).
    pub alpha: Estimate,
    /// Correlation of the estimates of ln(a/b) and ln α (0 when a/b was given).
    pub correlation: f64,
    /// Restitution residuals (joint fit with restitution data), data order.
    pub restitution_residuals: Vec<Residual>,
    /// Acceleration residuals, data order.
    pub acceleration_residuals: Vec<Residual>,
    /// Residual standard deviation of ln A.
    pub acceleration_residual_std: f64,
}

/// Why an identification failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IdentifyError {
    /// Not enough data points.
    #[error("too few {what} points: {got}, need at least {need}")]
    TooFewPoints {
        /// Which data set.
        what: &'static str,
        /// Points given.
        got: usize,
        /// Points needed.
        need: usize,
    },
    /// A data point is outside the model's domain.
    #[error("{what} point {index} (counting from 0): {reason}")]
    InvalidSample {
        /// Which data set.
        what: &'static str,
        /// Index of the point in the data set.
        index: usize,
        /// What is wrong.
        reason: String,
    },
    /// The data do not determine the parameter.
    #[error("the data do not identify {0}")]
    NotIdentifiable(String),
    /// A model evaluation failed.
    #[error(transparent)]
    Model(#[from] ImpactError),
    /// A mass or fixed parameter is invalid.
    #[error("{0}")]
    InvalidParameter(String),
}

fn validate_restitution(samples: &[RestitutionSample]) -> Result<(), IdentifyError> {
    const W: &str = "restitution";
    for (index, s) in samples.iter().enumerate() {
        let bad = |reason: String| {
            Err(IdentifyError::InvalidSample {
                what: W,
                index,
                reason,
            })
        };
        if !(s.impact_velocity > 0.0 && s.impact_velocity.is_finite()) {
            return bad(format!(
                "impact_velocity = {} must be finite and > 0",
                s.impact_velocity
            ));
        }
        // Measured values slightly above 1 are measurement noise and are kept;
        // values of 1.5 or more cannot come from a passive impact.
        if !(s.restitution > 0.0 && s.restitution < 1.5) {
            return bad(format!(
                "restitution = {}: must be above 0 and below 1.5 (a passive impact; values a little above 1 are kept as measurement noise)",
                s.restitution
            ));
        }
    }
    if samples.len() < 2 {
        return Err(IdentifyError::TooFewPoints {
            what: W,
            got: samples.len(),
            need: 2,
        });
    }
    repeated(
        W,
        samples.iter().map(|s| (s.impact_velocity, s.restitution)),
        2,
    )?;
    Ok(())
}

fn validate_acceleration(samples: &[AccelerationSample], need: usize) -> Result<(), IdentifyError> {
    const W: &str = "acceleration";
    for (index, s) in samples.iter().enumerate() {
        let bad = |reason: String| {
            Err(IdentifyError::InvalidSample {
                what: W,
                index,
                reason,
            })
        };
        if !(s.impact_velocity > 0.0 && s.impact_velocity.is_finite()) {
            return bad(format!(
                "impact_velocity = {} must be finite and > 0",
                s.impact_velocity
            ));
        }
        if !(s.peak_acceleration > 0.0 && s.peak_acceleration.is_finite()) {
            return bad(format!(
                "peak_acceleration = {} must be finite and > 0",
                s.peak_acceleration
            ));
        }
    }
    if samples.len() < need {
        return Err(IdentifyError::TooFewPoints {
            what: W,
            got: samples.len(),
            need,
        });
    }
    repeated(
        W,
        samples
            .iter()
            .map(|s| (s.impact_velocity, s.peak_acceleration)),
        need,
    )
}

/// Refuses points that hold fewer than `need` distinct pairs: repeats of
/// one measurement fix a value but not its standard error (three
/// identical restitution points gave a/b ± 1e-15, "0.00 %").
fn repeated(
    what: &'static str,
    points: impl Iterator<Item = (f64, f64)>,
    need: usize,
) -> Result<(), IdentifyError> {
    let mut pairs: Vec<(u64, u64)> = points.map(|(a, b)| (a.to_bits(), b.to_bits())).collect();
    let n = pairs.len();
    pairs.sort_unstable();
    pairs.dedup();
    if pairs.len() < need {
        return Err(IdentifyError::NotIdentifiable(format!(
            "a standard error: the {n} {what} points hold {} distinct (impact velocity, value) pair{}; give {need} distinct points at least",
            pairs.len(),
            if pairs.len() == 1 { "" } else { "s" }
        )));
    }
    Ok(())
}

/// Model e and ∂e/∂ln q at impact velocity `u` for q = a/b.
fn restitution_model(u: f64, q: f64) -> Result<(f64, f64), ImpactError> {
    let v = u / q;
    let e = restitution(v)?;
    Ok((e, -v * restitution_derivative(v, e)))
}

/// Model ln(A/α) and ∂ln A/∂ln q at impact velocity `u` for q = a/b:
/// `ln A = ln α + ln(f_max(U/q) μ q² / m1)`.
fn log_acceleration_model(u: f64, q: f64, mu_over_m1: f64) -> Result<(f64, f64), ImpactError> {
    let v = u / q;
    let w = peak_velocity(v)?;
    let f = w * (1.0 + w);
    let value = f.ln() + (mu_over_m1 * q * q).ln();
    let slope = 2.0 - v * peak_force_dimensionless_derivative(v, w) / f;
    Ok((value, slope))
}

/// Samples the coarse grid searches use at most.
const GRID_SAMPLES: usize = 2000;

/// At most [`GRID_SAMPLES`] samples spread evenly over `samples` (all of
/// them when there are fewer).
fn spread<T: Clone>(samples: &[T]) -> Vec<T> {
    let n = samples.len();
    if n <= GRID_SAMPLES {
        return samples.to_vec();
    }
    (0..GRID_SAMPLES)
        .map(|k| samples[k * n / GRID_SAMPLES].clone())
        .collect()
}

/// Grid of ln q candidates spanning V_median = U_median/q from 1e-4 to 1e4.
fn log_q_grid(velocities: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut logs: Vec<f64> = velocities.map(f64::ln).collect();
    logs.sort_by(f64::total_cmp);
    let center = logs[logs.len() / 2];
    (0..=160)
        .map(|i| center - (4.0 - 8.0 * i as f64 / 160.0) * std::f64::consts::LN_10)
        .collect()
}

/// Least-squares a/b from (U, e) pairs (the seed's figure 4).
pub fn fit_a_over_b(samples: &[RestitutionSample]) -> Result<RestitutionFit, IdentifyError> {
    validate_restitution(samples)?;
    let ssr = |theta: f64| -> Result<f64, ImpactError> {
        let q = theta.exp();
        samples.iter().try_fold(0.0, |acc, s| {
            let (e, _) = restitution_model(s.impact_velocity, q)?;
            Ok(acc + (s.restitution - e).powi(2))
        })
    };
    // Coarse grid (on at most GRID_SAMPLES evenly spread samples: the grid
    // only brackets the minimum), then Levenberg–Marquardt on θ = ln q with
    // every sample.
    let grid = log_q_grid(samples.iter().map(|s| s.impact_velocity));
    let coarse = spread(samples);
    let coarse_ssr = |theta: f64| -> Result<f64, ImpactError> {
        let q = theta.exp();
        coarse.iter().try_fold(0.0, |acc, s| {
            let (e, _) = restitution_model(s.impact_velocity, q)?;
            Ok(acc + (s.restitution - e).powi(2))
        })
    };
    let mut best = (0, f64::INFINITY);
    for (i, &t) in grid.iter().enumerate() {
        let r = coarse_ssr(t)?;
        if r < best.1 {
            best = (i, r);
        }
    }
    // The grid's sum is that of every sample unless it ran on a spread.
    let best = if coarse.len() < samples.len() {
        (best.0, ssr(grid[best.0])?)
    } else {
        best
    };
    if best.0 == 0 || best.0 == grid.len() - 1 {
        let direction = if best.0 == 0 {
            "a/b -> 0 (every e near 0)"
        } else {
            "a/b -> infinity (every e near 1, perfectly elastic)"
        };
        return Err(IdentifyError::NotIdentifiable(format!(
            "a/b: the least-squares fit runs off to {direction}"
        )));
    }
    let mut theta = grid[best.0];
    let mut cost = best.1;
    let mut lambda = 1e-3;
    for _ in 0..100 {
        let q = theta.exp();
        let (mut g, mut h) = (0.0, 0.0);
        for s in samples {
            let (e, de) = restitution_model(s.impact_velocity, q)?;
            g += de * (s.restitution - e);
            h += de * de;
        }
        if h <= 0.0 {
            return Err(IdentifyError::NotIdentifiable(
                "a/b: the model does not depend on it at these velocities".into(),
            ));
        }
        let mut accepted = false;
        for _ in 0..30 {
            let step = g / (h * (1.0 + lambda));
            let trial = ssr(theta + step)?;
            if trial <= cost {
                theta += step;
                let converged = step.abs() < 1e-14 || cost - trial <= 1e-15 * cost;
                cost = trial;
                lambda = (lambda * 0.3).max(1e-12);
                accepted = true;
                if converged {
                    return finish_restitution_fit(samples, theta, cost);
                }
                break;
            }
            lambda *= 10.0;
        }
        if !accepted {
            // No decrease possible: θ is at the minimum to rounding.
            return finish_restitution_fit(samples, theta, cost);
        }
    }
    finish_restitution_fit(samples, theta, cost)
}

fn finish_restitution_fit(
    samples: &[RestitutionSample],
    theta: f64,
    ssr: f64,
) -> Result<RestitutionFit, IdentifyError> {
    let q = theta.exp();
    let n = samples.len();
    let mut jtj = 0.0;
    let mut residuals = Vec::with_capacity(n);
    for s in samples {
        let (e, de) = restitution_model(s.impact_velocity, q)?;
        jtj += de * de;
        residuals.push(Residual {
            impact_velocity: s.impact_velocity,
            measured: s.restitution,
            fitted: e,
            residual: s.restitution - e,
        });
    }
    let s2 = ssr / (n - 1) as f64;
    Ok(RestitutionFit {
        a_over_b: Estimate {
            value: q,
            std_error: q * (s2 / jtj).sqrt(),
        },
        residuals,
        residual_std: s2.sqrt(),
    })
}

fn mu_over_m1(bodies: &TwoBodies) -> f64 {
    bodies.reduced_mass() / bodies.m1()
}

fn acceleration_residuals(
    samples: &[AccelerationSample],
    q: f64,
    alpha: f64,
    bodies: &TwoBodies,
) -> Result<Vec<Residual>, IdentifyError> {
    samples
        .iter()
        .map(|s| {
            let (lg, _) = log_acceleration_model(s.impact_velocity, q, mu_over_m1(bodies))?;
            let fitted = alpha * lg.exp();
            Ok(Residual {
                impact_velocity: s.impact_velocity,
                measured: s.peak_acceleration,
                fitted,
                residual: (s.peak_acceleration / fitted).ln(),
            })
        })
        .collect()
}

/// ln α = mean(ln A_i - ln g_i) at fixed q, with its residual sum of squares.
fn profile_log_alpha(
    samples: &[AccelerationSample],
    q: f64,
    bodies: &TwoBodies,
) -> Result<(f64, f64), IdentifyError> {
    let d: Vec<f64> = samples
        .iter()
        .map(|s| {
            Ok(s.peak_acceleration.ln()
                - log_acceleration_model(s.impact_velocity, q, mu_over_m1(bodies))?.0)
        })
        .collect::<Result<_, ImpactError>>()?;
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let ssr = d.iter().map(|x| (x - mean).powi(2)).sum();
    Ok((mean, ssr))
}

/// Least-squares α (on ln A) from (U, peak acceleration of body 1) pairs with
/// a/b given (the seed's figure 5).
pub fn fit_alpha(
    samples: &[AccelerationSample],
    bodies: TwoBodies,
    a_over_b: f64,
) -> Result<ExponentialLawFit, IdentifyError> {
    validate_acceleration(samples, 2)?;
    if !(a_over_b > 0.0 && a_over_b.is_finite()) {
        return Err(IdentifyError::InvalidParameter(format!(
            "a/b = {a_over_b} must be finite and > 0"
        )));
    }
    let (log_alpha, ssr) = profile_log_alpha(samples, a_over_b, &bodies)?;
    let n = samples.len() as f64;
    let s = (ssr / (n - 1.0)).sqrt();
    let alpha = log_alpha.exp();
    Ok(ExponentialLawFit {
        method: "alpha-given-a-over-b",
        a_over_b: Estimate {
            value: a_over_b,
            std_error: 0.0,
        },
        alpha: Estimate {
            value: alpha,
            std_error: alpha * s / n.sqrt(),
        },
        correlation: 0.0,
        restitution_residuals: Vec::new(),
        acceleration_residuals: acceleration_residuals(samples, a_over_b, alpha, &bodies)?,
        acceleration_residual_std: s,
    })
}

/// Weighted sum of squares, JᵀJ and Jᵀr of the joint problem.
type NormalEquations = (f64, [[f64; 2]; 2], [f64; 2]);

/// Weighted residuals and Jacobian rows of the joint problem at θ = (ln q, ln α).
struct JointProblem<'a> {
    restitution: &'a [RestitutionSample],
    acceleration: &'a [AccelerationSample],
    bodies: TwoBodies,
    sigma_e: f64,
    sigma_a: f64,
}

impl JointProblem<'_> {
    /// Weighted SSR, gradient-side JᵀJ and Jᵀr at θ.
    fn normal_equations(&self, theta: [f64; 2]) -> Result<NormalEquations, ImpactError> {
        let q = theta[0].exp();
        let mut ssr = 0.0;
        let mut jtj = [[0.0; 2]; 2];
        let mut jtr = [0.0; 2];
        let mut add = |r: f64, j: [f64; 2]| {
            ssr += r * r;
            for a in 0..2 {
                jtr[a] += j[a] * r;
                for b in 0..2 {
                    jtj[a][b] += j[a] * j[b];
                }
            }
        };
        for s in self.restitution {
            let (e, de) = restitution_model(s.impact_velocity, q)?;
            add((s.restitution - e) / self.sigma_e, [de / self.sigma_e, 0.0]);
        }
        for s in self.acceleration {
            let (lg, dlg) = log_acceleration_model(s.impact_velocity, q, mu_over_m1(&self.bodies))?;
            let r = s.peak_acceleration.ln() - theta[1] - lg;
            add(r / self.sigma_a, [dlg / self.sigma_a, 1.0 / self.sigma_a]);
        }
        Ok((ssr, jtj, jtr))
    }
}

fn solve2(m: [[f64; 2]; 2], r: [f64; 2]) -> Option<[f64; 2]> {
    let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
    if det.abs() <= 1e-14 * (m[0][0] * m[1][1]).abs() || det == 0.0 {
        return None;
    }
    Some([
        (r[0] * m[1][1] - r[1] * m[0][1]) / det,
        (m[0][0] * r[1] - m[1][0] * r[0]) / det,
    ])
}

/// Joint least-squares a/b and α from restitution data (may be empty) and
/// acceleration data. With restitution data the residuals of each set are
/// weighted by its separate fit's residual standard deviation.
pub fn fit_joint(
    restitution_samples: &[RestitutionSample],
    acceleration_samples: &[AccelerationSample],
    bodies: TwoBodies,
) -> Result<ExponentialLawFit, IdentifyError> {
    let acceleration_only = restitution_samples.is_empty();
    validate_acceleration(acceleration_samples, if acceleration_only { 3 } else { 2 })?;
    // Starting point and weights.
    let (mut theta, sigma_e) = if acceleration_only {
        let grid = log_q_grid(acceleration_samples.iter().map(|s| s.impact_velocity));
        let coarse = spread(acceleration_samples);
        let mut best = (0, f64::INFINITY, 0.0);
        for (i, &t) in grid.iter().enumerate() {
            let (la, ssr) = profile_log_alpha(&coarse, t.exp(), &bodies)?;
            if ssr < best.1 {
                best = (i, ssr, la);
            }
        }
        if coarse.len() < acceleration_samples.len() {
            best.2 = profile_log_alpha(acceleration_samples, grid[best.0].exp(), &bodies)?.0;
        }
        if best.0 == 0 || best.0 == grid.len() - 1 {
            return Err(IdentifyError::NotIdentifiable(
                "a/b from accelerations alone: the fit runs off the range of V = U/(a/b) from 1e-4 to 1e4; give a/b or restitution data".into(),
            ));
        }
        ([grid[best.0], best.2], 1.0)
    } else {
        let r = fit_a_over_b(restitution_samples)?;
        let (la, _) = profile_log_alpha(acceleration_samples, r.a_over_b.value, &bodies)?;
        ([r.a_over_b.value.ln(), la], r.residual_std.max(1e-12))
    };
    let (_, ssr_a) = profile_log_alpha(acceleration_samples, theta[0].exp(), &bodies)?;
    let sigma_a = if acceleration_only {
        1.0
    } else {
        (ssr_a / (acceleration_samples.len() - 1) as f64)
            .sqrt()
            .max(1e-12)
    };
    let problem = JointProblem {
        restitution: restitution_samples,
        acceleration: acceleration_samples,
        bodies,
        sigma_e,
        sigma_a,
    };
    let (mut cost, mut jtj, mut jtr) = problem.normal_equations(theta)?;
    let mut lambda = 1e-3;
    'outer: for _ in 0..200 {
        for _ in 0..30 {
            let damped = [
                [jtj[0][0] * (1.0 + lambda), jtj[0][1]],
                [jtj[1][0], jtj[1][1] * (1.0 + lambda)],
            ];
            let Some(step) = solve2(damped, jtr) else {
                return Err(IdentifyError::NotIdentifiable(
                    "a/b and alpha jointly: the normal equations are singular (the data determine only a combination of them); give a/b or restitution data".into(),
                ));
            };
            let trial_theta = [theta[0] + step[0], theta[1] + step[1]];
            let (trial, tj, tr) = problem.normal_equations(trial_theta)?;
            if trial <= cost {
                let converged =
                    step[0].abs().max(step[1].abs()) < 1e-13 || cost - trial <= 1e-15 * cost;
                theta = trial_theta;
                cost = trial;
                jtj = tj;
                jtr = tr;
                lambda = (lambda * 0.3).max(1e-12);
                if converged {
                    break 'outer;
                }
                continue 'outer;
            }
            lambda *= 10.0;
        }
        break;
    }
    let n = restitution_samples.len() + acceleration_samples.len();
    let s2 = cost / (n - 2) as f64;
    let inv = |r| solve2(jtj, r);
    let (Some(c0), Some(c1)) = (inv([1.0, 0.0]), inv([0.0, 1.0])) else {
        return Err(IdentifyError::NotIdentifiable(
            "a/b and alpha jointly: singular covariance".into(),
        ));
    };
    let (var_q, var_a, cov) = (s2 * c0[0], s2 * c1[1], s2 * c0[1]);
    let (q, alpha) = (theta[0].exp(), theta[1].exp());
    let restitution_residuals = if acceleration_only {
        Vec::new()
    } else {
        finish_restitution_fit(restitution_samples, theta[0], 0.0)?.residuals
    };
    let acceleration_residuals = acceleration_residuals(acceleration_samples, q, alpha, &bodies)?;
    let ssr_log: f64 = acceleration_residuals
        .iter()
        .map(|r| r.residual * r.residual)
        .sum();
    Ok(ExponentialLawFit {
        method: if acceleration_only {
            "joint-acceleration-only"
        } else {
            "joint"
        },
        a_over_b: Estimate {
            value: q,
            std_error: q * var_q.sqrt(),
        },
        alpha: Estimate {
            value: alpha,
            std_error: alpha * var_a.sqrt(),
        },
        correlation: cov / (var_q * var_a).sqrt(),
        restitution_residuals,
        acceleration_residuals,
        acceleration_residual_std: (ssr_log / (acceleration_samples.len() - 1) as f64).sqrt(),
    })
}

/// Result of an identification from measured impacts.
#[derive(Serialize, Debug, Clone)]
pub struct Identification {
    /// How it was made.
    pub method: String,
    /// a/b (m/s), if determined or given.
    pub a_over_b: Option<Estimate>,
    /// α (1/m), if acceleration data were given.
    pub alpha: Option<Estimate>,
    /// The a/b fit to the restitution data alone.
    pub restitution_fit: Option<RestitutionFit>,
    /// The α (or joint) fit.
    pub acceleration_fit: Option<ExponentialLawFit>,
}

/// The identification of seed §3 from whatever was measured: a/b from
/// restitution data alone; with acceleration data too, α given a/b
/// (`a_over_b` known, or fitted to the restitution data first: sequential,
/// as in the seed) or both jointly (`joint`, or no restitution data). An
/// empty slice means that data set was not measured.
pub fn identify(
    restitution: &[RestitutionSample],
    acceleration: &[AccelerationSample],
    bodies: TwoBodies,
    a_over_b: Option<f64>,
    joint: bool,
) -> Result<Identification, IdentifyError> {
    let restitution_fit = (!restitution.is_empty())
        .then(|| fit_a_over_b(restitution))
        .transpose()?;
    if acceleration.is_empty() {
        let Some(fit) = restitution_fit else {
            return Err(IdentifyError::InvalidParameter(
                "nothing to identify: give restitution and/or acceleration data".into(),
            ));
        };
        return Ok(Identification {
            method: "a-over-b-from-restitution".into(),
            a_over_b: Some(fit.a_over_b),
            alpha: None,
            restitution_fit: Some(fit),
            acceleration_fit: None,
        });
    }
    let (fit, method) = match (a_over_b, joint, &restitution_fit) {
        (Some(q), _, _) => (fit_alpha(acceleration, bodies, q), "alpha-given-a-over-b"),
        (None, true, _) | (None, false, None) => {
            (fit_joint(restitution, acceleration, bodies), "joint")
        }
        (None, false, Some(r)) => (
            fit_alpha(acceleration, bodies, r.a_over_b.value),
            "sequential: a/b from restitution, then alpha given a/b (alpha's std_error excludes a/b's uncertainty; use --joint for both)",
        ),
    };
    let fit = fit?;
    let a_over_b = match (&restitution_fit, method) {
        (Some(r), m) if m.starts_with("sequential") => Some(r.a_over_b),
        _ => Some(fit.a_over_b),
    };
    Ok(Identification {
        method: if method == "joint" {
            fit.method.to_string()
        } else {
            method.to_string()
        },
        a_over_b,
        alpha: Some(fit.alpha),
        restitution_fit,
        acceleration_fit: Some(fit),
    })
}

pub mod measured;

#[cfg(test)]
mod tests;
