//! Contacts between two bodies that move alike (docs/theory.md §10): the
//! bodies' difference is a free damped oscillator, whatever drives them,
//! so its check needs no bound over a horizon. Where the difference's
//! energy cannot reach the contact, it is safe to the run's end; where
//! the contact's gap is fixed (a rigid contact's judging gap or touch), the
//! difference's first rise through it is found on its closed form and the
//! contact is checked there, once, instead of at a sequence of bounds.

use std::f64::consts::PI;

use super::*;
use crate::numeric::newton_bracketed_from;

/// Two bodies that move alike: each a group of its own, with the same
/// `ω² = k/m > 0` and `c/m`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Alike {
    /// ω² = k/m (1/s²).
    w2: f64,
    /// c/m (1/s).
    c2: f64,
}

/// The two bodies of contact `c` if they move alike: each a group of its
/// own (no coupling), the same k/m > 0 and c/m, and no harmonic force or
/// storey on either. Then the base drives both alike and their difference
/// `Δ = u_l − u_r` is a free damped oscillator: its energy `Δ̇² + ω²Δ²`
/// never grows, so `|Δ| <= sqrt(E)/ω` for all time.
pub(super) fn alike(free: &FreeMotion, c: &Contact) -> Option<Alike> {
    let (l, r) = (c.pair.left()?, c.pair.right()?);
    // (Each alone in its group: its rates k/m and c/m are its closed
    // form's, and its group's forces and storeys are its.)
    let rates = |i: usize| free.groups()[free.place(i).0].lone_rates();
    let ((w2, c2), other) = (rates(l)?, rates(r)?);
    let forced = |i: usize| {
        let g = free.place(i).0;
        !free.forces_in(g).is_empty() || !free.storeys_in(g).is_empty()
    };
    (w2 > 0.0 && (w2, c2) == other && !forced(l) && !forced(r)).then_some(Alike { w2, c2 })
}

/// The first `τ > 0` at which `Δ`, the free damped oscillation of `m`
/// from `(Δ, Δ̇) = (d0, dv0)` with `d0 < level`, rises through `level`;
/// infinite if it never does. Within `margin` of it at a maximum without
/// reaching it (a graze to rounding): that maximum, for the bounds to
/// judge. None where the closed form does not serve (not underdamped, the
/// root not found): the bounds decide.
///
/// Underdamped, `Δ = e^{−στ}(p cos θ + q sin θ)` with `θ = ω_d τ`,
/// `σ = c/2m`; `Δ̇` has the same form, zero at every π of θ. So `Δ` rises
/// on alternate stretches of π, and each maximum is `e^{−2πσ/ω_d}` times
/// the one before: only the first rising stretch can cross `level`.
fn first_rise(d0: f64, dv0: f64, m: Alike, level: f64, margin: f64) -> Option<f64> {
    let sigma = 0.5 * m.c2;
    let wd2 = m.w2 - sigma * sigma;
    if wd2 <= 0.0 {
        return None;
    }
    let wd = wd2.sqrt();
    let (p, q) = (d0, (dv0 + sigma * d0) / wd);
    // Δ̇ = e^{−στ}(pd cos θ + qd sin θ).
    let (pd, qd) = (dv0, -sigma * q - wd * p);
    let at = |theta: f64| {
        let (s, c) = theta.sin_cos();
        let envelope = (-sigma * theta / wd).exp();
        (envelope * (p * c + q * s), envelope * (pd * c + qd * s))
    };
    // Δ̇'s first zero after θ = 0 (one at 0 itself: the next).
    let mut first = (qd.atan2(pd) + 0.5 * PI).rem_euclid(PI);
    if first == 0.0 {
        first = PI;
    }
    let rising = dv0 > 0.0 || (dv0 == 0.0 && d0 < 0.0);
    let (lo, hi) = if rising {
        (0.0, first)
    } else {
        (first, first + PI)
    };
    let (top, _) = at(hi);
    if top < level - margin {
        return Some(f64::INFINITY);
    }
    if top < level {
        return Some(hi / wd);
    }
    let (bottom, _) = at(lo);
    if bottom >= level {
        return None;
    }
    let guess = lo + (level - bottom) / (top - bottom) * (hi - lo);
    let f = |theta: f64| {
        let (d, v) = at(theta);
        (d - level, v / wd)
    };
    let theta = newton_bracketed_from(f, lo, hi, guess, 1e-14, 100).ok()?;
    Some(theta / wd)
}

impl Run<'_> {
    /// For a contact between bodies that move alike: the run's end, if
    /// their difference's energy keeps the gap below activation for all
    /// time; for a rigid contact, the difference's first rise through its
    /// gap ([`first_rise`]), both from their states at `t`. None: the
    /// bounds decide.
    pub(super) fn alike_bound<'s>(
        &self,
        c: &Contact,
        k: usize,
        t: f64,
        state: &impl Fn(usize) -> &'s [f64],
    ) -> Option<f64> {
        let (Some(m), Some(l), Some(r)) = (self.alike[k], c.pair.left(), c.pair.right()) else {
            return None;
        };
        // Bodies that move alike: the gap's bound for all time.
        let (xl, xr) = (state(self.free.place(l).0), state(self.free.place(r).0));
        let (d, dv) = (xl[0] - xr[0], xl[1] - xr[1]);
        let energy = dv * dv + m.w2 * d * d;
        let reach = (energy / m.w2).sqrt();
        let size = c.clearance + xl[0].abs() + xr[0].abs();
        let gap = self.check_gap(k, energy.sqrt());
        // Safe to the end while both move exactly: no check is queued,
        // so every path that changes either body's motion must lapse
        // or reschedule this contact (`join` does, and `release`
        // schedules the contacts it frees).
        if reach - c.clearance + 1e-12 * size < gap {
            return Some(self.opts.t_end);
        }
        // A rigid contact's gap does not depend on the speed: the rise
        // through it, from clearly below (at it, the bounds judge).
        let level = gap + c.clearance;
        if !self.is_rigid(k) || level - d <= 8.0 * f64::EPSILON * size {
            return None;
        }
        let tau = first_rise(d, dv, m, level, 1e-12 * size)?;
        (t + tau > t).then(|| (t + tau).min(self.opts.t_end))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The free damped oscillation from (d0, dv0) at τ, by its modes.
    fn oscillation(d0: f64, dv0: f64, m: Alike, tau: f64) -> f64 {
        let sigma = 0.5 * m.c2;
        let wd = (m.w2 - sigma * sigma).sqrt();
        (-sigma * tau).exp() * (d0 * (wd * tau).cos() + (dv0 + sigma * d0) / wd * (wd * tau).sin())
    }

    /// The first upward crossing of `level` by a fine scan and bisection
    /// (an independent computation).
    fn scanned(d0: f64, dv0: f64, m: Alike, level: f64) -> f64 {
        let f = |t: f64| oscillation(d0, dv0, m, t) - level;
        let h = 1e-4;
        let mut t = 0.0;
        while t < 50.0 {
            if f(t) < 0.0 && f(t + h) >= 0.0 {
                let (mut a, mut b) = (t, t + h);
                for _ in 0..80 {
                    let mid = 0.5 * (a + b);
                    if f(mid) < 0.0 {
                        a = mid;
                    } else {
                        b = mid;
                    }
                }
                return b;
            }
            t += h;
        }
        f64::INFINITY
    }

    #[test]
    fn the_first_rise_is_the_scanned_crossing() {
        let m = Alike { w2: 49.0, c2: 0.7 };
        // Rising, falling first, from rest, at a maximum, and one that
        // never reaches the level.
        for (d0, dv0, level) in [
            (0.0, 0.01, 1e-3),
            (2e-3, -0.02, 1e-3),
            (-1e-3, 0.0, 5e-4),
            (1e-3, 0.0, 1.2e-3),
            (-3e-4, 0.004, 1e-3),
            (0.0, 0.02, 1e-3),
        ] {
            let got = first_rise(d0, dv0, m, level, 0.0).expect("underdamped");
            let want = scanned(d0, dv0, m, level);
            if want.is_infinite() {
                assert!(got.is_infinite(), "{d0} {dv0}: {got} (never)");
            } else {
                assert!((got - want).abs() < 1e-12, "{d0} {dv0}: {got} vs {want}");
                let v = oscillation(d0, dv0, m, got);
                assert!((v - level).abs() < 1e-15, "{v} vs {level}");
            }
        }
        // Undamped: the same.
        let free = Alike { w2: 49.0, c2: 0.0 };
        let got = first_rise(2e-3, -0.02, free, 1e-3, 0.0).expect("undamped");
        assert!((got - scanned(2e-3, -0.02, free, 1e-3)).abs() < 1e-12);
        // Overdamped: left to the bounds.
        assert!(first_rise(0.0, 0.01, Alike { w2: 1.0, c2: 3.0 }, 1e-3, 0.0).is_none());
        // A graze within the margin: checked at its maximum.
        let graze = first_rise(0.0, 0.007 * (1.0 - 1e-13), free, 1e-3, 1e-12).expect("graze");
        assert!((7.0 * graze - 0.5 * PI).abs() < 1e-12, "{graze}");
    }
}
