//! Exact extrema under the local integrator (docs/theory.md §10): the
//! active set's steps are scanned on its dense output as the global
//! integrator's are ([`ExtremaScan`]), with the contacts between the set
//! and an exactly moving group; the exact motion of a group, and its
//! contacts with other exact groups or walls, on its own propagation,
//! just before its reference state moves (so no interval is skipped, and
//! a group at rest costs nothing until then). Over a grid of a sixteenth
//! of the group's fastest period (and a record's samples) an interior
//! maximum of |u_i| lies where v_i changes sign (Brent), one of |v_i| where
//! the acceleration does (golden section), one of a contact's approach
//! where ṡ does: the same tests as on the global integrator's steps, on
//! intervals no longer than its steps over free flight.

use super::*;
use crate::simulate::gauges::{Gauge, GaugeScan};

/// Extrema over the window, and how far each group and contact has been
/// scanned.
pub(super) struct LocalExtrema {
    window: (f64, f64),
    /// Per group: its bodies are scanned up to this time while it moves
    /// exactly (−∞: not yet).
    group_scanned: Vec<f64>,
    /// Per contact: its approach is scanned up to this time (by its exact
    /// groups, or the set's steps while a side is in the set).
    contact_scanned: Vec<f64>,
    /// Per group: grid step of its exact motion (s).
    grid: Vec<f64>,
    /// The impact threshold of every contact.
    s_on: Vec<f64>,
    found: Extrema,
    /// The options' gauges, each scanned up to a time like a contact.
    gauges: Vec<GaugeScan>,
    gauge_scanned: Vec<f64>,
    /// Per group: the gauges that read one of its bodies.
    group_gauges: Vec<Vec<usize>>,
    /// Per gauge: whether it reads one group alone (with the ground).
    within: Vec<bool>,
    /// Whether the bodies and contacts are scanned (else the gauges alone).
    bodies: bool,
}

impl LocalExtrema {
    /// Nothing found yet over `window`.
    pub(super) fn new(
        window: (f64, f64),
        model: &Model,
        free: &FreeMotion,
        (s_on, gauges, bodies): (Vec<f64>, &[Gauge], bool),
    ) -> Self {
        let mut group_gauges = vec![Vec::new(); free.groups().len()];
        let within = gauges
            .iter()
            .map(|gauge| {
                let mut groups = gauge.sides().into_iter().flatten().map(|i| free.place(i).0);
                let first = groups.next();
                groups.all(|g| Some(g) == first)
            })
            .collect();
        for (w, gauge) in gauges.iter().enumerate() {
            for i in gauge.sides().into_iter().flatten() {
                let g = free.place(i).0;
                if group_gauges[g].last() != Some(&w) {
                    group_gauges[g].push(w);
                }
            }
        }
        let record_step = free.record_step().unwrap_or(f64::INFINITY);
        let grid = free
            .groups()
            .iter()
            .map(|g| FreeMotion::natural_piece(g.rate()).min(record_step))
            .collect();
        Self {
            window,
            group_scanned: vec![f64::NEG_INFINITY; free.groups().len()],
            contact_scanned: vec![f64::NEG_INFINITY; s_on.len()],
            grid,
            found: Extrema {
                max_displacement: vec![0.0; model.bodies().len()],
                max_velocity: vec![0.0; model.bodies().len()],
                impact_margin: vec![f64::NEG_INFINITY; s_on.len()],
                gauges: Vec::new(),
            },
            s_on,
            gauges: gauges.iter().cloned().map(GaugeScan::new).collect(),
            gauge_scanned: vec![f64::NEG_INFINITY; gauges.len()],
            group_gauges,
            within,
            bodies,
        }
    }

    /// The extrema found.
    pub(super) fn into_found(mut self) -> Extrema {
        self.found.gauges = self.gauges.iter().map(GaugeScan::reading).collect();
        self.found
    }

    /// Merges what a set's scan found (its bodies and contacts).
    pub(super) fn merge(&mut self, set: &ActiveSet, scan: &ExtremaScan) {
        let f = &mut self.found;
        for (j, &i) in set.bodies.iter().enumerate() {
            f.max_displacement[i] = f.max_displacement[i].max(scan.found.max_displacement[j]);
            f.max_velocity[i] = f.max_velocity[i].max(scan.found.max_velocity[j]);
        }
        for (kl, &k) in set.scan.ids.iter().enumerate() {
            f.impact_margin[k] = f.impact_margin[k].max(scan.found.impact_margin[kl]);
        }
    }

    /// A scan of a new set's steps from its start.
    pub(super) fn set_scan(
        &self,
        ids: &[usize],
        bodies: usize,
        st: &Stepper,
        sys: &SetSystem,
    ) -> ExtremaScan {
        let s_on = ids.iter().map(|&k| self.s_on[k]).collect();
        // (The gauges are read by the run, on the set's steps.)
        ExtremaScan::new(
            self.window,
            bodies,
            (s_on, &[], self.bodies),
            st,
            sys.chain(),
        )
    }

    /// The part of `[from, t]` inside the window, if any (a point counts).
    fn span(&self, from: f64, t: f64) -> Option<(f64, f64)> {
        let (a, b) = (from.max(self.window.0), t.min(self.window.1));
        (a <= b).then_some((a, b))
    }

    fn note_margin(&mut self, k: usize, s: f64) {
        let m = &mut self.found.impact_margin[k];
        *m = m.max(s - self.s_on[k]);
    }

    fn note_body(&mut self, i: usize, u: f64, v: f64) {
        let f = &mut self.found;
        f.max_displacement[i] = f.max_displacement[i].max(u.abs());
        f.max_velocity[i] = f.max_velocity[i].max(v.abs());
    }
}

/// An exact side's group state, carried along a scan.
struct Carried {
    g: usize,
    /// The side's place in its group.
    j: usize,
    t: f64,
    x: Rows,
    /// The furthest state read ahead of `t` since it moved, and its time
    /// (NaN: none): a piece's end is read first, then carried to.
    ahead: (f64, Rows),
}

impl Carried {
    /// The state moved on to `t`.
    fn advance(&mut self, free: &FreeMotion, t: f64) {
        if self.ahead.0 == t {
            std::mem::swap(&mut self.x, &mut self.ahead.1);
        } else {
            free.propagate(self.g, self.t, t, &mut self.x);
        }
        self.t = t;
        self.ahead.0 = f64::NAN;
    }

    /// The side's (u, v) at `t` (from the carried state).
    fn at(&mut self, free: &FreeMotion, t: f64) -> (f64, f64) {
        if t == self.t {
            return (self.x[2 * self.j], self.x[2 * self.j + 1]);
        }
        if t == self.ahead.0 {
            return (self.ahead.1[2 * self.j], self.ahead.1[2 * self.j + 1]);
        }
        let mut inside = Rows::new();
        let y = if self.ahead.0.is_nan() || t > self.ahead.0 {
            self.ahead.0 = t;
            &mut self.ahead.1
        } else {
            &mut inside
        };
        y.clone_from(&self.x);
        free.propagate(self.g, self.t, t, y);
        (y[2 * self.j], y[2 * self.j + 1])
    }
}

impl Run<'_> {
    /// Scans group `g`'s exact motion, and its contacts with other exact
    /// groups or walls, up to `t`: called before its reference state moves
    /// to `t` or it joins the set at `t`.
    pub(super) fn scan_group_to(&mut self, g: usize, t: f64) {
        let Some(mut ex) = self.extrema.take() else {
            return;
        };
        let from = ex.group_scanned[g].max(self.exact[g].0);
        if let (Some((a, b)), true) = (ex.span(from, t), ex.bodies) {
            self.scan_bodies(&mut ex, g, a, b);
        }
        ex.group_scanned[g] = ex.group_scanned[g].max(t);
        let contacts = if ex.bodies {
            self.group_contacts[g].len()
        } else {
            0
        };
        for c in 0..contacts {
            let k = self.group_contacts[g][c];
            if self.touches_set(k) {
                continue;
            }
            if let Some((a, b)) = ex.span(ex.contact_scanned[k], t) {
                self.scan_contact(&mut ex, k, a, b);
            }
            ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
        }
        // The group's own gauges in one pass over its motion, the others
        // (reading another exact group too) each on its own.
        let (mut own, mut across) = (Vec::new(), Vec::new());
        for &w in &ex.group_gauges[g] {
            if !self.gauge_in_set(&ex, w) {
                if ex.within[w] {
                    own.push(w);
                } else {
                    across.push(w);
                }
            }
        }
        if let Some(&first) = own.first() {
            if let Some((a, b)) = ex.span(ex.gauge_scanned[first], t) {
                self.scan_group_gauges(&mut ex, g, &own, a, b);
            }
            for &w in &own {
                ex.gauge_scanned[w] = ex.gauge_scanned[w].max(t);
            }
        }
        // The others by the group they read besides `g` (and where they
        // were scanned to): each such batch in one pass over both motions.
        let other = |w: usize| {
            let sides = ex.gauges[w].gauge.sides();
            let groups = sides.into_iter().flatten().map(|i| self.free.place(i).0);
            groups.filter(|&h| h != g).min()
        };
        let mut batches: Vec<(Option<usize>, f64, Vec<usize>)> = Vec::new();
        for w in across {
            let key = (other(w), ex.gauge_scanned[w]);
            match batches.iter_mut().find(|b| (b.0, b.1) == key) {
                Some(b) => b.2.push(w),
                None => batches.push((key.0, key.1, vec![w])),
            }
        }
        for (h, from, ws) in batches {
            match (h, ex.span(from, t)) {
                (Some(h), Some((a, b))) => self.scan_pair_gauges(&mut ex, [g, h], &ws, a, b),
                (None, _) => ws.iter().for_each(|&w| self.gauge_to(&mut ex, w, t)),
                (Some(_), None) => {}
            }
            for w in ws {
                ex.gauge_scanned[w] = ex.gauge_scanned[w].max(t);
            }
        }
        self.extrema = Some(ex);
    }

    /// Separations `ws` between exact groups `gs` (scanned up to the same
    /// time) on `[a, b]`: per piece of the finer of their grids both
    /// states at the ends once, the values and rates exact, the interior
    /// by propagation from the piece's start.
    fn scan_pair_gauges(
        &self,
        ex: &mut LocalExtrema,
        gs: [usize; 2],
        ws: &[usize],
        a: f64,
        b: f64,
    ) {
        let free = &self.free;
        let mut xa = gs.map(|g| {
            let (t0, x0) = &self.exact[g];
            let mut x = x0.clone();
            free.propagate(g, *t0, a, &mut x);
            x
        });
        // (On the finer grid's parts: those cost the finer group nothing.)
        let finer = if ex.grid[gs[0]] <= ex.grid[gs[1]] {
            gs[0]
        } else {
            gs[1]
        };
        // The gauge's value and rate in the groups' states x.
        let read = |gauge: &Gauge, x: &[Rows; 2]| -> (f64, f64) {
            let side = |i: Option<usize>| {
                i.map_or((0.0, 0.0), |i| {
                    let (h, j) = free.place(i);
                    let x = &x[usize::from(h != gs[0])];
                    (x[2 * j], x[2 * j + 1])
                })
            };
            let [l, r] = gauge.sides().map(side);
            (l.0 - r.0, l.1 - r.1)
        };
        let mut xb = xa.clone();
        let mut ta = a;
        for tb in free.grid(finer, a, b, ex.grid[finer]) {
            for (k, &g) in gs.iter().enumerate() {
                xb[k].copy_from_slice(&xa[k]);
                free.propagate(g, ta, tb, &mut xb[k]);
            }
            for &w in ws {
                let gauge = ex.gauges[w].gauge;
                let ends = (read(&gauge, &xa), read(&gauge, &xb));
                ex.gauges[w].scan_ends((ta, tb), ends, |t| {
                    let mut x = xa.clone();
                    for (k, &g) in gs.iter().enumerate() {
                        free.propagate(g, ta, t, &mut x[k]);
                    }
                    read(&gauge, &x)
                });
            }
            std::mem::swap(&mut xa, &mut xb);
            ta = tb;
        }
    }

    /// Group `g`'s own gauges `ws` (scanned up to the same time) on
    /// `[a, b]` of its exact motion: per piece of its grid the state at
    /// the ends once, the values and rates exact (a separation's relative
    /// velocity, an acceleration's jerk [`FreeMotion::absolute_jerk`]),
    /// the interior by propagation from the piece's start.
    fn scan_group_gauges(&self, ex: &mut LocalExtrema, g: usize, ws: &[usize], a: f64, b: f64) {
        let free = &self.free;
        let m = free.groups()[g].bodies().len();
        let (t0, x0) = &self.exact[g];
        let mut xa = x0.clone();
        free.propagate(g, *t0, a, &mut xa);
        // The bodies' accelerations in the group's state x at t.
        let accelerations = |t: f64, x: &[f64], acc: &mut Vec<f64>| {
            acc.clear();
            acc.extend((0..m).map(|i| free.acceleration(g, t, x, i)));
        };
        // The gauge's value and rate in the group's state x at t, with its
        // bodies' accelerations acc.
        let read = |gauge: &Gauge, t: f64, x: &[f64], acc: &[f64]| -> (f64, f64) {
            match *gauge {
                Gauge::Separation { left, right, .. } => {
                    let side = |i: Option<usize>| {
                        i.map_or((0.0, 0.0), |i| {
                            let j = free.place(i).1;
                            (x[2 * j], x[2 * j + 1])
                        })
                    };
                    let (l, r) = (side(left), side(right));
                    (l.0 - r.0, l.1 - r.1)
                }
                Gauge::AbsoluteAcceleration { body } => {
                    let j = free.place(body).1;
                    let ground = self.model.base().at(t);
                    (acc[j] + ground, free.absolute_jerk(g, t, x, acc, j))
                }
            }
        };
        let (mut acc_a, mut acc_b) = (Vec::with_capacity(m), Vec::with_capacity(m));
        accelerations(a, &xa, &mut acc_a);
        let mut xb = xa.clone();
        let mut ta = a;
        for tb in free.grid(g, a, b, ex.grid[g]) {
            xb.copy_from_slice(&xa);
            free.propagate(g, ta, tb, &mut xb);
            accelerations(tb, &xb, &mut acc_b);
            for &w in ws {
                let gauge = ex.gauges[w].gauge;
                let ends = (read(&gauge, ta, &xa, &acc_a), read(&gauge, tb, &xb, &acc_b));
                ex.gauges[w].scan_ends((ta, tb), ends, |t| {
                    let mut x = xa.clone();
                    free.propagate(g, ta, t, &mut x);
                    let mut acc = Vec::with_capacity(m);
                    accelerations(t, &x, &mut acc);
                    read(&gauge, t, &x, &acc)
                });
            }
            std::mem::swap(&mut xa, &mut xb);
            std::mem::swap(&mut acc_a, &mut acc_b);
            ta = tb;
        }
    }

    /// Whether gauge `w` reads a body in the set.
    fn gauge_in_set(&self, ex: &LocalExtrema, w: usize) -> bool {
        let sides = ex.gauges[w].gauge.sides();
        sides.into_iter().flatten().any(|i| self.slot[i].is_some())
    }

    /// Gauge `w` scanned from where it was up to `t`.
    fn gauge_to(&mut self, ex: &mut LocalExtrema, w: usize, t: f64) {
        if let Some((a, b)) = ex.span(ex.gauge_scanned[w], t) {
            self.scan_gauge(ex, w, a, b);
        }
        ex.gauge_scanned[w] = ex.gauge_scanned[w].max(t);
    }

    /// A group leaves the set at `t`: its exact motion, and its contacts,
    /// are scanned from there (the set's scan covered them so far).
    pub(super) fn extrema_from(&mut self, g: usize, t: f64) {
        if let Some(ex) = self.extrema.as_mut() {
            ex.group_scanned[g] = t;
            for &k in &self.group_contacts[g] {
                ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
            }
            for &w in &ex.group_gauges[g] {
                ex.gauge_scanned[w] = ex.gauge_scanned[w].max(t);
            }
        }
    }

    /// After a kept step of the set: the set's scan, and the contacts
    /// between the set and an exact group over the step.
    pub(super) fn scan_set_step(&mut self) {
        let Some(mut ex) = self.extrema.take() else {
            return;
        };
        if let Some(set) = self.set.as_mut() {
            if let Some(scan) = set.extrema.as_mut() {
                scan.step(&mut set.st, &mut set.sys);
            }
            let t = set.st.t();
            let boundary = if ex.bodies {
                set.boundary.clone()
            } else {
                Vec::new()
            };
            for k in boundary {
                if let Some((a, b)) = ex.span(ex.contact_scanned[k], t) {
                    self.scan_contact(&mut ex, k, a, b);
                }
                ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
            }
            for w in 0..ex.gauges.len() {
                if self.gauge_in_set(&ex, w) {
                    self.gauge_to(&mut ex, w, t);
                }
            }
        }
        self.extrema = Some(ex);
    }

    /// Gauge `w` on `[a, b]`: over the grid of its exact sides (one piece
    /// within a step of the set), as [`GaugeScan::scan`] reads a piece; an
    /// exact side's group state carried from piece to piece.
    fn scan_gauge(&mut self, ex: &mut LocalExtrema, w: usize, a: f64, b: f64) {
        let gauge = ex.gauges[w].gauge;
        let sides = gauge.sides();
        let step = sides
            .into_iter()
            .flatten()
            .filter(|&i| self.slot[i].is_none())
            .map(|i| ex.grid[self.free.place(i).0])
            .fold(f64::INFINITY, f64::min);
        let mut carried = sides.map(|side| {
            let i = side.filter(|&i| self.slot[i].is_none())?;
            let (g, j) = self.free.place(i);
            let (t0, x0) = &self.exact[g];
            let mut x = x0.clone();
            self.free.propagate(g, *t0, a, &mut x);
            Some(Carried {
                g,
                j,
                t: a,
                ahead: (f64::NAN, x.clone()),
                x,
            })
        });
        let (free, set, slot) = (&self.free, &mut self.set, &self.slot);
        let ground = |t| self.model.base().at(t);
        let mut ta = a;
        for tb in FreeMotion::equal_pieces(a, b, step) {
            let reading = &mut ex.gauges[w];
            // A side's (u, v) at t: carried exactly, or the set's dense
            // output.
            let mut side = |k: usize, t: f64| match (sides[k], &mut carried[k]) {
                (None, _) => (0.0, 0.0),
                (Some(_), Some(c)) => c.at(free, t),
                (Some(i), None) => match (slot[i], set.as_mut()) {
                    (Some(j), Some(set)) => (
                        set.st.dense_component(&mut set.sys, 2 * j, t),
                        set.st.dense_component(&mut set.sys, 2 * j + 1, t),
                    ),
                    _ => (f64::NAN, f64::NAN),
                },
            };
            match gauge {
                Gauge::Separation { .. } => reading.scan(ta, tb, |t| {
                    let (l, r) = (side(0, t), side(1, t));
                    (l.0 - r.0, l.1 - r.1)
                }),
                // (A body's own gauge reaches here only while it is in the
                // set: the slope of its dense velocity.)
                Gauge::AbsoluteAcceleration { .. } => {
                    let h = 1e-4 * (tb - ta);
                    let mut acceleration =
                        |t: f64| (side(0, t + h).1 - side(0, t - h).1) / (2.0 * h) + ground(t);
                    reading.scan(ta, tb, |t| {
                        let (lo, hi) = ((t - h).max(ta), (t + h).min(tb));
                        let x = acceleration(t);
                        (x, (acceleration(hi) - acceleration(lo)) / (hi - lo))
                    });
                }
            }
            for c in carried.iter_mut().flatten() {
                c.advance(free, tb);
            }
            ta = tb;
        }
    }

    /// A body's (u, v) at `t` (None: the ground): exact from its group's
    /// reference state, or the set's dense output.
    fn side_at(&mut self, side: Option<usize>, t: f64) -> (f64, f64) {
        let Some(i) = side else {
            return (0.0, 0.0);
        };
        match (self.slot[i], self.set.as_mut()) {
            (Some(j), Some(set)) => (
                set.st.dense_component(&mut set.sys, 2 * j, t),
                set.st.dense_component(&mut set.sys, 2 * j + 1, t),
            ),
            (Some(_), None) => (f64::NAN, f64::NAN),
            (None, _) => self.exact_body(i, t),
        }
    }

    /// |u|, |v| of group `g`'s bodies on `[a, b]` (its exact motion).
    fn scan_bodies(&self, ex: &mut LocalExtrema, g: usize, a: f64, b: f64) {
        let free = &self.free;
        let (t0, x0) = &self.exact[g];
        let mut xa = x0.clone();
        free.propagate(g, *t0, a, &mut xa);
        let bodies = free.groups()[g].bodies();
        for (j, &i) in bodies.iter().enumerate() {
            ex.note_body(i, xa[2 * j], xa[2 * j + 1]);
        }
        let mut ta = a;
        for tb in free.grid(g, a, b, ex.grid[g]) {
            let mut xb = xa.clone();
            free.propagate(g, ta, tb, &mut xb);
            let at = |t: f64| {
                let mut y = xa.clone();
                free.propagate(g, ta, t, &mut y);
                y
            };
            for (j, &i) in bodies.iter().enumerate() {
                ex.note_body(i, xb[2 * j], xb[2 * j + 1]);
                let (va, vb) = (xa[2 * j + 1], xb[2 * j + 1]);
                if va * vb < 0.0 {
                    let v = |t: f64| at(t)[2 * j + 1];
                    if let Ok(tm) = EventLocator::FINE.locate(v, (ta, va), (tb, vb)) {
                        ex.note_body(i, at(tm)[2 * j], 0.0);
                    }
                }
                let (aa, ab) = (
                    free.acceleration(g, ta, &xa, j),
                    free.acceleration(g, tb, &xb, j),
                );
                if aa * ab < 0.0 {
                    let v = maximum(|t| at(t)[2 * j + 1].abs(), ta, tb).0;
                    ex.note_body(i, 0.0, v);
                }
            }
            (xa, ta) = (xb, tb);
        }
    }

    /// Contact k's approach on `[a, b]`: its ends, and an interior maximum
    /// where ṡ changes sign on the grid of its exact sides.
    fn scan_contact(&mut self, ex: &mut LocalExtrema, k: usize, a: f64, b: f64) {
        let c = &self.model.contacts()[k];
        let step = [c.pair.left(), c.pair.right()]
            .into_iter()
            .flatten()
            .filter(|&i| self.slot[i].is_none())
            .map(|i| ex.grid[self.free.place(i).0])
            .fold(f64::INFINITY, f64::min);
        let (mut ta, mut sa) = (a, self.approach(k, a));
        ex.note_margin(k, sa.0);
        for tb in FreeMotion::equal_pieces(a, b, step) {
            let sb = self.approach(k, tb);
            ex.note_margin(k, sb.0);
            if sa.1 > 0.0 && sb.1 < 0.0 {
                let rate = |t: f64| self.approach(k, t).1;
                if let Ok(tm) = EventLocator::FINE.locate(rate, (ta, sa.1), (tb, sb.1)) {
                    let s = self.approach(k, tm).0;
                    ex.note_margin(k, s);
                }
            }
            (ta, sa) = (tb, sb);
        }
    }

    /// Contact k's (s, ṡ) at `t`: exact sides from their reference states,
    /// a side in the set from its dense output.
    fn approach(&mut self, k: usize, t: f64) -> (f64, f64) {
        let c = &self.model.contacts()[k];
        let clearance = c.clearance;
        let (l, r) = (c.pair.left(), c.pair.right());
        let (l, r) = (self.side_at(l, t), self.side_at(r, t));
        (l.0 - r.0 - clearance, l.1 - r.1)
    }
}
