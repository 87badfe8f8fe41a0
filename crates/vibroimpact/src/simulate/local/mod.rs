//! The local integrator (docs/theory.md §10): exact motion between
//! contacts, the step driver only where bodies touch.
//!
//! ## Files
//! - `mod.rs` — the active set and the local run's state;
//! - `driver.rs` — the event loop; `pace.rs` — when its steps or checks
//!   crawl;
//! - `activation.rs`, `membership.rs`, `rebuild.rs` — when a contact
//!   matters, the set's edge, rebuilding the set;
//! - `alike.rs` — the check of a contact between bodies that move alike;
//! - `clusters.rs` — a set and a stepper per cluster, earliest first;
//! - `lists.rs` — lists per group in one flat array;
//! - `free_motion/` — exact motion between contacts;
//! - `storeys.rs` — hysteretic storeys under the local integrator;
//! - `rigid.rs` — rigid impacts: jumps between exact motions, soft
//!   episodes;
//! - `envelope.rs` — the modal bound of a check;
//! - `extrema.rs`, `energy.rs`, `tape.rs` — exact extrema, the energy
//!   audit, the tangent tape;
//! - `tests/` — against the global integrator (`mod.rs`) and with storeys
//!   (`storeys.rs`).
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
//! accelerations over a horizon ([`crate::simulate::local::free_motion::Group`]'s energy
//! bound), `s(t₀ + τ) <= s₀ + ṡ₀ τ + C τ²` — and is checked again then
//! (an event queue in time order, ties by contact index). A grazing contact
//! cannot be missed: the bound holds over the whole interval. Contacts
//! between the set and an exactly moving group are followed on every step
//! of the set over its dense output; one that reaches `s_act` inside a
//! step sends the set back to the step's start, to be integrated to that
//! time exactly and the group joined there.
//!
//! Hysteretic storeys (`storeys.rs`): a storey on a linear branch is
//! a spring with a constant force, so its group moves exactly about its
//! rest state; a bilinear storey's approach to yield is checked like a
//! contact's (its drift against the branch's window), and its group is
//! integrated, its branches switched at located events, from within
//! `storeys::YIELD_APPROACH` of yield until it is elastic and safely
//! below yield again. A Bouc–Wen storey's group is integrated throughout.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use smallvec::SmallVec;

use super::switches::{apply_event, Event, Switches, Verdict};
use super::*;
use crate::contact::LawKind;
use crate::dynamics::variational::Variational;
use crate::dynamics::{Chain, SetSystem, StoreyTerms};
use crate::integrate::Recorder;
use crate::model::{Body, Contact, ContactPair, Coupling, HarmonicForce, Storey};
use crate::simulate::local::free_motion::{FreeMotion, Rows};

mod activation;
mod alike;
mod clusters;
mod driver;
mod energy;
mod envelope;
mod extrema;
pub mod free_motion;
mod lists;
mod membership;
mod pace;
mod rebuild;
mod rigid;
mod storeys;
mod tape;

use activation::{first_step, like_previous, Activation};
use clusters::clustered;
pub(super) use driver::{run, Tangents};
use energy::LocalEnergy;
use extrema::LocalExtrema;
use lists::Lists;
use membership::Crossing;
use rigid::rigid_parts;
pub use tape::LocalTape;
use tape::TapeRecord;

/// Work of the local integrator, beside the integrator's counters.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LocalStats {
    /// Bound checks of contacts between exactly moving bodies (and of
    /// storeys' approach to yield).
    pub contact_checks: u64,
    /// Times the active set was formed or changed.
    pub set_changes: u64,
    /// Largest number of bodies integrated at once.
    pub largest_set: usize,
    /// Most sets integrated side by side (clusters, each with its own
    /// stepper) at once.
    pub most_sets: usize,
    /// Right-hand-side evaluations of each body (0: the body moved exactly
    /// for the whole run and was never evaluated).
    pub body_evaluations: Vec<u64>,
    /// Rigid impacts taken as jumps between exact motions.
    pub rigid_impacts: u64,
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

/// The integrated bodies and their system (kept boxed: it is large, and
/// sets change places often).
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
    /// Model indices of its storeys (the set's storey k is `storeys[k]`).
    storeys: Vec<usize>,
    /// Its storeys' branch switches and its contacts' onsets.
    switches: Option<Switches>,
    /// The event its last kept step ended at, applied once the step's
    /// samples are taken.
    event: Option<Event>,
    /// The exactly moving groups of its boundary contacts at the end of
    /// its last step: (group, time, state), the next step's start.
    carried: Vec<(usize, f64, Rows)>,
    /// The activation its steps are to stop at (after a step taken back).
    pending: Crossing,
    /// Its last kept step while it is open (its impacts not yet logged,
    /// its membership not yet settled), with the activation reached at
    /// its end if any; None once closed.
    open: Option<Crossing>,
    /// Whether its open step's impacts are logged and its extrema
    /// scanned (that comes before the step's samples are taken).
    scanned: bool,
}

/// The local integrator's run.
struct Run<'a> {
    model: &'a Model,
    opts: &'a SimulationOptions,
    method: Method,
    free: FreeMotion,
    /// Per group: time and interleaved state of its exact motion.
    exact: Vec<(f64, Rows)>,
    /// Per group: in the active set.
    in_set: Vec<bool>,
    /// Per group: when it last joined the set.
    joined: Vec<f64>,
    /// While the set steps: checks do not move exact groups' reference
    /// states (samples and a step taken back still need earlier times);
    /// the moves wait in `deferred` (group, time, state).
    defer: bool,
    deferred: Vec<(usize, f64, Rows)>,
    /// Per body: index in the active set.
    slot: Vec<Option<usize>>,
    activation: Vec<Activation>,
    /// Per group: its contacts and checked (bilinear and Bouc–Wen) storeys
    /// (model indices, ascending; its couplings and forces are the free
    /// motion's).
    group_contacts: Lists,
    group_storeys: Lists,
    /// Per check (contacts, then storeys: check `nc + s` is storey s's):
    /// the generation of its scheduled check (older queue entries are
    /// stale).
    generation: Vec<u64>,
    queue: BinaryHeap<Reverse<(Time, usize, u64)>>,
    /// The set being stepped or changed (it holds the impact log while
    /// it is here), and with clusters the others, each at its own time
    /// (see `clusters.rs`).
    set: Option<Box<ActiveSet>>,
    // (Boxed: a set is 3.9 kB, and moves between `set` and `sets` on
    // every switch; unboxed moves took 10 % of a run of 100 bodies.)
    #[allow(clippy::vec_box)]
    sets: Vec<Box<ActiveSet>>,
    /// Sets taken to the current one's time to merge with it at the next
    /// rebuild.
    #[allow(clippy::vec_box)]
    merging: Vec<Box<ActiveSet>>,
    /// Whether each cluster of the set is its own set with its own
    /// stepper (else one set holds every integrated group).
    clustered: bool,
    /// Per contact: the impact under way (index into `impacts`) and the
    /// onset velocity, while the contact is not in the set.
    impacts: Vec<ImpactRecord>,
    onset: Vec<(Option<usize>, f64)>,
    stats: Stats,
    contact_evaluations: u64,
    local: LocalStats,
    /// Per check (contacts, then storeys): the checks made (which one
    /// crawls).
    checks_per_contact: Vec<u64>,
    /// The storeys' memory for the whole model: the branches of those
    /// moving exactly (the set's own are in its system until it is taken
    /// apart, [`Run::sync_storeys`]), and `hysteretic`, the Bouc–Wen
    /// states after the interleaved state (`storeys` reads them at index
    /// 2N on).
    storeys: StoreyTerms,
    hysteretic: Vec<f64>,
    /// The extrema over the window, when asked for.
    extrema: Option<LocalExtrema>,
    /// Tangent columns carried (0: none).
    columns: usize,
    /// Per group: time and tangent columns (each of the group's
    /// interleaved rows, one after the other) of its exact motion; the
    /// set's are in its state. Empty when no tangents are given.
    tangents: Vec<(f64, Vec<f64>)>,
    breakpoints: Vec<f64>,
    /// The record of the run's linearisation, when a tape is asked for.
    tape: Option<TapeRecord>,
    /// Per contact between two bodies that move alike (`alike.rs`).
    alike: Vec<Option<alike::Alike>>,
    /// The energy audit's sums, when asked for.
    energy: Option<LocalEnergy>,
    /// Per contact: its rigid limit, for rigid impacts (`rigid.rs`).
    rigid: crate::model::RigidLimits,
    /// Per contact: its last rigid impact's time and estimated duration.
    last_impact: Vec<(f64, f64)>,
    /// Per contact: where a rigid contact's impact is judged (its law's
    /// onset approach, negative for the exponential law), and whether it
    /// was judged rigid and is checked against its touch now.
    pre: Vec<f64>,
    armed: Vec<bool>,
    /// The rigid contacts' soft episodes.
    episodes: Vec<super::SoftEpisode>,
}

/// The first time a quantity that starts `d` below its limit, at rate `b`
/// and with |second derivative| <= 2 `cq`, can reach it: the root of `b τ +
/// cq τ² = d` (infinite if it never does); None if it is there already,
/// or within rounding of `size` and closing.
fn reach_time(d: f64, b: f64, cq: f64, size: f64) -> Option<f64> {
    Some(if d < 0.0 || (d <= 8.0 * f64::EPSILON * size && b > 0.0) {
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
    })
}

/// The rows `[u, v]` of `bodies` in an interleaved state `v` of the whole
/// model.
fn rows_of(bodies: &[usize], v: &[f64]) -> Rows {
    let mut rows = Rows::new();
    for &i in bodies {
        rows.extend_from_slice(&v[2 * i..2 * i + 2]);
    }
    rows
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
        let mut x = Rows::from_slice(x);
        self.free.propagate(g, *t0, t, &mut x);
        (x[2 * j], x[2 * j + 1])
    }

    /// The time until which check k (a contact with both sides moving
    /// exactly, or a storey moving exactly) surely stays inactive, from
    /// `t`; None: active now (or so soon that the bound cannot tell). A
    /// contact open at rest for good is not counted as checked.
    fn safe_until(&mut self, k: usize, t: f64) -> Option<f64> {
        if self.open_at_rest(k, |g| self.free.stays_at_rest(g, &self.exact[g].1)) {
            return Some(f64::INFINITY);
        }
        self.local.contact_checks += 1;
        self.checks_per_contact[k] += 1;
        // The sides' groups at t: their reference states move there (in
        // place, no allocation). Inside a step of the set the moves only go
        // into `deferred`: samples and a step taken back still ask for
        // earlier times of these groups, and exact motion never runs
        // backward.
        let mut groups = [usize::MAX; 2];
        let mut count = 0;
        for i in self.sides(k).into_iter().flatten() {
            let g = self.free.place(i).0;
            if !groups[..count].contains(&g) {
                groups[count] = g;
                count += 1;
            }
        }
        let groups = &groups[..count];
        if self.defer {
            let at = self.states_at(groups, t);
            self.disarm_if_open(k, |g| {
                at.iter().find(|(h, _)| *h == g).map(|(_, x)| x.as_slice())
            });
            let until = {
                let exact = &self.exact;
                self.bound(k, t, f64::INFINITY, |g| {
                    at.iter()
                        .find(|(h, _)| *h == g)
                        .map_or(exact[g].1.as_slice(), |(_, x)| x.as_slice())
                })
            };
            self.deferred.extend(at.into_iter().map(|(g, x)| (g, t, x)));
            return until;
        }
        for &g in groups {
            self.before_move(g, t);
            let Run { free, exact, .. } = &mut *self;
            let (t0, x) = &mut exact[g];
            free.propagate(g, *t0, t, x);
            *t0 = t;
        }
        let exact = std::mem::take(&mut self.exact);
        self.disarm_if_open(k, |g| Some(exact[g].1.as_slice()));
        let until = self.bound(k, t, f64::INFINITY, |g| exact[g].1.as_slice());
        self.exact = exact;
        until
    }

    /// Whether check k is a contact whose sides' groups are at rest and
    /// stay there (`still`: a row's bodies before a pulse reaches them)
    /// with its gap open: open for good (a change of either side's motion
    /// schedules its check again).
    fn open_at_rest(&self, k: usize, still: impl Fn(usize) -> bool) -> bool {
        let Some(c) = self.model.contacts().get(k) else {
            return false;
        };
        let mut sides = self.sides(k).into_iter().flatten();
        !self.armed[k]
            && sides.all(|i| still(self.free.place(i).0))
            && -c.clearance < self.check_gap(k, 0.0)
    }

    /// The states of `groups` at `t` by their exact motion (copies).
    fn states_at(&self, groups: &[usize], t: f64) -> SmallVec<[(usize, Rows); 2]> {
        groups
            .iter()
            .map(|&g| {
                let (t0, x) = &self.exact[g];
                let mut x = Rows::from_slice(x);
                self.free.propagate(g, *t0, t, &mut x);
                (g, x)
            })
            .collect()
    }

    /// A rigid contact judged rigid that opens below its judging gap again
    /// without touching is judged afresh on its next approach (`state(g)`:
    /// its sides' groups' states now).
    fn disarm_if_open<'s>(&mut self, k: usize, state: impl Fn(usize) -> Option<&'s [f64]>) {
        if self.armed.get(k) != Some(&true) {
            return;
        }
        let c = &self.model.contacts()[k];
        let (mut s, mut sd) = (-c.clearance, 0.0);
        for (side, sign) in [(c.pair.left(), 1.0), (c.pair.right(), -1.0)] {
            if let Some(i) = side {
                let (g, j) = self.free.place(i);
                if let Some(x) = state(g) {
                    s += sign * x[2 * j];
                    sd += sign * x[2 * j + 1];
                }
            }
        }
        if s < self.pre[k] && sd < 0.0 {
            self.armed[k] = false;
        }
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
    /// at `t` (`state(g)`), as if they moved exactly from there. The modal
    /// bound is tried only where the energy bound falls short of `enough`
    /// after `t` (a release needs its lookahead, a check all it can get).
    fn bound<'s>(
        &self,
        k: usize,
        t: f64,
        enough: f64,
        state: impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        if let Some(c) = self.model.contacts().get(k) {
            if let Some(until) = self.alike_bound(c, k, t, &state) {
                return Some(until);
            }
        }
        let remaining = self.opts.t_end - t;
        let rate = self
            .sides(k)
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
        let start = horizon;
        let quadratic = loop {
            let zdd = self.free.base_peak(t, t + horizon);
            let tau = match self.model.contacts().get(k) {
                Some(c) => self.bound_over(c, k, (horizon, zdd), &state),
                None => {
                    let s = k - self.model.contacts().len();
                    self.storey_bound_over(s, (horizon, zdd), &state)
                }
            };
            match tau {
                Some(tau) if tau <= floor && self.is_rigid(k) => {
                    // (A rigid contact's jump is taken where its gap is
                    // reached, not within the floor of it.)
                    break self.locate_gap(k, t, 2.0 * floor, &state);
                }
                Some(tau) if tau < horizon || horizon >= remaining => {
                    break (tau > floor && t + tau > t).then_some(t + tau);
                }
                Some(_) => horizon = remaining.min(2.0 * horizon),
                None => break None,
            }
        };
        // Both bounds hold: the later wins.
        let reached = quadratic.map_or(0.0, |until| until - t);
        if reached >= enough.min(remaining) {
            return quadratic;
        }
        // Both bounds hold: the later wins.
        let modal = self.modal_until(
            k,
            t,
            (start.max(reached), remaining, reached == 0.0),
            &state,
        );
        match (quadratic, modal) {
            (Some(a), Some(b)) => Some(a.max(b)),
            (a, b) => a.or(b),
        }
    }

    /// The time within `horizon` until which contact `c` (index `k`) stays
    /// inactive by the bound from the sides' states, the base's |z̈| below
    /// `zdd` over the horizon; None: active now.
    fn bound_over<'s>(
        &self,
        c: &Contact,
        k: usize,
        (horizon, zdd): (f64, f64),
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let (mut s0, mut sd0, mut acc) = (-c.clearance, 0.0, 0.0);
        // The rounding of s: a gap that close to activation and closing is
        // active (else checks would hover there at rounding-sized steps).
        let mut size = c.clearance;
        // Every body feels the base as −m z̈, so between two bodies it
        // cancels in s̈ (it still feeds their energies); against a wall,
        // which moves with the base, it does not.
        let zdd_in_gap = if c.pair.left().is_some() && c.pair.right().is_some() {
            0.0
        } else {
            zdd
        };
        for (side, sign) in [c.pair.left(), c.pair.right()].into_iter().zip([1.0, -1.0]) {
            let Some(i) = side else { continue };
            let (g, j) = self.free.place(i);
            let x = state(g);
            size += x[2 * j].abs();
            s0 += sign * x[2 * j];
            sd0 += sign * x[2 * j + 1];
            let group = &self.free.groups()[g];
            let energy = group.energy_ahead(x, horizon, zdd);
            acc += group.acceleration_bound(j, energy, zdd_in_gap);
        }
        if !(s0.is_finite() && sd0.is_finite() && acc.is_finite()) {
            return None;
        }
        let speed = sd0.abs() + acc * horizon;
        // A rigid contact opening past its gap (just after its jump, at
        // s = 0 to rounding) is judged again only once it closes.
        let gap = self.check_gap(k, speed);
        if self.is_rigid(k) && sd0 <= 0.0 {
            s0 = s0.min(gap);
        }
        let d = gap - s0;
        Some(reach_time(d, sd0, 0.5 * acc, size)?.min(horizon))
    }

    /// Schedules contact k's next check (both sides exact) from `t`, or
    /// returns true if it is active now.
    fn schedule(&mut self, k: usize, t: f64) -> bool {
        self.generation[k] += 1;
        match self.safe_until(k, t) {
            None => true,
            Some(until) => {
                let until = self.free.sample_before(t, until);
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

    /// Whether check k (a contact or a storey) has a side in the active
    /// set.
    fn touches_set(&self, k: usize) -> bool {
        self.sides(k)
            .into_iter()
            .flatten()
            .any(|i| self.slot[i].is_some())
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
mod tests;
