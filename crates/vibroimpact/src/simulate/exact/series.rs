//! The motion over one interval as its Taylor series (docs/theory.md §13):
//! `ẏ = A y + b − e (a₀ + s τ)` from `y = (u, v)` at τ = 0 moves as
//! `u(τ) = Σ c_j τ^j` (the velocities its derivative), with `c₀ = u`,
//! `c₁ = v` and, from the velocity rows of A (`K` on displacements, `C`
//! on velocities: `v̇ = K u + C v + b − a₀ − s τ`),
//! `c_{j+2} = (K c_j + (j+1) C c_{j+1} + f_j)/((j+1)(j+2))`, `f₀ = b − a₀`,
//! `f₁ = −s`, exactly (the series of a linear system with a forcing
//! linear in time): summed until a bound on what the terms left would add
//! is below 1e-16 of the largest ([`CUT`]), it is the motion to rounding,
//! and so are its derivatives. The
//! coefficients are kept scaled, `c_j h^j` (a polynomial in θ = τ/h on
//! [0, 1]): a term's size is then the coefficient's, and the values at
//! the interval's end are sums. Displacements alone are kept: a velocity
//! coefficient is the next displacement's times (j+1)/h, so a term costs
//! one row per body.

use crate::dynamics::{Added, FixedChain, PiecewiseForm};
use crate::numeric::larger;

/// Most terms of a series; an interval whose terms have not fallen by
/// then is too long for it ([`Built::TooLong`]).
const MAX_TERMS: usize = 40;
/// Where a series is cut: at the first term k (from the fifth) past
/// which the terms' sum on the displacements and on the velocities times
/// h, `Σ_{i>k} i |c_i h^i|`, is bounded below this part of the largest
/// `i |c_i h^i|` over the interval, with |u| and |v h| (what is left is
/// then below rounding). The
/// bound: from the recurrence, `M_{i+2} ≤ α_i M_i + β_i M_{i+1}` (M_i the
/// largest coefficient of term i, `α_i = |K| h²/((i+1)(i+2))` and `β_i =
/// |C| h/(i+2)` falling with i), so that every two terms past k are at
/// most ρ = α_{k−1} + β_{k−1} times the two before, and the sum is at
/// most `2 e ρ (k + 2)/(1 − ρ)²`, e the larger of terms k − 1 and k
/// (taken where ρ < 1/2; where both are zero, so is every term after).
/// |K| and |C| are upper bounds on the infinity norms
/// ([`PiecewiseForm::norms`]).
const CUT: f64 = 1e-16;

/// Per recurrence step j, `1/((j+1)(j+2))` and `1/(j+2)`: its weights
/// `wx_j` and `wz_j` over h² and h (see `Series::build`).
const STEPS: [[f64; 2]; MAX_TERMS] = {
    let mut w = [[0.0; 2]; MAX_TERMS];
    let mut j = 0;
    while j < MAX_TERMS {
        let jf = j as f64;
        w[j] = [1.0 / ((jf + 1.0) * (jf + 2.0)), 1.0 / (jf + 2.0)];
        j += 1;
    }
    w
};

/// Per term k, its weights in the sums at the end: θ^k's first three
/// derivatives at θ = 1 (its value there is one).
const AT_END: [[f64; 3]; MAX_TERMS] = {
    let mut w = [[0.0; 3]; MAX_TERMS];
    let mut k = 0;
    while k < MAX_TERMS {
        let kf = k as f64;
        w[k] = [kf, kf * (kf - 1.0), kf * (kf - 1.0) * (kf - 2.0)];
        k += 1;
    }
    w
};

/// How a series was built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Built {
    /// Its tail's bound fell below [`CUT`].
    Done,
    /// They did not by [`MAX_TERMS`]: halve the interval.
    TooLong,
    /// A term was not finite.
    NonFinite,
}

/// The series of one interval.
#[derive(Clone, Debug)]
pub(super) struct Series {
    /// Bodies.
    n: usize,
    /// The scaled displacement coefficients `c_j h^j`, one term's bodies
    /// after the other.
    c: Vec<f64>,
    /// The velocities at τ = 0 (exactly as given: `c₁ h / h` may differ
    /// in the last bit).
    v0: Vec<f64>,
    /// How many terms.
    terms: usize,
    /// The interval's length and the powers of its inverse (1, 1/h, 1/h²,
    /// 1/h³).
    h: f64,
    inv: [f64; 4],
    /// Every body's displacement and its first three derivatives at the
    /// end, τ = h (read at every piece's end: the samples, the gauges,
    /// the switches and the next state); while the series is built, the
    /// sums at θ = 1 that give them.
    end: Vec<[f64; 4]>,
    /// `Σ_{j≥4} j m_j` and `Σ_{j≥4} j (j−1) m_j`, m_j the largest
    /// displacement's coefficient of term j: the tails of
    /// [`Series::rate_bounds`].
    tails: (f64, f64),
}

impl Series {
    /// Room for states of `dim` values (`dim / 2` bodies).
    pub(super) fn new(dim: usize) -> Self {
        let n = dim / 2;
        Self {
            n,
            c: vec![0.0; n * MAX_TERMS],
            v0: vec![0.0; n],
            terms: 0,
            h: 0.0,
            inv: [1.0; 4],
            end: vec![[0.0; 4]; n],
            tails: (0.0, 0.0),
        }
    }

    /// The series of the motion of `form` from `y` over `[0, h]` under the
    /// base acceleration `a0 + s τ`. (A building of up to eight storeys
    /// by its chain's arrays, [`FixedChain`]: the same arithmetic, a
    /// third fewer instructions on the 4-storey frame.)
    pub(super) fn build(
        &mut self,
        form: &PiecewiseForm,
        y: &[f64],
        base: (f64, f64),
        h: f64,
    ) -> Built {
        let fixed = match self.n {
            1 => self.build_fixed::<1>(form, y, base, h),
            2 => self.build_fixed::<2>(form, y, base, h),
            3 => self.build_fixed::<3>(form, y, base, h),
            4 => self.build_fixed::<4>(form, y, base, h),
            5 => self.build_fixed::<5>(form, y, base, h),
            6 => self.build_fixed::<6>(form, y, base, h),
            7 => self.build_fixed::<7>(form, y, base, h),
            8 => self.build_fixed::<8>(form, y, base, h),
            _ => None,
        };
        fixed.unwrap_or_else(|| self.build_by(y, base, h, form.norms(), &Rows(form)))
    }

    /// [`Series::build`] by `form`'s chain of N bodies, if it is one.
    fn build_fixed<const N: usize>(
        &mut self,
        form: &PiecewiseForm,
        y: &[f64],
        base: (f64, f64),
        h: f64,
    ) -> Option<Built> {
        let chain = form.fixed::<N>()?;
        Some(self.build_by(y, base, h, form.norms(), &chain))
    }

    /// [`Series::build`] with the terms' product `terms`, under the form's
    /// `norms`.
    #[inline(always)]
    fn build_by(
        &mut self,
        y: &[f64],
        (a0, s): (f64, f64),
        h: f64,
        norms: (f64, f64),
        terms: &impl Terms,
    ) -> Built {
        let n = self.n;
        self.h = h;
        let r = 1.0 / h;
        self.inv = [1.0, r, r * r, r * r * r];
        let (c0, rest) = self.c.split_at_mut(n);
        let c1 = &mut rest[..n];
        let mut largest = 0.0f64;
        for ((((u, v), (c0, c1)), v0), e) in y
            .iter()
            .step_by(2)
            .zip(y.iter().skip(1).step_by(2))
            .zip(c0.iter_mut().zip(c1.iter_mut()))
            .zip(self.v0.iter_mut())
            .zip(self.end.iter_mut())
        {
            (*c0, *c1, *v0) = (*u, v * h, *v);
            largest = larger(larger(largest, u.abs()), c1.abs());
            *e = [*c0 + *c1, *c1, 0.0, 0.0];
        }
        self.tails = (0.0, 0.0);
        let mut term = |j: usize, w: (f64, f64), added: Added| {
            terms.term((&mut self.c, &self.v0, &mut self.end), j, w, added)
        };
        // (c_{j+2} h^{j+2} = K c_j h^j wx_j + C c_{j+1} h^{j+1} wz_j + f_j
        // h^{j+2}/((j+1)(j+2)), wx_j = h²/((j+1)(j+2)), wz_j = h/(j+2).)
        let h2 = h * h;
        let weights = |[a, b]: [f64; 2]| (h2 * a, h * b);
        // (The base in the first two: c₂ the constant acceleration less
        // a₀, c₃ the jerk; the velocity's weight in the first is h²/2, c₁
        // being v, not v h.)
        let (wx, _) = weights(STEPS[0]);
        let mut last = term(0, (wx, wx), Added::ConstantLess(a0, wx));
        let (wx, wz) = weights(STEPS[1]);
        let mut top = term(1, (wx, wz), Added::Less(s * h * wx));
        if !(last.is_finite() && top.is_finite()) {
            return Built::NonFinite;
        }
        largest = larger(larger(largest, 2.0 * last), 3.0 * top);
        for j in 2..MAX_TERMS - 2 {
            let (wx, wz) = weights(STEPS[j]);
            (last, top) = (top, term(j, (wx, wz), Added::Nothing));
            if !top.is_finite() {
                return Built::NonFinite;
            }
            let [k, k2, _] = AT_END[j + 2];
            largest = larger(largest, k * top);
            self.tails.0 += k * top;
            self.tails.1 += k2 * top;
            // (The tail past term k: every two terms at most ρ times the
            // two before, ρ = |K| wx_{k−1} + |C| wz_{k−1} (see
            // `CUT`).)
            let (wx, wz) = weights(STEPS[j + 1]);
            let rho = norms.0 * wx + norms.1 * wz;
            let e = larger(top, last);
            if e == 0.0
                || rho < 0.5
                    && 2.0 * e * rho * (k + 2.0) <= CUT * largest * (1.0 - rho) * (1.0 - rho)
            {
                self.terms = j + 3;
                terms.sums(&self.c[..self.terms * n], &mut self.end);
                self.ends();
                return Built::Done;
            }
        }
        Built::TooLong
    }

    /// Every body's displacement and its first three derivatives at `h`
    /// in `end`, from their sums at θ = 1 (met as the terms were built).
    fn ends(&mut self) {
        let [_, r, q, p] = self.inv;
        for e in self.end.iter_mut() {
            *e = [e[0], e[1] * r, e[2] * q, e[3] * p];
        }
    }

    /// How many terms it has (displacement coefficients).
    pub(super) fn terms(&self) -> usize {
        self.terms
    }

    /// The state at τ into `out` (`[u, v]` per body).
    pub(super) fn state(&self, tau: f64, out: &mut [f64]) {
        if tau == 0.0 {
            for ((o, u), v) in out.chunks_exact_mut(2).zip(&self.c).zip(&self.v0) {
                (o[0], o[1]) = (*u, *v);
            }
            return;
        }
        if let Some(dt) = self.before_end(tau) {
            for (o, e) in out.chunks_exact_mut(2).zip(&self.end) {
                let e = shifted(e, dt);
                (o[0], o[1]) = (e[0], e[1]);
            }
            return;
        }
        let theta = tau * self.inv[1];
        let done = match self.n {
            1 => self.state_inside::<1>(theta, out),
            2 => self.state_inside::<2>(theta, out),
            3 => self.state_inside::<3>(theta, out),
            4 => self.state_inside::<4>(theta, out),
            5 => self.state_inside::<5>(theta, out),
            6 => self.state_inside::<6>(theta, out),
            7 => self.state_inside::<7>(theta, out),
            8 => self.state_inside::<8>(theta, out),
            _ => false,
        };
        if !done {
            for (b, o) in out.chunks_exact_mut(2).enumerate() {
                (o[0], o[1]) = self.value_rate_inside(b, None, tau);
            }
        }
    }

    /// [`Series::state`] inside the interval, at θ = τ/h, for a series of
    /// N bodies: every body's Horner sums in one pass over the terms, the
    /// same arithmetic in the same order as [`Series::value_rate_inside`]
    /// per body (the tail of a record's run samples its long
    /// free-vibration pieces inside: a quarter of the reads per body).
    /// False where the series is not of N bodies.
    #[inline(never)]
    fn state_inside<const N: usize>(&self, theta: f64, out: &mut [f64]) -> bool {
        if self.n != N || out.len() != 2 * N {
            return false;
        }
        let (mut x, mut dx) = ([0.0; N], [0.0; N]);
        for row in self.c[..self.terms * N].chunks_exact(N).rev() {
            let Some(row) = row.first_chunk::<N>() else {
                return false;
            };
            for ((x, dx), c) in x.iter_mut().zip(dx.iter_mut()).zip(row) {
                *dx = *dx * theta + *x;
                *x = *x * theta + c;
            }
        }
        let r = self.inv[1];
        for ((o, x), dx) in out.chunks_exact_mut(2).zip(x).zip(dx) {
            (o[0], o[1]) = (x, dx * r);
        }
        true
    }

    /// Body b's acceleration at τ.
    pub(super) fn acceleration(&self, b: usize, tau: f64) -> f64 {
        match self.before_end(tau) {
            Some(dt) => shifted(&self.end[b], dt)[2],
            None => self.component(2 * b + 1, tau).1,
        }
    }

    /// `τ − h` where τ is within 1e-9 h of the end (a sample's time and
    /// the piece's end apart by rounding): a Taylor step from the end's
    /// four derivatives is then the series to rounding (what it leaves out
    /// is about (1e-9 ω h)² of the acceleration: ω h is below 1/2 within
    /// the record, and a few past it).
    #[inline(always)]
    fn before_end(&self, tau: f64) -> Option<f64> {
        let dt = tau - self.h;
        (dt.abs() <= 1e-9 * self.h).then_some(dt)
    }

    /// Component i of the state (`2 b`: body b's displacement, `2 b + 1`:
    /// its velocity) at τ and its first two derivatives.
    #[inline(always)]
    pub(super) fn component(&self, i: usize, tau: f64) -> (f64, f64, f64) {
        let (b, d) = (i / 2, i % 2);
        let n = self.n;
        if tau == 0.0 {
            let [_, _, q, p] = self.inv;
            let (c2, c3) = (self.c[2 * n + b], self.c[3 * n + b]);
            return match d {
                0 => (self.c[b], self.v0[b], 2.0 * c2 * q),
                _ => (self.v0[b], 2.0 * c2 * q, 6.0 * c3 * p),
            };
        }
        let e = if tau == self.h {
            self.end[b]
        } else {
            self.derivatives_inside(b, tau)
        };
        (e[d], e[d + 1], e[d + 2])
    }

    /// Body b's displacement and its first three derivatives inside the
    /// interval, by Horner.
    #[inline(never)]
    fn derivatives_inside(&self, b: usize, tau: f64) -> [f64; 4] {
        let n = self.n;
        let theta = tau * self.inv[1];
        let mut e = [0.0; 4];
        for row in self.c[..self.terms * n].chunks_exact(n).rev() {
            let c = row[b];
            e[3] = e[3] * theta + 3.0 * e[2];
            e[2] = e[2] * theta + 2.0 * e[1];
            e[1] = e[1] * theta + e[0];
            e[0] = e[0] * theta + c;
        }
        for (e, r) in e.iter_mut().zip(self.inv) {
            *e *= r;
        }
        e
    }

    /// `component(i) − component(j)` (j None: zero), two displacements
    /// (i, j even), at τ and its rate.
    #[inline(always)]
    pub(super) fn value_rate(&self, i: usize, j: Option<usize>, tau: f64) -> (f64, f64) {
        debug_assert!(i % 2 == 0 && j.is_none_or(|j| j % 2 == 0));
        let (a, b) = (i / 2, j.map(|j| j / 2));
        if tau == 0.0 {
            let at = |b: usize| (self.c[b], self.v0[b]);
            let (x, r) = at(a);
            let (y, q) = b.map_or((0.0, 0.0), at);
            return (x - y, r - q);
        }
        if tau == self.h {
            let (x, y) = (self.end[a], b.map_or([0.0; 4], |b| self.end[b]));
            return (x[0] - y[0], x[1] - y[1]);
        }
        self.value_rate_inside(a, b, tau)
    }

    /// The states (`[u, v]` per body) of bodies `a` and `b` (if any) at τ
    /// into `y`, each exactly as [`Series::value_rate`] reads it alone;
    /// inside the interval both in one pass over the terms (a storey's
    /// two floors, read at every point the switch search looks at).
    #[inline(always)]
    pub(super) fn two_states(&self, a: usize, b: Option<usize>, tau: f64, y: &mut [f64]) {
        match b {
            Some(b) if tau != 0.0 && tau != self.h => {
                let theta = tau * self.inv[1];
                let [(ua, va), (ub, vb)] = self.two_inside(a, b, theta);
                (y[2 * a], y[2 * a + 1]) = (ua, va);
                (y[2 * b], y[2 * b + 1]) = (ub, vb);
            }
            _ => {
                for i in [Some(a), b].into_iter().flatten() {
                    (y[2 * i], y[2 * i + 1]) = self.value_rate(2 * i, None, tau);
                }
            }
        }
    }

    /// Bodies a and b's displacements and velocities at θ = τ/h inside
    /// the interval, by Horner side by side (each as
    /// [`Series::value_rate_inside`] alone).
    #[inline(never)]
    fn two_inside(&self, a: usize, b: usize, theta: f64) -> [(f64, f64); 2] {
        let (mut x, mut dx) = ([0.0; 2], [0.0; 2]);
        for row in self.c[..self.terms * self.n].chunks_exact(self.n).rev() {
            for (k, c) in [row[a], row[b]].into_iter().enumerate() {
                dx[k] = dx[k] * theta + x[k];
                x[k] = x[k] * theta + c;
            }
        }
        let r = self.inv[1];
        [(x[0], dx[0] * r), (x[1], dx[1] * r)]
    }

    /// [`Series::value_rate`] inside the interval (bodies a and b), by
    /// Horner on the difference's coefficients.
    #[inline(never)]
    fn value_rate_inside(&self, a: usize, b: Option<usize>, tau: f64) -> (f64, f64) {
        let theta = tau * self.inv[1];
        let (mut x, mut dx) = (0.0, 0.0);
        let mut horner = |c: f64| {
            dx = dx * theta + x;
            x = x * theta + c;
        };
        let rows = self.c[..self.terms * self.n].chunks_exact(self.n).rev();
        match b {
            Some(b) => rows.for_each(|row| horner(row[a] - row[b])),
            None => rows.for_each(|row| horner(row[a])),
        }
        (x, dx * self.inv[1])
    }

    /// Bounds over the whole interval on the first and second derivatives
    /// of `component(i) − component(j)`, two displacements (i, j even),
    /// from the coefficients' magnitudes: `Σ k |c_k| h^{k−1}` and `Σ k (k−1)
    /// |c_k| h^{k−2}` of the difference, rigorous for the series; beyond
    /// the third term by the largest displacement's coefficients, once for
    /// each side.
    #[inline(always)]
    pub(super) fn rate_bounds(&self, i: usize, j: Option<usize>) -> (f64, f64) {
        debug_assert!(i % 2 == 0 && j.is_none_or(|j| j % 2 == 0));
        let n = self.n;
        let (a, b) = (i / 2, j.map(|j| j / 2));
        let (mut first, mut second) = (0.0, 0.0);
        for k in 1..self.terms.min(4) {
            let c = (self.c[k * n + a] - b.map_or(0.0, |b| self.c[k * n + b])).abs();
            let kf = k as f64;
            first += kf * c;
            second += kf * (kf - 1.0) * c;
        }
        let sides = if b.is_some() { 2.0 } else { 1.0 };
        first += sides * self.tails.0;
        second += sides * self.tails.1;
        (first * self.inv[1], second * self.inv[2])
    }
}

/// How a series' terms are made: term j + 2 from terms j and j + 1 of the
/// rows (the velocities for j = 0) with the weights (wx, wz) and what
/// `added` says, into its row and the end's sums, its largest coefficient
/// returned (see [`PiecewiseForm::displacement_term`]).
trait Terms {
    /// Term j + 2 (see [`Terms`]).
    fn term(
        &self,
        rows: (&mut [f64], &[f64], &mut [[f64; 4]]),
        j: usize,
        w: (f64, f64),
        added: Added,
    ) -> f64;

    /// The end's sums of `rows`, where the terms did not add them.
    fn sums(&self, rows: &[f64], sums: &mut [[f64; 4]]);
}

/// Any form's terms, on rows of its bodies.
struct Rows<'a>(&'a PiecewiseForm);

impl Terms for Rows<'_> {
    #[inline(always)]
    fn term(
        &self,
        (c, v0, sums): (&mut [f64], &[f64], &mut [[f64; 4]]),
        j: usize,
        (wx, wz): (f64, f64),
        added: Added,
    ) -> f64 {
        let n = v0.len();
        let (before, after) = c.split_at_mut((j + 2) * n);
        let z = match j {
            0 => v0,
            _ => &before[(j + 1) * n..],
        };
        let x = &before[j * n..(j + 1) * n];
        let out = &mut after[..n];
        self.0
            .displacement_term((x, wx), (z, wz), out, added, (sums, AT_END[j + 2]))
    }

    /// (Its terms added them.)
    #[inline(always)]
    fn sums(&self, _: &[f64], _: &mut [[f64; 4]]) {}
}

/// A chain of N bodies' terms, on rows of N.
impl<const N: usize> Terms for FixedChain<N> {
    #[inline(always)]
    fn term(
        &self,
        (c, v0, _): (&mut [f64], &[f64], &mut [[f64; 4]]),
        j: usize,
        (wx, wz): (f64, f64),
        added: Added,
    ) -> f64 {
        let (before, after) = c.split_at_mut((j + 2) * N);
        let z = match j {
            0 => v0,
            _ => &before[(j + 1) * N..],
        };
        let (Some(x), Some(z), Some(out)) = (
            before[j * N..].first_chunk::<N>(),
            z.first_chunk::<N>(),
            after.first_chunk_mut::<N>(),
        ) else {
            // (Rows of N bodies, a term within them: never.)
            return f64::NAN;
        };
        FixedChain::term(self, (x, wx), (z, wz), out, added)
    }

    /// The sums term by term from the third, in the order the terms'
    /// products would add them (the first two's are there), kept in
    /// registers while the rows are read.
    #[inline(always)]
    fn sums(&self, rows: &[f64], sums: &mut [[f64; 4]]) {
        let mut e = [[0.0; N]; 4];
        for (i, s) in sums.iter().take(N).enumerate() {
            for (e, s) in e.iter_mut().zip(s) {
                e[i] = *s;
            }
        }
        for (row, w) in rows.chunks_exact(N).zip(AT_END.iter()).skip(2) {
            for (e, w) in e.iter_mut().zip([1.0, w[0], w[1], w[2]]) {
                for (e, c) in e.iter_mut().zip(row) {
                    *e += c * w;
                }
            }
        }
        for (i, s) in sums.iter_mut().take(N).enumerate() {
            *s = [e[0][i], e[1][i], e[2][i], e[3][i]];
        }
    }
}

/// A displacement's value and first two derivatives `dt` from where they
/// and the third are `e` (the third taken as constant over `dt`; at
/// `dt` = 0 themselves, whatever the third).
#[inline(always)]
fn shifted(e: &[f64; 4], dt: f64) -> [f64; 3] {
    if dt == 0.0 {
        return [e[0], e[1], e[2]];
    }
    let half = 0.5 * dt;
    [
        e[0] + dt * (e[1] + half * (e[2] + dt / 3.0 * e[3])),
        e[1] + dt * (e[2] + half * e[3]),
        e[2] + dt * e[3],
    ]
}
