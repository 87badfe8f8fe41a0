//! Exact extrema under the local integrator (docs/theory.md §10): the
//! active set's steps are scanned on its dense output as the global
//! integrator's are ([`ExtremaScan`]); the exact motion of the other
//! groups, and the contacts with a side moving exactly, on their own
//! propagation. Over a grid of a sixteenth of the fastest period (and a
//! record's samples) an interior maximum of |u_i| lies where v_i changes
//! sign (Brent), one of |v_i| where the acceleration does (golden section),
//! one of a contact's approach where ṡ does: the same tests as on the
//! global integrator's steps, on intervals no longer than its steps over
//! free flight.

use super::*;

/// Extrema over the window, and how far the exact motion has been scanned.
pub(super) struct LocalExtrema {
    window: (f64, f64),
    /// The exact motion is scanned up to this time (−∞: not yet at all).
    scanned: f64,
    /// The impact threshold of every contact.
    s_on: Vec<f64>,
    /// Grid step of the exact motion (s).
    grid: f64,
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
        let rate = free
            .groups()
            .iter()
            .map(|g| g.rate())
            .fold(0.0f64, f64::max);
        let mut grid = if rate > 0.0 {
            std::f64::consts::PI / (8.0 * rate)
        } else {
            f64::INFINITY
        };
        if let BaseExcitation::Record(r) = model.base() {
            let t = r.times();
            grid = grid.min((t[t.len() - 1] - t[0]) / (t.len().max(2) - 1) as f64);
        }
        Self {
            window,
            scanned: f64::NEG_INFINITY,
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
        sys: &ChainDynamics,
    ) -> ExtremaScan {
        let s_on = ids.iter().map(|&k| self.s_on[k]).collect();
        ExtremaScan::new(self.window, bodies, s_on, st, sys)
    }
}

/// A side of a contact at the grid's points: a body moving exactly (its
/// group's place among the scanned groups, the group, index in the group)
/// or in the set (state index), or a wall.
#[derive(Clone, Copy)]
enum Side {
    Exact(usize, usize, usize),
    Set(usize),
    Wall,
}

impl Run<'_> {
    /// Scans the exact motion from where it was scanned to `t`: every group
    /// moving exactly, and every contact with a side moving exactly. (The
    /// set, if any, holds `t` and the scanned time in its last step; the
    /// motion before `t` is sampled and checked, so that the exact groups'
    /// reference states may move up to `t`.)
    pub(super) fn scan_exact_to(&mut self, t: f64) {
        let Some(mut ex) = self.extrema.take() else {
            return;
        };
        self.scan_exact(&mut ex, t);
        self.extrema = Some(ex);
    }

    /// [`scan_exact_to`](Self::scan_exact_to) into `ex`.
    fn scan_exact(&mut self, ex: &mut LocalExtrema, t: f64) {
        let first = ex.scanned == f64::NEG_INFINITY;
        if t < ex.scanned || (t == ex.scanned && !first) {
            return;
        }
        let (a, b) = (ex.scanned.max(ex.window.0), t.min(ex.window.1));
        ex.scanned = t;
        if a > b || (a == b && !first) {
            return;
        }
        let grid = ex.grid;
        let groups: Vec<usize> = (0..self.exact.len()).filter(|&g| !self.in_set[g]).collect();
        let mut place = vec![usize::MAX; self.exact.len()];
        for (p, &g) in groups.iter().enumerate() {
            place[g] = p;
        }
        let side = |i: Option<usize>| match i {
            None => Side::Wall,
            Some(i) => match self.slot[i] {
                Some(j) => Side::Set(2 * j),
                None => {
                    let (g, j) = self.free.place(i);
                    Side::Exact(place[g], g, j)
                }
            },
        };
        let contacts: Vec<(usize, [Side; 2])> = (0..self.model.contacts().len())
            .filter_map(|k| {
                let c = &self.model.contacts()[k];
                let sides = [side(c.pair.left()), side(c.pair.right())];
                sides
                    .iter()
                    .any(|s| matches!(s, Side::Exact(..)))
                    .then_some((k, sides))
            })
            .collect();
        let mut xa: Vec<Vec<f64>> = groups
            .iter()
            .map(|&g| {
                let (t0, x) = &self.exact[g];
                let mut x = x.clone();
                self.free.propagate(g, *t0, a, &mut x);
                x
            })
            .collect();
        let pieces = ((b - a) / grid).ceil().clamp(1.0, 1e9) as usize;
        let mut ta = a;
        let mut sa: Vec<(f64, f64)> = contacts
            .iter()
            .map(|&(k, sides)| self.approach_at(k, sides, &xa, ta))
            .collect();
        self.note_points(ex, &groups, &xa, &contacts, &sa);
        for p in 1..=pieces {
            let tb = if p == pieces {
                b
            } else {
                a + (b - a) * p as f64 / pieces as f64
            };
            if tb <= ta {
                continue;
            }
            let mut xb = xa.clone();
            for (x, &g) in xb.iter_mut().zip(&groups) {
                self.free.propagate(g, ta, tb, x);
            }
            let sb: Vec<(f64, f64)> = contacts
                .iter()
                .map(|&(k, sides)| self.approach_at(k, sides, &xb, tb))
                .collect();
            self.note_points(ex, &groups, &xb, &contacts, &sb);
            self.interior_of_groups(ex, &groups, (ta, &xa), (tb, &xb));
            for (c, &(k, sides)) in contacts.iter().enumerate() {
                let (sda, sdb) = (sa[c].1, sb[c].1);
                if sda > 0.0 && sdb < 0.0 {
                    let rate = |t: f64| self.approach_from(k, sides, &xa, ta, t).1;
                    if let Ok(tm) = EventLocator::FINE.locate(rate, (ta, sda), (tb, sdb)) {
                        let s = self.approach_from(k, sides, &xa, ta, tm).0;
                        ex.found.impact_margin[k] = ex.found.impact_margin[k].max(s - ex.s_on[k]);
                    }
                }
            }
            (xa, sa, ta) = (xb, sb, tb);
        }
        // Everything up to b is scanned (and sampled and checked: the
        // callers' condition): the groups' reference states move there, so
        // that the samples at b do not propagate again.
        for (x, &g) in xa.into_iter().zip(&groups) {
            if b > self.exact[g].0 {
                self.exact[g] = (b, x);
            }
        }
    }

    /// The ends: |u|, |v| of the exact bodies and the contacts' approach.
    fn note_points(
        &self,
        ex: &mut LocalExtrema,
        groups: &[usize],
        x: &[Vec<f64>],
        contacts: &[(usize, [Side; 2])],
        s: &[(f64, f64)],
    ) {
        for (xg, &g) in x.iter().zip(groups) {
            for (j, &i) in self.free.groups()[g].bodies().iter().enumerate() {
                let f = &mut ex.found;
                f.max_displacement[i] = f.max_displacement[i].max(xg[2 * j].abs());
                f.max_velocity[i] = f.max_velocity[i].max(xg[2 * j + 1].abs());
            }
        }
        for (&(k, _), &(sk, _)) in contacts.iter().zip(s) {
            ex.found.impact_margin[k] = ex.found.impact_margin[k].max(sk - ex.s_on[k]);
        }
    }

    /// Interior extrema of the exact bodies on `[ta, tb]`.
    fn interior_of_groups(
        &self,
        ex: &mut LocalExtrema,
        groups: &[usize],
        (ta, xa): (f64, &[Vec<f64>]),
        (tb, xb): (f64, &[Vec<f64>]),
    ) {
        for (p, &g) in groups.iter().enumerate() {
            let free = &self.free;
            let at = |t: f64| {
                let mut y = xa[p].clone();
                free.propagate(g, ta, t, &mut y);
                y
            };
            for (j, &i) in free.groups()[g].bodies().iter().enumerate() {
                let (va, vb) = (xa[p][2 * j + 1], xb[p][2 * j + 1]);
                let mut max_u = 0.0f64;
                let mut max_v = 0.0f64;
                if va * vb < 0.0 {
                    let v = |t: f64| at(t)[2 * j + 1];
                    if let Ok(tm) = EventLocator::FINE.locate(v, (ta, va), (tb, vb)) {
                        max_u = at(tm)[2 * j].abs();
                    }
                }
                let (aa, ab) = (
                    free.acceleration(g, ta, &xa[p], j),
                    free.acceleration(g, tb, &xb[p], j),
                );
                if aa * ab < 0.0 {
                    max_v = golden_max(|t| at(t)[2 * j + 1].abs(), ta, tb).0;
                }
                let f = &mut ex.found;
                f.max_displacement[i] = f.max_displacement[i].max(max_u);
                f.max_velocity[i] = f.max_velocity[i].max(max_v);
            }
        }
    }

    /// Contact k's (s, ṡ) at `t` from the exact groups' states `x` at `t`
    /// and the set's dense output.
    fn approach_at(&mut self, k: usize, sides: [Side; 2], x: &[Vec<f64>], t: f64) -> (f64, f64) {
        self.approach_from(k, sides, x, t, t)
    }

    /// Contact k's (s, ṡ) at `t`, its exact sides propagated from their
    /// groups' states `x` at `t0 <= t`.
    fn approach_from(
        &mut self,
        k: usize,
        sides: [Side; 2],
        x: &[Vec<f64>],
        t0: f64,
        t: f64,
    ) -> (f64, f64) {
        let mut uv = [(0.0, 0.0); 2];
        for (slot, side) in uv.iter_mut().zip(sides) {
            *slot = match side {
                Side::Wall => (0.0, 0.0),
                Side::Exact(p, _, j) if t == t0 => (x[p][2 * j], x[p][2 * j + 1]),
                Side::Exact(p, g, j) => {
                    let mut y = x[p].clone();
                    self.free.propagate(g, t0, t, &mut y);
                    (y[2 * j], y[2 * j + 1])
                }
                // (A set side exists only with a set: `slot` says so.)
                Side::Set(iu) => match self.set.as_mut() {
                    Some(set) => (
                        set.st.dense_component(&mut set.sys, iu, t),
                        set.st.dense_component(&mut set.sys, iu + 1, t),
                    ),
                    None => (f64::NAN, f64::NAN),
                },
            };
        }
        let clearance = self.model.contacts()[k].clearance;
        (uv[0].0 - uv[1].0 - clearance, uv[0].1 - uv[1].1)
    }
}
