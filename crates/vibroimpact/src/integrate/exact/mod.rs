//! The exact flow of a linear system under harmonic forcing, as a step
//! method: "EXACT" (docs/theory.md §12: the rigid period map between
//! impacts).
//!
//! Files: `mod.rs` (the form and the method), `series.rs` (a step's
//! motion as a power series), `steady.rs` (the harmonics' steady
//! states), `tests.rs` (against closed forms and DOP853).
//!
//! A system whose right-hand side is `f(t, y) = A y + b(t)`, the state made
//! of blocks of one dimension d that share the d × d matrix `A`, each with
//! its own forcing `b(t) = Σ_j (c_j cos Ω_j t + s_j sin Ω_j t)`
//! ([`LinearForm`]; a chain whose every contact is rigid, and its
//! variational columns), moves as
//!
//! ```text
//! y(t) = y_p(t) + e^{A (t − t₀)} (y(t₀) − y_p(t₀)),
//! ```
//!
//! `y_p` the steady state of the harmonics, `Re[X e^{iΩt}]` with
//! `(iΩ − A) X = c − i s` (a constant force is Ω = 0). Where some
//! `iΩ − A` is singular (a resonance, a free body under a constant force)
//! the system has no exact form here, and [`LinearForm::solve`] says so.
//!
//! * **A step** of size h multiplies each block's deviation from the
//!   steady state by `e^{Ah}`, kept with `e^{Ah/4}`, `e^{Ah/2}` and
//!   `e^{3Ah/4}` for the last few step sizes met more than once (one
//!   matrix exponential and three products a size; the steps are mostly
//!   `h_max`). A size met once (a step cut short at an event or a sample)
//!   is taken by the exponential's series on the deviation instead, which
//!   its dense output then reads: a few products of `A` with a vector, not
//!   an exponential of `A`. Its error is rounding, so the driver sees zero
//!   and the step grows to `h_max`, kept below [`Linear::step_limit`]
//!   (`‖A‖ h ≤ 2`, the norm balanced: `‖S A S⁻¹‖∞` with `S` diagonal
//!   in powers of two, so that a chain's velocity rows, which carry ω²
//!   against the displacement rows' 1, carry ω as they do; the series and
//!   its products are the same, only measured balanced: `S` is exact).
//! * **Dense output**: at a quarter of the step those matrices; elsewhere
//!   (an event being located) the exponential's series on the deviation,
//!   `Σ_k τ^k A^k v / k!` to the first term below 1e-17 of the sum, built
//!   once a step and summed by Horner in four chains (at `‖A‖ τ ≤ 2` its
//!   terms never exceed the sum by more than a factor 3): exact to
//!   rounding, so events are located on the motion itself. The steady
//!   state's own series about the step's start is folded into it at the
//!   first such output, so the sum is the motion and takes no sine
//!   (unless the forcing is so fast against the step that its terms
//!   would pass `MAX_TERMS`: then the steady state is added at each).
//! * `f(t + h, y_new)` is `A y_new + b(t + h)`: no evaluation of the
//!   system's own right-hand side inside a step.
//!
//! The form is read at the first reset: a system handed to this method
//! keeps its form for the whole integration (rigid impacts jump the state,
//! not `A`). Every buffer is allocated in `ExactMethod::new` and that
//! reset.

use nalgebra::DMatrix;

use super::driver::{all_finite, Attempt, Driver, Point, StepMethod, Trial, NON_FINITE};

mod series;
mod steady;
use super::{OdeSystem, RejectReason, Stats};
use series::{fold_steady, series_at, series_terms, sum_series};
use steady::{steady_state, Steady};

/// Most terms of a step's series (at `‖A‖ h ≤ 2` it meets 1e-17 of the
/// sum by the 30th).
const MAX_TERMS: usize = 40;
/// Largest `‖A‖ h` of a step (‖A‖: balanced, [`Linear::norm`]).
const NORM_STEP: f64 = 2.0;

/// One harmonic of a block's forcing, `cos·cos(Ω t) + sin·sin(Ω t)` (Ω ≥
/// 0; Ω = 0 a constant `cos`).
#[derive(Clone, Debug, PartialEq)]
pub struct Harmonic {
    /// Ω (rad/s).
    pub omega: f64,
    /// The cosine's coefficients, one per row of the block.
    pub cos: Vec<f64>,
    /// The sine's coefficients, one per row of the block.
    pub sin: Vec<f64>,
}

/// A linear system under harmonic forcing: blocks of the state that share
/// the matrix `a`, each under its own harmonics.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearForm {
    /// The d × d matrix every block moves by.
    pub a: DMatrix<f64>,
    /// Per block (the state is `blocks.len()` blocks of d rows, in order),
    /// its forcing.
    pub blocks: Vec<Vec<Harmonic>>,
}

impl LinearForm {
    /// The form with its steady states solved, or None where some
    /// `iΩ − A` is singular or the coefficients are not finite.
    pub fn solve(self) -> Option<Linear> {
        let d = self.a.nrows();
        if self.a.ncols() != d || !self.a.iter().all(|x| x.is_finite()) {
            return None;
        }
        let rows: Vec<f64> = (0..d)
            .flat_map(|i| (0..d).map(move |j| (i, j)))
            .map(|(i, j)| self.a[(i, j)])
            .collect();
        let scale = balancing(&rows, d);
        let norm_of = |s: &[f64]| {
            (0..d)
                .map(|i| {
                    (0..d)
                        .map(|j| (rows[i * d + j] * s[i] / s[j]).abs())
                        .sum::<f64>()
                })
                .fold(0.0, f64::max)
        };
        let raw_norm = norm_of(&vec![1.0; d]);
        let mut steady = Vec::with_capacity(self.blocks.len());
        for block in &self.blocks {
            let mut terms = Vec::with_capacity(block.len());
            for h in block {
                if h.cos.len() != d || h.sin.len() != d {
                    return None;
                }
                terms.push(steady_state(&self.a, raw_norm, h)?);
            }
            steady.push(terms);
        }
        let balanced = (0..d * d)
            .map(|ij| rows[ij] * scale[ij / d] / scale[ij % d])
            .collect();
        Some(Linear {
            norm: norm_of(&scale),
            balanced,
            rows,
            d,
            scale,
            steady,
            forcing: self.blocks,
        })
    }
}

/// The diagonal balancing `S` of `A` (d × d, by rows) in powers of two
/// (Osborne's iteration, as LAPACK's `gebal` scales): `S A S⁻¹` has row
/// and column sums of its off-diagonal moduli within a factor 2 where
/// both are nonzero. Powers of two keep `S A S⁻¹` and every product with
/// it exact: the balanced series is the series itself, only measured in
/// the balanced norm (a chain's velocity rows carry ω² against the
/// displacement rows' 1; balanced, both carry ω, and the step grows by ω).
fn balancing(rows: &[f64], d: usize) -> Vec<f64> {
    // (LAPACK's D, B = D⁻¹ A D; S = D⁻¹.)
    let mut dd = vec![1.0f64; d];
    for _sweep in 0..64 {
        let mut changed = false;
        for i in 0..d {
            let (mut c, mut r) = (0.0, 0.0);
            for j in (0..d).filter(|&j| j != i) {
                c += (rows[j * d + i] * dd[i] / dd[j]).abs();
                r += (rows[i * d + j] * dd[j] / dd[i]).abs();
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let sum = c + r;
            let mut f = 1.0;
            while c < 0.5 * r {
                (f, c, r) = (2.0 * f, 2.0 * c, 0.5 * r);
            }
            while 0.5 * c >= r {
                (f, c, r) = (0.5 * f, 0.5 * c, 2.0 * r);
            }
            if c + r < 0.95 * sum {
                dd[i] *= f;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    dd.iter().map(|x| 1.0 / x).collect()
}

/// A [`LinearForm`] with its steady states: what [`ExactMethod`] steps.
#[derive(Clone, Debug)]
pub struct Linear {
    /// `A` by rows, d × d.
    rows: Vec<f64>,
    d: usize,
    /// The balancing `S` (powers of two, [`balancing`]) and `S A S⁻¹` by
    /// rows.
    scale: Vec<f64>,
    balanced: Vec<f64>,
    /// `‖S A S⁻¹‖∞`.
    norm: f64,
    /// Per block, per harmonic: (Ω, Re X, Im X).
    steady: Vec<Vec<Steady>>,
    /// Per block, its harmonics as given.
    forcing: Vec<Vec<Harmonic>>,
}

impl Linear {
    /// The longest step the method takes (`‖A‖ h ≤ 2`; unbounded for
    /// `A = 0`).
    pub fn step_limit(&self) -> f64 {
        if self.norm > 0.0 {
            NORM_STEP / self.norm
        } else {
            f64::INFINITY
        }
    }

    /// Moves `y` (every block) exactly from `t0` to `t1`: `y_p(t1) +
    /// e^{A(t1 − t0)} (y − y_p(t0))`, the exponential that of a span of
    /// `‖A‖ τ ≤ 0.5` (balanced) squared up to the whole span (a segment
    /// between impacts taken at once: a handful of d × d products, not a
    /// step each a third of a period).
    pub fn flow(&self, (t0, t1): (f64, f64), y: &mut [f64]) {
        let d = self.d;
        let tau = t1 - t0;
        let mut squarings = 0;
        while self.norm * tau.abs() / f64::from(1u32 << squarings) > 0.5 && squarings < 30 {
            squarings += 1;
        }
        let (mut e, mut term, mut next) = (vec![0.0; d * d], vec![0.0; d * d], vec![0.0; d * d]);
        self.exponential_into(
            tau / f64::from(1u32 << squarings),
            &mut e,
            [&mut term, &mut next],
        );
        for _ in 0..squarings {
            product(&e, &e, &mut term);
            std::mem::swap(&mut e, &mut term);
        }
        let mut steady = vec![0.0; y.len()];
        self.steady_into(t0, &mut steady);
        let mut v = vec![0.0; d];
        for (yb, pb) in y.chunks_exact_mut(d).zip(steady.chunks_exact(d)) {
            for ((v, y), p) in v.iter_mut().zip(yb.iter()).zip(pb) {
                *v = y - p;
            }
            times(&e, &v, yb);
        }
        self.steady_into(t1, &mut steady);
        y.iter_mut().zip(&steady).for_each(|(y, p)| *y += p);
    }

    /// The form of the first `blocks` blocks alone (a variational
    /// system's state, the first block of its columns' form): nothing
    /// solved again.
    pub fn leading(&self, blocks: usize) -> Linear {
        let blocks = blocks.min(self.steady.len());
        Linear {
            rows: self.rows.clone(),
            d: self.d,
            scale: self.scale.clone(),
            balanced: self.balanced.clone(),
            norm: self.norm,
            steady: self.steady[..blocks].to_vec(),
            forcing: self.forcing[..blocks].to_vec(),
        }
    }

    /// The state's dimension: the blocks' rows together.
    pub fn dim(&self) -> usize {
        self.d * self.steady.len()
    }

    /// The steady state's row `r` of block `b` at `t`.
    fn steady_at(&self, b: usize, r: usize, t: f64) -> f64 {
        self.steady[b]
            .iter()
            .map(|(w, xr, xi)| {
                let (s, c) = (w * t).sin_cos();
                xr[r] * c - xi[r] * s
            })
            .sum()
    }

    /// The steady state of every block at `t` into `out`.
    fn steady_into(&self, t: f64, out: &mut [f64]) {
        out.fill(0.0);
        for (block, terms) in out.chunks_mut(self.d).zip(&self.steady) {
            for (w, xr, xi) in terms {
                let (s, c) = (w * t).sin_cos();
                for ((o, r), i) in block.iter_mut().zip(xr).zip(xi) {
                    *o += r * c - i * s;
                }
            }
        }
    }

    /// `A y + b(t)`, the right-hand side, into `out`.
    fn rate(&self, t: f64, y: &[f64], out: &mut [f64]) {
        let d = self.d;
        for ((yb, ob), forcing) in y
            .chunks_exact(d)
            .zip(out.chunks_exact_mut(d))
            .zip(&self.forcing)
        {
            times(&self.rows, yb, ob);
            for h in forcing {
                let (s, c) = (h.omega * t).sin_cos();
                for ((o, hc), hs) in ob.iter_mut().zip(&h.cos).zip(&h.sin) {
                    *o += hc * c + hs * s;
                }
            }
        }
    }

    /// `e^{Aτ}` by rows into `e`, for `‖A‖ τ ≤ 0.55` (balanced; a quarter
    /// step): the series of `S A S⁻¹` to the first term below 1e-17 (at
    /// most 20 terms), unbalanced (exactly: `S` is powers of two).
    /// `term` and `next` are scratch of d² each.
    fn exponential_into(&self, tau: f64, e: &mut [f64], [term, next]: [&mut [f64]; 2]) {
        let (d, b) = (self.d, &self.balanced);
        e.fill(0.0);
        term.fill(0.0);
        for i in 0..d {
            e[i * d + i] = 1.0;
            term[i * d + i] = 1.0;
        }
        let (mut term, mut next) = (term, next);
        for k in 1..=MAX_TERMS {
            let c = tau / k as f64;
            product(term, b, next);
            next.iter_mut().for_each(|n| *n *= c);
            std::mem::swap(&mut term, &mut next);
            let largest = term.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            e.iter_mut().zip(term.iter()).for_each(|(e, t)| *e += t);
            if largest <= 1e-17 {
                break;
            }
        }
        // e^{Aτ} = S⁻¹ e^{Bτ} S.
        for (ij, x) in e.iter_mut().enumerate() {
            *x *= self.scale[ij % d] / self.scale[ij / d];
        }
    }
}

/// `out = M x`, M by rows (square, of x's length); the small chains'
/// sizes (up to 8 rows, a global run's exact limit) unrolled, the same
/// sums in the same order.
fn times(m: &[f64], x: &[f64], out: &mut [f64]) {
    match x.len() {
        2 => times_of::<2>(m, x, out),
        4 => times_of::<4>(m, x, out),
        6 => times_of::<6>(m, x, out),
        8 => times_of::<8>(m, x, out),
        d => {
            for (o, row) in out.iter_mut().zip(m.chunks_exact(d)) {
                *o = row.iter().zip(x).map(|(a, b)| a * b).sum();
            }
        }
    }
}

/// [`times`] of D rows.
fn times_of<const D: usize>(m: &[f64], x: &[f64], out: &mut [f64]) {
    let x = &x[..D];
    for (o, row) in out.iter_mut().zip(m.chunks_exact(D)) {
        *o = row[..D].iter().zip(x).map(|(a, b)| a * b).sum();
    }
}

/// `out = P Q`, all square by rows; the small sizes unrolled as in
/// [`times`].
fn product(p: &[f64], q: &[f64], out: &mut [f64]) {
    match out.len() {
        4 => product_of::<2>(p, q, out),
        16 => product_of::<4>(p, q, out),
        36 => product_of::<6>(p, q, out),
        64 => product_of::<8>(p, q, out),
        len => {
            let d = (len as f64).sqrt() as usize;
            for (pi, oi) in p.chunks_exact(d).zip(out.chunks_exact_mut(d)) {
                oi.fill(0.0);
                for (x, ql) in pi.iter().zip(q.chunks_exact(d)) {
                    for (o, y) in oi.iter_mut().zip(ql) {
                        *o += x * y;
                    }
                }
            }
        }
    }
}

/// [`product`] of D × D.
fn product_of<const D: usize>(p: &[f64], q: &[f64], out: &mut [f64]) {
    for (pi, oi) in p.chunks_exact(D).zip(out.chunks_exact_mut(D)) {
        let mut row = [0.0; D];
        for (x, ql) in pi[..D].iter().zip(q.chunks_exact(D)) {
            for (o, y) in row.iter_mut().zip(&ql[..D]) {
                *o += x * y;
            }
        }
        oi[..D].copy_from_slice(&row);
    }
}

/// `e^{A j h/4}` for j = 1 … 4, by rows, of one step size h.
#[derive(Clone, Debug)]
struct Quarters {
    h: f64,
    e: [Vec<f64>; 4],
}

impl Quarters {
    /// Room for the four of a d × d matrix.
    fn new(d: usize) -> Self {
        Self {
            h: f64::NAN,
            e: std::array::from_fn(|_| vec![0.0; d * d]),
        }
    }

    /// The four of step size h, from one exponential and three products
    /// (`scratch`: two d² buffers).
    fn fill(&mut self, form: &Linear, h: f64, scratch: &mut [Vec<f64>; 2]) {
        let [e1, e2, e3, e4] = &mut self.e;
        let [t, n] = scratch;
        form.exponential_into(0.25 * h, e1, [t, n]);
        product(e1, e1, e2);
        product(e2, e1, e3);
        product(e2, e2, e4);
        self.h = h;
    }
}

/// The quarter `j/4` of a step that `s` is (to rounding), as the index
/// j − 1 of [`Quarters::e`].
fn quarter(s: f64) -> Option<usize> {
    let j = (4.0 * s).round();
    ((4.0 * s - j).abs() <= 1e-12 && (1.0..=4.0).contains(&j)).then(|| j as usize - 1)
}

/// How many step sizes keep their quarters.
const KEPT_SIZES: usize = 4;

/// The exact flow of a [`LinearForm`]: the shared [`Driver`] around the
/// [`ExactMethod`].
pub type Exact = Driver<ExactMethod>;

/// The exact step and dense output (see the module documentation).
#[derive(Clone, Debug)]
pub struct ExactMethod {
    form: Option<Linear>,
    /// The quarters of the step sizes met more than once, and which to
    /// replace next.
    sizes: Vec<Quarters>,
    next: usize,
    /// The last step sizes met once (a size met again gets its quarters;
    /// one met once, such as a step cut short at an event, is taken by
    /// the series), and which to replace next.
    seen: [f64; KEPT_SIZES],
    seen_next: usize,
    /// The attempt's deviation from the steady state at its start, and
    /// its quarters (None: taken by the series).
    deviation: Vec<f64>,
    quarters: Option<usize>,
    /// The accepted step's.
    deviation_acc: Vec<f64>,
    quarters_acc: Option<usize>,
    /// The accepted step's series terms `A^k v / k!`, term k at
    /// `[k·n..(k+1)·n]`, how many (0: not built yet) and of how many
    /// leading components (a dense output of a leading part builds its
    /// blocks alone); the attempt's, where it was taken by the series.
    terms: Vec<f64>,
    count: usize,
    built: usize,
    /// Whether `terms` hold the steady state's series too (the motion
    /// itself, [`fold_steady`]).
    folded: bool,
    terms_try: Vec<f64>,
    count_try: usize,
    /// Scratch: a steady state; two d × d matrices.
    steady: Vec<f64>,
    scratch: [Vec<f64>; 2],
    /// `f(t + h, y_new)`.
    end: Vec<f64>,
}

impl ExactMethod {
    /// The method for a system of dimension `dim` whose form is already
    /// solved (a [`crate::integrate::Stepper`] that read it to choose the
    /// method).
    pub(crate) fn with_form(form: Linear, dim: usize) -> Self {
        let d2 = form.d * form.d;
        Self {
            form: Some(form),
            scratch: [vec![0.0; d2], vec![0.0; d2]],
            ..<Self as StepMethod>::new(dim)
        }
    }

    /// The accepted step's series of (at least) the first `m` components,
    /// built on first use (see the module documentation) for the blocks
    /// they lie in; false where it does not converge.
    fn series(&mut self, h: f64, m: usize) -> bool {
        if self.count > 0 && self.built >= m {
            return true;
        }
        let Some(form) = self.form.as_ref() else {
            return false;
        };
        let (n, m) = (self.deviation_acc.len(), m.div_ceil(form.d) * form.d);
        match series_terms(form, (&self.deviation_acc[..m], n), h, &mut self.terms) {
            Some(count) => {
                (self.count, self.built, self.folded) = (count, m, false);
                true
            }
            None => false,
        }
    }

    /// Folds the steady state about the accepted step's start `t0` into
    /// its series (built), once: false where it does not fold (the
    /// steady state is then added at each dense output).
    fn fold(&mut self, t0: f64, h: f64) -> bool {
        if self.folded {
            return true;
        }
        let Some(form) = self.form.as_ref() else {
            return false;
        };
        let n = self.deviation_acc.len();
        let sizes = (n, self.built);
        match fold_steady(form, (t0, h), sizes, &mut self.terms, self.count) {
            Some(count) => {
                (self.count, self.folded) = (count, true);
                true
            }
            None => false,
        }
    }
}

impl StepMethod for ExactMethod {
    // The error is rounding: the controller grows every step to `h_max`.
    const ERROR_EXPONENT: f64 = 1.0 / 8.0;
    const SHRINK_LIMIT: f64 = 4.0;

    fn new(dim: usize) -> Self {
        Self {
            form: None,
            sizes: Vec::with_capacity(KEPT_SIZES),
            next: 0,
            seen: [f64::NAN; KEPT_SIZES],
            seen_next: 0,
            deviation: vec![0.0; dim],
            quarters: None,
            deviation_acc: vec![0.0; dim],
            quarters_acc: None,
            terms: vec![0.0; (MAX_TERMS + 1) * dim],
            count: 0,
            terms_try: vec![0.0; (MAX_TERMS + 1) * dim],
            count_try: 0,
            built: 0,
            folded: false,
            steady: vec![0.0; dim],
            scratch: [Vec::new(), Vec::new()],
            end: vec![0.0; dim],
        }
    }

    fn reset<S: OdeSystem>(&mut self, sys: &S, dim: usize) {
        if self.form.is_none() {
            self.form = sys
                .linear_form()
                .and_then(LinearForm::solve)
                .filter(|f| f.d * f.steady.len() == dim);
            self.scratch = self.form.as_ref().map_or_else(Default::default, |f| {
                [vec![0.0; f.d * f.d], vec![0.0; f.d * f.d]]
            });
        }
    }

    fn begin_step<S: OdeSystem>(&mut self, _sys: &mut S, _at: &Point, _stats: &mut Stats) {}

    /// `y_p(t + h) + e^{Ah} (y − y_p(t))`.
    fn attempt<S: OdeSystem>(&mut self, _sys: &mut S, at: &Point, trial: &mut Trial) -> Attempt {
        let Some(form) = self.form.as_ref() else {
            return Err(NON_FINITE);
        };
        let (h, d) = (trial.h, form.d);
        // (The driver stretches a step by up to 1 % onto its bound.)
        if form.norm * h > NORM_STEP * 1.05 {
            let factor = (NORM_STEP / (form.norm * h)).min(0.9);
            return Err((RejectReason::ErrorEstimate, factor));
        }
        let q = match self.sizes.iter().position(|q| q.h == h) {
            Some(q) => Some(q),
            None if !self.seen.contains(&h) => {
                self.seen[self.seen_next] = h;
                self.seen_next = (self.seen_next + 1) % KEPT_SIZES;
                None
            }
            None if self.sizes.len() < KEPT_SIZES => {
                let mut q = Quarters::new(d);
                q.fill(form, h, &mut self.scratch);
                self.sizes.push(q);
                Some(self.sizes.len() - 1)
            }
            None => {
                // (Never the accepted step's own: its dense output reads them.)
                let mut q = self.next;
                if Some(q) == self.quarters_acc {
                    q = (q + 1) % KEPT_SIZES;
                }
                self.next = (q + 1) % KEPT_SIZES;
                self.sizes[q].fill(form, h, &mut self.scratch);
                Some(q)
            }
        };
        self.quarters = q;
        form.steady_into(at.t, &mut self.steady);
        for ((v, y), p) in self.deviation.iter_mut().zip(&at.y).zip(&self.steady) {
            *v = y - p;
        }
        let y_new = &mut *trial.y_new;
        match q {
            Some(q) => {
                form.steady_into(trial.t_new, &mut self.steady);
                let e = &self.sizes[q].e[3];
                for ((yb, vb), pb) in y_new
                    .chunks_exact_mut(d)
                    .zip(self.deviation.chunks_exact(d))
                    .zip(self.steady.chunks_exact(d))
                {
                    times(e, vb, yb);
                    for (y, p) in yb.iter_mut().zip(pb) {
                        *y += p;
                    }
                }
            }
            // A size met once: the series on the deviation, kept for the
            // step's dense output.
            None => {
                let n = self.deviation.len();
                let Some(count) = series_terms(form, (&self.deviation, n), h, &mut self.terms_try)
                else {
                    return Err(NON_FINITE);
                };
                self.count_try = count;
                sum_series(&self.terms_try, (y_new.len(), count), h, y_new);
                form.steady_into(trial.t_new, &mut self.steady);
                for (y, p) in y_new.iter_mut().zip(&self.steady) {
                    *y += p;
                }
            }
        }
        if !all_finite(y_new) {
            return Err(NON_FINITE);
        }
        Ok(0.0)
    }

    /// `A y_new + b(t + h)`.
    fn evaluate_end<S: OdeSystem>(&mut self, _sys: &mut S, trial: &mut Trial) -> bool {
        let Some(form) = self.form.as_ref() else {
            return false;
        };
        form.rate(trial.t_new, trial.y_new, &mut self.end);
        all_finite(&self.end)
    }

    fn accept(&mut self, _at: &Point, _y_new: &[f64], _h: f64) {
        std::mem::swap(&mut self.deviation, &mut self.deviation_acc);
        self.quarters_acc = self.quarters;
        (self.count, self.folded) = (0, false);
        if self.quarters.is_none() {
            std::mem::swap(&mut self.terms, &mut self.terms_try);
            (self.count, self.built) = (self.count_try, self.terms.len() / (MAX_TERMS + 1));
        }
    }

    fn end_derivative(&self) -> &[f64] {
        &self.end
    }

    // The dense output is the exponential's series on the deviation: the
    // flow to rounding.
    const DENSE_IS_FLOW: bool = true;

    /// The step's first part keeps its series (its quarters are the whole
    /// step's: no longer read); `f(t, y)` as at a step's end.
    fn shorten(&mut self, t: f64, y: &[f64]) {
        self.quarters_acc = None;
        if let Some(form) = self.form.as_ref() {
            form.rate(t, y, &mut self.end);
        }
    }

    /// Component i as [`ExactMethod::dense_all`] has it.
    fn dense<S: OdeSystem>(
        &mut self,
        _sys: &mut S,
        at: &Point,
        i: usize,
        s: f64,
        _stats: &mut Stats,
    ) -> f64 {
        let Some(form) = self.form.as_ref() else {
            return f64::NAN;
        };
        let (n, d, h) = (at.dim(), form.d, at.h_last);
        let tau = s * h;
        let (b, r) = (i / d, i % d);
        if let (Some(j), Some(q)) = (quarter(s), self.quarters_acc) {
            let steady = form.steady_at(b, r, at.t_prev + tau);
            let row = &self.sizes[q].e[j][r * d..(r + 1) * d];
            let v = &self.deviation_acc[b * d..(b + 1) * d];
            return steady + row.iter().zip(v).map(|(a, x)| a * x).sum::<f64>();
        }
        if !self.series(h, i + 1) {
            return f64::NAN;
        }
        let series = series_at(&self.terms, (n, self.count), tau, i);
        if self.fold(at.t_prev, h) {
            return series;
        }
        let steady = self
            .form
            .as_ref()
            .map_or(f64::NAN, |f| f.steady_at(b, r, at.t_prev + tau));
        steady + series
    }

    /// At a quarter of the step its matrix on the deviation; elsewhere the
    /// series; plus the steady state there.
    fn dense_all<S: OdeSystem>(
        &mut self,
        _sys: &mut S,
        at: &Point,
        s: f64,
        out: &mut [f64],
        _stats: &mut Stats,
    ) {
        let Some(form) = self.form.as_ref() else {
            out.fill(f64::NAN);
            return;
        };
        let (d, h) = (form.d, at.h_last);
        let tau = s * h;
        if let (Some(j), Some(q)) = (quarter(s), self.quarters_acc) {
            form.steady_into(at.t_prev + tau, out);
            let e = &self.sizes[q].e[j];
            // (`chunks_mut`: a leading part may end inside a block.)
            for (ob, vb) in out.chunks_mut(d).zip(self.deviation_acc.chunks_exact(d)) {
                for (o, row) in ob.iter_mut().zip(e.chunks_exact(d)) {
                    *o += row.iter().zip(vb).map(|(a, b)| a * b).sum::<f64>();
                }
            }
            return;
        }
        if !self.series(h, out.len()) {
            out.fill(f64::NAN);
            return;
        }
        let n = self.steady.len();
        if self.fold(at.t_prev, h) {
            sum_series(&self.terms, (n, self.count), tau, out);
            return;
        }
        let series = &mut self.steady[..out.len()];
        sum_series(&self.terms, (n, self.count), tau, series);
        if let Some(form) = self.form.as_ref() {
            form.steady_into(at.t_prev + tau, out);
        }
        for (o, x) in out.iter_mut().zip(series.iter()) {
            *o += x;
        }
    }
}

#[cfg(test)]
mod tests;
