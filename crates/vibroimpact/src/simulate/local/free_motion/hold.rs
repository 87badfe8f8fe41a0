//! A record under first-order hold: its sample intervals, its typical
//! step, and the step `x(b) = Φ x(a) + γ₀ f(a) + γ₁ f'` of one interval
//! from the exponential of the augmented matrix (Van Loan; see the module
//! documentation of `free_motion`).

use nalgebra::DMatrix;

use crate::model::Accelerogram;

/// The first-order-hold step of one record sample interval `τ`: `x(b) =
/// Φ x(a) + γ₀ f(a) + γ₁ f'` (the columns of the augmented exponential).
#[derive(Clone, Debug)]
pub(super) struct HoldStep {
    pub(super) tau: f64,
    pub(super) phi: DMatrix<f64>,
    pub(super) g0: Vec<f64>,
    pub(super) g1: Vec<f64>,
}

/// Calls `step(τ, f(a), f')` for every interval `[a, a + τ]` between
/// `t0`, the record's samples and `t1`: the forcing `f = −z̈` (zero
/// outside the record) is linear over each. A sample within 1e-12 of a
/// record step of `t0` or `t1` (rounding of the same time) is not a
/// breakpoint: the sliver would cost a step of its own for a change of
/// the state far below any tolerance.
pub(super) fn intervals(rec: &Accelerogram, t0: f64, t1: f64, mut step: impl FnMut(f64, f64, f64)) {
    let times = rec.times();
    let (first, last) = (times[0], times[times.len() - 1]);
    let sliver = 1e-12 * (last - first) / (times.len().max(2) - 1) as f64;
    let mut ta = t0;
    let mut k = times.partition_point(|&s| s <= t0 + sliver);
    while ta < t1 {
        let tb = match times.get(k) {
            Some(&s) if s < t1 - sliver => s,
            _ => t1,
        };
        let mid = 0.5 * (ta + tb);
        let (fa, fb) = if mid > first && mid < last {
            (-rec.at(ta), -rec.at(tb))
        } else {
            (0.0, 0.0)
        };
        let tau = tb - ta;
        step(tau, fa, (fb - fa) / tau);
        ta = tb;
        k += 1;
    }
}

/// The typical sample step of `times`: the median of its steps. Whole
/// steps of that length are computed once; a record need not be uniform
/// for that to pay (a pounding row appends a free-vibration tail, two
/// steps of other lengths, to its record: with a uniform step required,
/// every step of such a record had its coefficients computed anew, 30 %
/// of a 16-building row's run).
pub(super) fn typical_step(times: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return None;
    }
    let mid = steps.len() / 2;
    let (_, median, _) = steps.select_nth_unstable_by(mid, f64::total_cmp);
    Some(*median)
}

/// `Φ = e^{Aτ}`, `γ₀` and `γ₁` of the first-order hold over `τ`: the
/// exponential of the augmented matrix (Van Loan).
pub(super) fn matrices(a: &DMatrix<f64>, tau: f64) -> (DMatrix<f64>, Vec<f64>, Vec<f64>) {
    let d = a.nrows();
    let mut big = DMatrix::<f64>::zeros(d + 2, d + 2);
    big.view_mut((0, 0), (d, d)).copy_from(&(a * tau));
    for j in 0..d / 2 {
        big[(2 * j + 1, d)] = tau;
    }
    big[(d, d + 1)] = tau;
    let e = big.exp();
    (
        e.view((0, 0), (d, d)).into_owned(),
        (0..d).map(|i| e[(i, d)]).collect(),
        (0..d).map(|i| e[(i, d + 1)]).collect(),
    )
}

/// `x ← Φ x + γ₀ fa + γ₁ slope`: `x(b)` from `x = x(a)` under the
/// forcing `f(t) = fa + slope (t − a)` in every velocity row (the
/// harmonic part already removed); `y` is scratch of `x`'s length.
pub(super) fn step(
    step: (&DMatrix<f64>, &[f64], &[f64]),
    fa: f64,
    slope: f64,
    x: &mut [f64],
    y: &mut [f64],
) {
    let (phi, g0, g1) = step;
    for ((yi, a), b) in y.iter_mut().zip(g0).zip(g1) {
        *yi = a * fa + b * slope;
    }
    // Column by column (Φ is stored by columns).
    for (column, xj) in phi.as_slice().chunks_exact(x.len()).zip(x.iter()) {
        for (yi, p) in y.iter_mut().zip(column) {
            *yi += p * xj;
        }
    }
    x.copy_from_slice(y);
}
