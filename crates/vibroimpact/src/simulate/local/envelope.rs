//! The modal bound of a check (docs/theory.md §10): a storey's drift or a
//! contact's gap (and its rate) bounded over a horizon by the envelopes of
//! its groups' modes ([`crate::simulate::local::free_motion::Envelope`]).
//! It holds whatever the phases of the modes, so a storey or gap whose
//! envelope stays clear of its limit is safe over the whole horizon; the
//! energy bound is kept beside it, and the later of the two wins.

use smallvec::{smallvec, SmallVec};

use super::storeys::YIELD_APPROACH;
use super::*;
use crate::simulate::local::free_motion::Envelope;

/// A check's quantity per group: (body, coefficient).
type Terms = SmallVec<[(usize, f64); 2]>;

/// Halvings tried below the first horizon before the modal bound gives up.
const HALVINGS: usize = 4;

/// One side of a check: its group's envelope of displacement and of
/// velocity, and the quantity's value at rest.
struct Side {
    shift: Envelope,
    rate: Envelope,
    rest: f64,
}

impl Run<'_> {
    /// The envelope of `Σ c u_i` over `terms` (body, coefficient), all in
    /// group `g`, from the group's state `x`.
    fn side(&self, g: usize, x: &[f64], terms: &[(usize, f64)]) -> Option<Side> {
        if !self.free.has_envelopes(g) {
            return None;
        }
        let at = |r: usize| -> Terms {
            terms
                .iter()
                .map(|&(i, c)| (2 * self.free.place(i).1 + r, c))
                .collect()
        };
        let group = &self.free.groups()[g];
        let rest = terms
            .iter()
            .map(|&(i, c)| c * group.rest(2 * self.free.place(i).1))
            .sum();
        let [shift, rate] = self.free.envelopes(g, x, [&at(0), &at(1)])?;
        Some(Side { shift, rate, rest })
    }

    /// The latest time, by the modal bound, until which check `k` stays
    /// inactive from `t` (its groups' states `state(g)`): the horizon
    /// doubles from `start` while the bound holds, up to `remaining`; where
    /// it does not hold there, it halves from it a few times, if `start`
    /// is the first horizon. None: no modes, or not safe over the horizons
    /// tried.
    pub(super) fn modal_until<'s>(
        &self,
        k: usize,
        t: f64,
        (start, remaining, first): (f64, f64, bool),
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let safe = self.modal_check(k, state)?;
        let holds = |h: f64| safe(h, self.free.base_peak(t, t + h));
        let mut h = start;
        if holds(h) {
            while h < remaining && holds(remaining.min(2.0 * h)) {
                h = remaining.min(2.0 * h);
            }
            return Some(t + h);
        }
        for _ in 0..if first { HALVINGS } else { 0 } {
            h *= 0.5;
            if holds(h) {
                return (t + h > t).then_some(t + h);
            }
        }
        None
    }

    /// The test of check `k` over a horizon `h` with the base's |z̈| below
    /// `zdd` (true: safe), from its groups' states; None without modes.
    #[allow(clippy::type_complexity)]
    fn modal_check<'s>(
        &self,
        k: usize,
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<Box<dyn Fn(f64, f64) -> bool + '_>> {
        let nc = self.model.contacts().len();
        if k >= nc {
            let s = k - nc;
            let (lo, hi) = self.storeys.linear_window(s, YIELD_APPROACH)?;
            let (below, above) = self.storeys.ends(s);
            let g = self.free.place(above).0;
            let mut terms: Terms = smallvec![(above, 1.0)];
            terms.extend(below.map(|b| (b, -1.0)));
            let side = self.side(g, state(g), &terms)?;
            return Some(Box::new(move |h, zdd| {
                let q = side.shift.reach(h, zdd);
                side.rest + q < hi && side.rest - q > lo
            }));
        }
        let c = &self.model.contacts()[k];
        // The gap s = u_l − u_r − clearance, per group of its sides.
        let mut by_group: SmallVec<[(usize, Terms); 2]> = SmallVec::new();
        for (side, sign) in [c.pair.left(), c.pair.right()].into_iter().zip([1.0, -1.0]) {
            let Some(i) = side else { continue };
            let g = self.free.place(i).0;
            match by_group.iter_mut().find(|(h, _)| *h == g) {
                Some((_, terms)) => terms.push((i, sign)),
                None => by_group.push((g, smallvec![(i, sign)])),
            }
        }
        let sides = by_group
            .iter()
            .map(|(g, terms)| self.side(*g, state(*g), terms))
            .collect::<Option<SmallVec<[Side; 2]>>>()?;
        let (activation, rigid) = (self.activation[k], self.is_rigid(k));
        let clearance = c.clearance;
        Some(Box::new(move |h, zdd| {
            let (mut s, mut speed) = (-clearance, 0.0);
            for side in &sides {
                s += side.rest + side.shift.reach(h, zdd);
                speed += side.rate.reach(h, zdd);
            }
            s < if rigid { 0.0 } else { activation.gap(speed) }
        }))
    }
}
