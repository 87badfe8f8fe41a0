//! Exact motion between contacts (docs/theory.md §10).
//!
//! Files: `mod.rs` (groups and their exact motion), `build.rs` (the
//! groups and their propagators built from a model), `modal.rs` (complex
//! modes), `hold.rs` (a record's sample steps under first-order hold),
//! `branches.rs` (a group's propagators per storey branch), `bounds.rs`
//! (bounds on the motion ahead), `tests.rs`.
//!
//! With every contact open, a model's equations are linear with
//! time-dependent forcing:
//!
//! ```text
//! ẋ = A x + Σ_j b_j sin(Ω_j t + φ_j) − e z̈_rec(t)
//! ```
//!
//! per group of bodies joined by springs and dampers (a body without
//! couplings is a group of one); `x` is the group's interleaved state
//! `[u_1, v_1, …]`, `e` has a 1 in every velocity row, and the harmonic
//! terms are the base's and the forces'. The state is propagated exactly:
//!
//! * harmonic forcing by its steady state `x_p(t) = Σ_j Im(X_j e^{i(Ω_j t +
//!   φ_j)})`, `(iΩ_j − A) X_j = b_j`, and the homogeneous rest by `e^{Aτ}`:
//!   `x(t₀ + τ) = x_p(t₀ + τ) + e^{Aτ}(x(t₀) − x_p(t₀))`;
//! * a recorded accelerogram (linear between samples, zero outside the
//!   record) sample by sample under first-order hold:
//!   `x(b) = e^{Aτ}x(a) + Γ₁ e f(a) + Γ₂ e f'` with `Γ₁ = ∫₀^τ e^{As} ds`,
//!   `Γ₂ = ∫₀^τ e^{A(τ−s)} s ds`, read off the exponential of the augmented
//!   matrix `[[A, e, 0], [0, 0, 1], [0, 0, 0]] τ` (Van Loan);
//! * for a single body `e^{Aτ}` in closed form (under-, critically and
//!   over-damped, and free bodies with ω0 = 0), for a group by
//!   nalgebra's matrix exponential.
//!
//! A hysteretic storey on a linear branch (docs/theory.md §11: an elastic
//! branch of a bilinear storey, `F = k d + F₀`) is a spring of its initial
//! stiffness `k` with a constant force `F₀`: the group moves about its
//! static rest state `x_s` (`K u_s = f₀`, zero velocities), `x(t) = x_s +`
//! the motion above of `x − x_s` ([`FreeMotion::set_rest`]).
//!
//! It also bounds the motion ahead, for the contact scheduler
//! (`bounds.rs`).

use nalgebra::{DMatrix, DVector};
use smallvec::SmallVec;

use crate::model::BaseExcitation;

pub use bounds::Envelope;
pub(crate) use build::spring_groups;
use hold::HoldStep;
use modal::Modal;

/// Largest group state (rows) that keeps a whole sample step's matrix
/// beside its modes (its matrix exponential costs (d + 2)³ once).
const HOLD_ROWS: usize = 32;

/// Longest run, in sample steps, taken through the whole step's matrix
/// rather than the modes.
const SHORT_RUN: f64 = 4.0;

/// Why a model's free motion has no exact propagator.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FreeMotionError {
    /// An undamped group has a natural frequency equal to a forcing
    /// frequency: its steady state grows without bound.
    #[error("the free motion of {bodies} is undamped and resonant at the forcing frequency {frequency} rad/s: it has no bounded steady state; use the global integrator")]
    Resonant {
        /// The group's body names.
        bodies: String,
        /// The forcing frequency (rad/s).
        frequency: f64,
    },
}

/// How a group's `e^{Aτ}` is computed.
#[derive(Clone, Debug)]
enum Propagator {
    /// One body: `ü = −w2 u − c2 u̇` in closed form.
    Single { w2: f64, c2: f64 },
    /// A group: the matrix exponential of `A` (boxed: a group stays
    /// small).
    Group(Box<DMatrix<f64>>),
}

/// A group's bodies (most groups of a row are one or two bodies: kept
/// inline, no allocation per group).
pub(crate) type Bodies = SmallVec<[usize; 2]>;
/// A value per body of a group.
type PerBody = SmallVec<[f64; 2]>;
/// A group's state rows (u, v per body), or a value per row. Copied by
/// `Rows::from_slice`: smallvec's `clone` collects through an iterator.
pub(crate) type Rows = SmallVec<[f64; 4]>;

/// One spring-coupled group of bodies and its exact propagator.
#[derive(Clone, Debug)]
pub struct Group {
    bodies: Bodies,
    propagator: Propagator,
    mass: PerBody,
    stiffness: PerBody,
    damping: PerBody,
    /// Fastest natural or forcing rate (rad/s), for the bound's horizon.
    rate: f64,
    /// The complex modes, where they can be trusted (not for a single
    /// body under harmonic forcing: closed form).
    modal: Option<Box<Modal>>,
    /// Its forcing, couplings, record step and rest state (None for a
    /// lone body without any: most groups of a row; boxed, a group
    /// stays small).
    terms: Option<Box<Terms>>,
    /// Its storeys and what a change of their branches needs (None
    /// without storeys: most groups of a row; boxed, a group stays small).
    branching: Option<Box<branches::Branching>>,
}

/// A harmonic term's steady state: (Ω, φ, Re X, Im X).
type Harmonic = (f64, f64, Vec<f64>, Vec<f64>);
/// A coupling inside a group: (local a, local b, k, c).
type Coupling = (usize, usize, f64, f64);

/// What a group has beyond its bodies' own springs and dampers.
#[derive(Clone, Debug)]
struct Terms {
    /// Steady states of the harmonic terms.
    harmonic: Vec<Harmonic>,
    /// Couplings inside the group.
    couplings: Vec<Coupling>,
    /// Sum of the harmonic forces' amplitudes on each body (N).
    force_amplitude: PerBody,
    /// Harmonic forces: (body in the group, P, Ω, φ).
    forces: Vec<(usize, f64, f64, f64)>,
    /// Without modes, under a record: the matrix form of a whole typical
    /// sample step, computed once.
    hold_step: Option<Box<HoldStep>>,
    /// The static rest state of its storeys' constant forces
    /// (interleaved; zero without storeys), and those forces.
    rest: Rows,
    rest_forces: PerBody,
}

impl Terms {
    /// None of them, for `m` bodies.
    fn none(m: usize) -> Self {
        Terms {
            harmonic: Vec::new(),
            couplings: Vec::new(),
            force_amplitude: PerBody::from_elem(0.0, m),
            forces: Vec::new(),
            hold_step: None,
            rest: Rows::from_elem(0.0, 2 * m),
            rest_forces: PerBody::from_elem(0.0, m),
        }
    }
}

/// The exact free motion of every group of a model.
#[derive(Clone, Debug)]
pub struct FreeMotion {
    groups: Vec<Group>,
    parts: build::Parts,
    /// (group, index in the group) of every body.
    place: Vec<(usize, usize)>,
    base: BaseExcitation,
    /// The base's |z̈| over stretches of time, for the bounds.
    peaks: bounds::Peaks,
    /// A record's typical sample step (s).
    record_step: Option<f64>,
}

/// `e^{Aτ}` of `ü = −w2 u − c2 u̇` as `[[p00, p01], [p10, p11]]`:
/// `e^{μτ}[C I + S (A − μ I)]` with `μ = −c2/2`, `δ = μ² − w2`, `C, S` the
/// cosine and sine (hyperbolic for δ > 0) of `√|δ| τ` (S divided by
/// `√|δ|`), by their series where `|δ| τ²` is small.
fn single_exp(w2: f64, c2: f64, tau: f64) -> [f64; 4] {
    let mu = -0.5 * c2;
    let delta = mu * mu - w2;
    let x = delta * tau * tau;
    let (ec, es) = if x.abs() < 1e-4 {
        let e = (mu * tau).exp();
        (
            e * (1.0 + x / 2.0 + x * x / 24.0),
            e * tau * (1.0 + x / 6.0 + x * x / 120.0),
        )
    } else if delta < 0.0 {
        let wd = (-delta).sqrt();
        let e = (mu * tau).exp();
        (e * (wd * tau).cos(), e * (wd * tau).sin() / wd)
    } else {
        // e^{μτ} cosh(rτ) and e^{μτ} sinh(rτ)/r from the two decaying
        // exponentials (μ + r <= 0: no overflow).
        let r = delta.sqrt();
        let (ep, em) = (((mu + r) * tau).exp(), ((mu - r) * tau).exp());
        (0.5 * (ep + em), 0.5 * (ep - em) / r)
    };
    [ec - mu * es, es, -w2 * es, ec + mu * es]
}

impl FreeMotion {
    /// A record's typical sample step (the median; s), if the base is a
    /// record.
    pub fn record_step(&self) -> Option<f64> {
        self.record_step
    }

    /// The ends of the equal pieces of `(a, b]` no longer than `step` (at
    /// least one; the last exactly `b`; none that does not advance).
    pub fn equal_pieces(a: f64, b: f64, step: f64) -> impl Iterator<Item = f64> {
        let pieces = ((b - a) / step).ceil().clamp(1.0, 1e9) as usize;
        let mut last = a;
        (1..=pieces).filter_map(move |p| {
            let t = if p == pieces {
                b
            } else {
                a + (b - a) * p as f64 / pieces as f64
            };
            (t > last).then(|| {
                last = t;
                t
            })
        })
    }

    /// The longest piece of the exact extrema's grid for a group of
    /// fastest rate `rate`: a sixteenth of its period (∞ at rest).
    pub fn natural_piece(rate: f64) -> f64 {
        if rate > 0.0 {
            std::f64::consts::PI / (8.0 * rate)
        } else {
            f64::INFINITY
        }
    }

    /// The ends of the exact extrema's pieces of `(a, b]` for group `g`,
    /// none longer than `step`, the last `b`: under a record each sample
    /// interval in equal parts (a typical one in the parts whose
    /// coefficients the group keeps, so a piece costs no exponential);
    /// otherwise `[a, b]` in equal pieces.
    pub fn grid(&self, g: usize, a: f64, b: f64, step: f64) -> Vec<f64> {
        let mut out = Vec::new();
        let part = self.groups[g].modal.as_ref().and_then(|m| m.part());
        let (BaseExcitation::Record(rec), Some(part), Some(whole)) =
            (&self.base, part, self.record_step)
        else {
            return Self::equal_pieces(a, b, step).collect();
        };
        let times = rec.times();
        let mut k = times.partition_point(|&s| s <= a).saturating_sub(1);
        let mut last = a;
        while last < b {
            let (s0, s1) = match (times.get(k), times.get(k + 1)) {
                (Some(&s0), Some(&s1)) if s0 <= last => (s0, s1),
                _ => {
                    out.extend(Self::equal_pieces(last, b, step));
                    return out;
                }
            };
            let len = s1 - s0;
            if len <= 0.0 {
                k += 1;
                continue;
            }
            let piece = if (len - whole).abs() <= 1e-12 * whole {
                part
            } else {
                len / (len / step).ceil().max(1.0)
            };
            // The interval's part ends after `last`, up to b.
            let mut i = ((last - s0) / piece).floor() + 1.0;
            loop {
                let t = if s0 + i * piece >= s1 - 1e-12 * len {
                    s1
                } else {
                    s0 + i * piece
                };
                if t >= b {
                    out.push(b);
                    return out;
                }
                if t > last {
                    out.push(t);
                    last = t;
                }
                if t == s1 {
                    break;
                }
                i += 1.0;
            }
            k += 1;
        }
        out
    }

    /// The groups.
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }

    /// The model's couplings in group `g` (model indices, ascending).
    pub(crate) fn couplings_in(&self, g: usize) -> &[usize] {
        &self.parts.couplings[g]
    }

    /// The model's storeys in group `g`, by the body above (model indices,
    /// ascending).
    pub(crate) fn storeys_in(&self, g: usize) -> &[usize] {
        &self.parts.storeys[g]
    }

    /// The model's harmonic forces on group `g` (model indices,
    /// ascending).
    pub(crate) fn forces_in(&self, g: usize) -> &[usize] {
        &self.parts.forces[g]
    }

    /// (group, index within the group) of body `i`.
    pub fn place(&self, i: usize) -> (usize, usize) {
        self.place[i]
    }

    /// Sets group `g`'s rest state to the static displacement under the
    /// constant forces `f` on its bodies (N, the group's order): `K u_s =
    /// f` (solved again only if `f` or the stiffness changed). A group without ground springs is solved in the least-squares
    /// sense (its storeys' forces act in pairs, within the range of `K`).
    /// Errors with the residual if `f` is not balanced by the springs.
    pub fn set_rest(&mut self, g: usize, f: &[f64]) -> Result<(), f64> {
        let group = &mut self.groups[g];
        let m = group.bodies.len();
        let zero = f.iter().all(|&x| x == 0.0);
        match group.terms.as_deref_mut() {
            // (Without terms the rest state is zero.)
            None if zero => return Ok(()),
            Some(t) if f == t.rest_forces.as_slice() => return Ok(()),
            Some(t) if zero => {
                t.rest.fill(0.0);
                t.rest_forces.fill(0.0);
                return Ok(());
            }
            _ => {}
        }
        let mut k = DMatrix::<f64>::zeros(m, m);
        for j in 0..m {
            k[(j, j)] = group.stiffness[j];
        }
        for &(a, b, kc, _) in group.couplings() {
            k[(a, a)] += kc;
            k[(b, b)] += kc;
            k[(a, b)] -= kc;
            k[(b, a)] -= kc;
        }
        let rhs = DVector::from_column_slice(f);
        let eps = 1e-13 * k.amax();
        let u = k
            .clone()
            .svd(true, true)
            .solve(&rhs, eps)
            .unwrap_or_else(|_| DVector::from_element(m, f64::NAN));
        let residual = (&k * &u - &rhs).amax();
        let scale = rhs.amax();
        if residual.is_nan() || residual > 1e-9 * scale {
            return Err(residual / scale);
        }
        let t = group.terms_mut();
        for j in 0..m {
            t.rest[2 * j] = u[j];
            t.rest[2 * j + 1] = 0.0;
        }
        t.rest_forces.copy_from_slice(f);
        Ok(())
    }

    /// Adds the particular motion of group `g` at time `t` (its rest state
    /// and harmonic steady state), times `sign`, to `x`.
    fn add_particular(&self, g: &Group, t: f64, sign: f64, x: &mut [f64]) {
        let Some(terms) = g.terms.as_deref() else {
            return;
        };
        for (xi, r) in x.iter_mut().zip(&terms.rest) {
            *xi += sign * r;
        }
        for (w, phi, re, im) in &terms.harmonic {
            let (s, c) = (w * t + phi).sin_cos();
            for (xi, (r, i)) in x.iter_mut().zip(re.iter().zip(im)) {
                *xi += sign * (r * s + i * c);
            }
        }
    }

    /// `x ← e^{Aτ} x` for group `g`.
    fn homogeneous(g: &Group, tau: f64, x: &mut [f64]) {
        match &g.propagator {
            Propagator::Single { w2, c2 } => {
                let p = single_exp(*w2, *c2, tau);
                let (u, v) = (x[0], x[1]);
                x[0] = p[0] * u + p[1] * v;
                x[1] = p[2] * u + p[3] * v;
            }
            Propagator::Group(a) => {
                let phi = (&**a * tau).exp();
                let y = &phi * DVector::from_column_slice(x);
                x.copy_from_slice(y.as_slice());
            }
        }
    }

    /// Whether group `g` at state `x` stays there for good: at rest at
    /// zero without forcing.
    pub fn stays_at_rest(&self, g: usize, x: &[f64]) -> bool {
        self.groups[g].at_rest(&self.base, x)
    }

    /// Propagates group `g`'s interleaved state `x` from `t0` to `t1 >= t0`
    /// exactly (in place).
    pub fn propagate(&self, g: usize, t0: f64, t1: f64, x: &mut [f64]) {
        let group = &self.groups[g];
        if t1 == t0 || group.at_rest(&self.base, x) {
            return;
        }
        self.add_particular(group, t0, -1.0, x);
        // A short run under a record: whole steps in the state (d² products
        // each, where a pass through the modes costs about 7 d² and 14 d a
        // step), a partial one through the modes.
        let short = group.hold_step().filter(|h| t1 - t0 <= SHORT_RUN * h.tau);
        match (&self.base, &group.modal, short) {
            (BaseExcitation::Record(rec), Some(modal), Some(h)) => {
                let (mut y, mut z) = (vec![0.0; x.len()], Vec::with_capacity(x.len()));
                hold::intervals(rec, t0, t1, |tau, fa, slope| {
                    if (tau - h.tau).abs() <= 1e-12 * h.tau {
                        hold::step((&h.phi, &h.g0, &h.g1), fa, slope, x, &mut y)
                    } else {
                        modal.to_modes(x, &mut z);
                        modal.hold(tau, fa, slope, &mut z);
                        modal.to_state(&z, x);
                    }
                });
            }
            (BaseExcitation::Record(rec), Some(modal), None) => {
                let mut z = Vec::with_capacity(x.len());
                modal.to_modes(x, &mut z);
                hold::intervals(rec, t0, t1, |tau, fa, slope| {
                    modal.hold(tau, fa, slope, &mut z)
                });
                modal.to_state(&z, x);
            }
            (BaseExcitation::Record(rec), None, _) => {
                let mut y = vec![0.0; x.len()];
                hold::intervals(rec, t0, t1, |tau, fa, slope| match group.hold_step() {
                    // A whole sample step (to rounding of the sample times:
                    // 1e-12 of a step moves the state by far less than any
                    // tolerance).
                    Some(h) if (tau - h.tau).abs() <= 1e-12 * h.tau => {
                        hold::step((&h.phi, &h.g0, &h.g1), fa, slope, x, &mut y)
                    }
                    _ => {
                        let (phi, g0, g1) = hold::matrices(&Self::matrix(group), tau);
                        hold::step((&phi, &g0, &g1), fa, slope, x, &mut y)
                    }
                });
            }
            (_, Some(modal), _) => {
                let mut z = Vec::with_capacity(x.len());
                modal.to_modes(x, &mut z);
                modal.free(t1 - t0, &mut z);
                modal.to_state(&z, x);
            }
            (_, None, _) => Self::homogeneous(group, t1 - t0, x),
        }
        self.add_particular(group, t1, 1.0, x);
    }

    /// Acceleration of body `j` of group `g` (index in the group) in the
    /// group's interleaved state `x` at `t`: springs, dampers, couplings,
    /// forces and the base (m/s², relative to the base).
    pub fn acceleration(&self, g: usize, t: f64, x: &[f64], j: usize) -> f64 {
        let group = &self.groups[g];
        // Springs act on the displacement from rest (the storeys' constant
        // forces balance there).
        let u = |i: usize| x[2 * i] - group.rest(2 * i);
        let mut f = -group.stiffness[j] * u(j) - group.damping[j] * x[2 * j + 1];
        for &(a, b, k, c) in group.couplings() {
            let other = match (a == j, b == j) {
                (true, _) => b,
                (_, true) => a,
                _ => continue,
            };
            f += k * (u(other) - u(j)) + c * (x[2 * other + 1] - x[2 * j + 1]);
        }
        for &(i, p, w, phi) in group.forces() {
            if i == j {
                f += p * (w * t + phi).sin();
            }
        }
        f / group.mass[j] - self.base.at(t)
    }

    /// The rate of body `j`'s absolute acceleration (its acceleration
    /// plus the base's) in group `g` at `t`, given the group's state `x`
    /// and its bodies' accelerations `acc` ([`FreeMotion::acceleration`]):
    /// the springs' and dampers' forces differentiated along the motion,
    /// and the forces' rates (m/s³; the base's rate cancels).
    pub fn absolute_jerk(&self, g: usize, t: f64, x: &[f64], acc: &[f64], j: usize) -> f64 {
        let group = &self.groups[g];
        let v = |i: usize| x[2 * i + 1];
        let mut f = -group.stiffness[j] * v(j) - group.damping[j] * acc[j];
        for &(a, b, k, c) in group.couplings() {
            let other = match (a == j, b == j) {
                (true, _) => b,
                (_, true) => a,
                _ => continue,
            };
            f += k * (v(other) - v(j)) + c * (acc[other] - acc[j]);
        }
        for &(i, p, w, phi) in group.forces() {
            if i == j {
                f += p * w * (w * t + phi).cos();
            }
        }
        f / group.mass[j]
    }

    /// `x ← e^{Aτ} x` for group `g`: a tangent vector of the free motion
    /// (the forcing does not enter the variational equations).
    pub fn propagate_homogeneous(&self, g: usize, tau: f64, x: &mut [f64]) {
        let group = &self.groups[g];
        if tau == 0.0 {
            return;
        }
        match &group.modal {
            Some(modal) => {
                let mut z = Vec::with_capacity(x.len());
                modal.to_modes(x, &mut z);
                modal.free(tau, &mut z);
                modal.to_state(&z, x);
            }
            None => Self::homogeneous(group, tau, x),
        }
    }

    /// The group's system matrix `A` (interleaved).
    fn matrix(g: &Group) -> DMatrix<f64> {
        match &g.propagator {
            Propagator::Group(a) => (**a).clone(),
            Propagator::Single { w2, c2 } => DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w2, -c2]),
        }
    }
}

impl Group {
    /// Whether the group at state `x` stays there exactly: at rest at zero
    /// without forcing (no harmonic term, no record, no constant force), as
    /// a row's bodies are before a pulse reaches them.
    fn at_rest(&self, base: &BaseExcitation, x: &[f64]) -> bool {
        (self.terms.as_deref())
            .is_none_or(|t| t.harmonic.is_empty() && t.rest.iter().all(|&r| r == 0.0))
            && !matches!(base, BaseExcitation::Record(_))
            && x.iter().all(|&v| v == 0.0)
    }

    /// Its harmonic terms' steady states.
    fn harmonic(&self) -> &[Harmonic] {
        self.terms.as_deref().map_or(&[], |t| &t.harmonic)
    }

    /// Its couplings.
    fn couplings(&self) -> &[Coupling] {
        self.terms.as_deref().map_or(&[], |t| &t.couplings)
    }

    /// Its harmonic forces.
    fn forces(&self) -> &[(usize, f64, f64, f64)] {
        self.terms.as_deref().map_or(&[], |t| &t.forces)
    }

    /// The sum of the harmonic forces' amplitudes on body `j` (N).
    fn force_amplitude(&self, j: usize) -> f64 {
        self.terms.as_deref().map_or(0.0, |t| t.force_amplitude[j])
    }

    /// A whole typical sample step's matrix form, if kept.
    fn hold_step(&self) -> Option<&HoldStep> {
        self.terms.as_deref().and_then(|t| t.hold_step.as_deref())
    }

    /// Its terms, given (none of them) where it had none.
    fn terms_mut(&mut self) -> &mut Terms {
        let m = self.bodies.len();
        self.terms.get_or_insert_with(|| Box::new(Terms::none(m)))
    }

    /// The bodies, in order along the line.
    pub fn bodies(&self) -> &[usize] {
        &self.bodies
    }

    /// Fastest natural frequency or forcing frequency of the group (rad/s;
    /// 0 for free bodies without forcing).
    pub fn rate(&self) -> f64 {
        self.rate
    }

    /// `(k/m, c/m)` of a body alone in its group (the rates of its closed
    /// form), else None.
    pub fn lone_rates(&self) -> Option<(f64, f64)> {
        match self.propagator {
            Propagator::Single { w2, c2 } => Some((w2, c2)),
            Propagator::Group(_) => None,
        }
    }
}

mod bounds;
mod branches;
mod build;
mod hold;
mod modal;

#[cfg(test)]
mod tests;
