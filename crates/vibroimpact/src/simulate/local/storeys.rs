//! Hysteretic storeys under the local integrator (docs/theory.md §10,
//! §11).
//!
//! A storey on a linear branch (an elastic law, or a bilinear storey's
//! elastic branch: `F = k d + F₀`) is a spring with a constant force: its
//! group moves exactly about its rest state ([`FreeMotion::set_rest`]).
//! A bilinear storey leaves its branch only at yield, `d` reaching the
//! branch's window `d₀ − z₀ ± u_y`; that approach is checked as a
//! contact's is, by the same energy bound on the group's motion, against
//! the window shrunk by [`YIELD_APPROACH`] of `u_y`. A storey that gets
//! that close sends its group into the set, whose steps switch branches at
//! located events as the global run does; the group moves exactly again
//! once all its storeys are elastic and the bound keeps them clear of
//! yield for a while. A Bouc–Wen storey's `z` never follows its drift
//! linearly: its group is integrated throughout.
//!
//! The run keeps every storey's memory ([`Run::storeys`]: branches, and
//! the Bouc–Wen states in [`Run::hysteretic`]); a set carries its own
//! storeys' in its system while it lives.

use super::*;
use crate::model::hysteresis::StoreyLaw;

/// How close to yield, as a part of the yield drift, a storey sends its
/// group into the set: the set then meets the yield with its events, and
/// the checks of a storey that swings just below yield do not crawl.
pub(super) const YIELD_APPROACH: f64 = 0.02;

/// How close to unloading a plastic storey sends its group into the set:
/// where its outward drift rate could vanish within this many radians of
/// the group's fastest rate (half the set's release lookahead,
/// `RELEASE_PERIOD_FRACTION`, so a group released on a plastic branch is
/// not taken back at its first check).
const UNLOAD_APPROACH: f64 = 0.025;

/// Where the Bouc–Wen states (z, e) of a set's storeys sit: (index in the
/// set's state by its terms `set`, index in the whole extended state by
/// the run's terms `whole`), for the set's `storeys` (model indices).
pub(super) fn hysteretic_places<'a>(
    set: &'a StoreyTerms,
    whole: &'a StoreyTerms,
    storeys: &'a [usize],
) -> impl Iterator<Item = (usize, usize)> + 'a {
    storeys
        .iter()
        .enumerate()
        .filter_map(|(ks, &s)| Some((set.state_index(ks)?, whole.state_index(s)?)))
}

impl Run<'_> {
    /// The bodies of check k: a contact's sides, or a storey's (above,
    /// below).
    pub(super) fn sides(&self, k: usize) -> [Option<usize>; 2] {
        let nc = self.model.contacts().len();
        match self.model.contacts().get(k) {
            Some(c) => [c.pair.left(), c.pair.right()],
            None => {
                let (below, above) = self.storeys.ends(k - nc);
                [Some(above), below]
            }
        }
    }

    /// Whether storey `s` needs checks and events (a bilinear or Bouc–Wen
    /// law; an elastic one is a spring).
    pub(super) fn checked_storey(model: &Model, s: usize) -> bool {
        !matches!(model.storeys()[s].law, StoreyLaw::Elastic { .. })
    }

    /// The time within `horizon` until which storey `s` (its group moving
    /// exactly from `state`, the base's |z̈| below `zdd`) surely stays on
    /// its linear branch, clear of yield by [`YIELD_APPROACH`]; None: not
    /// on a linear branch, or that close already.
    pub(super) fn storey_bound_over<'s>(
        &self,
        s: usize,
        (horizon, zdd): (f64, f64),
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let window = self.storeys.linear_window(s, YIELD_APPROACH);
        let plastic = self.storeys.plastic_sign(s);
        if window.is_none() && plastic.is_none() {
            return None;
        }
        let (below, above) = self.storeys.ends(s);
        let (g, ja) = self.free.place(above);
        let jb = below.map(|b| self.free.place(b).1);
        let x = state(g);
        let of = |j: Option<usize>, r: usize| j.map_or(0.0, |j| x[2 * j + r]);
        let (d, dd) = (x[2 * ja] - of(jb, 0), x[2 * ja + 1] - of(jb, 1));
        let group = &self.free.groups()[g];
        let e = group.energy_ahead(x, horizon, zdd);
        // Between two bodies the base's acceleration cancels in the drift's
        // (it still feeds the energy); to the ground it does not.
        let acc = match jb {
            Some(jb) => group.acceleration_bound(ja, e, 0.0) + group.acceleration_bound(jb, e, 0.0),
            None => group.acceleration_bound(ja, e, zdd),
        };
        if !(d.is_finite() && dd.is_finite() && acc.is_finite()) {
            return None;
        }
        let Some((lo, hi)) = window else {
            // On the plastic branch until the drift turns: its outward rate
            // falls at most at `acc`. Close to the turn (within
            // `UNLOAD_APPROACH` radians of the group's fastest rate) the
            // group joins the set, which locates it.
            let outward = dd * plastic.unwrap_or(1.0);
            let tau = if acc > 0.0 {
                outward / acc
            } else {
                f64::INFINITY
            };
            let soon = UNLOAD_APPROACH / group.rate().max(f64::MIN_POSITIVE);
            return (outward > 0.0 && tau > soon).then_some(tau.min(horizon));
        };
        let size = d.abs() + (hi - lo);
        let up = reach_time(hi - d, dd, 0.5 * acc, size)?;
        let down = reach_time(d - lo, -dd, 0.5 * acc, size)?;
        Some(up.min(down).min(horizon))
    }

    /// Gives group `g` the propagators of its storeys' branches and sets
    /// its rest state from their constant forces (each on a linear branch,
    /// elastic or plastic; an elastic law's force is zero).
    pub(super) fn settle_rest(&mut self, g: usize) -> Result<(), IntegrationError> {
        let group = &self.free.groups()[g];
        let first = group.bodies()[0];
        let mut f = vec![0.0; group.bodies().len()];
        let mut k = Vec::new();
        for s in group.storeys() {
            let st = &self.model.storeys()[s];
            let (kb, f0) = self.storeys.linear_branch(s).ok_or_else(|| {
                IntegrationError::InvalidOptions(format!(
                    "storey {}: not on a linear branch where its group was to move exactly (internal error)",
                    s + 1
                ))
            })?;
            k.push(kb - st.p_delta);
            f[self.free.place(st.above).1] -= f0;
            if let Some(b) = st.below {
                f[self.free.place(b).1] += f0;
            }
        }
        self.free
            .set_storey_stiffness(g, &k)
            .map_err(|e| IntegrationError::InvalidOptions(e.to_string()))?;
        self.free.set_rest(g, &f).map_err(|residual| {
            IntegrationError::InvalidOptions(format!(
                "the rest state of {}'s group: its springs balance its storeys' forces only to {residual:.1e}",
                self.model.bodies()[first].name
            ))
        })
    }

    /// Copies every set's storeys' memory (branches, Bouc–Wen states at
    /// its current point) into the run's: the current set's, the parked
    /// ones' and those merging (their branches hold over their open
    /// steps: an event at a step's end applies when it closes); only the
    /// current set's if not `all`.
    pub(super) fn sync_storeys(&mut self, all: bool) {
        let first = 2 * self.model.bodies().len();
        let others = self.sets.iter().chain(&self.merging).filter(|_| all);
        for set in self
            .set
            .iter()
            .chain(others)
            .filter(|s| !s.storeys.is_empty())
        {
            let (terms, y) = (set.sys.chain().storeys(), set.st.y());
            for (ks, &s) in set.storeys.iter().enumerate() {
                self.storeys.set_branch(s, terms.branch(ks));
            }
            for (i, w) in hysteretic_places(terms, &self.storeys, &set.storeys) {
                self.hysteretic[w - first..w - first + 2].copy_from_slice(&y[i..i + 2]);
            }
        }
    }

    /// Gives a new set's system its storeys' memory (`storeys`, model
    /// indices) and appends their Bouc–Wen states to its state `y` (the
    /// bodies' (u, v) so far).
    pub(super) fn load_storeys(&self, sys: &mut SetSystem, storeys: &[usize], y: &mut Vec<f64>) {
        let first = 2 * self.model.bodies().len();
        let terms = sys.chain_mut().storeys_mut();
        for (ks, &s) in storeys.iter().enumerate() {
            terms.set_branch(ks, self.storeys.branch(s));
        }
        y.resize(y.len() + terms.states(), 0.0);
        for (i, w) in hysteretic_places(terms, &self.storeys, storeys) {
            y[i..i + 2].copy_from_slice(&self.hysteretic[w - first..w - first + 2]);
        }
    }

    /// Whether group `g` of the set must stay for its storeys at `t`: one
    /// is off a linear branch (Bouc–Wen) or softened past zero stiffness,
    /// or may come within [`YIELD_APPROACH`] of yield or within
    /// `UNLOAD_APPROACH` of unloading within `lookahead` (the group's
    /// propagators and rest state are settled for the judgement). `state` is the group's
    /// interleaved state in the set.
    pub(super) fn storeys_engaged(
        &mut self,
        g: usize,
        t: f64,
        lookahead: f64,
        state: &[f64],
    ) -> Result<bool, IntegrationError> {
        let nc = self.model.contacts().len();
        let storeys = &self.group_storeys[g];
        if storeys.is_empty() {
            return Ok(false);
        }
        // Off a linear branch (Bouc–Wen), or softened past zero stiffness
        // by P-Δ on a plastic one (the bounds need a positive energy).
        let model = self.model;
        if storeys.iter().any(|&s| {
            self.storeys
                .linear_branch(s)
                .is_none_or(|(k, _)| k < model.storeys()[s].p_delta)
        }) {
            return Ok(true);
        }
        self.settle_rest(g)?;
        let storeys = &self.group_storeys[g];
        // A plastic storey needs only to stay clear of its reversal's
        // approach for a while past it (its checks then come down to
        // it), not the set's whole lookahead: a set's steps may last a
        // good part of a plastic excursion.
        let rate = self.free.groups()[g].rate().max(f64::MIN_POSITIVE);
        let plastic = (2.0 * UNLOAD_APPROACH / rate).min(lookahead);
        Ok(storeys.iter().any(|&s| {
            let need = match self.storeys.plastic_sign(s) {
                Some(_) => plastic,
                None => lookahead,
            };
            self.bound(nc + s, t, need, |_| state)
                .is_none_or(|until| until - t < need)
        }))
    }

    /// The storeys' forces at the point of the whole extended state `y`
    /// (interleaved, the Bouc–Wen states after it), in model order.
    pub(super) fn storey_forces(&self, y: &[f64], out: &mut [f64]) {
        for (k, f) in out.iter_mut().enumerate() {
            *f = self.storeys.force(k, y);
        }
    }

    /// Applies the event the set's last kept step ended at, if any (a
    /// branch switch or an onset velocity; the set's stepper restarts
    /// there).
    pub(super) fn apply_set_event(&mut self) -> Result<(), IntegrationError> {
        if let Some(set) = self.set.as_mut() {
            if let Some(e) = set.event.take() {
                apply_event(&mut set.st, &mut set.sys, e)?;
            }
        }
        Ok(())
    }
}
