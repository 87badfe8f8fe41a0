//! The equations of motion of a [`Model`] as a first-order ODE
//! (docs/theory.md §4), for the integrators.
//!
//! ## Files
//! - `mod.rs` — [`ChainDynamics`]: its terms, contact screens, energy
//!   audit;
//! - `rhs.rs` — the right-hand side: the bodies' forces, the storeys' and
//!   the screened contacts';
//! - `jacobian.rs` — the analytic Jacobian and its record for tangent
//!   replay;
//! - `storeys.rs` — the hysteretic storeys' terms and states;
//! - `state.rs` — the state layout: interleaving, a model's state length
//!   and initial state;
//! - `linear.rs` — the linear form of a chain whose contacts are rigid;
//! - `saltation.rs` — the saltation matrix of a rigid impact;
//! - `episodes.rs` — a rigid contact's soft episodes;
//! - `variational.rs` — the variational equations (sensitivities,
//!   monodromy matrices, docs/theory.md §5);
//! - `tests.rs` — the checks.
//!
//! ## State layout
//! Interleaved, `y = [u_1, v_1, u_2, v_2, …, u_N, v_N]`, so that a chain whose
//! couplings and contacts join bodies at most `d` apart has a banded
//! Jacobian with lower/upper bandwidths `(2d + 1, 2d)` (`(1, 1)` without
//! couplings). The Bouc–Wen storeys' states follow (`storeys.rs`);
//! with the energy audit on, three quadratures come last:
//! `W` (work of the excitation), `D_c` (dissipation of the dampers) and
//! `D_k` (dissipation of the contacts), so that
//! `E(t) + D_c + D_k + D_h - W = E(0)` with the mechanical energy
//! `E = Σ ½ m v² + Σ ½ k u² + Σ ½ k_ij Δu² + Σ P_contact(s) + Σ E_s`
//! (see [`ContactLaw::potential`]), `E_s` what a hysteretic storey stores
//! and `D_h` what it has dissipated, both from its state
//! ([`StoreyLaw::stored`](crate::model::hysteresis::StoreyLaw::stored),
//! [`StoreyLaw::dissipated`](crate::model::hysteresis::StoreyLaw::dissipated)).
//!
//! ## Contacts far apart are not evaluated
//! Each right-hand side skips a contact whose force is certainly below
//! `1e-3 ε` (ε = f64::EPSILON) of its force scale `F_ref` (the smaller of
//! the two bodies' `k g + m max|z̈|`; `a` when that is zero), i.e. far below
//! rounding of the other forces on those bodies: for the exponential law
//! when `α s + ln a + b|ṡ|/a < ln(1e-3 ε F_ref)` (a bound of
//! `ln((a + b|ṡ|) e^{αs})` that needs no exp or ln), for laws with compact
//! support when `s <= 0`. For the seed's row (R2) this skips a contact while
//! its gap exceeds about 0.36 mm, so the cost of a right-hand side grows with
//! the number of contacts actually closing, and linearly with N.

use std::sync::Arc;

use crate::contact::{ContactForce, ContactLaw, LawKind};
use crate::dynamics::variational::Variational;
use crate::impact::rigid::RigidLaw;
use crate::integrate::{BandMatrix, LinearForm, OdeSystem, Recorder};
use crate::model::{BaseExcitation, Model};

mod episodes;
mod jacobian;
mod linear;
mod rhs;
pub mod saltation;
mod state;
mod storeys;
pub mod variational;
pub use linear::{Added, FixedChain, PiecewiseForm};
pub use state::{from_interleaved, interleaved_index, to_interleaved};
pub use storeys::{Branch, StoreyTerms};

/// The contacts `start..end` that join a chain's neighbours (`0..0`
/// without one).
fn chain_range(sc: &ScreenSoA, n: usize) -> (usize, usize) {
    match sc.chain {
        Some(fp) => (fp, fp + n - 1),
        None => (0, 0),
    }
}

/// How a contact is screened before evaluation.
#[derive(Clone, Copy, Debug)]
enum Screen {
    /// Skip when `alpha s + b_over_a |ṡ| < limit`.
    Exponential {
        alpha: f64,
        b_over_a: f64,
        limit: f64,
    },
    /// Skip when `s <= 0`.
    CompactSupport,
    /// Always skip: rigid impacts.
    Never,
}

#[derive(Clone, Debug)]
struct ContactTerm {
    left: Option<usize>,
    right: Option<usize>,
    clearance: f64,
    law: ContactLaw,
    screen: Screen,
    absurd: f64,
    /// Rigid impacts (docs/theory.md §12): never evaluated; the run
    /// applies each impact as a velocity jump by this map.
    rigid: Option<Arc<RigidLaw>>,
    /// The law's own screen and absurd approach: a rigid contact's soft
    /// episode evaluates its law (`episodes.rs`).
    soft: (Screen, f64),
}

/// Equations of motion of a model, ready for an integrator.
#[derive(Clone, Debug)]
pub struct ChainDynamics {
    n: usize,
    mass: Vec<f64>,
    inv_mass: Vec<f64>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    couplings: Vec<(usize, usize, f64, f64)>,
    contacts: Vec<ContactTerm>,
    forces: Vec<(usize, f64, f64, f64)>,
    base: BaseExcitation,
    /// The record segment of the last right-hand side (a lookup hint).
    segment: usize,
    /// Onset approach velocity of each contact's current impact (read by
    /// laws that need it: Lankarani–Nikravesh).
    onset_velocity: Vec<f64>,
    energy: bool,
    force: Vec<f64>,
    contact_evaluations: u64,
    /// The contacts the last right-hand side evaluated, in its order, with
    /// their forces and partial derivatives (`jacobian.rs`).
    evaluated: Vec<(usize, ContactForce)>,
    /// Whether the right-hand side keeps `evaluated` (off where no
    /// Jacobian, tape or replay reads it after the right-hand side; those
    /// then evaluate the laws afresh).
    partials: bool,
    bandwidth: (usize, usize),
    screen: ScreenSoA,
    storeys: StoreyTerms,
}

/// Contact screening in structure-of-arrays form (the hot loop of every
/// right-hand side): `s = ml u_l - mr u_r - g`, `ṡ = ml v_l - mr v_r`, with
/// the masks `ml`, `mr` 0 for a wall side (index 0 then) and 1 otherwise;
/// contact k is evaluated only if `alpha s + boa |ṡ| >= limit` (exponential
/// law: see the module notes; compact support: alpha = 1, boa = 0,
/// limit = 0, i.e. `s >= 0`). Branch-free up to the final test.
#[derive(Clone, Debug, Default)]
struct ScreenSoA {
    /// Contact index of the pair (body 0, body 1) when the contacts between
    /// neighbours are stored consecutively (a chain: the row); then contact
    /// `first_pair + i` joins bodies i and i + 1 and the pair loop needs no
    /// index gathers.
    chain: Option<usize>,
    l: Vec<usize>,
    r: Vec<usize>,
    ml: Vec<f64>,
    mr: Vec<f64>,
    /// Per contact, the test's terms side by side, `[g, alpha, boa,
    /// limit]`: the pair loop walks one array (four had held one register
    /// too many in that loop: two reloads a pair).
    test: Vec<[f64; 4]>,
}

impl ChainDynamics {
    /// The dynamics of `model`; `energy` appends the three energy
    /// quadratures (after the storeys' states: [`Self::audit_index`]).
    pub fn new(model: &Model, energy: bool) -> Self {
        let bodies = model.bodies();
        let n = bodies.len();
        // (A rigid contact's law was checked when it was set:
        // Model::with_impacts.)
        let mut rigid_laws = model
            .rigid_laws()
            .unwrap_or_else(|_| {
                (0..model.contacts().len())
                    .map(|k| model.rigid_law(k).ok().flatten().map(Arc::new))
                    .collect()
            })
            .into_iter();
        let contacts = model
            .contacts()
            .iter()
            .enumerate()
            .map(|(k, c)| {
                let f_ref = model.contact_force_scale(k);
                let (screen, absurd) = match *c.law.kind() {
                    LawKind::Exponential { a, b, alpha } => {
                        let f_ref = f_ref.unwrap_or(a);
                        let limit = (1e-3 * f64::EPSILON * f_ref).ln() - a.ln();
                        // Beyond α s = 100 the force exceeds a e^100: no physical state.
                        (
                            Screen::Exponential {
                                alpha,
                                b_over_a: b / a,
                                limit,
                            },
                            100.0 / alpha,
                        )
                    }
                    _ => (Screen::CompactSupport, f64::INFINITY),
                };
                let rigid = rigid_laws.next().flatten();
                let soft = (screen, absurd);
                let (screen, absurd) = if rigid.is_some() {
                    (Screen::Never, f64::INFINITY)
                } else {
                    soft
                };
                ContactTerm {
                    left: c.pair.left(),
                    right: c.pair.right(),
                    clearance: c.clearance,
                    law: c.law,
                    screen,
                    absurd,
                    rigid,
                    soft,
                }
            })
            .collect::<Vec<_>>();
        // The storeys' states right after (u, v), the audit's quadratures
        // last: an error norm over the first components covers them.
        let storeys = StoreyTerms::new(model.storeys(), 2 * n, model.initial_displacement());
        let mut reach = storeys.reach();
        for c in model.couplings() {
            reach = reach.max(c.a.abs_diff(c.b));
        }
        for c in &contacts {
            if let (Some(l), Some(r)) = (c.left, c.right) {
                reach = reach.max(l.abs_diff(r));
            }
        }
        let bandwidth = if reach == 0 {
            (1, 1)
        } else {
            (2 * reach + 1, 2 * reach)
        };
        let mut screen = ScreenSoA::default();
        for c in &contacts {
            screen.l.push(c.left.unwrap_or(0));
            screen.r.push(c.right.unwrap_or(0));
            screen.ml.push(if c.left.is_some() { 1.0 } else { 0.0 });
            screen.mr.push(if c.right.is_some() { 1.0 } else { 0.0 });
            let (alpha, boa, limit) = c.screen.parts();
            screen.test.push([c.clearance, alpha, boa, limit]);
        }
        screen.chain = (n >= 2)
            .then(|| {
                contacts
                    .iter()
                    .position(|c| c.left == Some(0) && c.right == Some(1))
                    .filter(|&fp| {
                        fp + n - 1 <= contacts.len()
                            && (0..n - 1).all(|i| {
                                contacts[fp + i].left == Some(i)
                                    && contacts[fp + i].right == Some(i + 1)
                            })
                    })
            })
            .flatten();
        Self {
            n,
            mass: bodies.iter().map(|b| b.mass).collect(),
            inv_mass: bodies.iter().map(|b| 1.0 / b.mass).collect(),
            stiffness: bodies.iter().map(|b| b.stiffness).collect(),
            damping: bodies.iter().map(|b| b.damping).collect(),
            couplings: model
                .couplings()
                .iter()
                .map(|c| (c.a, c.b, c.stiffness, c.damping))
                .collect(),
            onset_velocity: vec![0.0; contacts.len()],
            contacts,
            // Gravity as a steady force −m g = −m g sin(0 t + π/2) per body.
            forces: model
                .forces()
                .iter()
                .map(|f| (f.body, f.amplitude, f.frequency, f.phase))
                .chain(
                    (0..model.bodies().len())
                        .filter(|_| model.gravity() != 0.0)
                        .map(|i| {
                            let weight = -model.bodies()[i].mass * model.gravity();
                            (i, weight, 0.0, std::f64::consts::FRAC_PI_2)
                        }),
                )
                .collect(),
            base: model.base().clone(),
            segment: 0,
            energy,
            force: vec![0.0; n],
            contact_evaluations: 0,
            evaluated: Vec::new(),
            partials: true,
            bandwidth,
            screen,
            storeys,
        }
    }

    /// Whether `other` screens and evaluates its contacts as this does (the
    /// same laws, gaps and screening limits: a copy in another forcing
    /// amplitude may screen with another force scale), so that its
    /// right-hand side may replay this one's ([`OdeSystem::rhs_reforced`]).
    pub fn same_contact_terms(&self, other: &ChainDynamics) -> bool {
        let (a, b) = (&self.screen, &other.screen);
        (a.chain, &a.l, &a.r, &a.ml, &a.mr, &a.test) == (b.chain, &b.l, &b.r, &b.ml, &b.mr, &b.test)
            && self.contacts.len() == other.contacts.len()
            && self
                .contacts
                .iter()
                .zip(&other.contacts)
                .all(|(p, q)| p.law == q.law)
    }

    /// Number of bodies.
    pub fn bodies(&self) -> usize {
        self.n
    }

    /// Dimension of the mechanical state (2N).
    pub fn state_dim(&self) -> usize {
        2 * self.n
    }

    /// Lower and upper bandwidths of the mechanical Jacobian.
    pub fn bandwidth(&self) -> (usize, usize) {
        self.bandwidth
    }

    /// This system with a right-hand side that does not keep its
    /// contacts' partial derivatives: for an integration that never asks
    /// for a Jacobian after it (an explicit method, no tangent columns,
    /// no tape). Results are unchanged; a Jacobian, tape record or replay
    /// from it then evaluates the laws afresh.
    pub fn without_partials(mut self) -> Self {
        self.partials = false;
        self.evaluated.clear();
        self
    }

    /// Contact law evaluations so far (skipped contacts not counted).
    pub fn contact_evaluations(&self) -> u64 {
        self.contact_evaluations
    }

    /// The hysteretic storeys.
    pub fn storeys(&self) -> &StoreyTerms {
        &self.storeys
    }

    /// The hysteretic storeys, to switch a bilinear storey's branch.
    pub fn storeys_mut(&mut self) -> &mut StoreyTerms {
        &mut self.storeys
    }

    /// The onset approach velocity of contact k's current impact.
    pub fn onset_velocity(&self, k: usize) -> f64 {
        self.onset_velocity[k]
    }

    /// Sets the onset approach velocity of contact k's current impact.
    pub fn set_onset_velocity(&mut self, k: usize, v: f64) {
        self.onset_velocity[k] = v;
    }

    /// Where the energy quadratures begin in the state (after the bodies'
    /// (u, v) and the storeys' states).
    pub fn audit_index(&self) -> usize {
        2 * self.n + self.storeys.states()
    }

    /// Approach coordinate and its rate of contact k in state y.
    #[inline]
    pub fn approach(&self, k: usize, y: &[f64]) -> (f64, f64) {
        let c = &self.contacts[k];
        let (ul, vl) = c.left.map_or((0.0, 0.0), |l| (y[2 * l], y[2 * l + 1]));
        let (ur, vr) = c.right.map_or((0.0, 0.0), |r| (y[2 * r], y[2 * r + 1]));
        (ul - ur - c.clearance, vl - vr)
    }

    /// State indices of (u_l, v_l, u_r, v_r) of contact k (None for walls).
    pub fn contact_indices(&self, k: usize) -> [Option<usize>; 4] {
        let c = &self.contacts[k];
        [
            c.left.map(|l| 2 * l),
            c.left.map(|l| 2 * l + 1),
            c.right.map(|r| 2 * r),
            c.right.map(|r| 2 * r + 1),
        ]
    }

    /// Body i's mass (kg).
    pub fn mass(&self, i: usize) -> f64 {
        self.mass[i]
    }

    /// Whether the state carries the energy audit's quadratures.
    pub fn audits_energy(&self) -> bool {
        self.energy
    }

    /// Contact k's rigid impact map (None: its soft law is integrated).
    pub fn rigid_law(&self, k: usize) -> Option<&RigidLaw> {
        self.contacts[k].rigid.as_deref()
    }

    /// Force of contact k at approach s and rate ṡ (N), as used in the
    /// equations of motion.
    #[inline]
    pub fn contact_force(&self, k: usize, s: f64, sdot: f64) -> f64 {
        self.contacts[k].law.force(s, sdot, self.onset_velocity[k])
    }

    /// Contact k's force ([`contact_force`](Self::contact_force)) at (s, ṡ)
    /// and its rate dF/dt with s̈ (N/s), from one evaluation of its law.
    #[inline]
    pub fn contact_force_and_rate(&self, k: usize, s: f64, sdot: f64, sddot: f64) -> (f64, f64) {
        let c = self.contacts[k].law.eval(s, sdot, self.onset_velocity[k]);
        (c.force, c.d_ds * sdot + c.d_dsdot * sddot)
    }

    /// Clearance of contact k (m).
    pub fn clearance(&self, k: usize) -> f64 {
        self.contacts[k].clearance
    }

    /// The contact law of contact k.
    pub fn contact_law(&self, k: usize) -> &ContactLaw {
        &self.contacts[k].law
    }

    /// The ground's acceleration z̈(t) (m/s²).
    pub fn base_acceleration(&self, t: f64) -> f64 {
        self.base.at(t)
    }

    /// The part of the right-hand side that depends on time alone (the
    /// base acceleration and the harmonic forces, per unit mass) at `t`,
    /// in the interleaved state layout of the 2N mechanical components:
    /// `f(t, y) = f(0-forcing; y) + source(t)` there. The energy
    /// quadratures (with `energy`) are not covered: the input work's rate
    /// depends on the forcing and the state together.
    pub fn source(&self, t: f64, out: &mut [f64]) {
        let zdd = self.base.at(t);
        for i in 0..self.n {
            out[2 * i] = 0.0;
            out[2 * i + 1] = -zdd;
        }
        for &(body, p, w, phi) in &self.forces {
            out[2 * body + 1] += p * (w * t + phi).sin() * self.inv_mass[body];
        }
    }

    /// [`source`](Self::source) of the bodies `bodies` (ascending) alone,
    /// into `out` (resized to their interleaved state).
    pub fn source_of(&self, t: f64, bodies: &[usize], out: &mut Vec<f64>) {
        let zdd = self.base.at(t);
        out.clear();
        for _ in bodies {
            out.extend([0.0, -zdd]);
        }
        for &(body, p, w, phi) in &self.forces {
            if let Ok(j) = bodies.binary_search(&body) {
                out[2 * j + 1] += p * (w * t + phi).sin() * self.inv_mass[body];
            }
        }
    }

    /// Number of contacts.
    pub fn contacts(&self) -> usize {
        self.contacts.len()
    }

    /// The contacts not screened out at `y`, with their laws' force and
    /// partial derivatives there (for the Jacobian).
    fn evaluated_contacts<'a>(
        &'a self,
        y: &'a [f64],
    ) -> impl Iterator<Item = (usize, ContactForce)> + 'a {
        let sc = &self.screen;
        (0..sc.l.len()).filter_map(move |k| {
            let (s, sdot) = self.approach(k, y);
            let [_, alpha, boa, limit] = sc.test[k];
            if alpha * s + boa * sdot.abs() < limit {
                None
            } else {
                Some((
                    k,
                    self.contacts[k].law.eval(s, sdot, self.onset_velocity[k]),
                ))
            }
        })
    }

    /// Mechanical energy E (J) of state y (see the module notes).
    pub fn mechanical_energy(&self, y: &[f64]) -> f64 {
        let mut e = 0.0;
        for i in 0..self.n {
            let (u, v) = (y[2 * i], y[2 * i + 1]);
            e += 0.5 * self.mass[i] * v * v + 0.5 * self.stiffness[i] * u * u;
        }
        for &(a, b, k, _) in &self.couplings {
            let du = y[2 * b] - y[2 * a];
            e += 0.5 * k * du * du;
        }
        for (k, c) in self
            .contacts
            .iter()
            .enumerate()
            .filter(|(_, c)| !matches!(c.screen, Screen::Never))
        {
            let (s, _) = self.approach(k, y);
            e += c.law.potential(s);
        }
        e + self.storeys.stored_energy(y)
    }

    #[cfg(test)]
    fn skip(screen: Screen, s: f64, sdot: f64) -> bool {
        match screen {
            Screen::Exponential {
                alpha,
                b_over_a,
                limit,
            } => alpha * s + b_over_a * sdot.abs() < limit,
            Screen::CompactSupport => s <= 0.0,
            Screen::Never => true,
        }
    }
}

/// A system whose state begins with a row's interleaved `[u, v]`: the row
/// itself, or the row with carried columns ([`Variational`]), so that the
/// event scan of a step reads the row whichever is integrated.
pub trait Chain: OdeSystem {
    /// The row's dynamics.
    fn chain(&self) -> &ChainDynamics;
    /// The row's dynamics, mutably (an impact's onset velocity).
    fn chain_mut(&mut self) -> &mut ChainDynamics;
}

impl Chain for ChainDynamics {
    fn chain(&self) -> &ChainDynamics {
        self
    }

    fn chain_mut(&mut self) -> &mut ChainDynamics {
        self
    }
}

impl Chain for Variational<ChainDynamics> {
    fn chain(&self) -> &ChainDynamics {
        self.system()
    }

    fn chain_mut(&mut self) -> &mut ChainDynamics {
        self.system_mut()
    }
}

/// The local integrator's active set: a row with tangent columns, its
/// Jacobian recorded at every evaluation while a tangent tape is made.
pub(crate) type SetSystem = Variational<Recorder<ChainDynamics>>;

impl Chain for SetSystem {
    fn chain(&self) -> &ChainDynamics {
        self.system().system()
    }

    fn chain_mut(&mut self) -> &mut ChainDynamics {
        self.system_mut().system_mut()
    }
}

impl OdeSystem for ChainDynamics {
    fn dim(&self) -> usize {
        2 * self.n + if self.energy { 3 } else { 0 } + self.storeys.states()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.rhs_with(t, y, dydt, None);
    }

    fn linear_form(&self) -> Option<LinearForm> {
        self.linear_form_of()
    }

    fn rhs_reforced(&mut self, source: &Self, t: f64, y: &[f64], dydt: &mut [f64]) {
        // The energy audit's contact term is not kept, nor are contacts a
        // source without partials evaluated: evaluate.
        let replay = (!self.energy && source.partials).then_some(&source.evaluated[..]);
        self.rhs_with(t, y, dydt, replay);
    }

    fn jacobian_after_rhs(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        self.jacobian_from(y, jac, self.partials)
    }

    /// A body's displacement and velocity: the error of the bodies that
    /// move is not averaged with that of bodies at rest.
    fn error_block(&self) -> Option<usize> {
        Some(2)
    }

    /// Banded for the mechanical state; dense with the energy quadratures
    /// (their rows depend on every velocity).
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        (!self.energy && !self.storeys.integrated()).then_some(self.bandwidth)
    }

    /// Analytic ∂f/∂y: springs, dampers, couplings and every contact not
    /// screened out, with the laws' analytic partial derivatives. The energy
    /// quadratures' rows are left to finite differences (returns false then).
    fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        self.jacobian_from(y, jac, false)
    }
    fn admissible(&self, _t: f64, y: &[f64]) -> bool {
        self.contacts.iter().enumerate().all(|(k, c)| {
            let (s, _) = self.approach(k, y);
            s <= c.absurd
        })
    }
}

#[cfg(test)]
mod tests;
