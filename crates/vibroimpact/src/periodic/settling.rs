//! Whether a run's Poincaré samples have settled (docs/theory.md §8): a
//! period is read off the samples only once they repeat to the cluster
//! tolerance; samples still converging onto an orbit are told apart from
//! motion that does not repeat, with the forcing periods they still need.

use serde::Serialize;

/// What a run's recorded Poincaré samples say about its motion.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Motion {
    /// Every sample equals the one `period` forcing periods later, to the
    /// cluster tolerance.
    Periodic,
    /// The samples still converge onto an orbit: the differences
    /// s_{k+p} − s_k shrink geometrically over the window but some exceed
    /// the tolerance.
    Settling,
    /// Neither: quasi-periodic or chaotic motion (the Lyapunov exponents
    /// tell them apart), or a convergence too slow to see in the window.
    Irregular,
}

/// The verdict on one window of samples.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Verdict {
    /// What the motion is.
    pub(crate) motion: Motion,
    /// The period in forcing periods: the repeating one (periodic), or
    /// the one the samples converge onto (settling).
    pub(crate) period: Option<usize>,
    /// Settling: the forcing periods after the window's end before a
    /// window of the same length repeats to the tolerance, extrapolated
    /// from the differences' geometric decay.
    pub(crate) periods_needed: Option<f64>,
}

/// The largest difference of two samples `[u.., v..]`, each component
/// relative to its scale (displacements, velocities).
pub(crate) fn difference(a: &[f64], b: &[f64], scale: (f64, f64)) -> f64 {
    let n = a.len() / 2;
    (0..2 * n).fold(0.0f64, |m, i| {
        let s = if i < n { scale.0 } else { scale.1 };
        m.max((a[i] - b[i]).abs() / s.max(f64::MIN_POSITIVE))
    })
}

/// The geometric decay of `d` (differences one forcing period apart, in
/// order): the least-squares line through ln d falls, its slope below −4
/// standard errors (on R2 N = 2 from 3.7 to 11.1 rad/s, runs with
/// differences under 1e-2 gave −4.5 to −20, runs with differences of
/// order 1 −4.4 to +6.4). Returns the factor per forcing
/// period and the largest value of the last third. A free oscillation
/// sampled once per period turns by 2π ω0/Ω a sample, so with two modes
/// single differences beat about the line; the fit sees through that.
fn decay(d: &[f64]) -> Option<(f64, f64)> {
    let len = d.len();
    if len < 6 || d.iter().any(|&x| !(x > 0.0 && x.is_finite())) {
        return None;
    }
    let x_mean = (len - 1) as f64 / 2.0;
    let y_mean = d.iter().map(|x| x.ln()).sum::<f64>() / len as f64;
    let sxx: f64 = (0..len).map(|k| (k as f64 - x_mean).powi(2)).sum();
    let sxy: f64 = d
        .iter()
        .enumerate()
        .map(|(k, x)| (k as f64 - x_mean) * (x.ln() - y_mean))
        .sum();
    let slope = sxy / sxx;
    let residual: f64 = d
        .iter()
        .enumerate()
        .map(|(k, x)| (x.ln() - y_mean - slope * (k as f64 - x_mean)).powi(2))
        .sum();
    let se = (residual / (len - 2) as f64 / sxx).sqrt();
    if !(slope < 0.0 && slope < -4.0 * se) {
        return None;
    }
    let last = d[len - len / 3..].iter().copied().fold(0.0, f64::max);
    Some((slope.exp(), last))
}

/// The verdict on the samples `s` (one per forcing period, in order) with
/// their scales and the cluster tolerance `tol`.
///
/// Periodic with the smallest p ≤ len/2 for which every sample equals the
/// last one of its phase (k mod p) to the tolerance, unless the differences one q < p apart still
/// decay: a lightly damped oscillation spiralling into a fixed point by a
/// third of a turn a period repeats every 3 samples once its residual
/// nears the tolerance (R2 N = 2 at Ω = 10 rad/s after 100 periods:
/// "period 4"), and is settling onto period q. Settling with the smallest
/// p whose differences decay; the periods still needed extrapolate that
/// decay from the last third of the window until the first difference of
/// a new window, summed with all that follow it (over 1 − the factor a
/// period), is below `tol`, with a quarter more as a margin.
pub(crate) fn verdict(s: &[Vec<f64>], scale: (f64, f64), tol: f64) -> Verdict {
    let half = s.len() / 2;
    let diffs = |p: usize| -> Vec<f64> {
        (0..s.len() - p)
            .map(|k| difference(&s[k], &s[k + p], scale))
            .collect()
    };
    // Each sample against the last of its phase: consecutive differences
    // under the tolerance can still add up to a drift over it.
    let repeats = (1..=half).find(|&p| {
        let last = s.len() - p;
        (0..s.len()).all(|k| difference(&s[k], &s[last + (k + p - last % p) % p], scale) <= tol)
    });
    let converging = (1..=half).find_map(|p| {
        let d = diffs(p);
        decay(&d).map(|(rate, last)| {
            let third = (d.len() / 3) as f64;
            // The drift from a sample to the window's end is at most its
            // difference over (1 − rate): that is what must reach `tol`.
            let target = tol * (1.0 - rate);
            let needed = if last > target {
                (target / last).ln() / rate.ln() - 0.5 * third
            } else {
                0.0
            };
            (p, 1.25 * needed.max(0.0) + p as f64)
        })
    });
    match (repeats, converging) {
        (Some(p), Some((q, needed))) if q < p => Verdict {
            motion: Motion::Settling,
            period: Some(q),
            periods_needed: Some(needed),
        },
        (Some(p), _) => Verdict {
            motion: Motion::Periodic,
            period: Some(p),
            periods_needed: None,
        },
        (None, Some((q, needed))) => Verdict {
            motion: Motion::Settling,
            period: Some(q),
            periods_needed: Some(needed),
        },
        (None, None) => Verdict {
            motion: Motion::Irregular,
            period: None,
            periods_needed: None,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of a decaying rotation about `centre` (a fixed point),
    /// `turn` radians and a factor `rho` a period, from radius `r0`.
    fn spiral(len: usize, r0: f64, rho: f64, turn: f64) -> Vec<Vec<f64>> {
        (0..len)
            .map(|k| {
                let r = r0 * rho.powi(k as i32);
                let a = turn * k as f64;
                vec![1.0 + r * a.cos(), 0.5 + r * a.sin()]
            })
            .collect()
    }

    /// A spiral shrinking by 0.9 a period from 1e-3 is settling onto
    /// period 1, and the periods it still needs, extrapolated, are those
    /// its exact decay needs (within the quarter margin and one third of
    /// the window); after them it is periodic. A spiral a third of a turn
    /// a period whose residual is under the tolerance every 3 samples but
    /// not every sample is settling onto period 1, not period 3. An exact
    /// period-3 sequence is periodic with period 3; a pseudo-random one is
    /// irregular.
    #[test]
    fn a_decaying_spiral_is_settling_and_a_cycle_is_periodic() {
        let scale = (1.0, 1.0);
        let tol = 1e-5;
        let s = spiral(20, 1e-3, 0.9, 0.7);
        let v = verdict(&s, scale, tol);
        assert_eq!((v.motion, v.period), (Motion::Settling, Some(1)));
        // Exact: the first difference of a window starting n periods
        // after this one's end, r0 |rho e^(i turn) - 1| rho^(20 + n), at
        // tol (1 - rho), where the drift it starts is at most tol.
        let chord = 1e-3 * (0.9 * 0.7f64.cos() - 1.0).hypot(0.9 * 0.7f64.sin());
        let exact = (0.1 * tol / chord).ln() / 0.9f64.ln() - 20.0;
        let needed = v.periods_needed.unwrap();
        assert!(
            needed > exact && needed < 1.25 * exact + 8.0,
            "{needed} vs {exact}"
        );
        let later = spiral(20 + needed.ceil() as usize + 20, 1e-3, 0.9, 0.7);
        let window = &later[later.len() - 20..];
        assert_eq!(verdict(window, scale, tol).motion, Motion::Periodic);

        let third = 2.0 * std::f64::consts::PI / 3.0;
        let s = spiral(20, 1e-4, 0.93, third);
        let v = verdict(&s, scale, 1e-4);
        assert_eq!((v.motion, v.period), (Motion::Settling, Some(1)));

        let cycle: Vec<Vec<f64>> = (0..20).map(|k| vec![(k % 3) as f64, 0.0]).collect();
        let v = verdict(&cycle, scale, tol);
        assert_eq!((v.motion, v.period), (Motion::Periodic, Some(3)));

        let mut x = 0.3f64;
        let chaos: Vec<Vec<f64>> = (0..20)
            .map(|_| {
                x = 3.99 * x * (1.0 - x);
                vec![x, 0.0]
            })
            .collect();
        assert_eq!(verdict(&chaos, scale, tol).motion, Motion::Irregular);
    }
}
