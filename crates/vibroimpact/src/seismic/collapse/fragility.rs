//! The lognormal collapse fragility P(collapse | S) = Φ(ln(S/θ)/β) fitted
//! to a collapse study's records by maximum likelihood (docs/theory.md
//! §11, "Fragility"): a record that collapsed at S contributes its density,
//! a censored one (standing up to S) its survival 1 − Φ.
//!
//! Without censored records the fit is closed form (θ the geometric mean,
//! β the standard deviation of ln S). With them it is the censored-normal
//! (Tobit) likelihood of ln S, concave in γ = 1/β and δ = μ/β (Olsen
//! 1978): Newton's method on (γ, δ) with a backtracking line search, from
//! the collapsed records' moments. Newton that does not converge is an
//! error, never a fit.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

/// A lognormal fragility fitted to a study's collapse intensities.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Fragility {
    /// θ, the median collapse intensity of the fit.
    pub median: f64,
    /// β, the dispersion (the standard deviation of ln S).
    pub dispersion: f64,
    /// The records fitted.
    pub records: usize,
    /// Those of them censored (no collapse up to their intensity).
    pub censored: usize,
}

impl Fragility {
    /// The fitted probability of collapse at intensity `s`.
    pub fn probability(&self, s: f64) -> f64 {
        if s <= 0.0 {
            return 0.0;
        }
        0.5 * libm::erfc(-(s / self.median).ln() / self.dispersion * FRAC_1_SQRT_2)
    }
}

/// Why no fragility is determined.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FragilityError {
    /// An intensity that is not positive and finite.
    #[error("record {index}: collapse intensity {value}; give positive finite intensities")]
    Intensity {
        /// The record (from 1).
        index: usize,
        /// Its intensity.
        value: f64,
    },
    /// Fewer than two records collapsed: no dispersion can be told.
    #[error(
        "{collapsed} of {records} records collapsed; a fragility needs at least two collapses"
    )]
    TooFewCollapses {
        /// The records that collapsed.
        collapsed: usize,
        /// All records.
        records: usize,
    },
    /// Every record collapsed at one intensity: zero dispersion.
    #[error("every record collapsed at the same intensity {0}; the dispersion is zero and no lognormal fragility is determined")]
    NoSpread(f64),
    /// Newton's method on the likelihood did not converge.
    #[error("the likelihood fit did not converge in {0} Newton steps")]
    NotConverged(usize),
}

/// The maximum-likelihood lognormal fragility of the records' intensities
/// (`intensities[i]` the collapse intensity, or with `censored[i]` the
/// largest intensity survived). Refuses fewer than two collapses and zero
/// spread.
pub fn fragility(intensities: &[f64], censored: &[bool]) -> Result<Fragility, FragilityError> {
    assert_eq!(intensities.len(), censored.len(), "one flag per record");
    if let Some((i, &v)) = intensities
        .iter()
        .enumerate()
        .find(|(_, v)| !(v.is_finite() && **v > 0.0))
    {
        return Err(FragilityError::Intensity {
            index: i + 1,
            value: v,
        });
    }
    let logs: Vec<f64> = intensities.iter().map(|s| s.ln()).collect();
    let fell: Vec<f64> = logs
        .iter()
        .zip(censored)
        .filter(|(_, c)| !**c)
        .map(|(y, _)| *y)
        .collect();
    if fell.len() < 2 {
        return Err(FragilityError::TooFewCollapses {
            collapsed: fell.len(),
            records: logs.len(),
        });
    }
    let n = fell.len() as f64;
    let mean = fell.iter().sum::<f64>() / n;
    let sd = (fell.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / n).sqrt();
    if sd <= 1e-14 * mean.abs().max(1.0) && fell.len() == logs.len() {
        return Err(FragilityError::NoSpread(fell[0].exp()));
    }
    let (mu, beta) = if fell.len() == logs.len() {
        (mean, sd)
    } else {
        tobit(&logs, censored, mean, sd.max(1e-3))?
    };
    Ok(Fragility {
        median: mu.exp(),
        dispersion: beta,
        records: logs.len(),
        censored: logs.len() - fell.len(),
    })
}

/// ln(1 − Φ(z)) and the inverse Mills ratio φ(z)/(1 − Φ(z)); far in the
/// upper tail from the ratio's asymptotic series (1 − Φ underflows).
fn upper_tail(z: f64) -> (f64, f64) {
    let q = 0.5 * libm::erfc(z * FRAC_1_SQRT_2);
    let log_phi = -0.5 * z * z - 0.5 * (2.0 * PI).ln();
    if q > 1e-300 {
        (q.ln(), (log_phi - q.ln()).exp())
    } else {
        // φ/Q = z + 1/z − 2/z³ + … for z → ∞.
        let mills = z + 1.0 / z - 2.0 / z.powi(3);
        (log_phi - mills.ln(), mills)
    }
}

/// The censored-normal likelihood of `logs` maximized by Newton's method
/// on (γ, δ) = (1/β, μ/β), where it is concave; returns (μ, β).
fn tobit(
    logs: &[f64],
    censored: &[bool],
    mu0: f64,
    beta0: f64,
) -> Result<(f64, f64), FragilityError> {
    const STEPS: usize = 200;
    // The log-likelihood with its gradient and Hessian in (γ, δ).
    let eval = |g: f64, d: f64| {
        let (mut l, mut grad, mut h) = (0.0, [0.0; 2], [[0.0; 2]; 2]);
        for (&y, &c) in logs.iter().zip(censored) {
            let z = g * y - d;
            if c {
                let (log_q, lam) = upper_tail(z);
                let w = lam * (lam - z);
                l += log_q;
                grad[0] -= lam * y;
                grad[1] += lam;
                h[0][0] -= w * y * y;
                h[0][1] += w * y;
                h[1][1] -= w;
            } else {
                l += -0.5 * z * z + g.ln();
                grad[0] += -z * y + 1.0 / g;
                grad[1] += z;
                h[0][0] -= y * y + 1.0 / (g * g);
                h[0][1] += y;
                h[1][1] -= 1.0;
            }
        }
        h[1][0] = h[0][1];
        (l, grad, h)
    };
    let (mut g, mut d) = (1.0 / beta0, mu0 / beta0);
    for _ in 0..STEPS {
        let (l, grad, h) = eval(g, d);
        // The Newton step −H⁻¹ ∇ℓ (H negative definite).
        let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
        let step = [
            -(h[1][1] * grad[0] - h[0][1] * grad[1]) / det,
            -(-h[1][0] * grad[0] + h[0][0] * grad[1]) / det,
        ];
        let decrement = -(step[0] * grad[0] + step[1] * grad[1]);
        if !decrement.is_finite() {
            break;
        }
        if decrement.abs() < 1e-24 * (1.0 + l.abs()) {
            return Ok((d / g, 1.0 / g));
        }
        let mut t = 1.0;
        loop {
            let (gn, dn) = (g + t * step[0], d + t * step[1]);
            if gn > 0.0 && eval(gn, dn).0 >= l {
                g = gn;
                d = dn;
                break;
            }
            t *= 0.5;
            if t < 1e-12 {
                return Err(FragilityError::NotConverged(STEPS));
            }
        }
        let small =
            (t * step[0]).abs() <= 1e-13 * g && (t * step[1]).abs() <= 1e-13 * (1.0 + d.abs());
        if small {
            return Ok((d / g, 1.0 / g));
        }
    }
    Err(FragilityError::NotConverged(STEPS))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic sample of a lognormal(θ, β): quantiles at
    /// (i − ½)/n.
    fn quantiles(n: usize, theta: f64, beta: f64) -> Vec<f64> {
        // Φ⁻¹ by bisection on erfc (a test's own inverse).
        let inv = |p: f64| {
            let (mut lo, mut hi) = (-10.0f64, 10.0f64);
            for _ in 0..200 {
                let m = 0.5 * (lo + hi);
                if 0.5 * libm::erfc(-m * FRAC_1_SQRT_2) < p {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            0.5 * (lo + hi)
        };
        (1..=n)
            .map(|i| theta * (beta * inv((i as f64 - 0.5) / n as f64)).exp())
            .collect()
    }

    /// Without censoring: θ the geometric mean, β the (population)
    /// standard deviation of ln S.
    #[test]
    fn uncensored_is_the_closed_form() {
        let s = [0.8, 1.1, 1.3, 2.0, 2.6];
        let f = fragility(&s, &[false; 5]).unwrap();
        let logs: Vec<f64> = s.iter().map(|x: &f64| x.ln()).collect();
        let mu = logs.iter().sum::<f64>() / 5.0;
        let beta = (logs.iter().map(|y| (y - mu).powi(2)).sum::<f64>() / 5.0).sqrt();
        assert!((f.median - mu.exp()).abs() < 1e-14);
        assert!((f.dispersion - beta).abs() < 1e-14);
        assert!((f.probability(f.median) - 0.5).abs() < 1e-15);
    }

    /// Censoring a sample's top at a level: the fit stays near the
    /// sample's own (the survival term carries the censored records);
    /// dropping them instead biases θ low. At the optimum the gradient
    /// vanishes (checked by central differences of the likelihood).
    #[test]
    fn censored_records_enter_with_their_survival() {
        let full = quantiles(400, 1.5, 0.4);
        let level = 2.2;
        let censored: Vec<bool> = full.iter().map(|s| *s > level).collect();
        let given: Vec<f64> = full.iter().map(|s| s.min(level)).collect();
        assert!(censored.iter().filter(|c| **c).count() > 50);
        let f = fragility(&given, &censored).unwrap();
        let whole = fragility(&full, &vec![false; 400]).unwrap();
        assert!(
            (f.median / whole.median - 1.0).abs() < 5e-3,
            "{f:?} {whole:?}"
        );
        assert!(
            (f.dispersion / whole.dispersion - 1.0).abs() < 2e-2,
            "{f:?} {whole:?}"
        );
        let fell: Vec<f64> = given
            .iter()
            .zip(&censored)
            .filter(|(_, c)| !**c)
            .map(|(s, _)| *s)
            .collect();
        let dropped = fragility(&fell, &vec![false; fell.len()]).unwrap();
        assert!(dropped.median < 0.95 * whole.median);
        // Stationary: the likelihood in (μ, β) is flat to first order.
        let ll = |mu: f64, beta: f64| -> f64 {
            given
                .iter()
                .zip(&censored)
                .map(|(s, c)| {
                    let z = (s.ln() - mu) / beta;
                    if *c {
                        upper_tail(z).0
                    } else {
                        -0.5 * z * z - beta.ln()
                    }
                })
                .sum()
        };
        let (mu, beta, h) = (f.median.ln(), f.dispersion, 1e-6);
        let dmu = (ll(mu + h, beta) - ll(mu - h, beta)) / (2.0 * h);
        let dbeta = (ll(mu, beta + h) - ll(mu, beta - h)) / (2.0 * h);
        assert!(dmu.abs() < 1e-5 && dbeta.abs() < 1e-5, "{dmu} {dbeta}");
    }

    /// One collapse, none, or no spread: refused, never a fit.
    #[test]
    fn undetermined_fits_are_refused() {
        assert_eq!(
            fragility(&[0.4], &[false]),
            Err(FragilityError::TooFewCollapses {
                collapsed: 1,
                records: 1
            })
        );
        assert!(matches!(
            fragility(&[1.0, 2.0, 3.0], &[true, true, false]),
            Err(FragilityError::TooFewCollapses { collapsed: 1, .. })
        ));
        assert_eq!(
            fragility(&[0.7, 0.7], &[false, false]),
            Err(FragilityError::NoSpread(0.7))
        );
        assert!(matches!(
            fragility(&[0.7, -1.0], &[false, false]),
            Err(FragilityError::Intensity { index: 2, .. })
        ));
    }

    /// The upper tail's series joins erfc where both hold.
    #[test]
    fn the_tail_series_joins_erfc() {
        let z = 30.0;
        let q = 0.5 * libm::erfc(z * FRAC_1_SQRT_2);
        let exact = (-0.5 * z * z - 0.5 * (2.0 * PI).ln()).exp() / q;
        let series = z + 1.0 / z - 2.0 / z.powi(3);
        assert!((series / exact - 1.0).abs() < 1e-6);
    }
}
