//! Test systems and option helpers shared by the integrator tests.

use crate::integrate::{BandMatrix, IntegratorOptions, OdeSystem};
use std::cell::Cell;

/// Harmonic oscillator y1' = y2, y2' = -y1; from (1, 0): (cos t, -sin t).
/// With `analytic`, the Jacobian is supplied (else finite differences).
pub struct Harmonic {
    pub analytic: bool,
}

impl Harmonic {
    /// Without an analytic Jacobian.
    pub fn plain() -> Self {
        Self { analytic: false }
    }
}

impl OdeSystem for Harmonic {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = -y[0];
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
        if self.analytic {
            jac.set(0, 1, 1.0);
            jac.set(1, 0, -1.0);
        }
        self.analytic
    }
}

/// y' = −y (exact: y0·e^{−t}) with traps: `f` is NaN where |y| >
/// `nan_above`, y < `nan_below` or t > `nan_after`; states are admissible
/// only in [`admissible_min`, `admissible_max`] and within `tube` of the
/// exact solution from y(0) = 1. Counts the traps that fired.
pub struct Decay {
    pub nan_above: f64,
    pub nan_below: f64,
    pub nan_after: f64,
    pub admissible_min: f64,
    pub admissible_max: f64,
    pub tube: f64,
    pub nan_returns: u64,
    pub inadmissible: Cell<u64>,
}

impl Decay {
    /// No trap set.
    pub fn new() -> Self {
        Self {
            nan_above: f64::INFINITY,
            nan_below: f64::NEG_INFINITY,
            nan_after: f64::INFINITY,
            admissible_min: f64::NEG_INFINITY,
            admissible_max: f64::INFINITY,
            tube: f64::INFINITY,
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
        if y[0].abs() > self.nan_above || y[0] < self.nan_below || t > self.nan_after {
            self.nan_returns += 1;
            d[0] = f64::NAN;
        } else {
            d[0] = -y[0];
        }
    }
    fn admissible(&self, t: f64, y: &[f64]) -> bool {
        let ok = (self.admissible_min..=self.admissible_max).contains(&y[0])
            && (y[0] - (-t).exp()).abs() <= self.tube;
        if !ok {
            self.inadmissible.set(self.inadmissible.get() + 1);
        }
        ok
    }
}

/// Options for fixed steps `h`: every step accepted (huge tolerances),
/// never grown (`h_max = h`).
pub fn fixed(h: f64) -> IntegratorOptions {
    IntegratorOptions {
        rtol: 1e6,
        atol: 1e6,
        h_init: Some(h),
        h_max: h,
        ..Default::default()
    }
}

/// Options with `rtol = atol = tol`.
pub fn tol(tol: f64) -> IntegratorOptions {
    IntegratorOptions {
        rtol: tol,
        atol: tol,
        ..Default::default()
    }
}

/// Observed order from the errors at step `h` and `h/2`.
pub fn observed_order(e_coarse: f64, e_fine: f64) -> f64 {
    (e_coarse / e_fine).log2()
}

/// All rooted trees up to `max_order`, as (order, children): children are
/// indices of earlier trees, non-increasing, so each tree appears once.
pub fn rooted_trees(max_order: usize) -> Vec<(usize, Vec<usize>)> {
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

/// Per tree: density γ(t) and the stage vector Φ_i(t) of the tableau `a`
/// (row i: the coefficients of stage i; `Φ_i(•) = 1`,
/// `Φ_i([t1..tm]) = Π_k Σ_j a_ij Φ_j(t_k)`). A method's weights `w` meet
/// the order condition of tree t when `w·Φ(t) = 1/γ(t)`.
pub fn tree_data(trees: &[(usize, Vec<usize>)], a: &[&[f64]]) -> Vec<(f64, Vec<f64>)> {
    let mut data: Vec<(f64, Vec<f64>)> = Vec::new();
    for (order, children) in trees {
        let mut gamma = *order as f64;
        let mut phi = vec![1.0; a.len()];
        for &c in children {
            let (g, pc) = &data[c];
            gamma *= g;
            for (i, p) in phi.iter_mut().enumerate() {
                let a_phi: f64 = a[i].iter().zip(pc).map(|(a, x)| a * x).sum();
                *p *= a_phi;
            }
        }
        data.push((gamma, phi));
    }
    data
}

/// `w · φ`.
pub fn dot(w: &[f64], phi: &[f64]) -> f64 {
    w.iter().zip(phi).map(|(a, b)| a * b).sum()
}
