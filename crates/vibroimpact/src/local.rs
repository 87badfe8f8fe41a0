//! The local integrator (docs/theory.md §10): exact motion between
//! contacts, the step driver only where bodies touch.
//!
//! Every group of bodies joined by springs ([`FreeMotion`]) moves exactly
//! while none of its contacts is active. A contact becomes active where its
//! force stops being negligible at the run's tolerance (`s_act`, see
//! `Activation`); the groups it joins are then integrated, with every
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
use crate::dynamics::{Chain, SetSystem};
use crate::free_motion::FreeMotion;
use crate::integrate::Recorder;
use crate::model::{Body, Contact, ContactPair, Coupling, HarmonicForce};
use crate::variational::Variational;

#[path = "local_activation.rs"]
mod activation;
#[path = "local_run.rs"]
mod driver;
#[path = "local_energy.rs"]
mod energy;
#[path = "local_extrema.rs"]
mod extrema;
#[path = "local_set.rs"]
mod membership;
#[path = "local_tape.rs"]
mod tape;

use activation::{first_step, Activation};
pub(super) use driver::{run, Tangents};
use energy::LocalEnergy;
use extrema::LocalExtrema;
use membership::Crossing;
pub use tape::LocalTape;
use tape::TapeRecord;

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

/// What a set that leaves hands to the next ([`Run::retire`]): its
/// bodies (ascending), their state, its groups and contacts, the impacts
/// logged so far and the step it had.
#[derive(Default)]
struct Retired {
    bodies: Vec<usize>,
    y: Vec<f64>,
    groups: Vec<usize>,
    contacts: Vec<usize>,
    impacts: Vec<ImpactRecord>,
    h_prev: Option<f64>,
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
    /// The set's row, with the tangent columns when they are carried.
    sys: SetSystem,
    st: Stepper,
    scan: StepScan,
    /// The set's state at the start of its last step.
    saved: (f64, Vec<f64>),
    /// The fastest natural or forcing rate of its groups (rad/s).
    rate: f64,
    /// The extrema of its steps, when asked for.
    extrema: Option<ExtremaScan>,
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
    /// Per contact: the checks made (which one crawls).
    checks_per_contact: Vec<u64>,
    /// The extrema over the window, when asked for.
    extrema: Option<LocalExtrema>,
    /// Tangent columns carried (0: none).
    columns: usize,
    /// Per group: time and tangent columns (each of the group's
    /// interleaved rows, one after the other) of its exact motion; the
    /// set's are in its state.
    tangents: Vec<(f64, Vec<f64>)>,
    breakpoints: Vec<f64>,
    /// The record of the run's linearisation, when a tape is asked for.
    tape: Option<TapeRecord>,
    /// Per contact between two bodies that move alike (see
    /// [`alike`]): their ω² = k/m.
    alike: Vec<Option<f64>>,
    /// The energy audit's sums, when asked for.
    energy: Option<LocalEnergy>,
}

/// ω² of the two bodies of contact `c` if they move alike: each a group
/// of its own (no coupling), the same k/m > 0 and c/m, and no harmonic
/// force on either. Then the base drives both alike and their difference
/// `Δ = u_l − u_r` is a free damped oscillator: its energy
/// `Δ̇² + ω²Δ²` never grows, so `|Δ| <= sqrt(E)/ω` for all time.
fn alike(model: &Model, free: &FreeMotion, c: &Contact) -> Option<f64> {
    let (l, r) = (c.pair.left()?, c.pair.right()?);
    let single = |i: usize| free.groups()[free.place(i).0].bodies().len() == 1;
    let forced = |i: usize| model.forces().iter().any(|f| f.body == i);
    if !single(l) || !single(r) || forced(l) || forced(r) {
        return None;
    }
    let (a, b) = (&model.bodies()[l], &model.bodies()[r]);
    let w2 = a.stiffness / a.mass;
    (w2 > 0.0 && w2 == b.stiffness / b.mass && a.damping / a.mass == b.damping / b.mass)
        .then_some(w2)
}

/// The rows `[u, v]` of `bodies` in an interleaved state `v` of the whole
/// model.
fn rows_of(bodies: &[usize], v: &[f64]) -> Vec<f64> {
    bodies
        .iter()
        .flat_map(|&i| [v[2 * i], v[2 * i + 1]])
        .collect()
}

/// Writes the rows `x` of `bodies` into an interleaved state `out` of the
/// whole model.
fn put_rows(bodies: &[usize], x: &[f64], out: &mut [f64]) {
    for (j, &i) in bodies.iter().enumerate() {
        out[2 * i] = x[2 * j];
        out[2 * i + 1] = x[2 * j + 1];
    }
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
        self.checks_per_contact[k] += 1;
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
                self.before_move(g, t);
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
                self.before_move(g, tc);
                self.exact[g] = (tc, x);
            }
        }
        self.deferred = later;
    }

    /// [`safe_until`](Self::safe_until) from the groups' interleaved states
    /// at `t` (`state(g)`), as if they moved exactly from there.
    fn bound<'s>(&self, k: usize, t: f64, state: impl Fn(usize) -> &'s [f64]) -> Option<f64> {
        let c = &self.model.contacts()[k];
        if let (Some(w2), Some(l), Some(r)) = (self.alike[k], c.pair.left(), c.pair.right()) {
            // Bodies that move alike: the gap's bound for all time.
            let (xl, xr) = (state(self.free.place(l).0), state(self.free.place(r).0));
            let (d, dv) = (xl[0] - xr[0], xl[1] - xr[1]);
            let energy = dv * dv + w2 * d * d;
            let reach = (energy / w2).sqrt();
            let size = c.clearance + xl[0].abs() + xr[0].abs();
            let gap = self.activation[k].gap(energy.sqrt());
            // Safe to the end while both move exactly: no check is queued,
            // so every path that changes either body's motion must lapse
            // or reschedule this contact (`join` does, and `release`
            // schedules the contacts it frees).
            if reach - c.clearance + 1e-12 * size < gap {
                return Some(self.opts.t_end);
            }
        }
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
        // Groups joining leave their exact motion: scanned up to here, and
        // their deferred reference states (of the motion before they
        // joined) lapse.
        for &g in &groups {
            if !self.in_set[g] {
                self.before_move(g, t);
                self.deferred.retain(|(h, ..)| *h != g);
            }
        }
        let old = self.retire(&groups, t);
        self.local.set_changes += 1;
        if groups.is_empty() {
            self.impacts = old.impacts;
            if let Some(tape) = self.tape.as_mut() {
                tape.form(t, &[], &[], None, &[]);
            }
            return Ok(());
        }
        let (bodies, y) = self.enter(&groups, &old, t);
        let (sub, ids, boundary) = self.sub_model(&groups, &bodies)?;
        let energy = self.energy.is_some();
        let chain = Recorder::new(ChainDynamics::new(&sub, energy), self.tape.is_some());
        let mut sys = Variational::new(chain, self.columns);
        let trackers = ids
            .iter()
            .enumerate()
            .map(|(kl, &k)| {
                let mut tr =
                    Tracker::new(&model.contacts()[k].law, self.opts.impact_force_threshold);
                tr.active = self.onset[k].0;
                sys.chain_mut().set_onset_velocity(kl, self.onset[k].1);
                tr
            })
            .collect();
        let int_opts = IntegratorOptions {
            rtol: self.opts.rtol,
            atol: self.opts.atol,
            max_steps: self.opts.max_steps,
            h_init: old.h_prev,
            error_components: energy.then_some(2 * bodies.len()),
            interrupt: self.opts.interrupt.clone(),
            ..IntegratorOptions::default()
        };
        // The onset velocity of an impact that begins as the contact enters
        // is the law's before the first evaluation.
        for (kl, &k) in ids.iter().enumerate() {
            let (s, sd) = sys.chain().approach(kl, &y);
            let s_on = model.contacts()[k]
                .law
                .onset_approach(self.opts.impact_force_threshold);
            if self.onset[k].0.is_none()
                && s > s_on
                && model.contacts()[k].law.needs_impact_velocity()
            {
                sys.chain_mut().set_onset_velocity(kl, sd);
            }
        }
        let mut st = Stepper::new(self.method, y.len(), int_opts)?;
        st.reset(&mut sys, t, &y)?;
        if let Some(tape) = self.tape.as_mut() {
            let rec = sys.system();
            if rec.time(0) != Some(t) {
                return Err(IntegrationError::InvalidOptions(
                    "tangent tape: no record of the set's first point (internal error)".into(),
                ));
            }
            tape.form(t, &groups, &bodies, Some(rec.system()), rec.evaluation(0));
        }
        let previous = (0..ids.len())
            .map(|kl| contact_end(sys.chain(), kl, st.y(), st.dydt()))
            .collect();
        self.local.largest_set = self.local.largest_set.max(bodies.len());
        let rate = groups
            .iter()
            .map(|&g| self.free.groups()[g].rate())
            .fold(0.0f64, f64::max);
        let mut scan = StepScan {
            ids,
            trackers,
            impacts: old.impacts,
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
        self.limit_first_step(&mut st, &sys, &scan, &old.contacts);
        let extrema = self
            .extrema
            .as_ref()
            .map(|ex| ex.set_scan(&scan.ids, bodies.len(), &st, &sys));
        self.set = Some(ActiveSet {
            groups,
            bodies,
            boundary,
            sys,
            st,
            scan,
            saved: (t, y),
            rate,
            extrema,
        });
        Ok(())
    }

    /// Takes the current set apart at `t`: its results return to the run,
    /// its groups that are not in `groups` move exactly from here, and
    /// what the next set needs of it is returned.
    fn retire(&mut self, groups: &[usize], t: f64) -> Retired {
        let mut out = Retired {
            impacts: std::mem::take(&mut self.impacts),
            ..Retired::default()
        };
        if let Some(mut old) = self.set.take() {
            out.h_prev = Some(old.st.h_next());
            self.absorb(&mut old);
            if let (Some(ex), Some(scan)) = (self.extrema.as_mut(), &old.extrema) {
                ex.merge(&old, scan);
            }
            self.contact_evaluations += old.sys.chain().contact_evaluations();
            let old_y = old.st.y().to_vec();
            self.energy_of_set(&old_y, old.bodies.len());
            for &i in &old.bodies {
                self.slot[i] = None;
            }
            let old_bodies = old.bodies;
            for (kl, &k) in old.scan.ids.iter().enumerate() {
                self.onset[k] = (
                    old.scan.trackers[kl].active,
                    old.sys.chain().onset_velocity(kl),
                );
            }
            out.impacts = old.scan.impacts;
            for &g in &old.groups {
                self.in_set[g] = false;
            }
            out.groups.clone_from(&old.groups);
            out.contacts.clone_from(&old.scan.ids);
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
                    self.extrema_from(g, t);
                    self.energy_from(g, t);
                    let b2 = old_bodies.len() * 2;
                    let mut w = Vec::new();
                    for c in 0..self.columns {
                        for &i in self.free.groups()[g].bodies() {
                            w.extend(match old_bodies.binary_search(&i) {
                                Ok(j) => {
                                    [old_y[b2 * (1 + c) + 2 * j], old_y[b2 * (1 + c) + 2 * j + 1]]
                                }
                                Err(_) => [f64::NAN; 2],
                            });
                        }
                    }
                    self.tangents[g] = (t, w);
                }
            }
            (out.bodies, out.y) = (old_bodies, old_y);
        }
        out
    }

    /// The new set's bodies (ascending) and state at `t` for `groups`:
    /// from the old set where it held them, else from the exact motion;
    /// the audit's quadratures and the tangent columns after it.
    fn enter(&mut self, groups: &[usize], old: &Retired, t: f64) -> (Vec<usize>, Vec<f64>) {
        let mut bodies: Vec<usize> = groups
            .iter()
            .flat_map(|&g| self.free.groups()[g].bodies().to_vec())
            .collect();
        bodies.sort_unstable();
        for (j, &i) in bodies.iter().enumerate() {
            self.slot[i] = Some(j);
        }
        for &g in groups {
            if !old.groups.contains(&g) {
                self.joined[g] = t;
            }
            self.in_set[g] = true;
        }
        let mut y = vec![0.0; 2 * bodies.len()];
        for (j, &i) in bodies.iter().enumerate() {
            let (u, v) = match old.bodies.binary_search(&i) {
                Ok(o) => (old.y[2 * o], old.y[2 * o + 1]),
                Err(_) => self.exact_body(i, t),
            };
            y[2 * j] = u;
            y[2 * j + 1] = v;
        }
        // The audit's quadratures after the state (from 0: the old set's
        // are in the sums).
        if self.energy.is_some() {
            y.extend([0.0; 3]);
        }
        // Tangent columns after the state: rows from the old set, or
        // from the joining groups' exact homogeneous motion.
        if self.columns > 0 {
            let (b2, o2) = (2 * bodies.len(), 2 * old.bodies.len());
            for &g in groups {
                if !old.groups.contains(&g) {
                    self.tangents_to(g, t);
                }
            }
            y.resize(b2 * (1 + self.columns), 0.0);
            for c in 0..self.columns {
                for (j, &i) in bodies.iter().enumerate() {
                    let (u, v) = match old.bodies.binary_search(&i) {
                        Ok(o) => (old.y[o2 * (1 + c) + 2 * o], old.y[o2 * (1 + c) + 2 * o + 1]),
                        Err(_) => {
                            let (g, jg) = self.free.place(i);
                            let m2 = 2 * self.free.groups()[g].bodies().len();
                            let w = &self.tangents[g].1;
                            (w[c * m2 + 2 * jg], w[c * m2 + 2 * jg + 1])
                        }
                    };
                    y[b2 * (1 + c) + 2 * j] = u;
                    y[b2 * (1 + c) + 2 * j + 1] = v;
                }
            }
        }
        (bodies, y)
    }

    /// The set's own model: its bodies, the contacts within it (renumbered)
    /// with their global ids, the springs and forces of its groups, and
    /// the contacts on its boundary (to a body outside).
    fn sub_model(
        &self,
        groups: &[usize],
        bodies: &[usize],
    ) -> Result<(Model, Vec<usize>, Vec<usize>), IntegrationError> {
        let model = self.model;
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
        Ok((sub, ids, boundary))
    }

    /// A fresh start knows nothing of the contacts' time scale, and a
    /// force that switches on (s^n at first touch, a damper's jump) is not
    /// smooth there: the first step is the one over which an entering
    /// contact's impulse stays below atol·μ. (Contacts already in the set,
    /// `old_contacts`, keep the step the set had.)
    fn limit_first_step(
        &self,
        st: &mut Stepper,
        sys: &SetSystem,
        scan: &StepScan,
        old_contacts: &[usize],
    ) {
        let model = self.model;
        for (kl, &k) in scan.ids.iter().enumerate() {
            if old_contacts.binary_search(&k).is_ok() {
                continue;
            }
            let (s, sd) = sys.chain().approach(kl, st.y());
            let h = st.h_next();
            if self.activation[k].margin(s + sd.max(0.0) * h, sd) > 0.0 {
                let c = &model.contacts()[k];
                let mass = |i: Option<usize>| i.map_or(f64::INFINITY, |i| model.bodies()[i].mass);
                let (ml, mr) = (mass(c.pair.left()), mass(c.pair.right()));
                let mu = 1.0 / (1.0 / ml + 1.0 / mr);
                let onset = sys.chain().onset_velocity(kl);
                let impulse = |h: f64| c.law.force(s + sd.max(0.0) * h, sd, onset).abs() * h;
                st.limit_next_step(first_step(impulse, self.opts.atol * mu, h));
            }
        }
    }
}

impl Run<'_> {
    /// Before group `g`'s reference state moves to `t` (or it joins the
    /// set there): its exact motion up to `t` is scanned for extrema and
    /// enters the energy audit.
    fn before_move(&mut self, g: usize, t: f64) {
        self.scan_group_to(g, t);
        self.energy_to(g, t);
    }

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

#[cfg(test)]
#[path = "local_tests.rs"]
mod tests;
