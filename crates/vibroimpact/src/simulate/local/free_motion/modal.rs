//! A group's free motion in its complex modes (docs/theory.md §10): with
//! `A = V Λ V⁻¹` and `z = V⁻¹ x`, every mode moves on its own,
//!
//! ```text
//! z_k(a + τ) = e^{λ_k τ} z_k(a) + β_k (f(a) τ φ₁(λ_k τ) + f' τ² φ₂(λ_k τ))
//! ```
//!
//! under a forcing `f` linear over the interval in every velocity row
//! (`β = V⁻¹ e`; `φ₁(s) = (e^s − 1)/s`, `φ₂(s) = (e^s − 1 − s)/s²`). A
//! propagation then costs two products with `V⁻¹` and `V` and scalars per
//! record sample, where the matrix exponential costs an exponential of the
//! augmented matrix per interval that does not start and end on samples.
//! Eigenvectors by inverse iteration on the eigenvalues of
//! [`crate::linalg::eigen`]; a group whose `V` is ill-conditioned (repeated or
//! nearly repeated eigenvalues: a critically damped body) has no modal
//! form and keeps the matrix exponential.

use nalgebra::{Complex, DMatrix, DVector};

type C64 = Complex<f64>;

/// Largest condition estimate `‖V‖₁ ‖V⁻¹‖₁` accepted: rounding in the
/// modal form grows with it (1e6: 1e-10 relative at worst).
const MAX_CONDITION: f64 = 1e6;

/// A group's modes.
#[derive(Clone, Debug)]
pub(super) struct Modal {
    lambda: Vec<C64>,
    v: DMatrix<C64>,
    /// `V` and `V⁻¹` by rows (each row contiguous: the transforms run
    /// along rows; nalgebra stores columns).
    v_rows: Vec<C64>,
    v_inv_rows: Vec<C64>,
    /// `V⁻¹ e` (`e`: ones in the velocity rows).
    beta: Vec<C64>,
    /// A record's whole sample step: τ and per mode `e^{λτ}`, `β τ φ₁`, `β
    /// τ² φ₂`.
    step: Option<(f64, Vec<[C64; 3]>)>,
    /// A whole step's equal part that the exact extrema's grid steps by
    /// (`FreeMotion::grid`), and its coefficients as for `step`.
    part: Option<(f64, Vec<[C64; 3]>)>,
}

/// `e^s`, `φ₁(s) = (e^s − 1)/s` and `φ₂(s) = (e^s − 1 − s)/s²`. For |s| ≤
/// 1 from the series of φ₂ (`φ₁ = 1 + s φ₂`, `e^s = 1 + s φ₁`: no
/// cancellation, no transcendental call), to the term `s^{M−2}/M!`
/// where the first one left, `|s|^{M−1}/(M+1)!`, is below 1e-18.
pub(super) fn phi(s: C64) -> (C64, C64, C64) {
    let r2 = s.norm_sqr();
    if r2 <= 1.0 {
        // φ₂ = (1/2)(1 + s/3 (1 + s/4 (1 + … (1 + s/M)))).
        let top = match r2 {
            r if r <= 1e-4 => 8,
            r if r <= 1e-2 => 11,
            r if r <= 0.0625 => 13,
            r if r <= 0.25 => 16,
            _ => 20,
        };
        let mut q = C64::new(1.0, 0.0);
        for m in (3..=top).rev() {
            q = q * s * (1.0 / m as f64) + 1.0;
        }
        let p2 = q * 0.5;
        let p1 = s * p2 + 1.0;
        (s * p1 + 1.0, p1, p2)
    } else {
        let e = s.exp();
        let p1 = (e - 1.0) / s;
        (e, p1, (p1 - 1.0) / s)
    }
}

/// The 1-norm (largest column sum) of a complex matrix.
fn norm1(m: &DMatrix<C64>) -> f64 {
    m.column_iter()
        .map(|c| c.iter().map(|z| z.norm()).sum::<f64>())
        .fold(0.0, f64::max)
}

impl Modal {
    /// The modes of `a` (interleaved `[u, v]` rows), with the whole-step
    /// coefficients for a record sampled every `record_step` s; None if
    /// they cannot be trusted.
    pub(super) fn new(a: &DMatrix<f64>, record_step: Option<f64>) -> Option<Self> {
        let d = a.nrows();
        let lambda = crate::linalg::eigen::eigenvalues(a)?;
        let scale = a.amax().max(f64::MIN_POSITIVE);
        let ac = a.map(|x| C64::new(x, 0.0));
        let mut v = DMatrix::<C64>::zeros(d, d);
        for (k, &l) in lambda.iter().enumerate() {
            // Inverse iteration from a shift just off the eigenvalue.
            let shift = l + C64::new(1e-10 * scale, 1e-10 * scale);
            let lu = (&ac - DMatrix::from_diagonal_element(d, d, shift)).lu();
            let mut x = DVector::<C64>::from_fn(d, |i, _| C64::new(1.0, 0.1 * i as f64));
            for _ in 0..3 {
                x = lu.solve(&x)?;
                let n = x.norm();
                if !(n.is_finite() && n > 0.0) {
                    return None;
                }
                x /= C64::new(n, 0.0);
            }
            // The residual of a true eigenvector is rounding.
            let r = (&ac * &x - &x * l).norm();
            if r.is_nan() || r > 1e-9 * scale {
                return None;
            }
            v.set_column(k, &x);
        }
        let v_inv = v.clone().try_inverse()?;
        let condition = norm1(&v) * norm1(&v_inv);
        if !(condition.is_finite() && condition <= MAX_CONDITION) {
            return None;
        }
        let beta: Vec<C64> = (0..d)
            .map(|k| (0..d / 2).map(|j| v_inv[(k, 2 * j + 1)]).sum())
            .collect();
        let v_rows = v.transpose().as_slice().to_vec();
        let v_inv_rows = v_inv.transpose().as_slice().to_vec();
        let mut modal = Self {
            lambda,
            v,
            v_rows,
            v_inv_rows,
            beta,
            step: None,
            part: None,
        };
        modal.step = record_step.map(|tau| (tau, modal.coefficients(tau)));
        Some(modal)
    }

    /// Per mode `e^{λτ}`, `β τ φ₁(λτ)`, `β τ² φ₂(λτ)`.
    fn coefficients(&self, tau: f64) -> Vec<[C64; 3]> {
        self.lambda
            .iter()
            .zip(&self.beta)
            .map(|(&l, &b)| {
                let (e, p1, p2) = phi(l * tau);
                [e, b * p1 * tau, b * p2 * tau * tau]
            })
            .collect()
    }

    /// Keeps the coefficients of `tau`, a whole step's equal part.
    pub(super) fn keep_part(&mut self, tau: f64) {
        self.part = Some((tau, self.coefficients(tau)));
    }

    /// The whole step's equal part whose coefficients are kept (s).
    pub(super) fn part(&self) -> Option<f64> {
        self.part.as_ref().map(|(h, _)| *h)
    }

    /// The whole sample step whose coefficients are kept (s).
    #[cfg(test)]
    pub(super) fn whole_step(&self) -> Option<f64> {
        self.step.as_ref().map(|(h, _)| *h)
    }

    /// `z = V⁻¹ x`.
    pub(super) fn to_modes(&self, x: &[f64], z: &mut Vec<C64>) {
        let d = x.len();
        z.clear();
        z.extend(self.v_inv_rows.chunks_exact(d).map(|r| {
            let (mut re, mut im) = (0.0, 0.0);
            for (a, &b) in r.iter().zip(x) {
                re += a.re * b;
                im += a.im * b;
            }
            C64::new(re, im)
        }));
    }

    /// `x = Re(V z)`.
    pub(super) fn to_state(&self, z: &[C64], x: &mut [f64]) {
        for (xi, r) in x.iter_mut().zip(self.v_rows.chunks_exact(z.len())) {
            *xi = r
                .iter()
                .zip(z)
                .map(|(a, b)| a.re * b.re - a.im * b.im)
                .sum();
        }
    }

    /// Per mode `[|w_k|, |z_k|, |β_k|, −Re λ_k]` of the quantity `q = Σ c
    /// x_r` over `rows` (row r of the interleaved state, coefficient c),
    /// `w_k = Σ c V_{rk}`, at the modal state `z` (an envelope's terms),
    /// into `out`.
    pub(super) fn envelope_terms(&self, z: &[C64], rows: &[(usize, f64)], out: &mut Vec<[f64; 4]>) {
        // |x| by the square root of the squares: `norm` calls hypot, a
        // tenth of a row's run at full scale.
        let abs = |x: C64| (x.re * x.re + x.im * x.im).sqrt();
        out.clear();
        out.extend((0..z.len()).map(|k| {
            let w: C64 = rows.iter().map(|&(r, c)| self.v[(r, k)] * c).sum();
            [abs(w), abs(z[k]), abs(self.beta[k]), -self.lambda[k].re]
        }));
    }

    /// `z ← e^{Λτ} z`, no forcing.
    pub(super) fn free(&self, tau: f64, z: &mut [C64]) {
        for (zk, l) in z.iter_mut().zip(&self.lambda) {
            *zk *= (l * tau).exp();
        }
    }

    /// One interval of length `tau` under the forcing `fa + slope s` in
    /// every velocity row.
    pub(super) fn hold(&self, tau: f64, fa: f64, slope: f64, z: &mut [C64]) {
        let apply = |z: &mut [C64], c: &[[C64; 3]]| {
            for (zk, [e, g0, g1]) in z.iter_mut().zip(c) {
                *zk = *e * *zk + g0 * fa + g1 * slope;
            }
        };
        // A whole sample step (to rounding of the sample times: 1e-12 of a
        // step moves the state by far less than any tolerance); a part of
        // the extrema's grid (to rounding of its times, a few ulps of the
        // time over the part: 1e-10 of it).
        let whole = self
            .step
            .as_ref()
            .filter(|(h, _)| (tau - h).abs() <= 1e-12 * h);
        let part = self
            .part
            .as_ref()
            .filter(|(h, _)| (tau - h).abs() <= 1e-10 * h);
        if let Some((_, c)) = whole.or(part) {
            apply(z, c);
        } else {
            // Any other: each mode's coefficients as they are used.
            for ((zk, &l), &b) in z.iter_mut().zip(&self.lambda).zip(&self.beta) {
                let (e, p1, p2) = phi(l * tau);
                *zk = e * *zk + b * p1 * (tau * fa) + b * p2 * (tau * tau * slope);
            }
        }
    }
}
