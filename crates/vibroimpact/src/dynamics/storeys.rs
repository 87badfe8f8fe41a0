//! The hysteretic storeys in the equations of motion (docs/theory.md §11).
//!
//! A Bouc–Wen storey integrates its hysteretic drift z and the work e of
//! its hysteretic part with the state: (z, e) after the bodies' (u, v).
//! A bilinear storey carries its branch as memory instead, as a contact
//! carries its onset velocity: elastic through an anchor, z = z₀ + d − d₀,
//! or plastic at z = ±u_y, with the work of its hysteretic part at the
//! branch's start (so the work is exact: ½ (1 − b) k (z² − z₀²) along an
//! elastic branch, (1 − b) k z (d − d₀) along a plastic one). Within a step
//! its force is then linear in the drift; the run locates a switch (yield: |z| reaches u_y; unloading: ḋ
//! turns against z) on the step's dense output, takes the step again up to
//! it and switches the branch there ([`StoreyTerms::switch_value`],
//! [`StoreyTerms::switch`]).

use crate::model::hysteresis::imk::ImkState;
use crate::model::hysteresis::{Hysteretic, StoreyLaw};
use crate::model::Storey;

/// How far past the yield drift (relative) the elastic branch may go
/// before a switch counts: a switch just located (ḋ = 0 to the last bits)
/// does not switch back at once.
const YIELD_SLACK: f64 = 1e-10;

/// A bilinear storey's branch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Branch {
    /// z = z₀ + d − d₀.
    Elastic {
        /// The drift at the anchor.
        d0: f64,
        /// z there.
        z0: f64,
        /// The hysteretic part's work there (J).
        e0: f64,
    },
    /// z held at ±u_y while the drift goes on outwards.
    Plastic {
        /// ±u_y.
        z: f64,
        /// The drift where it yielded.
        d0: f64,
        /// The hysteretic part's work there (J).
        e0: f64,
    },
    /// An IMK storey's state at its last event: the force is linear in the
    /// drift from there ([`crate::model::hysteresis::imk::Imk::piece_force`]).
    Imk(ImkState),
}

/// One storey's term.
#[derive(Clone, Debug)]
struct Term {
    below: Option<usize>,
    above: usize,
    law: StoreyLaw,
    /// The P-Δ geometric stiffness P/h (N/m).
    p_delta: f64,
    /// The branch of a bilinear storey.
    branch: Branch,
    /// Where a Bouc–Wen storey's (z, e) sit in the state.
    state: Option<usize>,
}

/// The hysteretic storeys of a model, as the equations of motion use them.
#[derive(Clone, Debug, Default)]
pub struct StoreyTerms {
    terms: Vec<Term>,
    /// The storeys that switch branches (bilinear and IMK), in order: the
    /// exact run asks at every piece (a filter over the laws there cost
    /// 0.45 % of the IMK frame's run).
    switching: Vec<usize>,
    states: usize,
    /// Changes whenever a branch does (unique over the process: a copy
    /// has its original's, any change a new one), so that what was
    /// computed from the branches can be kept while the stamp holds.
    stamp: u64,
}

/// A stamp no branches had before.
fn new_stamp() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

impl StoreyTerms {
    /// The terms of `storeys`; a Bouc–Wen storey's state from index
    /// `first_state` on (two each); every bilinear storey elastic from
    /// rest at the initial drifts of `u0` (displacements, body order).
    pub fn new(storeys: &[Storey], first_state: usize, u0: &[f64]) -> Self {
        let mut states = 0;
        let terms = storeys
            .iter()
            .map(|s| {
                let d0 = u0[s.above] - s.below.map_or(0.0, |b| u0[b]);
                let state = matches!(s.law, StoreyLaw::BoucWen(_)).then(|| {
                    states += 2;
                    first_state + states - 2
                });
                // An IMK storey starts from rest at zero drift, pushed
                // monotonically to the initial drift.
                let branch = match s.law {
                    StoreyLaw::Imk(m) => {
                        let mut st = m.rest();
                        m.advance(&mut st, d0);
                        Branch::Imk(st)
                    }
                    _ => Branch::Elastic {
                        d0,
                        z0: 0.0,
                        e0: 0.0,
                    },
                };
                Term {
                    below: s.below,
                    above: s.above,
                    law: s.law,
                    p_delta: s.p_delta,
                    branch,
                    state,
                }
            })
            .collect::<Vec<Term>>();
        let switching = (0..terms.len())
            .filter(|&k| matches!(terms[k].law, StoreyLaw::Bilinear(_) | StoreyLaw::Imk(_)))
            .collect();
        Self {
            terms,
            switching,
            states,
            stamp: new_stamp(),
        }
    }

    /// The branches' stamp: equal stamps, equal branches.
    pub fn stamp(&self) -> u64 {
        self.stamp
    }

    /// How many storeys.
    pub fn len(&self) -> usize {
        self.terms.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.terms.is_empty()
    }

    /// How many states the Bouc–Wen storeys add.
    pub fn states(&self) -> usize {
        self.states
    }

    /// Whether any storey integrates a state (then the Jacobian is dense).
    pub fn integrated(&self) -> bool {
        self.states > 0
    }

    /// The farthest apart two bodies a storey joins (for the bandwidth).
    pub fn reach(&self) -> usize {
        self.terms
            .iter()
            .filter_map(|t| t.below.map(|b| b.abs_diff(t.above)))
            .max()
            .unwrap_or(0)
    }

    /// Storey k's drift and drift rate in the interleaved state `y`.
    #[inline]
    pub(crate) fn drift(&self, k: usize, y: &[f64]) -> (f64, f64) {
        let t = &self.terms[k];
        let (u, v) = (y[2 * t.above], y[2 * t.above + 1]);
        match t.below {
            Some(b) => (u - y[2 * b], v - y[2 * b + 1]),
            None => (u, v),
        }
    }

    /// Storey k's hysteretic state in the state `y` (z and the work of its
    /// hysteretic part; zero for an elastic storey).
    pub fn state(&self, k: usize, y: &[f64]) -> Hysteretic {
        let (d, _) = self.drift(k, y);
        self.hysteretic(k, d, y)
    }

    /// Storey k's hysteretic state at drift `d` in `y`.
    fn hysteretic(&self, k: usize, d: f64, y: &[f64]) -> Hysteretic {
        let t = &self.terms[k];
        let kh = match t.law {
            StoreyLaw::Bilinear(b) => (1.0 - b.post_yield_ratio) * b.stiffness,
            _ => 0.0,
        };
        match (t.state, &t.branch) {
            (Some(i), _) => Hysteretic {
                z: y[i],
                work: y[i + 1],
            },
            (None, &Branch::Elastic { d0, z0, e0 }) => {
                let z = z0 + d - d0;
                Hysteretic {
                    z,
                    work: e0 + 0.5 * kh * (z * z - z0 * z0),
                }
            }
            (None, &Branch::Plastic { z, d0, e0 }) => Hysteretic {
                z,
                work: e0 + kh * z * (d - d0),
            },
            // (An IMK storey's memory is its state; z is not used.)
            (None, Branch::Imk(_)) => Hysteretic::default(),
        }
    }

    /// Storey k's law force at drift `d` in `y` (an IMK storey's from its
    /// state).
    #[inline]
    fn law_force(&self, k: usize, d: f64, y: &[f64]) -> f64 {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => m.piece_force(st, d),
            _ => t.law.force(d, self.hysteretic(k, d, y)),
        }
    }

    /// The energy storey k has dissipated by hysteresis in `y`.
    pub fn dissipated_by(&self, k: usize, y: &[f64]) -> f64 {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => {
                let (d, _) = self.drift(k, y);
                m.piece_work(st, d) - m.piece_stored(st, d)
            }
            _ => t.law.dissipated(self.state(k, y)),
        }
    }

    /// Storey k's force F(d, z) in the state `y` (N): its law's, without
    /// the P-Δ shear.
    pub fn force(&self, k: usize, y: &[f64]) -> f64 {
        let (d, _) = self.drift(k, y);
        self.law_force(k, d, y)
    }

    /// The energy the storeys store in `y`: ½ b k d² + ½ (1 − b) k z² each
    /// (½ k d² for an elastic one), less the P-Δ loads' ½ (P/h) d² (the
    /// work the gravity loads did as the storey drifted).
    pub fn stored_energy(&self, y: &[f64]) -> f64 {
        (0..self.terms.len())
            .map(|k| {
                let (d, _) = self.drift(k, y);
                let t = &self.terms[k];
                let stored = match (&t.law, &t.branch) {
                    (StoreyLaw::Imk(m), Branch::Imk(st)) => m.piece_stored(st, d),
                    _ => t.law.stored(d, self.hysteretic(k, d, y)),
                };
                stored - 0.5 * t.p_delta * d * d
            })
            .sum()
    }

    /// The energy the storeys have dissipated by hysteresis in `y`.
    pub fn dissipated(&self, y: &[f64]) -> f64 {
        (0..self.terms.len())
            .map(|k| self.dissipated_by(k, y))
            .sum()
    }

    /// Adds every storey's force to the bodies' `force` and writes the
    /// Bouc–Wen states' rates into `dydt`.
    pub fn apply(&self, y: &[f64], force: &mut [f64], dydt: &mut [f64]) {
        for (k, t) in self.terms.iter().enumerate() {
            let (d, dd) = self.drift(k, y);
            let f = self.law_force(k, d, y) - t.p_delta * d;
            force[t.above] -= f;
            if let Some(b) = t.below {
                force[b] += f;
            }
            if let (Some(i), StoreyLaw::BoucWen(w)) = (t.state, &t.law) {
                let s = self.hysteretic(k, d, y);
                let (dz, de) = w.slope(s, dd);
                dydt[i] = dd * dz;
                dydt[i + 1] = dd * de;
            }
        }
    }

    /// The storeys whose branch switches (bilinear and IMK).
    pub fn switching(&self) -> impl Iterator<Item = usize> + '_ {
        self.switching.iter().copied()
    }

    /// Storey k's switch function in `y`: positive while its branch
    /// holds, zero where it switches (a bilinear storey: yield from the
    /// elastic branch, unloading from the plastic one; an IMK storey:
    /// [`Imk::switch_value`](crate::model::hysteresis::imk::Imk::switch_value)).
    pub fn switch_value(&self, k: usize, y: &[f64]) -> f64 {
        let (drift, rate) = self.switch_parts(k, y);
        drift.min(rate)
    }

    /// Storey k's switch function ([`StoreyTerms::switch_value`]) in two
    /// parts, whose least it is: the terms in the drift, and those in its
    /// rate (a reversal's; ∞ where none).
    pub fn switch_parts(&self, k: usize, y: &[f64]) -> (f64, f64) {
        let t = &self.terms[k];
        let (d, dd) = self.drift(k, y);
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => m.switch_parts(st, d, dd),
            (StoreyLaw::Bilinear(b), Branch::Elastic { d0, z0, .. }) => (
                b.yield_drift * (1.0 + YIELD_SLACK) - (z0 + d - d0).abs(),
                f64::INFINITY,
            ),
            (StoreyLaw::Bilinear(_), Branch::Plastic { z, .. }) => (f64::INFINITY, dd * z.signum()),
            _ => (1.0, f64::INFINITY),
        }
    }

    /// Bounds on how fast storey k's two [`StoreyTerms::switch_parts`]
    /// change over a step of length `h` between the states `y0` and `y1`
    /// with derivatives `f0` and `f1`: its drift's speed is bounded by the
    /// larger end speed plus half a step at the acceleration bound A, A
    /// the larger end acceleration plus their difference (a step is short
    /// against the motion's periods: its acceleration barely turns). A
    /// step where each part stays, by its bound, further from zero than it
    /// can move needs no look inside.
    pub fn switch_rate_bounds(
        &self,
        k: usize,
        (y0, f0): (&[f64], &[f64]),
        (y1, f1): (&[f64], &[f64]),
        h: f64,
    ) -> (f64, f64) {
        let ((_, v0), (_, v1)) = (self.drift(k, y0), self.drift(k, y1));
        let ((_, a0), (_, a1)) = (self.drift(k, f0), self.drift(k, f1));
        let acceleration = a0.abs().max(a1.abs()) + (a1 - a0).abs();
        let speed = v0.abs().max(v1.abs()) + 0.5 * acceleration * h;
        self.switch_rate_bounds_for(k, speed, acceleration)
    }

    /// Bounds on how fast storey k's two [`StoreyTerms::switch_parts`]
    /// change while its drift moves no faster than `speed` and its rate
    /// changes no faster than `acceleration`.
    pub fn switch_rate_bounds_for(&self, k: usize, speed: f64, acceleration: f64) -> (f64, f64) {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => m.switch_rate_bounds(st, speed, acceleration),
            _ => (speed, acceleration),
        }
    }

    /// Whether, while its drift moves one way, storey k's drift terms
    /// ([`StoreyTerms::switch_parts`]' first) are each least at an end of
    /// every interval of it on its current piece: a bilinear storey's
    /// (|z| against its yield drift, a minimum of two lines); an IMK
    /// storey's as its law's `drift_terms_least_at_ends` says.
    pub fn drift_terms_least_at_ends(&self, k: usize) -> bool {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => m.drift_terms_least_at_ends(st),
            _ => true,
        }
    }

    /// Switches bilinear storey k's branch in the state `y` where its
    /// switch function vanished.
    pub fn switch(&mut self, k: usize, y: &[f64]) {
        self.stamp = new_stamp();
        let (d, dd) = self.drift(k, y);
        if let (StoreyLaw::Imk(m), Branch::Imk(mut st)) = (self.terms[k].law, self.terms[k].branch)
        {
            m.switch(&mut st, d, dd);
            self.terms[k].branch = Branch::Imk(st);
            return;
        }
        let s = self.hysteretic(k, d, y);
        let t = &mut self.terms[k];
        let StoreyLaw::Bilinear(b) = t.law else {
            return;
        };
        t.branch = match t.branch {
            Branch::Elastic { .. } => Branch::Plastic {
                z: b.yield_drift.copysign(s.z),
                d0: d,
                e0: s.work,
            },
            Branch::Plastic { z, .. } => Branch::Elastic {
                d0: d,
                z0: z,
                e0: s.work,
            },
            other => other,
        };
    }

    /// Bilinear storey k's branch.
    pub fn branch(&self, k: usize) -> Branch {
        self.terms[k].branch
    }

    /// Sets bilinear storey k's branch (carried from another run's terms).
    pub fn set_branch(&mut self, k: usize, branch: Branch) {
        if self.terms[k].branch != branch {
            self.stamp = new_stamp();
            self.terms[k].branch = branch;
        }
    }

    /// Where storey k's Bouc–Wen state (z, e) sits in the state, if it has
    /// one.
    pub fn state_index(&self, k: usize) -> Option<usize> {
        self.terms[k].state
    }

    /// Storey k's bodies: (below, or None for the ground; above).
    pub fn ends(&self, k: usize) -> (Option<usize>, usize) {
        (self.terms[k].below, self.terms[k].above)
    }

    /// Storey k's P-Δ geometric stiffness P/h (N/m; 0: none).
    pub fn p_delta(&self, k: usize) -> f64 {
        self.terms[k].p_delta
    }

    /// Storey k on a linear branch, F = k_b d + F₀ (the P-Δ shear −(P/h) d
    /// beside it): returns (k_b, F₀). An elastic law's is (k, 0); a
    /// bilinear storey's elastic branch (k, (1 − b) k (z₀ − d₀)), its
    /// plastic branch (b k, (1 − b) k z) with z = ±u_y. None for Bouc–Wen
    /// and IMK, whose force is not linear in the drift between events
    /// that the local integrator knows.
    pub fn linear_branch(&self, k: usize) -> Option<(f64, f64)> {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Elastic { .. }, _) => Some((t.law.initial_stiffness(), 0.0)),
            (StoreyLaw::Bilinear(b), Branch::Elastic { d0, z0, .. }) => Some((
                b.stiffness,
                (1.0 - b.post_yield_ratio) * b.stiffness * (z0 - d0),
            )),
            (StoreyLaw::Bilinear(b), Branch::Plastic { z, .. }) => Some((
                b.post_yield_ratio * b.stiffness,
                (1.0 - b.post_yield_ratio) * b.stiffness * z,
            )),
            _ => None,
        }
    }

    /// Storey k's force on its current piece, F = k_b d + F₀ (the P-Δ
    /// shear beside it), as [`StoreyTerms::linear_branch`] gives it, and
    /// also an IMK storey's, whose force is linear in the drift between
    /// its events ([`Imk::piece_force`](crate::model::hysteresis::imk::Imk::piece_force)):
    /// (k_b, F₀). None for Bouc–Wen.
    pub fn piece(&self, k: usize) -> Option<(f64, f64)> {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Imk(m), Branch::Imk(st)) => Some(m.piece_line(st)),
            _ => self.linear_branch(k),
        }
    }

    /// The sign of a bilinear storey k's plastic branch (+1 yielding
    /// towards +u_y, −1 towards −u_y); None on another branch.
    pub fn plastic_sign(&self, k: usize) -> Option<f64> {
        match (&self.terms[k].law, &self.terms[k].branch) {
            (StoreyLaw::Bilinear(_), Branch::Plastic { z, .. }) => Some(z.signum()),
            _ => None,
        }
    }

    /// The drifts between which storey k stays on its linear branch, shrunk
    /// by `margin` of its yield drift at both ends (unbounded for an
    /// elastic law); None off an elastic branch.
    pub fn linear_window(&self, k: usize, margin: f64) -> Option<(f64, f64)> {
        let t = &self.terms[k];
        match (&t.law, &t.branch) {
            (StoreyLaw::Elastic { .. }, _) => Some((f64::NEG_INFINITY, f64::INFINITY)),
            (StoreyLaw::Bilinear(b), Branch::Elastic { d0, z0, .. }) => {
                let reach = b.yield_drift * (1.0 - margin);
                Some((d0 - z0 - reach, d0 - z0 + reach))
            }
            _ => None,
        }
    }
}
