//! Rigid impacts under the local integrator (docs/theory.md §12): exact
//! free motion between instantaneous impacts.
//!
//! A rigid contact between two exactly moving groups (or a group and a
//! wall) is checked, by the same bounds as a soft contact's activation
//! (so no impact is missed, grazing ones included), first against where
//! it is judged (where its law starts to act), then, judged rigid,
//! against its touch s = 0. At the touch the velocities jump by the
//! impulse μ(1 + e)U, the energy audit takes the loss, the impact log the
//! jump, and both groups move exactly again from there: no step is taken.
//! Where the rigid idealisation breaks (the global run's reasons, the same
//! judgement: a resting contact, an approach at the absolute tolerance, a
//! neighbour's impact overlapping, a neighbour about to reach its law or
//! being integrated) the groups join the integrated set, whose own model
//! takes the contact by its law, until the set lets them go: a soft
//! episode.

use super::*;
use crate::impact::ImpactError;
use crate::model::RigidLimits;
use crate::simulate::switches::{judged, reaches_within, EpisodeReason, SoftEpisode};

/// Per contact: its rigid limit (rigid impacts only) and where it is
/// judged: its law's onset approach at the impact threshold (negative for
/// the exponential law; 0 for the others and for soft contacts).
pub(super) fn rigid_parts(
    model: &Model,
    opts: &SimulationOptions,
    like: &[bool],
) -> Result<(RigidLimits, Vec<f64>), OptionsError> {
    let nc = model.contacts().len();
    let laws = model
        .rigid_limits()
        .map_err(|e| OptionsError(e.to_string()))?;
    let mut pre: Vec<f64> = Vec::with_capacity(nc);
    let mut judged = 0.0;
    for (k, c) in model.contacts().iter().enumerate() {
        if !like[k] {
            judged = c.law.onset_approach(opts.impact_force_threshold).min(0.0);
        }
        pre.push(if model.impacts(k).is_rigid() {
            judged
        } else {
            0.0
        });
    }
    Ok((laws, pre))
}

impl Run<'_> {
    /// The gap a check of contact or storey `k` must stay below while
    /// its sides move at relative speed `speed`: a rigid contact's judging
    /// gap, or its touch once judged rigid; else the activation gap.
    pub(super) fn check_gap(&self, k: usize, speed: f64) -> f64 {
        match self.rigid.get(k) {
            Some(_) if self.armed[k] => 0.0,
            Some(_) => self.pre[k],
            None => self.activation[k].gap(speed),
        }
    }

    /// Rigid contact k's gap ([`Run::check_gap`]) where the bounds leave
    /// it within their floor of `t` (the sides' states at `t`: `state`):
    /// the time it is reached on the sides' exact motion, by Newton's
    /// steps from `t`, to rounding. None: reached at `t` already, or not
    /// within `limit` (then taken as reached at `t`, as before).
    pub(super) fn locate_gap<'s>(
        &self,
        k: usize,
        t: f64,
        limit: f64,
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let c = &self.model.contacts()[k];
        let gap = self.check_gap(k, 0.0);
        let at = |tau: f64| {
            let (mut s, mut sd) = (-c.clearance - gap, 0.0);
            for (side, sign) in [c.pair.left(), c.pair.right()].into_iter().zip([1.0, -1.0]) {
                let Some(i) = side else { continue };
                let (g, j) = self.free.place(i);
                let mut x = Rows::from_slice(state(g));
                self.free.propagate(g, t, t + tau, &mut x);
                s += sign * x[2 * j];
                sd += sign * x[2 * j + 1];
            }
            (s, sd)
        };
        let mut tau = 0.0;
        for _ in 0..8 {
            let (s, sd) = at(tau);
            if s >= 0.0 {
                break;
            }
            let next = tau - s / sd;
            if !(sd > 0.0 && next <= limit) {
                return None;
            }
            if next == tau {
                break;
            }
            tau = next;
        }
        (t + tau > t).then_some(t + tau)
    }

    /// Whether check `k` is a rigid contact.
    pub(super) fn is_rigid(&self, k: usize) -> bool {
        self.rigid.get(k).is_some()
    }

    /// Rigid contact k found at its gap at `t` (both sides moving
    /// exactly): where its law starts acting ([`Run::check_gap`]), judged
    /// rigid (checked on against its touch, true) or soft (its episode
    /// opened for the join that follows, false); at its touch, judged
    /// again (a neighbour may have struck since), its jump taken (true) or
    /// an episode from there (false). Any other check: false.
    pub(super) fn rigid_touch(&mut self, k: usize, t: f64) -> Result<bool, IntegrationError> {
        let Some(law) = self.rigid.get(k) else {
            return Ok(false);
        };
        // A neighbour integrated: the contact joins it.
        if let Some(other) = self.integrated_neighbour(k) {
            self.open_episode(k, t, EpisodeReason::Cluster { other });
            return Ok(false);
        }
        let groups = self.groups_of(k);
        let mut states = self.states_at(&groups, t);
        let c = &self.model.contacts()[k];
        let sides = [(c.pair.left(), 1.0), (c.pair.right(), -1.0)];
        let (mut u, mut pressing) = (0.0, 0.0);
        for (i, sign) in sides.iter().filter_map(|&(i, s)| Some((i?, s))) {
            let (g, j) = self.free.place(i);
            let Some((_, x)) = states.iter().find(|(h, _)| *h == g) else {
                continue;
            };
            u += sign * x[2 * j + 1];
            pressing += sign * self.free.acceleration(g, t, x, j);
        }
        if u <= self.opts.atol {
            self.open_episode(k, t, EpisodeReason::Slow { velocity: u });
            return Ok(false);
        }
        // (At the touch the impact at u serves the judging and the jump;
        // at the law's onset the judging's part of it alone.)
        let onset = !self.armed[k] && self.pre[k] < 0.0;
        let failed = |e: ImpactError| IntegrationError::RigidImpact {
            t,
            contact: k,
            reason: e.to_string(),
        };
        let (r, judging) = if onset {
            (None, law.judging(u).map_err(failed)?)
        } else {
            let r = law.impact(u).map_err(failed)?;
            (Some(r), (r.duration, r.rebound_velocity))
        };
        if let Some(reason) = judged(judging, pressing, |d| self.neighbours(k, t, d)) {
            // (Its duration kept for the neighbours' overlap, as a
            // jump's: `Switches::soft_impact`.)
            self.last_impact[k] = (t, judging.0);
            self.open_episode(k, t, reason);
            return Ok(false);
        }
        let Some(r) = r else {
            // Rigid: on to the touch.
            self.armed[k] = true;
            self.generation[k] += 1;
            if self.schedule(k, t) {
                return self.rigid_touch(k, t);
            }
            return Ok(true);
        };
        // The jump: left side −P/m, right side +P/m.
        for (i, sign) in sides.iter().filter_map(|&(i, s)| Some((i?, s))) {
            let (g, j) = self.free.place(i);
            let Some((_, x)) = states.iter_mut().find(|(h, _)| *h == g) else {
                continue;
            };
            x[2 * j + 1] -= sign * r.impulse / self.model.bodies()[i].mass;
        }
        for (g, x) in states {
            self.before_move(g, t);
            self.deferred.retain(|(h, ..)| *h != g);
            self.exact[g] = (t, x);
        }
        if let Some(energy) = self.energy.as_mut() {
            energy.sums[2] += r.energy_lost;
        }
        self.impact_log().push(ImpactRecord::jump(k, t, r));
        self.last_impact[k] = (t, r.duration);
        self.armed[k] = false;
        self.local.rigid_impacts += 1;
        self.reschedule(&groups, t)?;
        Ok(true)
    }

    /// The neighbours' reason for rigid contact k's impact at `t` of
    /// estimated `duration`, as the global run judges it
    /// ([`crate::simulate::switches`]): a contact sharing a body, in
    /// contact order, whose impact began within its own duration before
    /// (an overlap), or that would reach its law within this one's (ahead).
    fn neighbours(&self, k: usize, t: f64, duration: f64) -> Option<EpisodeReason> {
        let mine = self.sides(k);
        let shares = |j: usize| {
            self.sides(j)
                .iter()
                .flatten()
                .any(|b| mine.contains(&Some(*b)))
        };
        let mut near: SmallVec<[usize; 8]> = self
            .groups_of(k)
            .into_iter()
            .flat_map(|g| self.group_contacts[g].iter().copied())
            .filter(|&j| j != k && shares(j))
            .collect();
        near.sort_unstable();
        near.dedup();
        near.into_iter().find_map(|j| {
            if let Some(overlap) = EpisodeReason::overlap(j, t, self.last_impact[j]) {
                return Some(overlap);
            }
            if !self.is_rigid(j) {
                return None;
            }
            let c = &self.model.contacts()[j];
            let (mut s, mut sd, mut sdd) = (-c.clearance, 0.0, 0.0);
            for (side, sign) in [(c.pair.left(), 1.0), (c.pair.right(), -1.0)] {
                let Some(i) = side else { continue };
                let (g, jj) = self.free.place(i);
                let (t0, x) = &self.exact[g];
                let mut x = Rows::from_slice(x);
                self.free.propagate(g, *t0, t, &mut x);
                s += sign * x[2 * jj];
                sd += sign * x[2 * jj + 1];
                sdd += sign * self.free.acceleration(g, t, &x, jj);
            }
            let within = reaches_within((s, sd, sdd), self.pre[j], duration)?;
            Some(EpisodeReason::Ahead {
                other: j,
                within,
                duration,
            })
        })
    }

    /// Another contact of k's groups with a side in an integrated set, if
    /// any (a jump would change the motion that set's steps have
    /// followed); k itself if only it reaches a set.
    fn integrated_neighbour(&self, k: usize) -> Option<usize> {
        let mut others = self
            .groups_of(k)
            .into_iter()
            .flat_map(|g| self.group_contacts[g].iter().copied());
        others
            .find(|&j| j != k && self.touches_set(j))
            .or_else(|| self.touches_set(k).then_some(k))
    }

    /// Every check of `groups` scheduled again from `t` (their motion
    /// changed there); those active at once (a chain's next touch) are
    /// taken in turn.
    fn reschedule(&mut self, groups: &[usize], t: f64) -> Result<(), IntegrationError> {
        let mut active: SmallVec<[usize; 4]> = SmallVec::new();
        for kk in self.checks_of(groups) {
            if !self.touches_set(kk) && self.schedule(kk, t) {
                active.push(kk);
            }
        }
        for kk in active {
            if !self.touches_set(kk) {
                self.join(kk, t)?;
            }
        }
        Ok(())
    }

    /// How long group `g` stays in a set after joining: `lookahead`, or
    /// none for a group whose contacts are all rigid and that has no
    /// checked storey (its episode ends when its contacts separate).
    pub(super) fn rigid_lookahead(&self, g: usize, lookahead: f64) -> f64 {
        let rigid = self.group_contacts[g].iter().all(|&k| self.is_rigid(k));
        if rigid && self.group_storeys[g].is_empty() {
            0.0
        } else {
            lookahead
        }
    }

    /// Opens rigid contact k's soft episode at `t` for this reason.
    fn open_episode(&mut self, k: usize, t: f64, reason: EpisodeReason) {
        self.armed[k] = false;
        if self
            .episodes
            .iter()
            .any(|e| e.contact == k && e.end_time.is_nan())
        {
            return;
        }
        self.episodes.push(SoftEpisode {
            contact: k,
            start_time: t,
            end_time: f64::NAN,
            reason,
        });
    }

    /// Ends, at `t`, the soft episodes whose contacts no set holds any
    /// more.
    pub(super) fn end_episodes(&mut self, t: f64) {
        for i in 0..self.episodes.len() {
            let k = self.episodes[i].contact;
            if self.episodes[i].end_time.is_nan() && !self.touches_set(k) {
                self.episodes[i].end_time = t;
            }
        }
    }
}
