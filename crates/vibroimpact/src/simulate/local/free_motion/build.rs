//! A model's groups and their free motions, built (docs/theory.md §10):
//! the spring-coupled groups by union–find, each group's couplings,
//! storeys and forces bucketed once, a lone body's closed form built
//! directly, every other group's propagator and steady states
//! (`branches.rs`), and under a record its modes and hold step.

use smallvec::smallvec;

use super::{bounds, branches, hold, Bodies, FreeMotion, FreeMotionError, Group, HoldStep, Modal};
use super::{Coupling, PerBody, Propagator, Terms, HOLD_ROWS};
use crate::model::{BaseExcitation, Body, Model};
use crate::simulate::local::lists::Lists;

/// The groups of `model`: the connected components of its couplings and
/// storeys (union–find), as each body's (group, index in the group) and each
/// group's bodies (ascending), groups in the order of their first body.
pub(crate) fn spring_groups(model: &Model) -> (Vec<(usize, usize)>, Vec<Bodies>) {
    let n = model.bodies().len();
    let mut root: Vec<usize> = (0..n).collect();
    fn find(root: &mut [usize], mut i: usize) -> usize {
        while root[i] != i {
            root[i] = root[root[i]];
            i = root[i];
        }
        i
    }
    let storeys = model
        .storeys()
        .iter()
        .filter_map(|s| Some((s.below?, s.above)));
    for (p, q) in model.couplings().iter().map(|c| (c.a, c.b)).chain(storeys) {
        let (a, b) = (find(&mut root, p), find(&mut root, q));
        root[a.max(b)] = a.min(b);
    }
    let mut place = vec![(usize::MAX, 0); n];
    let mut members: Vec<Bodies> = Vec::new();
    for i in 0..n {
        let r = find(&mut root, i);
        if place[r].0 == usize::MAX {
            place[r] = (members.len(), 0);
            members.push(Bodies::new());
        }
        let g = place[r].0;
        place[i] = (g, members[g].len());
        members[g].push(i);
    }
    (place, members)
}

/// Per group, the model's couplings (by their first body), storeys (by
/// the body above) and harmonic forces in it.
#[derive(Clone, Debug)]
pub(super) struct Parts {
    pub(super) couplings: Lists,
    pub(super) storeys: Lists,
    pub(super) forces: Lists,
}

impl Parts {
    /// Whether group `g` has no couplings, storeys or forces.
    fn is_empty(&self, g: usize) -> bool {
        self.couplings[g].is_empty() && self.storeys[g].is_empty() && self.forces[g].is_empty()
    }
}

impl FreeMotion {
    /// The groups of `model` and their propagators. Errors for an undamped
    /// group in resonance with a harmonic forcing term.
    pub fn new(model: &Model) -> Result<Self, FreeMotionError> {
        let (place, members) = spring_groups(model);
        let ng = members.len();
        let parts = Parts {
            couplings: Lists::new(
                ng,
                (model.couplings().iter().enumerate()).map(|(i, c)| (place[c.a].0, i)),
            ),
            storeys: Lists::new(
                ng,
                (model.storeys().iter().enumerate()).map(|(i, s)| (place[s.above].0, i)),
            ),
            forces: Lists::new(
                ng,
                (model.forces().iter().enumerate()).map(|(i, f)| (place[f.body].0, i)),
            ),
        };
        let unforced = match model.base() {
            BaseExcitation::Harmonic { amplitude, .. } => *amplitude == 0.0,
            _ => true,
        };
        let lone = |g: usize, bodies: &Bodies| bodies.len() == 1 && unforced && parts.is_empty(g);
        let mut groups: Vec<Group> = if (members.iter().enumerate()).all(|(g, b)| lone(g, b)) {
            // (A row of lone bodies: built in place, without a `Result`
            // between, which costs a copy of each group.)
            (members.into_iter())
                .map(|bodies| {
                    let body = &model.bodies()[bodies[0]];
                    Group::single(bodies, body)
                })
                .collect()
        } else {
            let mut groups = Vec::with_capacity(ng);
            for (g, bodies) in members.into_iter().enumerate() {
                groups.push(if lone(g, &bodies) {
                    let body = &model.bodies()[bodies[0]];
                    Group::single(bodies, body)
                } else {
                    Self::group(model, &place, bodies, &parts, g)?
                });
            }
            groups
        };
        let record_step = match model.base() {
            BaseExcitation::Record(rec) => Some(hold::typical_step(rec.times())),
            _ => None,
        };
        for g in &mut groups {
            Self::dress(g, record_step);
        }
        Ok(Self {
            groups,
            parts,
            place,
            base: model.base().clone(),
            peaks: bounds::Peaks::new(model.base()),
            record_step: record_step.flatten(),
        })
    }

    /// Gives group `g` its modes and its whole sample step's matrix, under
    /// a record sampled every `record_step` (Some(None): not uniformly).
    pub(super) fn dress(g: &mut Group, record_step: Option<Option<f64>>) {
        g.modal = None;
        if let Some(t) = g.terms.as_deref_mut() {
            t.hold_step = None;
        }
        if record_step.is_some() || matches!(g.propagator, Propagator::Group(_)) {
            g.modal = Modal::new(&Self::matrix(g), record_step.flatten()).map(Box::new);
        }
        // The exact extrema's grid parts a whole step into pieces of at
        // most a sixteenth of the fastest period ([`FreeMotion::grid`]).
        if let (Some(modal), Some(Some(tau))) = (g.modal.as_mut(), record_step) {
            let parts = (tau / Self::natural_piece(g.rate)).ceil();
            if (2.0..=1e3).contains(&parts) {
                modal.keep_part(tau / parts);
            }
        }
        // Without modes every whole step, with modes the short runs of a
        // few (samples, checks a step apart) take the matrix form.
        let small = 2 * g.bodies.len() <= HOLD_ROWS;
        if let (true, Some(Some(tau))) = (g.modal.is_none() || small, record_step) {
            let (phi, g0, g1) = hold::matrices(&Self::matrix(g), tau);
            g.terms_mut().hold_step = Some(Box::new(HoldStep { tau, phi, g0, g1 }));
        }
    }

    fn group(
        model: &Model,
        place: &[(usize, usize)],
        bodies: Bodies,
        parts: &Parts,
        here: usize,
    ) -> Result<Group, FreeMotionError> {
        let m = bodies.len();
        let all = model.bodies();
        let mass: PerBody = bodies.iter().map(|&i| all[i].mass).collect();
        let own_stiffness: PerBody = bodies.iter().map(|&i| all[i].stiffness).collect();
        let mut stiffness = own_stiffness.clone();
        let damping: PerBody = bodies.iter().map(|&i| all[i].damping).collect();
        let mut couplings: Vec<Coupling> = parts.couplings[here]
            .iter()
            .map(|&i| &model.couplings()[i])
            .map(|c| (place[c.a].1, place[c.b].1, c.stiffness, c.damping))
            .collect();
        // A storey is a spring of its initial stiffness less its P-Δ
        // stiffness (its constant force is the rest state's, `set_rest`);
        // another branch's stiffness replaces it there
        // (`set_storey_stiffness`).
        let mut storeys = Vec::new();
        let mut storey_stiffness = Vec::new();
        for &i in &parts.storeys[here] {
            let s = &model.storeys()[i];
            let k = s.law.initial_stiffness() - s.p_delta;
            let slot = match s.below {
                None => {
                    stiffness[place[s.above].1] += k;
                    branches::Slot::Ground(place[s.above].1)
                }
                Some(b) => {
                    couplings.push((place[b].1, place[s.above].1, k, 0.0));
                    branches::Slot::Coupling(couplings.len() - 1)
                }
            };
            storeys.push((i, slot));
            storey_stiffness.push(k);
        }
        // Harmonic terms b sin(Ω t + φ) (per unit mass, velocity rows); a
        // term of zero amplitude has the steady state zero, and is left out.
        let mut terms: Vec<(f64, f64, Vec<f64>)> = Vec::new();
        if let BaseExcitation::Harmonic {
            amplitude,
            frequency,
            phase,
        } = *model.base()
        {
            if amplitude != 0.0 {
                let mut b = vec![0.0; 2 * m];
                for j in 0..m {
                    b[2 * j + 1] = -amplitude;
                }
                terms.push((frequency, phase, b));
            }
        }
        let mut force_amplitude = PerBody::from_elem(0.0, m);
        let mut forces = Vec::new();
        for &i in &parts.forces[here] {
            let f = &model.forces()[i];
            let j = place[f.body].1;
            let mut b = vec![0.0; 2 * m];
            b[2 * j + 1] = f.amplitude / mass[j];
            force_amplitude[j] += f.amplitude.abs();
            forces.push((j, f.amplitude, f.frequency, f.phase));
            if f.amplitude != 0.0 {
                terms.push((f.frequency, f.phase, b));
            }
        }
        // The names serve a resonance's error alone (none without terms).
        let names = if terms.is_empty() {
            String::new()
        } else {
            bodies
                .iter()
                .map(|&i| all[i].name.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let (propagator, harmonic, rate) =
            branches::motion(&mass, &stiffness, &damping, &couplings, &terms, &names)?;
        let extra = Terms {
            harmonic,
            couplings,
            force_amplitude,
            forces,
            ..Terms::none(m)
        };
        let none =
            extra.harmonic.is_empty() && extra.couplings.is_empty() && extra.forces.is_empty();
        Ok(Group {
            bodies,
            propagator,
            mass,
            stiffness,
            damping,
            rate,
            modal: None,
            terms: (!none).then(|| Box::new(extra)),
            branching: (!storeys.is_empty()).then(|| {
                Box::new(branches::Branching {
                    storeys,
                    stiffness: storey_stiffness,
                    terms,
                    own_stiffness,
                    names,
                    cache: Vec::new(),
                })
            }),
        })
    }
}

impl Group {
    /// A body alone (no couplings, storeys or forces, no harmonic base):
    /// its closed form, built without the general path's lists.
    fn single(bodies: Bodies, b: &Body) -> Self {
        let (w2, c2) = (b.stiffness / b.mass, b.damping / b.mass);
        Group {
            bodies,
            propagator: Propagator::Single { w2, c2 },
            mass: smallvec![b.mass],
            stiffness: smallvec![b.stiffness],
            damping: smallvec![b.damping],
            rate: w2.max(0.0).sqrt(),
            modal: None,
            terms: None,
            branching: None,
        }
    }
}
