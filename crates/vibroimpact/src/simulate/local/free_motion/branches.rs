//! A group's propagators per storey branch (docs/theory.md §10): a
//! bilinear storey on its plastic branch is a spring of its post-yield
//! stiffness with a constant force, so its group still moves exactly,
//! with the system matrix of that stiffness. A group keeps the
//! propagators of the branches it has met (a yielding building goes back
//! and forth between a few), keyed by its storeys' stiffness.

use nalgebra::{Complex, DMatrix, DVector};

use super::{Coupling, FreeMotion, FreeMotionError, Group, Harmonic, HoldStep, Modal, Propagator};

/// Where a storey's stiffness sits in its group.
#[derive(Clone, Copy, Debug)]
pub(super) enum Slot {
    /// Added to body j's spring to the ground.
    Ground(usize),
    /// The coupling of this index.
    Coupling(usize),
}

/// A group's storeys and what a change of their branches needs.
#[derive(Clone, Debug)]
pub(super) struct Branching {
    /// Its storeys (model index), where each one's stiffness sits, and
    /// that stiffness now (its branch's, less its P-Δ stiffness).
    pub(super) storeys: Vec<(usize, Slot)>,
    pub(super) stiffness: Vec<f64>,
    /// The harmonic terms b sin(Ω t + φ) per unit mass: (Ω, φ, b).
    pub(super) terms: Vec<(f64, f64, Vec<f64>)>,
    /// The bodies' own springs to the ground (without storeys), and the
    /// bodies' names (for errors).
    pub(super) own_stiffness: super::PerBody,
    pub(super) names: String,
    /// The propagators of other branches met so far, by their storeys'
    /// stiffness ([`FreeMotion::set_storey_stiffness`]).
    pub(super) cache: Vec<(Vec<f64>, Variant)>,
}

/// What changes with the storeys' stiffness.
#[derive(Clone, Debug)]
pub(super) struct Variant {
    stiffness: super::PerBody,
    couplings: Vec<Coupling>,
    propagator: Propagator,
    harmonic: Vec<Harmonic>,
    rate: f64,
    modal: Option<Box<Modal>>,
    hold_step: Option<Box<HoldStep>>,
}

/// The system matrix `A` (interleaved `[u, v]` rows) of bodies with
/// `mass`, ground `stiffness` and `damping`, and `couplings` (a, b, k, c).
pub(super) fn system_matrix(
    mass: &[f64],
    stiffness: &[f64],
    damping: &[f64],
    couplings: &[Coupling],
) -> DMatrix<f64> {
    let m = mass.len();
    let mut a = DMatrix::<f64>::zeros(2 * m, 2 * m);
    for j in 0..m {
        a[(2 * j, 2 * j + 1)] = 1.0;
        a[(2 * j + 1, 2 * j)] = -stiffness[j] / mass[j];
        a[(2 * j + 1, 2 * j + 1)] = -damping[j] / mass[j];
    }
    for &(p, q, k, c) in couplings {
        for (i, j) in [(p, q), (q, p)] {
            a[(2 * i + 1, 2 * i)] -= k / mass[i];
            a[(2 * i + 1, 2 * j)] += k / mass[i];
            a[(2 * i + 1, 2 * i + 1)] -= c / mass[i];
            a[(2 * i + 1, 2 * j + 1)] += c / mass[i];
        }
    }
    a
}

/// The steady states `(iΩ − A) X = b` of the harmonic `terms` (Ω, φ, b),
/// as (Ω, φ, Re X, Im X), and the fastest natural or forcing rate of `A`
/// (rad/s). Errors for a resonance (`names`: the group's bodies).
#[allow(clippy::type_complexity)]
pub(super) fn steady_states(
    a: &DMatrix<f64>,
    terms: &[(f64, f64, Vec<f64>)],
    names: &str,
) -> Result<(Vec<Harmonic>, f64), FreeMotionError> {
    let d = a.nrows();
    let mut harmonic = Vec::with_capacity(terms.len());
    let mut rate = 0.0f64;
    for (w, phi, b) in terms {
        let w = *w;
        rate = rate.max(w);
        let mut lhs = DMatrix::<Complex<f64>>::from_fn(d, d, |i, j| Complex::new(-a[(i, j)], 0.0));
        for i in 0..d {
            lhs[(i, i)] += Complex::new(0.0, w);
        }
        let rhs = DVector::<Complex<f64>>::from_fn(d, |i, _| Complex::new(b[i], 0.0));
        let scale = a.amax() + w;
        let x = lhs
            .lu()
            .solve(&rhs)
            .filter(|x| x.iter().all(|z| z.re.is_finite() && z.im.is_finite()))
            // An exactly singular pivot may still solve to huge values:
            // resonance shows as a response far beyond any physical one.
            .filter(|x| {
                let bmax = b.iter().fold(0.0f64, |s, v| s.max(v.abs()));
                x.iter()
                    .all(|z| z.norm() * scale * 1e-12 <= bmax.max(1e-300))
            })
            .ok_or_else(|| FreeMotionError::Resonant {
                bodies: names.to_string(),
                frequency: w,
            })?;
        harmonic.push((
            w,
            *phi,
            x.iter().map(|z| z.re).collect(),
            x.iter().map(|z| z.im).collect(),
        ));
    }
    for j in 0..d / 2 {
        rate = rate.max((-a[(2 * j + 1, 2 * j)]).max(0.0).sqrt());
    }
    Ok((harmonic, rate))
}

/// The free motion of bodies with `mass`, ground `stiffness` and
/// `damping`, and `couplings`, under the harmonic `terms`: its propagator
/// (a single body's closed form, or the group's system matrix), the
/// terms' steady states and the fastest rate ([`steady_states`]). A
/// single body without terms builds no matrix: a row of a thousand
/// pendulums sets up a thousand of these.
pub(super) fn motion(
    mass: &[f64],
    stiffness: &[f64],
    damping: &[f64],
    couplings: &[Coupling],
    terms: &[(f64, f64, Vec<f64>)],
    names: &str,
) -> Result<(Propagator, Vec<Harmonic>, f64), FreeMotionError> {
    if mass.len() == 1 && couplings.is_empty() && terms.is_empty() {
        let (w2, c2) = (stiffness[0] / mass[0], damping[0] / mass[0]);
        return Ok((
            Propagator::Single { w2, c2 },
            Vec::new(),
            w2.max(0.0).sqrt(),
        ));
    }
    let a = system_matrix(mass, stiffness, damping, couplings);
    let (harmonic, rate) = steady_states(&a, terms, names)?;
    let propagator = if mass.len() == 1 {
        Propagator::Single {
            w2: -a[(1, 0)],
            c2: -a[(1, 1)],
        }
    } else {
        Propagator::Group(Box::new(a))
    };
    Ok((propagator, harmonic, rate))
}

impl Group {
    /// Moves the current propagators out (the group is left to be given
    /// others).
    fn take_variant(&mut self) -> Variant {
        Variant {
            stiffness: self.stiffness.clone(),
            couplings: self.couplings().to_vec(),
            propagator: self.propagator.clone(),
            harmonic: std::mem::take(&mut self.terms_mut().harmonic),
            rate: self.rate,
            modal: self.modal.take(),
            hold_step: self.terms_mut().hold_step.take(),
        }
    }

    fn put_variant(&mut self, v: Variant) {
        self.stiffness = v.stiffness;
        self.propagator = v.propagator;
        self.rate = v.rate;
        self.modal = v.modal;
        let t = self.terms_mut();
        t.couplings = v.couplings;
        t.harmonic = v.harmonic;
        t.hold_step = v.hold_step;
    }

    /// Its storeys (model indices), in the order
    /// [`FreeMotion::set_storey_stiffness`] takes their stiffness.
    pub fn storeys(&self) -> impl Iterator<Item = usize> + '_ {
        (self.branching.iter()).flat_map(|b| b.storeys.iter().map(|&(s, _)| s))
    }
}

impl FreeMotion {
    /// Gives group `g` the propagators of its storeys' stiffness `k` (one
    /// per storey of [`Group::storeys`], N/m: the branch's, less the P-Δ
    /// stiffness), from those met before or new. The rest state is then
    /// to be set again ([`FreeMotion::set_rest`]). Errors for a
    /// resonance with a harmonic force.
    pub fn set_storey_stiffness(&mut self, g: usize, k: &[f64]) -> Result<(), FreeMotionError> {
        let record_step = matches!(self.base, crate::model::BaseExcitation::Record(_))
            .then_some(self.record_step);
        let group = &mut self.groups[g];
        // (Without storeys `k` is empty: nothing to change.)
        let Some(mut br) = group.branching.take() else {
            return Ok(());
        };
        if br.stiffness == k {
            group.branching = Some(br);
            return Ok(());
        }
        let old = group.take_variant();
        let key = std::mem::replace(&mut br.stiffness, k.to_vec());
        // The rest state belongs to the stiffness: set again even for the
        // same forces.
        group.terms_mut().rest_forces.fill(f64::NAN);
        br.cache.push((key, old));
        if let Some(i) = br.cache.iter().position(|(key, _)| key == k) {
            let (_, v) = br.cache.swap_remove(i);
            group.put_variant(v);
            group.branching = Some(br);
            return Ok(());
        }
        group.stiffness.clone_from(&br.own_stiffness);
        for (&(_, slot), &new) in br.storeys.iter().zip(k) {
            match slot {
                Slot::Ground(j) => group.stiffness[j] += new,
                Slot::Coupling(c) => group.terms_mut().couplings[c].2 = new,
            }
        }
        let found = motion(
            &group.mass,
            &group.stiffness,
            &group.damping,
            group.couplings(),
            &br.terms,
            &br.names,
        );
        group.branching = Some(br);
        let (propagator, harmonic, rate) = found?;
        group.terms_mut().harmonic = harmonic;
        group.rate = rate;
        group.propagator = propagator;
        Self::dress(group, record_step);
        Ok(())
    }
}
