//! A chain's linear form `A y + b(t)` where it has one (docs/theory.md
//! §12): every contact rigid (between impacts no contact force acts), no
//! storeys, no energy quadratures, and a forcing of harmonics (a
//! harmonic base or none, harmonic forces, gravity as Ω = 0). The period
//! map of such a chain moves exactly between its impacts
//! ([`crate::integrate::Method::Exact`]).

use nalgebra::DMatrix;

use super::{ChainDynamics, Screen};
use crate::integrate::{Harmonic, LinearForm};
use crate::model::BaseExcitation;
use crate::numeric::larger;

impl ChainDynamics {
    /// The chain as `A y + b(t)` (one block), or None where it is not
    /// linear with harmonic forcing (see the module documentation).
    pub(super) fn linear_form_of(&self) -> Option<LinearForm> {
        let n = self.n;
        let linear = !self.energy
            && self.storeys.is_empty()
            && self
                .contacts
                .iter()
                .all(|c| c.rigid.is_some() && matches!(c.screen, Screen::Never));
        if !linear {
            return None;
        }
        let mut a = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(2 * i, 2 * i + 1)] = 1.0;
            a[(2 * i + 1, 2 * i)] = -self.stiffness[i] * self.inv_mass[i];
            a[(2 * i + 1, 2 * i + 1)] = -self.damping[i] * self.inv_mass[i];
        }
        // A coupling's force k Δu + c Δv on a, its opposite on b.
        for &(p, q, k, c) in &self.couplings {
            for (i, j) in [(p, q), (q, p)] {
                let w = self.inv_mass[i];
                a[(2 * i + 1, 2 * i)] -= k * w;
                a[(2 * i + 1, 2 * j)] += k * w;
                a[(2 * i + 1, 2 * i + 1)] -= c * w;
                a[(2 * i + 1, 2 * j + 1)] += c * w;
            }
        }
        // b(t): P sin(Ω t + φ) = P sin φ cos Ω t + P cos φ sin Ω t.
        let mut harmonics: Vec<Harmonic> = Vec::new();
        let mut add = |omega: f64, row: Option<usize>, p: f64, phi: f64| {
            let at = match harmonics.iter().position(|h| h.omega == omega) {
                Some(k) => k,
                None => {
                    harmonics.push(Harmonic {
                        omega,
                        cos: vec![0.0; 2 * n],
                        sin: vec![0.0; 2 * n],
                    });
                    harmonics.len() - 1
                }
            };
            let h = &mut harmonics[at];
            let (s, c) = phi.sin_cos();
            let rows: Vec<usize> = match row {
                Some(i) => vec![i],
                None => (0..n).collect(),
            };
            for i in rows {
                h.cos[2 * i + 1] += p * s;
                h.sin[2 * i + 1] += p * c;
            }
        };
        match self.base {
            BaseExcitation::None => {}
            BaseExcitation::Harmonic {
                amplitude,
                frequency,
                phase,
            } => add(frequency, None, -amplitude, phase),
            _ => return None,
        }
        for &(body, p, w, phi) in &self.forces {
            add(w, Some(body), p * self.inv_mass[body], phi);
        }
        Some(LinearForm {
            a,
            blocks: vec![harmonics],
        })
    }
}

/// A chain with no contacts, its storeys on linear pieces, as `ẏ = A y +
/// b − e z̈(t)` (`e`: ones in the velocity rows; docs/theory.md §13): per
/// body its own spring, damper and constant force, and the links between
/// bodies (couplings and storeys, with their P-Δ), so that a product with
/// `A` costs what a right-hand side does.
#[derive(Clone, Debug, Default)]
pub struct PiecewiseForm {
    inv_mass: Vec<f64>,
    /// Per body: its spring and damper to the ground (N/m, N s/m) and its
    /// constant force (N).
    ground: Vec<[f64; 3]>,
    /// (a, b, k, c): the force k (u_b − u_a) + c (v_b − v_a) on a, its
    /// opposite on b.
    links: Vec<(usize, usize, f64, f64)>,
    /// Where the links join each body to the next and no other (a
    /// building: its storeys), link i's (k, c) between bodies i and i + 1
    /// (the force k (u_{i+1} − u_i) + c (v_{i+1} − v_i) on i): the product
    /// then walks the bodies once.
    chain: Option<Vec<[f64; 2]>>,
    /// Upper bounds on the largest row sums of |K| and |C|, the velocity
    /// rows of `A` on the displacements and on the velocities
    /// ([`PiecewiseForm::norms`]).
    norms: (f64, f64),
}

/// What a term of a series adds to each body's row (docs/theory.md §13).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Added {
    /// Nothing (the fifth term on).
    Nothing,
    /// The body's constant acceleration `b` less the base's `a₀`, times
    /// the weight given (the third term, c₂).
    ConstantLess(f64, f64),
    /// Minus this (the fourth term, c₃: the base's jerk, weighted).
    Less(f64),
}

impl PiecewiseForm {
    /// `out = (K x) wx + (C z) wz + added` per body, `K` and `C` the
    /// velocity rows of `A` on the displacements and on the velocities
    /// (without the base but as `added` says), each body's `out_i (1, w)`
    /// added to `sums[i]` (the series' sums at its end, met while the row
    /// is at hand), and the largest |out| (a NaN passed over, as by `f64::max`):
    /// a displacement term of a series (docs/theory.md §13). (Inlined
    /// always: where `added` is known, its match goes.)
    #[inline(always)]
    pub fn displacement_term(
        &self,
        (x, wx): (&[f64], f64),
        (z, wz): (&[f64], f64),
        out: &mut [f64],
        added: Added,
        (sums, w): (&mut [[f64; 4]], [f64; 3]),
    ) -> f64 {
        if let Some(chain) = &self.chain {
            return self.chain_term(chain, (x, wx), (z, wz), out, added, (sums, w));
        }
        let n = self.ground.len();
        let (x, z, out, sums) = (&x[..n], &z[..n], &mut out[..n], &mut sums[..n]);
        for ((o, g), (x, z)) in out.iter_mut().zip(&self.ground).zip(x.iter().zip(z)) {
            *o = (-g[0] * x) * wx + (-g[1] * z) * wz;
        }
        for &(a, b, k, c) in &self.links {
            let f = k * (x[b] - x[a]) * wx + c * (z[b] - z[a]) * wz;
            out[a] += f;
            out[b] -= f;
        }
        let mut top = 0.0f64;
        for (i, ((o, m), e)) in out.iter_mut().zip(&self.inv_mass).zip(sums).enumerate() {
            *o = *o * m + self.added(i, added);
            top = larger(top, o.abs());
            add_weighted(e, *o, w);
        }
        top
    }

    /// What `added` adds to body i's row.
    #[inline(always)]
    fn added(&self, i: usize, added: Added) -> f64 {
        match added {
            Added::Nothing => 0.0,
            Added::ConstantLess(a0, w) => (self.constant(i) - a0) * w,
            Added::Less(x) => -x,
        }
    }

    /// [`PiecewiseForm::displacement_term`] on a chain: each link's force
    /// once, in one pass over the bodies, a body's row written when the
    /// link above it is known (iterators throughout: no index to check).
    #[inline(always)]
    fn chain_term(
        &self,
        chain: &[[f64; 2]],
        (x, wx): (&[f64], f64),
        (z, wz): (&[f64], f64),
        out: &mut [f64],
        added: Added,
        (sums, w): (&mut [[f64; 4]], [f64; 3]),
    ) -> f64 {
        let mut top = 0.0f64;
        let n = self.ground.len();
        let (x, z, out, sums) = (&x[..n], &z[..n], &mut out[..n], &mut sums[..n]);
        let mut rows = out
            .iter_mut()
            .zip(sums)
            .zip(self.ground.iter().zip(&self.inv_mass));
        let (Some(&(mut u)), Some(&(mut v)), Some((mut o, (mut g, mut m)))) =
            (x.first(), z.first(), rows.next())
        else {
            return top;
        };
        let mut below = (0.0, 0.0);
        let mut row = |(o, e): (&mut f64, &mut [f64; 4]),
                       (u, v): (f64, f64),
                       g: &[f64; 3],
                       m: f64,
                       above: (f64, f64)| {
            *o = chain_row((g, m), (u, v), (above, below), (wx, wz), added);
            top = larger(top, o.abs());
            add_weighted(e, *o, w);
            below = above;
        };
        for (((&xn, &zn), &[k, c]), (o_next, (g_next, m_next))) in
            x[1..].iter().zip(&z[1..]).zip(chain).zip(rows)
        {
            row(o, (u, v), g, *m, (k * (xn - u), c * (zn - v)));
            (u, v) = (xn, zn);
            (o, g, m) = (o_next, g_next, m_next);
        }
        row(o, (u, v), g, *m, (0.0, 0.0));
        top
    }

    /// The chain of exactly `N` bodies as arrays (None: not a chain, or
    /// not of N bodies), for [`FixedChain::term`].
    #[inline(always)]
    pub fn fixed<const N: usize>(&self) -> Option<FixedChain<N>> {
        let chain = self.chain.as_ref()?;
        let (ground, inv_mass): (&[[f64; 3]; N], [f64; N]) = (
            self.ground.as_slice().try_into().ok()?,
            self.inv_mass.as_slice().try_into().ok()?,
        );
        let (mut link_k, mut link_c) = ([0.0; N], [0.0; N]);
        for ((k, c), link) in link_k.iter_mut().zip(link_c.iter_mut()).zip(chain) {
            (*k, *c) = (link[0], link[1]);
        }
        Some(FixedChain {
            ground_k: ground.map(|g| g[0]),
            ground_c: ground.map(|g| g[1]),
            constant: ground.map(|g| g[2]),
            inv_mass,
            link_k,
            link_c,
        })
    }

    /// Whether its links are taken as a chain.
    #[cfg(test)]
    pub(crate) fn is_chain(&self) -> bool {
        self.chain.is_some()
    }

    /// The same form with its links taken one by one (a chain's product
    /// checked against them).
    #[cfg(test)]
    pub(crate) fn unchained(&self) -> Self {
        Self {
            chain: None,
            ..self.clone()
        }
    }

    /// The links as a chain, if they are one (see `chain`).
    fn chain_of(&mut self) {
        let n = self.ground.len();
        let mut chain = vec![[0.0; 2]; n.saturating_sub(1)];
        let mut seen = vec![false; chain.len()];
        for &(a, b, k, c) in &self.links {
            // (k (u_b − u_a) on a is k (u_{lo+1} − u_lo) on lo either way.)
            let lo = match (a + 1 == b, b + 1 == a) {
                (true, _) => a,
                (_, true) => b,
                _ => {
                    self.chain = None;
                    return;
                }
            };
            if seen[lo] {
                self.chain = None;
                return;
            }
            seen[lo] = true;
            chain[lo] = [k, c];
        }
        self.chain = Some(chain);
    }

    /// Upper bounds on the infinity norms of `K` and `C`, the velocity rows
    /// of `A` on the displacements and on the velocities: `|K x|∞ ≤
    /// norms.0 |x|∞`, and
    /// the same for `C` (a series' tail bounded by them:
    /// docs/theory.md §13).
    pub fn norms(&self) -> (f64, f64) {
        self.norms
    }

    /// [`PiecewiseForm::norms`] from the ground and the links.
    fn norms_of(&mut self) {
        let mut rows: Vec<[f64; 2]> = self
            .ground
            .iter()
            .map(|g| [g[0].abs(), g[1].abs()])
            .collect();
        for &(a, b, k, c) in &self.links {
            for i in [a, b] {
                rows[i][0] += 2.0 * k.abs();
                rows[i][1] += 2.0 * c.abs();
            }
        }
        self.norms = rows
            .iter()
            .zip(&self.inv_mass)
            .fold((0.0, 0.0), |(nk, nc), (r, m)| {
                (f64::max(nk, r[0] * m.abs()), f64::max(nc, r[1] * m.abs()))
            });
    }

    /// Body i's constant acceleration `b` (its velocity row's).
    #[inline]
    pub fn constant(&self, i: usize) -> f64 {
        self.ground[i][2] * self.inv_mass[i]
    }
}

/// A chain of `N` bodies ([`PiecewiseForm::fixed`]): its product with
/// rows of a known length, which the compiler unrolls, with no index to
/// check (a building of up to eight storeys: the exact run's series).
#[derive(Clone, Copy, Debug)]
pub struct FixedChain<const N: usize> {
    /// Per body: its spring, damper and constant force to the ground, its
    /// inverse mass, and the link above it (stiffness and damping; zero
    /// above the last).
    ground_k: [f64; N],
    ground_c: [f64; N],
    constant: [f64; N],
    inv_mass: [f64; N],
    link_k: [f64; N],
    link_c: [f64; N],
}

impl<const N: usize> FixedChain<N> {
    /// [`PiecewiseForm::displacement_term`] on rows of N, without the
    /// sums (a series of them sums its rows once it has them: see
    /// `simulate::exact`): the same arithmetic in the same order, each
    /// link's force once.
    #[inline(always)]
    pub fn term(
        &self,
        (x, wx): (&[f64; N], f64),
        (z, wz): (&[f64; N], f64),
        out: &mut [f64; N],
        added: Added,
    ) -> f64 {
        // (Each link's force, link i between bodies i and i + 1; none
        // above the last.)
        let (mut fk, mut fc) = ([0.0; N], [0.0; N]);
        for i in 1..N {
            fk[i - 1] = self.link_k[i - 1] * (x[i] - x[i - 1]);
            fc[i - 1] = self.link_c[i - 1] * (z[i] - z[i - 1]);
        }
        for i in 0..N {
            let below = match i {
                0 => (0.0, 0.0),
                _ => (fk[i - 1], fc[i - 1]),
            };
            let g = [self.ground_k[i], self.ground_c[i], self.constant[i]];
            let m = self.inv_mass[i];
            out[i] = chain_row(
                (&g, m),
                (x[i], z[i]),
                ((fk[i], fc[i]), below),
                (wx, wz),
                added,
            );
        }
        out.iter().fold(0.0f64, |top, o| larger(top, o.abs()))
    }
}

/// A chain body's row of a term: from its ground (spring, damper,
/// constant force) and inverse mass, its displacement and velocity terms
/// `(u, v)`, and the forces of the links above and below it (each `(k
/// Δu, c Δv)`), weighted by `(wx, wz)`, with what `added` adds.
#[inline(always)]
fn chain_row(
    (g, m): (&[f64; 3], f64),
    (u, v): (f64, f64),
    (above, below): ((f64, f64), (f64, f64)),
    (wx, wz): (f64, f64),
    added: Added,
) -> f64 {
    let a = ((-g[0] * u + above.0 - below.0) * wx + (-g[1] * v + above.1 - below.1) * wz) * m;
    match added {
        Added::Nothing => a,
        Added::ConstantLess(a0, w) => a + (g[2] * m - a0) * w,
        Added::Less(x) => a - x,
    }
}

/// `e += c (1, w₁, w₂, w₃)`, element by element (a term's first weight
/// in the sums at θ = 1, θ^k's value there, is one).
#[inline(always)]
fn add_weighted(e: &mut [f64; 4], c: f64, w: [f64; 3]) {
    *e = [e[0] + c, e[1] + c * w[0], e[2] + c * w[1], e[3] + c * w[2]];
}

impl ChainDynamics {
    /// The chain's [`PiecewiseForm`] on its storeys' current pieces, into
    /// `form`; false where it has none: contacts, harmonic forces or base
    /// motion, gravity, Bouc–Wen storeys or the energy audit's quadratures.
    pub fn piecewise_form(&self, form: &mut PiecewiseForm) -> bool {
        let base = matches!(self.base, BaseExcitation::None | BaseExcitation::Record(_));
        let storeys = &self.storeys;
        if !base
            || !self.contacts.is_empty()
            || !self.forces.is_empty()
            || self.energy
            || storeys.integrated()
        {
            return false;
        }
        let n = self.n;
        form.inv_mass.clone_from(&self.inv_mass);
        form.ground.clear();
        form.ground
            .extend((0..n).map(|i| [self.stiffness[i], self.damping[i], 0.0]));
        form.links.clear();
        form.links.extend_from_slice(&self.couplings);
        // (A storey between two bodies a coupling joins joins its link.)
        let mut link = |a: usize, b: usize, k: f64| match form
            .links
            .iter_mut()
            .find(|l| (l.0, l.1) == (a, b) || (l.0, l.1) == (b, a))
        {
            Some(l) => l.2 += k,
            None => form.links.push((a, b, k, 0.0)),
        };
        for k in 0..storeys.len() {
            let Some((kb, f0)) = storeys.piece(k) else {
                return false;
            };
            let (below, above) = storeys.ends(k);
            let stiffness = kb - storeys.p_delta(k);
            form.ground[above][2] -= f0;
            match below {
                Some(b) => {
                    link(above, b, stiffness);
                    form.ground[b][2] += f0;
                }
                None => form.ground[above][0] += stiffness,
            }
        }
        form.chain_of();
        form.norms_of();
        true
    }
}
