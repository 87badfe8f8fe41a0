//! The local integrator (docs/theory.md §10): exact motion between
//! contacts, the step driver only where bodies touch.
//!
//! Every group of bodies joined by springs ([`FreeMotion`]) moves exactly
//! while none of its contacts is active. A contact becomes active where its
//! force stops being negligible at the run's tolerance (`s_act`, see
//! [`Activation`]); the groups it joins are then integrated, with every
//! other group that is integrated at that time, as one system of those
//! bodies alone (the *active set*, its own [`Stepper`] with the error norm
//! per body). A group leaves the set when all its contacts have separated
//! beyond `s_act` with a margin, and moves exactly again from the set's
//! state.
//!
//! Contacts between two exactly moving groups (or a group and a wall) are
//! never evaluated: each carries the time until which its gap provably
//! stays below `s_act` — from the gap, its rate and a bound on the sides'
//! accelerations over a horizon ([`crate::free_motion::Group`]'s energy
//! bound), `s(t₀ + τ) <= s₀ + ṡ₀ τ + C τ²` — and is checked again then
//! (an event queue in time order, ties by contact index). A grazing contact
//! cannot be missed: the bound holds over the whole interval. Contacts
//! between the set and an exactly moving group are followed on every step
//! of the set over its dense output; one that reaches `s_act` inside a
//! step sends the set back to the step's start, to be integrated to that
//! time exactly and the group joined there.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use super::*;
use crate::contact::LawKind;
use crate::free_motion::FreeMotion;
use crate::model::{Body, Contact, ContactPair, Coupling, HarmonicForce};

/// Work of the local integrator, beside the integrator's counters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalStats {
    /// Bound checks of contacts between exactly moving bodies.
    pub contact_checks: u64,
    /// Times the active set was formed or changed.
    pub set_changes: u64,
    /// Largest number of bodies integrated at once.
    pub largest_set: usize,
    /// Right-hand-side evaluations of each body (0: the body moved exactly
    /// for the whole run and was never evaluated).
    pub body_evaluations: Vec<u64>,
}

impl LocalStats {
    /// Number of bodies that were integrated at some time.
    pub fn bodies_integrated(&self) -> usize {
        self.body_evaluations.iter().filter(|&&e| e > 0).count()
    }
}

/// The gap at which a contact's force stops being negligible.
#[derive(Clone, Copy, Debug)]
enum Activation {
    /// Compact support, active at any positive approach (Kelvin–Voigt:
    /// its damping force acts from the first touch).
    Compact,
    /// `F <= k s^n (1 + factor |ṡ|)` for s > 0 (Hertz, Hunt–Crossley,
    /// Lankarani–Nikravesh): active where that bound exceeds `f_neg`, the
    /// force that changes the lighter of the contact's bodies' velocity by
    /// less than `atol` over the whole run.
    Power {
        k: f64,
        n: f64,
        factor: f64,
        f_neg: f64,
    },
    /// The exponential law `(a + b ṡ) e^{αs}`: active where
    /// `α s + (b/a)|ṡ| >= ln(F_neg/a)`, `F_neg = 1e-3 rtol F_ref`.
    Exponential { alpha: f64, boa: f64, limit: f64 },
}

impl Activation {
    fn new(model: &Model, k_index: usize, opts: &SimulationOptions, s_on: f64) -> Self {
        let rtol = opts.rtol;
        let c = &model.contacts()[k_index];
        match *c.law.kind() {
            LawKind::Exponential { a, b, alpha } => {
                let bodies = model.bodies();
                let peak = match model.base() {
                    BaseExcitation::None => 0.0,
                    BaseExcitation::Harmonic { amplitude, .. } => amplitude.abs(),
                    BaseExcitation::Record(r) => r.peak(),
                };
                let f_ref = [c.pair.left(), c.pair.right()]
                    .into_iter()
                    .flatten()
                    .map(|i| bodies[i].stiffness * c.clearance + bodies[i].mass * peak)
                    .fold(f64::INFINITY, f64::min);
                let f_ref = if f_ref > 0.0 && f_ref.is_finite() {
                    f_ref
                } else {
                    a
                };
                // Never later than the impact threshold.
                let limit = ((1e-3 * rtol * f_ref) / a).ln().min(alpha * s_on);
                Activation::Exponential {
                    alpha,
                    boa: b / a,
                    limit,
                }
            }
            LawKind::Hertz { k, n } => Self::power(model, k_index, (k, n, 0.0), opts),
            LawKind::HuntCrossley { k, n, chi } => Self::power(model, k_index, (k, n, chi), opts),
            LawKind::LankaraniNikravesh {
                k,
                n,
                restitution,
                min_impact_velocity,
            } => {
                let factor = 0.75 * (1.0 - restitution * restitution) / min_impact_velocity;
                Self::power(model, k_index, (k, n, factor), opts)
            }
            LawKind::KelvinVoigt { .. } => Activation::Compact,
        }
    }

    fn power(
        model: &Model,
        contact: usize,
        law: (f64, f64, f64),
        opts: &SimulationOptions,
    ) -> Self {
        let c = &model.contacts()[contact];
        let lighter = [c.pair.left(), c.pair.right()]
            .into_iter()
            .flatten()
            .map(|i| model.bodies()[i].mass)
            .fold(f64::INFINITY, f64::min);
        let (k, n, factor) = law;
        Activation::Power {
            k,
            n,
            factor,
            f_neg: lighter * opts.atol / opts.t_end,
        }
    }

    /// The largest gap that is surely inactive while |ṡ| <= `speed`.
    fn gap(&self, speed: f64) -> f64 {
        match *self {
            Activation::Compact => 0.0,
            Activation::Power {
                k,
                n,
                factor,
                f_neg,
            } => (f_neg / (k * (1.0 + factor * speed))).powf(1.0 / n),
            Activation::Exponential { alpha, boa, limit } => (limit - boa * speed) / alpha,
        }
    }

    /// Positive where the contact is active at (s, ṡ).
    fn margin(&self, s: f64, sdot: f64) -> f64 {
        match *self {
            Activation::Compact => s,
            Activation::Power { .. } => s - self.gap(sdot.abs()),
            Activation::Exponential { alpha, boa, limit } => s + (boa * sdot.abs() - limit) / alpha,
        }
    }
}

/// The largest `h <= h_max` (to a factor 2) with `impulse(h) <= limit`,
/// for an impulse that grows with `h`; `h_max` if it stays below.
fn first_step(impulse: impl Fn(f64) -> f64, limit: f64, h_max: f64) -> f64 {
    let mut h = h_max;
    // 60 halvings reach 1e-18 of the proposed step.
    for _ in 0..60 {
        if impulse(h) <= limit {
            return h;
        }
        h *= 0.5;
    }
    h
}

/// How far ahead a set looks before it lets a group move exactly again,
/// as a part of its fastest period (radians of its fastest rate).
const RELEASE_PERIOD_FRACTION: f64 = 0.05;

/// Total order on check times for the event queue.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Time(f64);
impl Eq for Time {}
impl PartialOrd for Time {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Time {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&o.0)
    }
}

/// The integrated bodies and their system.
struct ActiveSet {
    /// Groups in the set, ascending.
    groups: Vec<usize>,
    /// Bodies, ascending (the set's body j is model body `bodies[j]`).
    bodies: Vec<usize>,
    /// Model contacts joining the set to an exactly moving group: (contact,
    /// whether its left side is in the set).
    boundary: Vec<usize>,
    sys: ChainDynamics,
    st: Stepper,
    scan: StepScan,
    /// The set's state at the start of its last step.
    saved: (f64, Vec<f64>),
    /// The fastest natural or forcing rate of its groups (rad/s).
    rate: f64,
}

/// The local integrator's run.
struct Run<'a> {
    model: &'a Model,
    opts: &'a SimulationOptions,
    method: Method,
    free: FreeMotion,
    /// Per group: time and interleaved state of its exact motion.
    exact: Vec<(f64, Vec<f64>)>,
    /// Per group: in the active set.
    in_set: Vec<bool>,
    /// Per group: when it last joined the set.
    joined: Vec<f64>,
    /// While the set steps: checks do not move exact groups' reference
    /// states (samples and a step taken back still need earlier times);
    /// the moves wait in `deferred` (group, time, state).
    defer: bool,
    deferred: Vec<(usize, f64, Vec<f64>)>,
    /// Per body: index in the active set.
    slot: Vec<Option<usize>>,
    activation: Vec<Activation>,
    /// Per group: its contacts, couplings and harmonic forces (model
    /// indices, ascending).
    group_contacts: Vec<Vec<usize>>,
    group_couplings: Vec<Vec<usize>>,
    group_forces: Vec<Vec<usize>>,
    /// Per contact: the generation of its scheduled check (older queue
    /// entries are stale).
    generation: Vec<u64>,
    queue: BinaryHeap<Reverse<(Time, usize, u64)>>,
    set: Option<ActiveSet>,
    /// Per contact: the impact under way (index into `impacts`) and the
    /// onset velocity, while the contact is not in the set.
    impacts: Vec<ImpactRecord>,
    onset: Vec<(Option<usize>, f64)>,
    stats: Stats,
    contact_evaluations: u64,
    local: LocalStats,
    breakpoints: Vec<f64>,
}

/// Group of a contact's side, if a body.
fn side_groups(free: &FreeMotion, c: &Contact) -> [Option<usize>; 2] {
    [
        c.pair.left().map(|i| free.place(i).0),
        c.pair.right().map(|i| free.place(i).0),
    ]
}

impl Run<'_> {
    /// State (u, v) of body `i` moving exactly, at `t` (not before its
    /// group's reference time).
    fn exact_body(&self, i: usize, t: f64) -> (f64, f64) {
        let (g, j) = self.free.place(i);
        let (t0, x) = &self.exact[g];
        let mut x = x.clone();
        self.free.propagate(g, *t0, t, &mut x);
        (x[2 * j], x[2 * j + 1])
    }

    /// The time until which contact k (both sides moving exactly) surely
    /// stays inactive, from `t`; None: active now (or so soon that the
    /// bound cannot tell).
    fn safe_until(&mut self, k: usize, t: f64) -> Option<f64> {
        self.local.contact_checks += 1;
        let c = &self.model.contacts()[k];
        // The sides' groups at t. Inside a step of the set they only go into
        // `deferred`: samples and a step taken back still ask for earlier
        // times of these groups, and exact motion never runs backward.
        let mut at: Vec<(usize, Vec<f64>)> = Vec::with_capacity(2);
        for i in [c.pair.left(), c.pair.right()].into_iter().flatten() {
            let g = self.free.place(i).0;
            if at.iter().any(|(h, _)| *h == g) {
                continue;
            }
            let (t0, x) = &self.exact[g];
            let mut x = x.clone();
            self.free.propagate(g, *t0, t, &mut x);
            at.push((g, x));
        }
        let until = {
            let at = &at;
            let exact = &self.exact;
            self.bound(k, t, move |g| {
                at.iter()
                    .find(|(h, _)| *h == g)
                    .map_or(exact[g].1.as_slice(), |(_, x)| x.as_slice())
            })
        };
        for (g, x) in at {
            if self.defer {
                self.deferred.push((g, t, x));
            } else {
                self.exact[g] = (t, x);
            }
        }
        until
    }

    /// Moves the exact groups' reference states deferred during a step of
    /// the set up to `t` (the time everything has been sampled to).
    fn apply_deferred(&mut self, t: f64) {
        let mut later = Vec::new();
        for (g, tc, x) in std::mem::take(&mut self.deferred) {
            if tc > t {
                later.push((g, tc, x));
            } else if !self.in_set[g] && tc > self.exact[g].0 {
                self.exact[g] = (tc, x);
            }
        }
        self.deferred = later;
    }

    /// [`safe_until`](Self::safe_until) from the groups' interleaved states
    /// at `t` (`state(g)`), as if they moved exactly from there.
    fn bound<'s>(&self, k: usize, t: f64, state: impl Fn(usize) -> &'s [f64]) -> Option<f64> {
        let c = &self.model.contacts()[k];
        let remaining = self.opts.t_end - t;
        let sides = [c.pair.left(), c.pair.right()];
        let rate = sides
            .iter()
            .flatten()
            .map(|&i| self.free.groups()[self.free.place(i).0].rate())
            .fold(0.0f64, f64::max);
        // The bound is tightest over a short horizon (the energy may grow
        // with it): start at a quarter of the fastest period and double it
        // while the bound lasts the whole horizon (a stiff body whose
        // motion is tiny is safe for far longer than its period).
        let mut horizon = if rate > 0.0 {
            remaining.min(0.5 * std::f64::consts::PI / rate)
        } else {
            remaining
        };
        let floor = 1e-10 * horizon;
        loop {
            let tau = self.bound_over(c, k, horizon, &state)?;
            if tau < horizon || horizon >= remaining {
                return (tau > floor && t + tau > t).then_some(t + tau);
            }
            horizon = remaining.min(2.0 * horizon);
        }
    }

    /// The time within `horizon` until which contact `c` (index `k`) stays
    /// inactive by the bound from the sides' states; None: active now.
    fn bound_over<'s>(
        &self,
        c: &Contact,
        k: usize,
        horizon: f64,
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let (mut s0, mut sd0, mut acc) = (-c.clearance, 0.0, 0.0);
        // The rounding of s: a gap that close to activation and closing is
        // active (else checks would hover there at rounding-sized steps).
        let mut size = c.clearance;
        for (side, sign) in [c.pair.left(), c.pair.right()].into_iter().zip([1.0, -1.0]) {
            let Some(i) = side else { continue };
            let (g, j) = self.free.place(i);
            let x = state(g);
            size += x[2 * j].abs();
            s0 += sign * x[2 * j];
            sd0 += sign * x[2 * j + 1];
            let group = &self.free.groups()[g];
            let root = group.energy(x).sqrt() + group.growth() * horizon;
            acc += group.acceleration_bound(j, root * root);
        }
        if !(s0.is_finite() && sd0.is_finite() && acc.is_finite()) {
            return None;
        }
        let speed = sd0.abs() + acc * horizon;
        let d = self.activation[k].gap(speed) - s0;
        let (b, cq) = (sd0, 0.5 * acc);
        let tau = if d < 0.0 || (d <= 8.0 * f64::EPSILON * size && b > 0.0) {
            return None;
        } else if cq == 0.0 {
            if b <= 0.0 {
                f64::INFINITY
            } else {
                d / b
            }
        } else {
            let root = (b * b + 4.0 * cq * d).sqrt();
            if b > 0.0 {
                2.0 * d / (b + root)
            } else {
                (root - b) / (2.0 * cq)
            }
        };
        Some(tau.min(horizon))
    }

    /// Schedules contact k's next check (both sides exact) from `t`, or
    /// returns true if it is active now.
    fn schedule(&mut self, k: usize, t: f64) -> bool {
        self.generation[k] += 1;
        match self.safe_until(k, t) {
            None => true,
            Some(until) => {
                if until < self.opts.t_end {
                    self.queue
                        .push(Reverse((Time(until), k, self.generation[k])));
                }
                false
            }
        }
    }

    /// The next valid check, without removing it.
    fn next_check(&mut self) -> Option<(f64, usize)> {
        while let Some(&Reverse((Time(t), k, gen))) = self.queue.peek() {
            if gen == self.generation[k] {
                return Some((t, k));
            }
            self.queue.pop();
        }
        None
    }

    /// Whether contact k has a side in the active set.
    fn touches_set(&self, k: usize) -> bool {
        let c = &self.model.contacts()[k];
        [c.pair.left(), c.pair.right()]
            .into_iter()
            .flatten()
            .any(|i| self.slot[i].is_some())
    }

    /// Rebuilds the active set with `groups` at time `t`, from the current
    /// set's state and the exact motion of the others.
    fn rebuild(&mut self, groups: Vec<usize>, t: f64) -> Result<(), IntegrationError> {
        let model = self.model;
        let mut h_prev = None;
        // The old set's groups, bodies (ascending) and state.
        let (mut old_bodies, mut old_y) = (Vec::new(), Vec::new());
        let mut old_groups = Vec::new();
        let mut old_contacts = Vec::new();
        let mut impacts = std::mem::take(&mut self.impacts);
        if let Some(mut old) = self.set.take() {
            h_prev = Some(old.st.h_next());
            self.absorb(&mut old);
            self.contact_evaluations += old.sys.contact_evaluations();
            old_y = old.st.y().to_vec();
            for &i in &old.bodies {
                self.slot[i] = None;
            }
            old_bodies = old.bodies;
            for (kl, &k) in old.scan.ids.iter().enumerate() {
                self.onset[k] = (old.scan.trackers[kl].active, old.sys.onset_velocity(kl));
            }
            impacts = old.scan.impacts;
            for &g in &old.groups {
                self.in_set[g] = false;
            }
            old_groups.clone_from(&old.groups);
            old_contacts.clone_from(&old.scan.ids);
            // Groups leaving move exactly from here.
            for &g in &old.groups {
                if !groups.contains(&g) {
                    let x = self.free.groups()[g]
                        .bodies()
                        .iter()
                        .flat_map(|&i| match old_bodies.binary_search(&i) {
                            Ok(j) => [old_y[2 * j], old_y[2 * j + 1]],
                            Err(_) => [f64::NAN; 2],
                        })
                        .collect();
                    self.exact[g] = (t, x);
                }
            }
        }
        self.local.set_changes += 1;
        if groups.is_empty() {
            self.impacts = impacts;
            return Ok(());
        }
        let mut bodies: Vec<usize> = groups
            .iter()
            .flat_map(|&g| self.free.groups()[g].bodies().to_vec())
            .collect();
        bodies.sort_unstable();
        for (j, &i) in bodies.iter().enumerate() {
            self.slot[i] = Some(j);
        }
        for &g in &groups {
            if !old_groups.contains(&g) {
                self.joined[g] = t;
            }
            self.in_set[g] = true;
        }
        let mut y = vec![0.0; 2 * bodies.len()];
        for (j, &i) in bodies.iter().enumerate() {
            let (u, v) = match old_bodies.binary_search(&i) {
                Ok(o) => (old_y[2 * o], old_y[2 * o + 1]),
                Err(_) => self.exact_body(i, t),
            };
            y[2 * j] = u;
            y[2 * j + 1] = v;
        }
        let local = |i: Option<usize>| i.map(|i| self.slot[i]);
        let mut ids = Vec::new();
        let mut contacts = Vec::new();
        let mut boundary = Vec::new();
        let mut touching: Vec<usize> = groups
            .iter()
            .flat_map(|&g| self.group_contacts[g].iter().copied())
            .collect();
        touching.sort_unstable();
        touching.dedup();
        for k in touching {
            let c = &model.contacts()[k];
            let (l, r) = (local(c.pair.left()), local(c.pair.right()));
            let pair = match (l, r) {
                (Some(Some(l)), Some(Some(r))) => ContactPair::Bodies { left: l, right: r },
                (Some(Some(l)), None) => ContactPair::RightWall { body: l },
                (None, Some(Some(r))) => ContactPair::LeftWall { body: r },
                (Some(None), Some(Some(_))) | (Some(Some(_)), Some(None)) => {
                    boundary.push(k);
                    continue;
                }
                _ => continue,
            };
            ids.push(k);
            contacts.push(Contact {
                pair,
                clearance: c.clearance,
                law: c.law,
            });
        }
        let sub_bodies: Vec<Body> = bodies.iter().map(|&i| model.bodies()[i].clone()).collect();
        let pick = |lists: &[Vec<usize>]| {
            let mut v: Vec<usize> = groups
                .iter()
                .flat_map(|&g| lists[g].iter().copied())
                .collect();
            v.sort_unstable();
            v
        };
        let couplings: Vec<Coupling> = pick(&self.group_couplings)
            .into_iter()
            .map(|i| &model.couplings()[i])
            .filter_map(|c| {
                Some(Coupling {
                    a: self.slot[c.a]?,
                    b: self.slot[c.b]?,
                    ..c.clone()
                })
            })
            .collect();
        let forces: Vec<HarmonicForce> = pick(&self.group_forces)
            .into_iter()
            .map(|i| &model.forces()[i])
            .filter_map(|f| {
                Some(HarmonicForce {
                    body: self.slot[f.body]?,
                    ..f.clone()
                })
            })
            .collect();
        let sub = Model::new(
            sub_bodies,
            couplings,
            contacts,
            model.base().clone(),
            forces,
            Vec::new(),
            Vec::new(),
        )
        .map_err(|e| IntegrationError::InvalidOptions(e.to_string()))?;
        let mut sys = ChainDynamics::new(&sub, false);
        let trackers = ids
            .iter()
            .enumerate()
            .map(|(kl, &k)| {
                let mut tr =
                    Tracker::new(&model.contacts()[k].law, self.opts.impact_force_threshold);
                tr.active = self.onset[k].0;
                sys.set_onset_velocity(kl, self.onset[k].1);
                tr
            })
            .collect();
        let int_opts = IntegratorOptions {
            rtol: self.opts.rtol,
            atol: self.opts.atol,
            max_steps: self.opts.max_steps,
            h_init: h_prev,
            interrupt: self.opts.interrupt.clone(),
            ..IntegratorOptions::default()
        };
        // The onset velocity of an impact that begins as the contact enters
        // is the law's before the first evaluation.
        for (kl, &k) in ids.iter().enumerate() {
            let (s, sd) = sys.approach(kl, &y);
            let s_on = model.contacts()[k]
                .law
                .onset_approach(self.opts.impact_force_threshold);
            if self.onset[k].0.is_none()
                && s > s_on
                && model.contacts()[k].law.needs_impact_velocity()
            {
                sys.set_onset_velocity(kl, sd);
            }
        }
        let mut st = Stepper::new(self.method, y.len(), int_opts)?;
        st.reset(&mut sys, t, &y)?;
        let previous = (0..ids.len())
            .map(|kl| contact_end(&sys, kl, st.y(), st.dydt()))
            .collect();
        self.local.largest_set = self.local.largest_set.max(bodies.len());
        let rate = groups
            .iter()
            .map(|&g| self.free.groups()[g].rate())
            .fold(0.0f64, f64::max);
        let mut scan = StepScan {
            ids,
            trackers,
            impacts,
            previous,
        };
        // A contact that enters past its impact threshold (the power laws'
        // s_act lies past first touch, by a negligible force) begins its
        // impact here.
        for kl in 0..scan.ids.len() {
            if scan.trackers[kl].active.is_none() && scan.previous[kl].0 > scan.trackers[kl].s_on {
                scan.start(&mut st, &mut sys, kl, t);
            }
        }
        if let Some(h) = scan.entry_limit(st.h_next()) {
            st.limit_next_step(h);
        }
        // A fresh start knows nothing of the contacts' time scale, and a
        // force that switches on (s^n at first touch, a damper's jump) is not
        // smooth there: the first step is the one over which an entering
        // contact's impulse stays below atol·μ. (Contacts already in the set
        // keep the step the set had.)
        for (kl, &k) in scan.ids.iter().enumerate() {
            if old_contacts.binary_search(&k).is_ok() {
                continue;
            }
            let (s, sd) = sys.approach(kl, st.y());
            let h = st.h_next();
            if self.activation[k].margin(s + sd.max(0.0) * h, sd) > 0.0 {
                let c = &model.contacts()[k];
                let mass = |i: Option<usize>| i.map_or(f64::INFINITY, |i| model.bodies()[i].mass);
                let (ml, mr) = (mass(c.pair.left()), mass(c.pair.right()));
                let mu = 1.0 / (1.0 / ml + 1.0 / mr);
                let onset = sys.onset_velocity(kl);
                let impulse = |h: f64| c.law.force(s + sd.max(0.0) * h, sd, onset).abs() * h;
                st.limit_next_step(first_step(impulse, self.opts.atol * mu, h));
            }
        }
        self.set = Some(ActiveSet {
            groups,
            bodies,
            boundary,
            sys,
            st,
            scan,
            saved: (t, y),
            rate,
        });
        Ok(())
    }
}

impl Run<'_> {
    /// Adds the set's integrator work since its last absorption to the
    /// run's counters (and to each of its bodies).
    fn absorb(&mut self, set: &mut ActiveSet) {
        let st = set.st.stats();
        self.stats = self.stats + st;
        for &i in &set.bodies {
            self.local.body_evaluations[i] += st.rhs_evaluations;
        }
        set.st.reset_stats();
    }
}

/// Where the active set's last step meets an activation: the earliest
/// time and the contact.
type Crossing = Option<(f64, usize)>;

impl Run<'_> {
    /// Contact k's (s, ṡ) at `t` within the set's last step, for a contact
    /// with one side in the set and the other moving exactly (or a wall).
    fn boundary_state(&mut self, set: &mut ActiveSet, k: usize, t: f64) -> (f64, f64) {
        let c = &self.model.contacts()[k];
        let mut s = -c.clearance;
        let mut sd = 0.0;
        for (side, sign) in [(c.pair.left(), 1.0), (c.pair.right(), -1.0)] {
            let Some(i) = side else { continue };
            let (u, v) = match self.slot[i] {
                Some(j) => {
                    if t == set.saved.0 {
                        (set.saved.1[2 * j], set.saved.1[2 * j + 1])
                    } else {
                        (
                            set.st.dense_component(&mut set.sys, 2 * j, t),
                            set.st.dense_component(&mut set.sys, 2 * j + 1, t),
                        )
                    }
                }
                None => self.exact_body(i, t),
            };
            s += sign * u;
            sd += sign * v;
        }
        (s, sd)
    }

    /// The first time in the set's last step where a boundary contact
    /// becomes active.
    fn boundary_crossing(&mut self, set: &mut ActiveSet) -> Crossing {
        let (ta, tb) = (set.saved.0, set.st.t());
        let mut first: Crossing = None;
        for bi in 0..set.boundary.len() {
            let k = set.boundary[bi];
            let act = self.activation[k];
            let (sa, sda) = self.boundary_state(set, k, ta);
            let (sb, sdb) = self.boundary_state(set, k, tb);
            let (ga, gb) = (act.margin(sa, sda), act.margin(sb, sdb));
            let margin = |run: &mut Self, set: &mut ActiveSet, t: f64| {
                let (s, sd) = run.boundary_state(set, k, t);
                act.margin(s, sd)
            };
            let at = if ga > 0.0 {
                Some(ta)
            } else if gb > 0.0 {
                EventLocator::FINE
                    .locate(|t| margin(self, set, t), (ta, ga), (tb, gb))
                    .ok()
                    .or(Some(tb))
            } else if sda > 0.0 && sdb < 0.0 {
                // The gap's interior maximum.
                let tm = EventLocator::FINE
                    .locate(|t| self.boundary_state(set, k, t).1, (ta, sda), (tb, sdb))
                    .unwrap_or(0.5 * (ta + tb));
                let gm = margin(self, set, tm);
                (gm > 0.0).then(|| {
                    EventLocator::FINE
                        .locate(|t| margin(self, set, t), (ta, ga), (tm, gm))
                        .unwrap_or(tm)
                })
            } else {
                None
            };
            if let Some(t) = at {
                if first.is_none_or(|(f, fk)| (t, k) < (f, fk)) {
                    first = Some((t, k));
                }
            }
        }
        first
    }

    /// Processes the checks due up to `until` (both sides moving exactly):
    /// reschedules the safe ones and returns the first that is active.
    fn due_checks(&mut self, until: f64) -> Crossing {
        while let Some((t, k)) = self.next_check() {
            if t > until {
                break;
            }
            self.queue.pop();
            if self.touches_set(k) {
                continue;
            }
            if self.schedule(k, t) {
                return Some((t, k));
            }
        }
        None
    }

    /// The groups of contact k's bodies.
    fn groups_of(&self, k: usize) -> Vec<usize> {
        side_groups(&self.free, &self.model.contacts()[k])
            .into_iter()
            .flatten()
            .collect()
    }

    /// Joins the groups of contact k to the set at `t` (the set, if any, is
    /// at `t`); the checks of the contacts that now touch the set lapse.
    fn join(&mut self, k: usize, t: f64) -> Result<(), IntegrationError> {
        let mut groups = self.set.as_ref().map_or(Vec::new(), |s| s.groups.clone());
        for g in self.groups_of(k) {
            if !groups.contains(&g) {
                groups.push(g);
            }
        }
        groups.sort_unstable();
        for g in self.groups_of(k) {
            for i in 0..self.group_contacts[g].len() {
                let kk = self.group_contacts[g][i];
                self.generation[kk] += 1;
            }
        }
        self.rebuild(groups, t)
    }

    /// Whether contact `kl` of the set is engaged at the set's current
    /// point: active now or within `lookahead` by its rate and
    /// acceleration. (An impact whose force has fallen below the
    /// negligible level is not: it ends when its bodies are released.)
    fn engaged(set: &ActiveSet, act: Activation, kl: usize, lookahead: f64) -> bool {
        let (s, sd) = set.sys.approach(kl, set.st.y());
        let idx = set.sys.contact_indices(kl);
        let dy = set.st.dydt();
        let sdd = idx[1].map_or(0.0, |i| dy[i]) - idx[3].map_or(0.0, |i| dy[i]);
        let reach = s + sd.max(0.0) * lookahead + 0.5 * sdd.max(0.0) * lookahead * lookahead;
        act.margin(reach, sd.abs() + sdd.abs() * lookahead) > 0.0
    }

    /// Lets the groups of the set whose contacts have all separated move
    /// exactly again; their contacts with other exact groups or walls are
    /// scheduled. Returns a contact that is active at once, if any.
    fn release(&mut self) -> Result<Crossing, IntegrationError> {
        let Some(set) = self.set.as_ref() else {
            return Ok(None);
        };
        let t = set.st.t();
        // How soon counts as engaged: a few steps, and a small part of the
        // fastest oscillation; a set stays that long before it may shrink.
        let steps = 4.0 * set.st.h_next();
        let lookahead = if set.rate > 0.0 {
            steps.max(RELEASE_PERIOD_FRACTION / set.rate)
        } else {
            steps
        };
        // A group that joined within the lookahead stays (no chatter).
        let mut engaged: Vec<bool> = set
            .groups
            .iter()
            .map(|&g| t - self.joined[g] < lookahead)
            .collect();
        for (kl, &k) in set.scan.ids.iter().enumerate() {
            if Self::engaged(set, self.activation[k], kl, lookahead) {
                for g in self.groups_of(k) {
                    if let Ok(p) = set.groups.binary_search(&g) {
                        engaged[p] = true;
                    }
                }
            }
        }
        // A group leaves only if its contacts that would join two exactly
        // moving groups (or a wall) stay safe for a while by the bound: no
        // release that the next check would undo at once.
        let states: Vec<Vec<f64>> = set
            .groups
            .iter()
            .map(|&g| {
                self.free.groups()[g]
                    .bodies()
                    .iter()
                    .flat_map(|&i| {
                        let j = self.slot[i].unwrap_or(0);
                        [set.st.y()[2 * j], set.st.y()[2 * j + 1]]
                    })
                    .collect()
            })
            .collect();
        loop {
            let mut changed = false;
            for p in 0..set.groups.len() {
                if engaged[p] {
                    continue;
                }
                for &k in &self.group_contacts[set.groups[p]] {
                    let sides = self.groups_of(k);
                    let stays = sides
                        .iter()
                        .any(|g| set.groups.binary_search(g).is_ok_and(|q| engaged[q]));
                    if stays {
                        continue;
                    }
                    let exact = &self.exact;
                    let groups = &set.groups;
                    let state = |g: usize| match groups.binary_search(&g) {
                        Ok(q) => states[q].as_slice(),
                        Err(_) => exact[g].1.as_slice(),
                    };
                    // Exact sides are at their own reference time: only
                    // contacts among set groups and walls are judged here.
                    if sides.iter().all(|g| groups.binary_search(g).is_ok())
                        && self
                            .bound(k, t, state)
                            .is_none_or(|until| until - t < lookahead)
                    {
                        engaged[p] = true;
                        changed = true;
                        break;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        if engaged.iter().all(|&e| e) {
            return Ok(None);
        }
        let keep: Vec<usize> = set
            .groups
            .iter()
            .zip(&engaged)
            .filter(|(_, &e)| e)
            .map(|(&g, _)| g)
            .collect();
        let leaving: Vec<usize> = set
            .groups
            .iter()
            .filter(|g| !keep.contains(g))
            .copied()
            .collect();
        // Impacts of released contacts end here.
        if let Some(set) = self.set.as_mut() {
            for kl in 0..set.scan.ids.len() {
                let released = side_groups(&self.free, &self.model.contacts()[set.scan.ids[kl]])
                    .into_iter()
                    .flatten()
                    .any(|g| leaving.contains(&g));
                if released && set.scan.trackers[kl].active.is_some() {
                    set.scan.finish(&mut set.st, &mut set.sys, kl, t);
                }
            }
        }
        self.rebuild(keep, t)?;
        let mut first: Crossing = None;
        let mut freed: Vec<usize> = leaving
            .iter()
            .flat_map(|&g| self.group_contacts[g].iter().copied())
            .collect();
        freed.sort_unstable();
        freed.dedup();
        for k in freed {
            if !self.touches_set(k) && self.schedule(k, t) && first.is_none() {
                first = Some((t, k));
            }
        }
        Ok(first)
    }
}

/// How a step of the active set ended.
enum Stepped {
    /// Taken back: an activation inside it; the set goes on to that time.
    RolledBack,
    /// Kept, with the activation reached at its end if any.
    Kept(Crossing),
}

/// What [`run`] returns to [`simulate_streaming`]: the result, the state
/// at its final time (interleaved) and the work.
pub(super) struct LocalRun {
    pub t: f64,
    pub y: Vec<f64>,
    pub impacts: Vec<ImpactRecord>,
    pub stats: Stats,
    pub contact_evaluations: u64,
    pub local: LocalStats,
    pub error: Option<IntegrationError>,
    pub sink_stopped: Option<f64>,
}

impl Run<'_> {
    /// Writes the whole interleaved state at `t` into `out`: the set's
    /// bodies from its dense output (its last step holds `t`), the others
    /// from their exact motion.
    fn state_at(&mut self, t: f64, out: &mut [f64]) {
        for g in 0..self.exact.len() {
            if self.in_set[g] {
                continue;
            }
            let (t0, x) = &self.exact[g];
            let mut x = x.clone();
            self.free.propagate(g, *t0, t, &mut x);
            for (j, &i) in self.free.groups()[g].bodies().iter().enumerate() {
                out[2 * i] = x[2 * j];
                out[2 * i + 1] = x[2 * j + 1];
            }
        }
        if let Some(set) = self.set.as_mut() {
            let mut y = vec![0.0; 2 * set.bodies.len()];
            set.st.dense_output(&mut set.sys, t, &mut y);
            for (j, &i) in set.bodies.iter().enumerate() {
                out[2 * i] = y[2 * j];
                out[2 * i + 1] = y[2 * j + 1];
            }
        }
    }

    /// One step of the active set, with its events: a boundary contact or
    /// a due check that becomes active inside the step sends the set back
    /// to the step's start and on to that time (`pending`); otherwise the
    /// step's impacts are logged. Returns the activation reached at the
    /// step's end, if any.
    fn step_set(
        &mut self,
        set: &mut ActiveSet,
        pending: &mut Crossing,
    ) -> Result<Stepped, IntegrationError> {
        let t = set.st.t();
        let next_break = self
            .breakpoints
            .get(self.breakpoints.partition_point(|&b| b <= t))
            .copied()
            .unwrap_or(f64::INFINITY);
        let bound = self
            .opts
            .t_end
            .min(next_break)
            .min(pending.map_or(f64::INFINITY, |p| p.0));
        set.saved.0 = t;
        set.saved.1.clear();
        set.saved.1.extend_from_slice(set.st.y());
        set.st.step(&mut set.sys, bound)?;
        let t1 = set.st.t();
        let mut first = self.boundary_crossing(set);
        if let Some(due) = self.due_checks(first.map_or(t1, |f| f.0)) {
            first = Some(due);
        }
        if let Some((ts, k)) = first.filter(|f| f.0 < t1) {
            // Back to the step's start; on to the activation.
            if let Some(p) = pending.take() {
                if p.0 > ts {
                    self.generation[p.1] += 1;
                    self.queue
                        .push(Reverse((Time(p.0), p.1, self.generation[p.1])));
                }
            }
            let (t0, y0) = (set.saved.0, set.saved.1.clone());
            self.absorb(set);
            set.st.reset(&mut set.sys, t0, &y0)?;
            if ts <= t0 {
                // Active where the step began: joined there.
                return Ok(Stepped::Kept(Some((t0, k))));
            }
            *pending = Some((ts, k));
            set.st.limit_next_step(ts - t0);
            return Ok(Stepped::RolledBack);
        }
        set.scan.scan(&mut set.st, &mut set.sys);
        if let Some(h) = set.scan.entry_limit(set.st.h_next()) {
            set.st.limit_next_step(h);
        }
        if let Some(p) = *pending {
            if p.0 <= t1 {
                *pending = None;
                // Another activation at the same time is checked again
                // there, once p's groups have joined.
                if let Some(f) = first.filter(|f| f.1 != p.1) {
                    self.generation[f.1] += 1;
                    self.queue
                        .push(Reverse((Time(f.0), f.1, self.generation[f.1])));
                }
                return Ok(Stepped::Kept(Some(p)));
            }
        }
        Ok(Stepped::Kept(first))
    }
}

/// Simulates `model` over `[0, opts.t_end]` by the local integrator,
/// handing samples to `record` as [`simulate_streaming`] does.
pub(super) fn run(
    model: &Model,
    opts: &SimulationOptions,
    method: Method,
    y0: &[f64],
    breakpoints: Vec<f64>,
    record: &mut dyn FnMut(f64, &[f64]) -> bool,
) -> Result<LocalRun, OptionsError> {
    if opts.energy {
        return Err(OptionsError(
            "the energy audit needs the global integrator (integrator = global)".into(),
        ));
    }
    if opts.extrema_window.is_some() {
        return Err(OptionsError(
            "exact extrema need the global integrator (integrator = global)".into(),
        ));
    }
    let free = FreeMotion::new(model).map_err(|e| OptionsError(e.to_string()))?;
    let n = model.bodies().len();
    let ng = free.groups().len();
    let nc = model.contacts().len();
    let mut group_contacts = vec![Vec::new(); ng];
    for (k, c) in model.contacts().iter().enumerate() {
        let sides = side_groups(&free, c);
        for g in sides.iter().flatten() {
            if group_contacts[*g].last() != Some(&k) {
                group_contacts[*g].push(k);
            }
        }
    }
    let mut group_couplings = vec![Vec::new(); ng];
    for (i, c) in model.couplings().iter().enumerate() {
        group_couplings[free.place(c.a).0].push(i);
    }
    let mut group_forces = vec![Vec::new(); ng];
    for (i, f) in model.forces().iter().enumerate() {
        group_forces[free.place(f.body).0].push(i);
    }
    let exact = free
        .groups()
        .iter()
        .map(|g| {
            let x = g
                .bodies()
                .iter()
                .flat_map(|&i| [y0[2 * i], y0[2 * i + 1]])
                .collect();
            (0.0, x)
        })
        .collect();
    let activation = (0..nc)
        .map(|k| {
            let s_on = model.contacts()[k]
                .law
                .onset_approach(opts.impact_force_threshold);
            Activation::new(model, k, opts, s_on)
        })
        .collect();
    let mut run = Run {
        model,
        opts,
        method,
        free,
        exact,
        in_set: vec![false; ng],
        joined: vec![0.0; ng],
        defer: false,
        deferred: Vec::new(),
        slot: vec![None; n],
        activation,
        group_contacts,
        group_couplings,
        group_forces,
        generation: vec![0; nc],
        queue: BinaryHeap::new(),
        set: None,
        impacts: Vec::new(),
        onset: vec![(None, 0.0); nc],
        stats: Stats::default(),
        contact_evaluations: 0,
        local: LocalStats {
            body_evaluations: vec![0; n],
            ..LocalStats::default()
        },
        breakpoints,
    };
    let mut out = LocalRun {
        t: 0.0,
        y: y0.to_vec(),
        impacts: Vec::new(),
        stats: Stats::default(),
        contact_evaluations: 0,
        local: LocalStats::default(),
        error: None,
        sink_stopped: None,
    };
    let mut sample = vec![0.0; 2 * n];
    let mut next_sample = 0usize;
    // Emits the samples up to `t` (inclusive) from the current motion.
    let mut emit = |run: &mut Run, t: f64, stopped: &mut Option<f64>| {
        let Some(dt) = opts.output_step else { return };
        while stopped.is_none() {
            let ts = next_sample as f64 * dt;
            if ts > t || ts > opts.t_end {
                break;
            }
            run.state_at(ts, &mut sample);
            let body: Vec<f64> = (0..n)
                .map(|i| sample[2 * i])
                .chain((0..n).map(|i| sample[2 * i + 1]))
                .collect();
            next_sample += 1;
            if !record(ts, &body) {
                *stopped = Some(ts);
            }
        }
    };
    // Contacts active at the start form the first set; the others are
    // scheduled.
    for k in 0..nc {
        if !run.touches_set(k) && run.schedule(k, 0.0) {
            if let Err(e) = run.join(k, 0.0) {
                out.error = Some(e);
                break;
            }
        }
    }
    let mut pending: Crossing = None;
    let mut t = 0.0;
    let mut steps: u64 = 0;
    let mut next_guard = PROGRESS_CHECK;
    let initial_checks = run.local.contact_checks;
    while out.error.is_none() && out.sink_stopped.is_none() && t < opts.t_end {
        if let Some(stop) = &opts.interrupt {
            if let Err(e) = stop.check(t) {
                out.error = Some(e);
                break;
            }
        }
        // Checks that crawl (bounds so loose that every check looks only a
        // hair ahead) end the run with the reason, as steps that crawl do.
        // (The first check of every contact at t = 0 is not pace.)
        let checks = run.local.contact_checks - initial_checks;
        if checks >= next_guard && t > 0.0 {
            next_guard = checks + PROGRESS_CHECK;
            let projected = checks as f64 * opts.t_end / t;
            if projected > CRAWL_FACTOR * (opts.max_steps as f64).max(nc as f64) {
                out.error = Some(IntegrationError::ChecksCrawl {
                    t,
                    checks,
                    projected,
                    limit: opts.max_steps,
                });
                break;
            }
        }
        if run.set.is_none() {
            let next = run.next_check().map_or(opts.t_end, |c| c.0.min(opts.t_end));
            emit(&mut run, next, &mut out.sink_stopped);
            t = next;
            if next >= opts.t_end {
                break;
            }
            if let Some(at) = run.due_checks(next) {
                if let Err(e) = run.join(at.1, at.0) {
                    out.error = Some(e);
                }
            }
            continue;
        }
        let Some(mut set) = run.set.take() else {
            continue;
        };
        run.defer = true;
        let stepped = run.step_set(&mut set, &mut pending);
        run.defer = false;
        t = set.st.t();
        run.set = Some(set);
        match stepped {
            Err(e) => {
                out.error = Some(e);
                break;
            }
            Ok(Stepped::RolledBack) => {}
            Ok(Stepped::Kept(reached)) => {
                steps += 1;
                if steps > opts.max_steps {
                    out.error = Some(IntegrationError::TooManySteps { t, steps });
                    break;
                }
                emit(&mut run, t, &mut out.sink_stopped);
                run.apply_deferred(t);
                let result = match reached {
                    Some((_, k)) => run.join(k, t).map(|_| None),
                    None if pending.is_none() => run.release(),
                    None => Ok(None),
                };
                match result {
                    Err(e) => out.error = Some(e),
                    Ok(Some((ta, k))) => {
                        if let Err(e) = run.join(k, ta) {
                            out.error = Some(e);
                        }
                    }
                    Ok(None) => {}
                }
            }
        }
    }
    // The state at the end (or where it stopped).
    let t_final = match &run.set {
        Some(set) => set.st.t(),
        None => t.min(opts.t_end),
    };
    let mut y = vec![0.0; 2 * n];
    run.state_at(t_final, &mut y);
    if let Some(mut set) = run.set.take() {
        run.absorb(&mut set);
        run.contact_evaluations += set.sys.contact_evaluations();
        run.impacts = set.scan.impacts;
    }
    out.t = t_final;
    out.y = y;
    out.impacts = std::mem::take(&mut run.impacts);
    out.stats = run.stats;
    out.contact_evaluations = run.contact_evaluations;
    out.local = run.local;
    Ok(out)
}

#[cfg(test)]
#[path = "local_tests.rs"]
mod tests;
