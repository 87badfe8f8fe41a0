//! A stepper per cluster (docs/theory.md §10, D39 in docs/decisions.md):
//! each cluster of integrated groups is a set of its own, stepped with
//! its own step and error control.
//!
//! No contact joins two sets: a set's boundary contacts end on exactly
//! moving groups or walls, so sets never read each other's motion. The
//! run steps the earliest set (ties: an open step first), so every other
//! set's last step holds that time: a set at `t_B` last stepped from a
//! time at or before the earliest. That last step stays *open* — its
//! impacts unlogged, its membership unsettled — until its set is the
//! earliest again ([`Run::close`]). A check of two exactly moving groups
//! is due in the run's loop when it comes before the earliest set (a
//! set's steps do not take it: another set may have run past it).
//! Samples are taken up to the earliest of both, from the open steps.
//!
//! A join at `t` (the joining set is the earliest, at `t`) merges every
//! set the joining groups touch: each is taken back to `t` — its open
//! step integrated again from its start to `t` ([`Run::bring_to`]) — and
//! the merged groups form one set. A rebuild splits its groups into the
//! clusters that no model contact joins, each its own set.

use super::*;
use crate::model::hysteresis::StoreyLaw;

/// Whether a run may step each cluster on its own: not with a tape or
/// tangent columns (one record in time order), the energy audit, a
/// Bouc–Wen storey (its states ride in one set's state) or extrema (their
/// scans follow one set), or a law that needs the onset velocity (its
/// events follow one set). Switching storeys (bilinear, IMK) may: their
/// memory is each set's, synced into the run's ([`Run::sync_storeys`]).
pub(super) fn clustered(
    model: &Model,
    opts: &SimulationOptions,
    tape: bool,
    columns: usize,
) -> bool {
    !tape
        && columns == 0
        && !opts.energy
        && opts.extrema_window.is_none()
        && !model
            .storeys()
            .iter()
            .any(|s| matches!(s.law, StoreyLaw::BoucWen(_)))
        && !model
            .contacts()
            .iter()
            .any(|c| c.law.needs_impact_velocity())
}

impl Run<'_> {
    /// The earliest set: its time, whether its last step is open, and
    /// where it is (None: the current one, else its place in `sets`).
    /// Among sets at one time, one with an open step comes first.
    pub(super) fn earliest(&self) -> Option<(f64, bool, Option<usize>)> {
        // (The key's order written out: the generic tuple comparison and
        // option tests cost a third of this loop, run before every step.)
        let key = |s: &ActiveSet| (s.st.t(), s.open.is_none());
        let mut best = self.set.as_ref().map(|s| (key(s), None));
        for (p, s) in self.sets.iter().enumerate() {
            let (t, closed) = key(s);
            let before = match best {
                None => true,
                Some(((tb, closed_b), _)) => t < tb || (t == tb && !closed && closed_b),
            };
            if before {
                best = Some(((t, closed), Some(p)));
            }
        }
        best.map(|((t, closed), at)| (t, !closed, at))
    }

    /// Makes the set at `which` (see [`Run::earliest`]) the current one;
    /// the impact log goes with it.
    pub(super) fn make_current(&mut self, which: Option<usize>) {
        let Some(p) = which else { return };
        let mut next = self.sets.swap_remove(p);
        self.park_current();
        next.scan.impacts = std::mem::take(&mut self.impacts);
        self.set = Some(next);
    }

    /// Parks the current set among the others; the impact log stays with
    /// the run.
    pub(super) fn park_current(&mut self) {
        if let Some(mut set) = self.set.take() {
            self.impacts = std::mem::take(&mut set.scan.impacts);
            self.sets.push(set);
        }
    }

    /// Closes the current set's open step at `t` (every set has reached
    /// `t`, and the samples are taken up to it): its impacts are logged,
    /// its extrema scanned, its event applied, and its membership settled
    /// — joined where it reached an activation, else released where its
    /// contacts have separated.
    pub(super) fn close(&mut self, t: f64) -> Result<(), IntegrationError> {
        let Some(set) = self.set.as_mut() else {
            return Ok(());
        };
        let Some(reached) = set.open.take() else {
            return Ok(());
        };
        let pending = set.pending;
        self.scan_open();
        self.apply_deferred(t);
        self.apply_set_event()?;
        let next = match reached {
            Some((_, k)) => self.join(k, t).map(|_| None),
            None if pending.is_none() => self.release(),
            None => Ok(None),
        }?;
        match next {
            Some((ta, k)) => self.join(k, ta),
            None => Ok(()),
        }
    }

    /// Logs the current set's open step's impacts and scans its extrema,
    /// once: before the step's samples are taken (under a record they move
    /// the exactly moving groups' references up to the sample).
    pub(super) fn scan_open(&mut self) {
        let Some(set) = self.set.as_mut() else {
            return;
        };
        if set.open.is_none() && set.scanned {
            return;
        }
        if !set.scanned {
            set.scanned = true;
            set.scan.scan(&mut set.st, &mut set.sys);
            if let Some(h) = set.scan.entry_limit(set.st.h_next()) {
                set.st.limit_next_step(h);
            }
            self.scan_set_step();
        }
    }

    /// The clusters of `groups` (ascending): the parts no model contact
    /// joins, each ascending, in the order of their first group.
    pub(super) fn components(&self, groups: &[usize]) -> Vec<Vec<usize>> {
        let mut part = vec![usize::MAX; groups.len()];
        let mut parts = Vec::new();
        for start in 0..groups.len() {
            if part[start] != usize::MAX {
                continue;
            }
            let id = parts.len();
            part[start] = id;
            let (mut members, mut stack) = (vec![groups[start]], vec![groups[start]]);
            while let Some(g) = stack.pop() {
                for &k in &self.group_contacts[g] {
                    for h in self.groups_of(k) {
                        if let Ok(q) = groups.binary_search(&h) {
                            if part[q] == usize::MAX {
                                part[q] = id;
                                members.push(h);
                                stack.push(h);
                            }
                        }
                    }
                }
            }
            members.sort_unstable();
            parts.push(members);
        }
        parts
    }

    /// The set holding body `i`: None if it moves exactly, Some(None) the
    /// current set, Some(Some(p)) the parked set `p`.
    fn holder(&self, i: usize) -> Option<Option<usize>> {
        self.slot[i]?;
        if self
            .set
            .as_ref()
            .is_some_and(|s| s.bodies.binary_search(&i).is_ok())
        {
            return Some(None);
        }
        self.sets
            .iter()
            .position(|s| s.bodies.binary_search(&i).is_ok())
            .map(Some)
    }

    /// Takes parked set `b` back to `t` (at or after its open step's
    /// start): its open step is integrated again from its start up to
    /// `t`, and the steps' impacts logged. (Nothing can have become
    /// active in it: the open step found nothing there.) The activations
    /// it was heading for are checked again.
    fn bring_to(&mut self, b: &mut ActiveSet, t: f64) -> Result<(), IntegrationError> {
        let open = b.open.take();
        for (ta, k) in [b.pending.take(), open.flatten()].into_iter().flatten() {
            self.generation[k] += 1;
            self.queue
                .push(Reverse((Time(ta.max(t)), k, self.generation[k])));
        }
        std::mem::swap(self.impact_log(), &mut b.scan.impacts);
        let result = (|| {
            if b.st.t() > t {
                // (Only the current set's open step is scanned before it
                // closes, and a join closes it.) An event at the step's
                // end lies past `t`: its branches stay as at the start.
                debug_assert!(!b.scanned);
                b.event = None;
                b.st.reset(&mut b.sys, b.saved.0, &b.saved.1)?;
                while b.st.t() < t {
                    b.st.step(&mut b.sys, t)?;
                    b.scan.scan(&mut b.st, &mut b.sys);
                }
            } else if open.is_some() && !b.scanned {
                b.scan.scan(&mut b.st, &mut b.sys);
            }
            b.scanned = true;
            if let Some(e) = b.event.take() {
                apply_event(&mut b.st, &mut b.sys, e)?;
            }
            Ok(())
        })();
        std::mem::swap(self.impact_log(), &mut b.scan.impacts);
        result
    }

    /// The impact log, wherever it is: with the current set, else the
    /// run.
    pub(super) fn impact_log(&mut self) -> &mut Vec<ImpactRecord> {
        match self.set.as_mut() {
            Some(set) => &mut set.scan.impacts,
            None => &mut self.impacts,
        }
    }

    /// Joins the groups of check k to the sets at `t` (the current set is
    /// the earliest, at `t`): every set holding a side of k, or a body
    /// that a contact of k's exactly moving groups reaches, merges with
    /// them into one set (taken back to `t`); the checks of the joining
    /// groups lapse.
    pub(super) fn join_clusters(&mut self, k: usize, t: f64) -> Result<(), IntegrationError> {
        let new: Vec<usize> = self
            .groups_of(k)
            .into_iter()
            .filter(|&g| !self.in_set[g])
            .collect();
        let mut touched: Vec<usize> = self.sides(k).into_iter().flatten().collect();
        for &g in &new {
            for &kk in &self.group_contacts[g] {
                touched.extend(self.sides(kk).into_iter().flatten());
            }
        }
        let (mut with_current, mut parked) = (false, Vec::new());
        for i in touched {
            match self.holder(i) {
                Some(None) => with_current = true,
                Some(Some(p)) if !parked.contains(&p) => parked.push(p),
                _ => {}
            }
        }
        if !with_current {
            self.park_current();
            // (Parking moved no parked set: it went to the end.)
        }
        parked.sort_unstable();
        let mut merging = Vec::with_capacity(parked.len());
        // Descending: each removal leaves the smaller places as they were.
        for p in parked.into_iter().rev() {
            let mut b = self.sets.swap_remove(p);
            if let Err(e) = self.bring_to(&mut b, t) {
                // The run ends here: every set taken out goes back, so
                // that the failure's state holds their bodies.
                self.sets.push(b);
                self.sets.append(&mut merging);
                return Err(e);
            }
            merging.push(b);
        }
        let mut groups = new;
        for s in self.set.iter().chain(&merging) {
            groups.extend_from_slice(&s.groups);
        }
        groups.sort_unstable();
        groups.dedup();
        self.lapse_checks_of(k);
        self.merging = merging;
        self.rebuild(groups, t)
    }
}
