//! Elastic response spectra of a record (docs/earthquakes.md): the peak
//! response of linear oscillators `x'' + 2ζω x' + ω² x = −a_g(t)` over the
//! record, computed exactly for the piecewise-linear ground acceleration of
//! its samples (Nigam and Jennings, 1969). Over a step of length h with
//! `a_g` linear from a_k to a_{k+1}, the state y = (x, x') obeys
//!
//! Files: `mod.rs` (the spectra), `tests.rs` (against closed forms and an
//! independent integration).
//!
//! `y_{k+1} = E y_k + Γ₀ a_k + Γ₁ (a_{k+1} − a_k)`,
//!
//! with `E = e^{Mh}` (M the oscillator's matrix), `Γ₀ = −∫₀ʰ e^{Ms} ds e₂`
//! and `Γ₁ = −∫₀ʰ e^{M(h−τ)} τ/h dτ e₂`, all read from the exponential of
//! one 4 × 4 block matrix (Van Loan, 1978), computed once per period and
//! time step. Peaks are taken over the record's time steps, as
//! Nigam–Jennings and `eqsig` do.

use crate::field_error::FieldError;
use nalgebra::{Matrix2, Matrix4, Vector2};

use crate::model::record::Record;

/// The spectral values at one period.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectralPoint {
    /// Period T (s).
    pub period: f64,
    /// Peak relative displacement SD = max |x| (m).
    pub displacement: f64,
    /// Pseudo-velocity PSV = ω SD (m/s).
    pub pseudo_velocity: f64,
    /// Pseudo-acceleration PSA = ω² SD (m/s²).
    pub pseudo_acceleration: f64,
}

/// The exact step (E, Γ₀, Γ₁) of one oscillator over one time step.
type Step = (Matrix2<f64>, Vector2<f64>, Vector2<f64>);

/// The step matrices (E, Γ₀, Γ₁) of the oscillator (ω, ζ) over h: the
/// exponential of the generator of w = (x, x', a_g, s) with a_g' = s (the
/// constant slope), s' = 0, started at (y, a_k, (a_{k+1} − a_k)/h): its
/// first two columns are E, its third Γ₀ and its fourth h·Γ₁.
fn step_matrices(omega: f64, zeta: f64, h: f64) -> Step {
    let mut a = Matrix4::zeros();
    a[(0, 1)] = 1.0;
    a[(1, 0)] = -omega * omega;
    a[(1, 1)] = -2.0 * zeta * omega;
    a[(1, 2)] = -1.0;
    a[(2, 3)] = 1.0;
    let e = (a * h).exp();
    (
        Matrix2::new(e[(0, 0)], e[(0, 1)], e[(1, 0)], e[(1, 1)]),
        Vector2::new(e[(0, 2)], e[(1, 2)]),
        Vector2::new(e[(0, 3)], e[(1, 3)]) / h,
    )
}

/// The response spectrum of `record` (scaled by `scale`) at damping ratio
/// `damping` for every period in `periods` (s, positive). Each oscillator
/// starts at rest; peaks over the record's time steps.
pub fn response_spectrum(
    record: &Record,
    scale: f64,
    damping: f64,
    periods: &[f64],
) -> Result<Vec<SpectralPoint>, FieldError> {
    if !(damping.is_finite() && (0.0..1.0).contains(&damping)) {
        return Err(FieldError::new(
            "damping",
            damping,
            "give a ratio in [0, 1)",
        ));
    }
    if !scale.is_finite() {
        return Err(FieldError::new("scale", scale, "must be finite"));
    }
    if let Some(t) = periods.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        return Err(FieldError::new(
            "periods",
            t,
            "periods must be positive and finite",
        ));
    }
    let a: Vec<f64> = record.acceleration.iter().map(|v| v * scale).collect();
    let steps: Vec<f64> = record.times.windows(2).map(|w| w[1] - w[0]).collect();
    Ok(periods
        .iter()
        .map(|&period| {
            let omega = 2.0 * std::f64::consts::PI / period;
            let mut cached: Option<(f64, Step)> = None;
            let mut y = Vector2::zeros();
            let mut peak = 0.0f64;
            for (k, &h) in steps.iter().enumerate() {
                let m = match cached {
                    Some((hc, m)) if hc == h => m,
                    _ => {
                        let m = step_matrices(omega, damping, h);
                        cached = Some((h, m));
                        m
                    }
                };
                y = m.0 * y + m.1 * a[k] + m.2 * (a[k + 1] - a[k]);
                peak = peak.max(y[0].abs());
            }
            SpectralPoint {
                period,
                displacement: peak,
                pseudo_velocity: omega * peak,
                pseudo_acceleration: omega * omega * peak,
            }
        })
        .collect())
}

/// `n` periods from `a` to `b` (s), logarithmically spaced if `log`.
pub fn periods(a: f64, b: f64, n: usize, log: bool) -> Result<Vec<f64>, String> {
    if !(a.is_finite() && b.is_finite() && a > 0.0 && b > a && n >= 2) {
        return Err(format!(
            "periods {a}:{b}:{n}: give 0 < first < last and at least 2 periods"
        ));
    }
    Ok((0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            if log {
                (a.ln() + s * (b.ln() - a.ln())).exp()
            } else {
                a + s * (b - a)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests;
