//! Rebuilding the active set (docs/theory.md §10): the set that leaves
//! hands its state and results back and its leaving groups to exact
//! motion; the new set gathers its bodies' state (and tangent columns),
//! builds its own model of the contacts, springs and forces within it,
//! and starts its stepper with the first step an entering contact allows.

use super::*;

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

/// The set's own model: its bodies, the contacts within it (renumbered),
/// the springs, forces and storeys of its groups; with the model ids of
/// its contacts and storeys, and the contacts on its boundary (to a body
/// outside).
struct SubModel {
    model: Model,
    contacts: Vec<usize>,
    boundary: Vec<usize>,
    storeys: Vec<usize>,
}

impl Run<'_> {
    /// Rebuilds the active set with `groups` at time `t`, from the current
    /// set's state and the exact motion of the others.
    pub(super) fn rebuild(&mut self, groups: Vec<usize>, t: f64) -> Result<(), IntegrationError> {
        // Groups joining leave their exact motion: scanned up to here, and
        // their deferred reference states (of the motion before they
        // joined) lapse.
        for &g in &groups {
            if !self.in_set[g] {
                self.before_move(g, t);
                self.deferred.retain(|(h, ..)| *h != g);
            }
        }
        self.sync_storeys(true);
        let mut old = self.retire(&groups, t);
        // Groups leaving move exactly about the rest of their storeys'
        // branches.
        for &g in &old.groups {
            if !groups.contains(&g) && !self.group_storeys[g].is_empty() {
                self.settle_rest(g)?;
            }
        }
        self.local.set_changes += 1;
        if groups.is_empty() {
            self.impacts = old.impacts;
            if let Some(tape) = self.tape.as_mut() {
                tape.form(t, &[], &[], None, &[]);
            }
            self.end_episodes(t);
            return Ok(());
        }
        // With clusters, each cluster is a set of its own.
        let parts = if self.clustered {
            self.components(&groups)
        } else {
            vec![groups]
        };
        // The log passes through every part as it forms (an impact that
        // begins as its contact enters is logged there), and stays with
        // the first, the current set.
        // (A part that fails leaves the log where it was.)
        let mut log = std::mem::take(&mut old.impacts);
        let mut formed = Ok(());
        for (p, part) in parts.into_iter().enumerate() {
            let mut set = match self.form(part, &old, &mut log, t) {
                Ok(set) => Box::new(set),
                Err(e) => {
                    formed = Err(e);
                    break;
                }
            };
            log = std::mem::take(&mut set.scan.impacts);
            if p == 0 {
                self.set = Some(set);
            } else {
                self.sets.push(set);
            }
        }
        *self.impact_log() = log;
        self.local.most_sets = self.local.most_sets.max(1 + self.sets.len());
        self.end_episodes(t);
        formed
    }

    /// A new set of `groups` at `t` (what the old sets hand over in
    /// `old`), taking the run's impact log `log` once nothing can fail.
    fn form(
        &mut self,
        groups: Vec<usize>,
        old: &Retired,
        log: &mut Vec<ImpactRecord>,
        t: f64,
    ) -> Result<ActiveSet, IntegrationError> {
        let model = self.model;
        let (bodies, mut y) = self.enter(&groups, old, t);
        let SubModel {
            model: sub,
            contacts: ids,
            boundary,
            storeys,
        } = self.sub_model(&groups, &bodies)?;
        let energy = self.energy.is_some();
        // A set whose steps no tape or tangent column reads keeps no
        // partial derivatives of its contacts.
        let dynamics = ChainDynamics::new(&sub, energy);
        let dynamics = if self.tape.is_none() && self.columns == 0 {
            dynamics.without_partials()
        } else {
            dynamics
        };
        let chain = Recorder::new(dynamics, self.tape.is_some());
        let mut sys = Variational::new(chain, self.columns);
        // The storeys' Bouc–Wen states after the bodies', then the audit's
        // quadratures (from 0: the old set's are in the sums). (No tangent
        // columns with either.)
        self.load_storeys(&mut sys, &storeys, &mut y);
        if energy {
            y.extend([0.0; 3]);
        }
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
            error_components: energy.then_some(sys.chain().audit_index()),
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
        let s_on = ids
            .iter()
            .map(|&k| {
                model.contacts()[k]
                    .law
                    .onset_approach(self.opts.impact_force_threshold)
            })
            .collect();
        // (A set's own model is soft throughout: no rigid contact.)
        let switches = Switches::new(sys.chain(), y.len(), s_on, vec![0.0; ids.len()]);
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
            impacts: std::mem::take(log),
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
        Ok(ActiveSet {
            groups,
            bodies,
            boundary,
            sys,
            st,
            scan,
            saved: (t, y),
            rate,
            extrema,
            storeys,
            switches,
            event: None,
            carried: Vec::new(),
            pending: None,
            open: None,
            scanned: true,
        })
    }

    /// Takes the current set (and the sets merging with it) apart at `t`:
    /// their results return to the run, their groups that are not in
    /// `groups` move exactly from here, and what the next sets need of
    /// them is returned.
    fn retire(&mut self, groups: &[usize], t: f64) -> Retired {
        let mut out = Retired {
            impacts: std::mem::take(&mut self.impacts),
            ..Retired::default()
        };
        let sets: Vec<Box<ActiveSet>> = self
            .set
            .take()
            .into_iter()
            .chain(std::mem::take(&mut self.merging))
            .collect();
        // Several sets hand over their bodies' states alone (no tangent
        // columns, storeys or audit with clusters), in body order.
        let several = sets.len() > 1;
        let mut rows: Vec<(usize, [f64; 2])> = Vec::new();
        for mut old in sets {
            // An activation it was heading for is checked again.
            if let Some((tp, k)) = old.pending.take() {
                self.generation[k] += 1;
                self.queue.push(Reverse((Time(tp), k, self.generation[k])));
            }
            let h = old.st.h_next();
            out.h_prev = Some(out.h_prev.map_or(h, |p: f64| p.min(h)));
            self.absorb(&mut old);
            if let (Some(ex), Some(scan)) = (self.extrema.as_mut(), &old.extrema) {
                ex.merge(&old, scan);
            }
            self.contact_evaluations += old.sys.chain().contact_evaluations();
            let old_y = old.st.y().to_vec();
            self.energy_of_set(&old_y, old.sys.chain().audit_index());
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
            // (One set holds the log, the others none: a move, not a copy.)
            if old.scan.impacts.len() > out.impacts.len() {
                std::mem::swap(&mut out.impacts, &mut old.scan.impacts);
            }
            out.impacts.append(&mut old.scan.impacts);
            for &g in &old.groups {
                self.in_set[g] = false;
            }
            out.groups.extend_from_slice(&old.groups);
            out.contacts.extend_from_slice(&old.scan.ids);
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
                    if self.columns > 0 {
                        self.tangents[g] = (t, w);
                    }
                }
            }
            if several {
                rows.extend(
                    (old_bodies.iter().enumerate())
                        .map(|(j, &i)| (i, [old_y[2 * j], old_y[2 * j + 1]])),
                );
            } else {
                (out.bodies, out.y) = (old_bodies, old_y);
            }
        }
        if several {
            rows.sort_unstable_by_key(|r| r.0);
            out.bodies = rows.iter().map(|r| r.0).collect();
            out.y = rows.iter().flat_map(|r| r.1).collect();
            out.groups.sort_unstable();
            out.contacts.sort_unstable();
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

    /// The set's own model ([`SubModel`]) of `groups`, its `bodies`.
    fn sub_model(&self, groups: &[usize], bodies: &[usize]) -> Result<SubModel, IntegrationError> {
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
        let free = &self.free;
        let pick = |list: fn(&FreeMotion, usize) -> &[usize]| {
            let mut v: Vec<usize> = groups
                .iter()
                .flat_map(|&g| list(free, g).iter().copied())
                .collect();
            v.sort_unstable();
            v
        };
        let couplings: Vec<Coupling> = pick(FreeMotion::couplings_in)
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
        let forces: Vec<HarmonicForce> = pick(FreeMotion::forces_in)
            .into_iter()
            .map(|i| &model.forces()[i])
            .filter_map(|f| {
                Some(HarmonicForce {
                    body: self.slot[f.body]?,
                    ..f.clone()
                })
            })
            .collect();
        let storey_ids: Vec<usize> = (0..model.storeys().len())
            .filter(|&s| bodies.binary_search(&model.storeys()[s].above).is_ok())
            .collect();
        // A storey joins bodies of one group: both in the set.
        let slot = |i: usize| {
            self.slot[i].ok_or_else(|| {
                IntegrationError::InvalidOptions(format!(
                    "a storey of {} reaches outside the integrated set (internal error)",
                    model.bodies()[i].name
                ))
            })
        };
        let storeys = storey_ids
            .iter()
            .map(|&s| &model.storeys()[s])
            .map(|s| {
                Ok(Storey {
                    below: s.below.map(slot).transpose()?,
                    above: slot(s.above)?,
                    law: s.law,
                    p_delta: s.p_delta,
                })
            })
            .collect::<Result<Vec<_>, IntegrationError>>()?;
        let sub = Model::part(
            sub_bodies,
            couplings,
            contacts,
            model.base().clone(),
            (forces, storeys),
        );
        Ok(SubModel {
            model: sub,
            contacts: ids,
            boundary,
            storeys: storey_ids,
        })
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
