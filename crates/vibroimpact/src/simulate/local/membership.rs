//! The active set's edge and membership (docs/theory.md §10): contacts
//! with exactly moving bodies followed over the set's steps, due checks,
//! groups joining and leaving.

use smallvec::SmallVec;

use super::*;

/// Where the active set's last step meets an activation: the earliest
/// time and the contact.
pub(super) type Crossing = Option<(f64, usize)>;

/// The exactly moving groups of a set's boundary contacts at the ends of
/// its last step: (group, state at `ta`, state at `tb`).
pub(super) struct BoundaryEnds {
    ta: f64,
    tb: f64,
    /// (group, state at `ta`, state at `tb`); a set has few boundary
    /// groups, kept inline.
    groups: SmallVec<[(usize, Rows, Rows); 2]>,
}

impl BoundaryEnds {
    /// Body `i`'s (u, v) at `t` in `[ta, tb]`, if its group is here.
    fn body(&self, free: &FreeMotion, i: usize, t: f64) -> Option<(f64, f64)> {
        let (g, j) = free.place(i);
        let (_, xa, xb) = self.groups.iter().find(|(h, ..)| *h == g)?;
        Some(if t == self.tb {
            (xb[2 * j], xb[2 * j + 1])
        } else if t == self.ta {
            (xa[2 * j], xa[2 * j + 1])
        } else {
            let mut x = Rows::from_slice(xa);
            free.propagate(g, self.ta, t, &mut x);
            (x[2 * j], x[2 * j + 1])
        })
    }
}

/// The groups of a check's bodies ([`Run::groups_of`]): one or two, in
/// the check's order, without a repeat. (A plain pair, not a small
/// vector: asked after nearly every step, whose growth checks cost more
/// than the two lookups.)
#[derive(Clone, Copy, Debug)]
pub(super) struct CheckGroups {
    groups: [usize; 2],
    len: usize,
}

impl std::ops::Deref for CheckGroups {
    type Target = [usize];

    fn deref(&self) -> &[usize] {
        &self.groups[..self.len]
    }
}

impl IntoIterator for CheckGroups {
    type Item = usize;
    type IntoIter = std::iter::Take<std::array::IntoIter<usize, 2>>;

    fn into_iter(self) -> Self::IntoIter {
        self.groups.into_iter().take(self.len)
    }
}

impl Run<'_> {
    /// Contact k's (s, ṡ) at `t` within the set's last step, for a contact
    /// with one side in the set and the other moving exactly (or a wall).
    /// The exactly moving side's group is read from `ends` (its states at
    /// the step's ends) at the ends, and propagated from the start inside.
    pub(super) fn boundary_state(
        &mut self,
        set: &mut ActiveSet,
        ends: &BoundaryEnds,
        k: usize,
        t: f64,
    ) -> (f64, f64) {
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
                None => ends
                    .body(&self.free, i, t)
                    .unwrap_or_else(|| self.exact_body(i, t)),
            };
            s += sign * u;
            sd += sign * v;
        }
        (s, sd)
    }

    /// The exactly moving groups of the set's boundary contacts at the
    /// ends of its last step `[ta, tb]`: the start's carried from the
    /// previous step's end where the set went on from there.
    fn boundary_ends(&mut self, set: &mut ActiveSet) -> BoundaryEnds {
        let (ta, tb) = (set.saved.0, set.st.t());
        let mut carried = std::mem::take(&mut set.carried);
        let mut ends = BoundaryEnds {
            ta,
            tb,
            groups: SmallVec::new(),
        };
        for &k in &set.boundary {
            let c = &self.model.contacts()[k];
            for i in [c.pair.left(), c.pair.right()].into_iter().flatten() {
                let g = self.free.place(i).0;
                if self.slot[i].is_some() || ends.groups.iter().any(|(h, ..)| *h == g) {
                    continue;
                }
                let (t0, x0) = &self.exact[g];
                let xa = match carried.iter().find(|(h, t, _)| *h == g && *t == ta) {
                    Some((_, _, x)) => Rows::from_slice(x),
                    None => {
                        let mut x = Rows::from_slice(x0);
                        self.free.propagate(g, *t0, ta, &mut x);
                        x
                    }
                };
                let mut xb = Rows::from_slice(&xa);
                self.free.propagate(g, ta, tb, &mut xb);
                ends.groups.push((g, xa, xb));
            }
        }
        // (The carried list's buffer is kept from step to step.)
        carried.clear();
        carried.extend(
            ends.groups
                .iter()
                .map(|(g, _, xb)| (*g, tb, Rows::from_slice(xb))),
        );
        set.carried = carried;
        ends
    }

    /// The first time in the set's last step where a boundary contact
    /// becomes active.
    pub(super) fn boundary_crossing(&mut self, set: &mut ActiveSet) -> Crossing {
        let (ta, tb) = (set.saved.0, set.st.t());
        let ends = self.boundary_ends(set);
        let ends = &ends;
        let mut first: Crossing = None;
        for bi in 0..set.boundary.len() {
            let k = set.boundary[bi];
            // A rigid contact joins where it is judged ([`Run::check_gap`];
            // just after its jump it stands at s = 0 to rounding, opening:
            // not an approach).
            let (act, rigid) = (self.activation[k], self.is_rigid(k));
            let judged_at = self.check_gap(k, 0.0);
            let gap = move |s: f64, sd: f64| match rigid {
                true if sd <= 0.0 => (s - judged_at).min(-f64::MIN_POSITIVE),
                true => s - judged_at,
                false => act.margin(s, sd),
            };
            let (sa, sda) = self.boundary_state(set, ends, k, ta);
            let (sb, sdb) = self.boundary_state(set, ends, k, tb);
            let (ga, gb) = (gap(sa, sda), gap(sb, sdb));
            let margin = |run: &mut Self, set: &mut ActiveSet, t: f64| {
                let (s, sd) = run.boundary_state(set, ends, k, t);
                gap(s, sd)
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
                    .locate(
                        |t| self.boundary_state(set, ends, k, t).1,
                        (ta, sda),
                        (tb, sdb),
                    )
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
    pub(super) fn due_checks(&mut self, until: f64) -> Crossing {
        while let Some((t, k)) = self.next_check() {
            if t > until {
                break;
            }
            self.queue.pop();
            if self.touches_set(k) {
                continue;
            }
            if self.schedule(k, t) {
                return Some((self.past_touch(k, t), k));
            }
        }
        None
    }

    /// When check k (both sides moving exactly) joins, found active at
    /// `t`: a Kelvin–Voigt contact's force jumps at first touch, so where
    /// its gap is still closed to rounding at `t` it joins a few ulps on,
    /// where the gap has opened (no step may start on the jump: the first
    /// stage would miss the force the others feel).
    fn past_touch(&self, k: usize, t: f64) -> f64 {
        let Some(c) = self.model.contacts().get(k) else {
            return t;
        };
        if !matches!(self.activation[k], Activation::Compact) {
            return t;
        }
        let mut at = t;
        for _ in 0..16 {
            let (mut s, mut sd) = (-c.clearance, 0.0);
            for (side, sign) in [(c.pair.left(), 1.0), (c.pair.right(), -1.0)] {
                if let Some(i) = side {
                    let (u, v) = self.exact_body(i, at);
                    s += sign * u;
                    sd += sign * v;
                }
            }
            if s > 0.0 || sd <= 0.0 {
                return at;
            }
            // (The next float up: `at` is not negative.)
            at = f64::from_bits(at.to_bits() + 1);
        }
        t
    }

    /// The groups of check k's bodies (a contact's, or a storey's group).
    pub(super) fn groups_of(&self, k: usize) -> CheckGroups {
        let mut groups = CheckGroups {
            groups: [0; 2],
            len: 0,
        };
        for i in self.sides(k).into_iter().flatten() {
            let g = self.free.place(i).0;
            if groups.last() != Some(&g) {
                groups.groups[groups.len] = g;
                groups.len += 1;
            }
        }
        groups
    }

    /// Joins the groups of check k (a contact, or a storey) to the set at
    /// `t` (the set, if any, is at `t`); the checks of the contacts and
    /// storeys that now touch the set lapse.
    pub(super) fn join(&mut self, k: usize, t: f64) -> Result<(), IntegrationError> {
        // A rigid contact's touch: a jump, or its soft episode joins.
        if self.rigid_touch(k, t)? {
            return Ok(());
        }
        if self.clustered {
            return self.join_clusters(k, t);
        }
        let mut groups = self.set.as_ref().map_or(Vec::new(), |s| s.groups.clone());
        for g in self.groups_of(k) {
            if !groups.contains(&g) {
                groups.push(g);
            }
        }
        groups.sort_unstable();
        self.lapse_checks_of(k);
        self.rebuild(groups, t)
    }

    /// The checks (contacts, then storeys `nc + s`) of `groups`, ascending,
    /// each once.
    pub(super) fn checks_of(&self, groups: &[usize]) -> SmallVec<[usize; 8]> {
        let nc = self.model.contacts().len();
        let mut checks: SmallVec<[usize; 8]> = groups
            .iter()
            .flat_map(|&g| {
                let storeys = self.group_storeys[g].iter().map(move |s| nc + s);
                self.group_contacts[g].iter().copied().chain(storeys)
            })
            .collect();
        checks.sort_unstable();
        checks.dedup();
        checks
    }

    /// The checks of the contacts and storeys of check k's groups lapse
    /// (the groups join a set).
    pub(super) fn lapse_checks_of(&mut self, k: usize) {
        let nc = self.model.contacts().len();
        for g in self.groups_of(k) {
            let checks = self.group_contacts[g]
                .iter()
                .copied()
                .chain(self.group_storeys[g].iter().map(|s| nc + s));
            for kk in checks {
                self.generation[kk] += 1;
            }
        }
    }

    /// Whether contact `kl` of the set is engaged at the set's current
    /// point: active now or within `lookahead` by its rate and
    /// acceleration. (An impact whose force has fallen below the
    /// negligible level is not: it ends when its bodies are released.)
    pub(super) fn engaged(set: &ActiveSet, act: Activation, kl: usize, lookahead: f64) -> bool {
        let (s, sd) = set.sys.chain().approach(kl, set.st.y());
        let idx = set.sys.chain().contact_indices(kl);
        let dy = set.st.dydt();
        let sdd = idx[1].map_or(0.0, |i| dy[i]) - idx[3].map_or(0.0, |i| dy[i]);
        let reach = s + sd.max(0.0) * lookahead + 0.5 * sdd.max(0.0) * lookahead * lookahead;
        act.margin(reach, sd.abs() + sdd.abs() * lookahead) > 0.0
    }

    /// Lets the groups of the set whose contacts have all separated move
    /// exactly again; their contacts with other exact groups or walls are
    /// scheduled. Returns a contact that is active at once, if any.
    pub(super) fn release(&mut self) -> Result<Crossing, IntegrationError> {
        self.sync_storeys(false);
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
        // A group that joined within the lookahead stays (no chatter); one
        // whose contacts are all rigid (a soft episode) leaves once they
        // have separated, as the global run's episode ends.
        let mut engaged: SmallVec<[bool; 8]> = SmallVec::new();
        for &g in &set.groups {
            engaged.push(t - self.joined[g] < self.rigid_lookahead(g, lookahead));
        }
        for (kl, &k) in set.scan.ids.iter().enumerate() {
            let ahead = if self.is_rigid(k) { 0.0 } else { lookahead };
            if Self::engaged(set, self.activation[k], kl, ahead) {
                for g in self.groups_of(k) {
                    if let Ok(p) = set.groups.binary_search(&g) {
                        engaged[p] = true;
                    }
                }
            }
        }
        // (Most steps: every group still engaged, nothing more to judge.)
        if engaged.iter().all(|&e| e) {
            return Ok(None);
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
        // A group stays while its storeys are off a linear branch or near
        // yield.
        let groups = set.groups.clone();
        for (p, &g) in groups.iter().enumerate() {
            if !engaged[p] && self.storeys_engaged(g, t, lookahead, &states[p])? {
                engaged[p] = true;
            }
        }
        let Some(set) = self.set.as_ref() else {
            return Ok(None);
        };
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
                    // (A rigid contact's next touch is a jump: only one
                    // that touches now keeps its group.)
                    let ahead = if self.is_rigid(k) { 0.0 } else { lookahead };
                    if sides.iter().all(|g| groups.binary_search(g).is_ok())
                        && self
                            .bound(k, t, lookahead, state)
                            .is_none_or(|until| until - t < ahead)
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
        for k in self.checks_of(&leaving) {
            if !self.touches_set(k) && self.schedule(k, t) {
                match first {
                    None => first = Some((t, k)),
                    // Another active at once: due at t (its check would
                    // otherwise be lost, `schedule` queues none).
                    Some(_) => self.queue.push(Reverse((Time(t), k, self.generation[k]))),
                }
            }
        }
        Ok(first)
    }
}
