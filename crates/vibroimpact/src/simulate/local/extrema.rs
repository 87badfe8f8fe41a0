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
}

impl LocalExtrema {
    /// Nothing found yet over `window`.
    pub(super) fn new(
        window: (f64, f64),
        model: &Model,
        free: &FreeMotion,
        s_on: Vec<f64>,
    ) -> Self {
        let record_step = match model.base() {
            BaseExcitation::Record(r) => {
                let t = r.times();
                (t[t.len() - 1] - t[0]) / (t.len().max(2) - 1) as f64
            }
            _ => f64::INFINITY,
        };
        let grid = free
            .groups()
            .iter()
            .map(|g| {
                let natural = if g.rate() > 0.0 {
                    std::f64::consts::PI / (8.0 * g.rate())
                } else {
                    f64::INFINITY
                };
                natural.min(record_step)
            })
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
            },
            s_on,
        }
    }

    /// The extrema found.
    pub(super) fn into_found(self) -> Extrema {
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
        ExtremaScan::new(self.window, bodies, s_on, st, sys.chain())
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

/// The ends of the equal pieces of `[a, b]` no longer than `step` (at
/// least one; the last exactly `b`; none that does not advance).
fn grid(a: f64, b: f64, step: f64) -> impl Iterator<Item = f64> {
    let pieces = ((b - a) / step).ceil().clamp(1.0, 1e9) as usize;
    let mut last = a;
    (1..=pieces).filter_map(move |p| {
        let t = if p == pieces {
            b
        } else {
            a + (b - a) * p as f64 / pieces as f64
        };
        (t > last).then(|| {
            last = t;
            t
        })
    })
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
        if let Some((a, b)) = ex.span(from, t) {
            self.scan_bodies(&mut ex, g, a, b);
        }
        ex.group_scanned[g] = ex.group_scanned[g].max(t);
        for c in 0..self.group_contacts[g].len() {
            let k = self.group_contacts[g][c];
            if self.touches_set(k) {
                continue;
            }
            if let Some((a, b)) = ex.span(ex.contact_scanned[k], t) {
                self.scan_contact(&mut ex, k, a, b);
            }
            ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
        }
        self.extrema = Some(ex);
    }

    /// A group leaves the set at `t`: its exact motion, and its contacts,
    /// are scanned from there (the set's scan covered them so far).
    pub(super) fn extrema_from(&mut self, g: usize, t: f64) {
        if let Some(ex) = self.extrema.as_mut() {
            ex.group_scanned[g] = t;
            for &k in &self.group_contacts[g] {
                ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
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
            let boundary = set.boundary.clone();
            for k in boundary {
                if let Some((a, b)) = ex.span(ex.contact_scanned[k], t) {
                    self.scan_contact(&mut ex, k, a, b);
                }
                ex.contact_scanned[k] = ex.contact_scanned[k].max(t);
            }
        }
        self.extrema = Some(ex);
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
        for tb in grid(a, b, ex.grid[g]) {
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
                    let v = golden_max(|t| at(t)[2 * j + 1].abs(), ta, tb).0;
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
        for tb in grid(a, b, step) {
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
        let mut uv = [(0.0, 0.0); 2];
        for (slot, side) in uv.iter_mut().zip([c.pair.left(), c.pair.right()]) {
            let Some(i) = side else { continue };
            *slot = match self.slot[i] {
                None => self.exact_body(i, t),
                // (A body has a slot only while the set exists.)
                Some(j) => match self.set.as_mut() {
                    Some(set) => (
                        set.st.dense_component(&mut set.sys, 2 * j, t),
                        set.st.dense_component(&mut set.sys, 2 * j + 1, t),
                    ),
                    None => (f64::NAN, f64::NAN),
                },
            };
        }
        (uv[0].0 - uv[1].0 - clearance, uv[0].1 - uv[1].1)
    }
}
