//! The motion over one interval as its Taylor series (docs/theory.md §13):
//! `ẏ = A y + b − e (a₀ + s τ)` from `y` at τ = 0 moves as `y(τ) = Σ c_j
//! τ^j` with `c₀ = y`, `c₁ = A y + b − e a₀`, `c₂ = (A c₁ − e s)/2` and
//! `c_j = A c_{j−1}/j` beyond, exactly (the series of a linear system with
//! a forcing linear in time): summed to the first term below 1e-16 of the
//! largest, it is the motion to rounding, and so are its derivatives. The
//! coefficients are kept scaled, `c_j h^j` (a polynomial in θ = τ/h on
//! [0, 1]): a term's size is then the coefficient's, and the values at
//! the interval's end are sums.

use crate::dynamics::{Added, PiecewiseForm};

/// Most terms of a series; an interval whose terms have not fallen by
/// then is too long for it ([`Built::TooLong`]).
const MAX_TERMS: usize = 40;
/// Where a series is cut: at the first term (from the third) below this
/// part of the largest over the interval (the terms then fall by more
/// than a factor 10 each, so what is left is below rounding).
const CUT: f64 = 1e-16;

/// How a series was built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Built {
    /// Its terms fell below [`CUT`].
    Done,
    /// They did not by [`MAX_TERMS`]: halve the interval.
    TooLong,
    /// A term was not finite.
    NonFinite,
}

/// The series of one interval.
#[derive(Clone, Debug)]
pub(super) struct Series {
    dim: usize,
    /// The scaled coefficients `c_j h^j`, one state after the other.
    c: Vec<f64>,
    /// How many.
    terms: usize,
    /// The interval's length, its inverse and its inverse squared.
    h: f64,
    inv_h: f64,
    inv_h2: f64,
    /// Every component's value and first two derivatives at its end, τ =
    /// h (read at every piece's end: the samples, the gauges, the
    /// switches and the next state).
    end: Vec<[f64; 3]>,
    /// `Σ_{j≥4} j m_j` and `Σ_{j≥4} j (j−1) m_j`, m_j the largest
    /// displacement's coefficient of term j: the tails of
    /// [`Series::rate_bounds`].
    tails: (f64, f64),
}

impl Series {
    /// Room for states of `dim` values.
    pub(super) fn new(dim: usize) -> Self {
        Self {
            dim,
            c: vec![0.0; dim * MAX_TERMS],
            terms: 0,
            h: 0.0,
            inv_h: 0.0,
            inv_h2: 0.0,
            end: vec![[0.0; 3]; dim],
            tails: (0.0, 0.0),
        }
    }

    /// The series of the motion of `form` from `y` over `[0, h]` under the
    /// base acceleration `a0 + s τ`.
    pub(super) fn build(
        &mut self,
        form: &PiecewiseForm,
        y: &[f64],
        (a0, s): (f64, f64),
        h: f64,
    ) -> Built {
        let d = self.dim;
        self.h = h;
        self.inv_h = 1.0 / h;
        self.inv_h2 = self.inv_h * self.inv_h;
        self.c[..d].copy_from_slice(y);
        let mut largest = y.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        self.tails = (0.0, 0.0);
        for j in 1..MAX_TERMS {
            let (before, after) = self.c.split_at_mut(j * d);
            let (prev, next) = (&before[(j - 1) * d..], &mut after[..d]);
            let added = match j {
                1 => Added::ConstantLess(a0),
                2 => Added::Less(s * h),
                _ => Added::Nothing,
            };
            let top = form.scaled_term(prev, next, added, h / j as f64);
            if j >= 4 {
                let jf = j as f64;
                self.tails.0 += jf * top[0];
                self.tails.1 += jf * (jf - 1.0) * top[0];
            }
            let top = if top[0] > top[1] { top[0] } else { top[1] };
            if !top.is_finite() {
                return Built::NonFinite;
            }
            largest = largest.max(top);
            if j >= 3 && top <= CUT * largest {
                self.terms = j + 1;
                self.ends();
                return Built::Done;
            }
        }
        Built::TooLong
    }

    /// Every component's value and first two derivatives at `h` into
    /// `end`: at θ = 1 sums of the coefficients.
    fn ends(&mut self) {
        let d = self.dim;
        for e in self.end.iter_mut() {
            *e = [0.0; 3];
        }
        for j in (0..self.terms).rev() {
            let jf = j as f64;
            let c = &self.c[j * d..(j + 1) * d];
            for (e, c) in self.end.iter_mut().zip(c) {
                e[0] += c;
                e[1] += jf * c;
                e[2] += jf * (jf - 1.0) * c;
            }
        }
        let (r, q) = (self.inv_h, self.inv_h2);
        for e in self.end.iter_mut() {
            e[1] *= r;
            e[2] *= q;
        }
    }

    /// How many terms it has.
    pub(super) fn terms(&self) -> usize {
        self.terms
    }

    /// The state at τ into `out`.
    pub(super) fn state(&self, tau: f64, out: &mut [f64]) {
        let d = self.dim;
        if tau == self.h {
            for (o, e) in out.iter_mut().zip(&self.end) {
                *o = e[0];
            }
            return;
        }
        let theta = tau / self.h;
        out.copy_from_slice(&self.c[(self.terms - 1) * d..self.terms * d]);
        for j in (0..self.terms - 1).rev() {
            let c = &self.c[j * d..(j + 1) * d];
            for (o, c) in out.iter_mut().zip(c) {
                *o = *o * theta + c;
            }
        }
    }

    /// Component i at τ and its first two derivatives.
    #[inline(always)]
    pub(super) fn component(&self, i: usize, tau: f64) -> (f64, f64, f64) {
        let d = self.dim;
        if tau == 0.0 {
            return (
                self.c[i],
                self.c[d + i] * self.inv_h,
                2.0 * self.c[2 * d + i] * self.inv_h2,
            );
        }
        if tau == self.h {
            let [x, r, q] = self.end[i];
            return (x, r, q);
        }
        self.component_inside(i, tau)
    }

    /// [`Series::component`] inside the interval, by Horner.
    #[inline(never)]
    fn component_inside(&self, i: usize, tau: f64) -> (f64, f64, f64) {
        let d = self.dim;
        let theta = tau / self.h;
        let (mut x, mut dx, mut ddx) = (0.0, 0.0, 0.0);
        for j in (0..self.terms).rev() {
            let c = self.c[j * d + i];
            ddx = ddx * theta + 2.0 * dx;
            dx = dx * theta + x;
            x = x * theta + c;
        }
        (x, dx * self.inv_h, ddx * self.inv_h2)
    }

    /// `component(i) − component(j)` (j None: zero) at τ and its rate.
    #[inline(always)]
    pub(super) fn value_rate(&self, i: usize, j: Option<usize>, tau: f64) -> (f64, f64) {
        if tau == 0.0 || tau == self.h {
            let a = self.component(i, tau);
            let b = j.map_or((0.0, 0.0, 0.0), |j| self.component(j, tau));
            return (a.0 - b.0, a.1 - b.1);
        }
        self.value_rate_inside(i, j, tau)
    }

    /// [`Series::value_rate`] inside the interval, by Horner on the
    /// difference's coefficients.
    #[inline(never)]
    fn value_rate_inside(&self, i: usize, j: Option<usize>, tau: f64) -> (f64, f64) {
        let d = self.dim;
        let theta = tau / self.h;
        let (mut x, mut dx) = (0.0, 0.0);
        for k in (0..self.terms).rev() {
            let c = self.c[k * d + i] - j.map_or(0.0, |j| self.c[k * d + j]);
            dx = dx * theta + x;
            x = x * theta + c;
        }
        (x, dx * self.inv_h)
    }

    /// Bounds over the whole interval on the first and second derivatives
    /// of `component(i) − component(j)`, two displacements (i, j even),
    /// from the coefficients' magnitudes: `Σ k |c_k| h^{k−1}` and `Σ k (k−1)
    /// |c_k| h^{k−2}` of the difference, rigorous for the series; beyond
    /// the third term by the largest displacement's coefficients, once for
    /// each side.
    pub(super) fn rate_bounds(&self, i: usize, j: Option<usize>) -> (f64, f64) {
        debug_assert!(i % 2 == 0 && j.is_none_or(|j| j % 2 == 0));
        let d = self.dim;
        let (mut first, mut second) = (0.0, 0.0);
        for k in 1..self.terms.min(4) {
            let c = (self.c[k * d + i] - j.map_or(0.0, |j| self.c[k * d + j])).abs();
            let kf = k as f64;
            first += kf * c;
            second += kf * (kf - 1.0) * c;
        }
        let sides = if j.is_some() { 2.0 } else { 1.0 };
        first += sides * self.tails.0;
        second += sides * self.tails.1;
        (first * self.inv_h, second * self.inv_h2)
    }
}
