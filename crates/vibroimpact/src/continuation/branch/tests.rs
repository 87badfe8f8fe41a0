//! The branch's start: a guess that is a symmetric orbit already is
//! corrected on the half map at once, and the branch is the one a shot
//! start gives.

use super::*;
use crate::continuation::{amplitude_homotopy, continue_branch};
use crate::model::family::of;
use crate::model::reference::{r2, r2_forced, BASE_AMPLITUDE, NATURAL_FREQUENCY as W0};

/// R2 N = 2 from 0.95 ω0 down to 0.85 ω0 (the primary orbit, by the
/// amplitude homotopy: symmetric): from a guess off the orbit (not
/// symmetric to 100 tol) the start is shot over the whole period; from
/// the orbit it reached (symmetric) it is corrected on the half map
/// without shooting. Both branches have the same points (parameters and
/// states to 1e-9 of the state's size) and multipliers (to 1e-7).
#[test]
fn a_symmetric_start_is_corrected_on_the_half_map_at_once() {
    let (from, to) = (0.95 * W0, 0.85 * W0);
    let model = r2(2, 1e-3, from).unwrap();
    let opts = ContinuationOptions::default();
    let amplitude = of("amplitude", |a: f64| r2_forced(2, 1e-3, from, a));
    let orbit = amplitude_homotopy(amplitude, BASE_AMPLITUDE, &opts).unwrap();
    let mut guess = orbit.clone();
    guess[0] += 2e-5;
    assert!(!is_symmetric_orbit(&model, &guess, &opts.shooting));
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let shot = continue_branch(family, from, &guess, to, &opts, |_| true).unwrap();
    let start = &shot.points[0].state;
    assert!(is_symmetric_orbit(&model, start, &opts.shooting));
    let corrected = continue_branch(family, from, start, to, &opts, |_| true).unwrap();
    assert_eq!(shot.stop, corrected.stop);
    assert_eq!(shot.points.len(), corrected.points.len());
    assert!(shot.points.len() > 3, "{}", shot.points.len());
    let size = start.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
    for (a, b) in shot.points.iter().zip(&corrected.points) {
        assert!((a.parameter - b.parameter).abs() < 1e-9 * W0);
        for (x, y) in a.state.iter().zip(&b.state) {
            assert!((x - y).abs() < 1e-9 * size, "{x} vs {y}");
        }
        for (m, n) in a.multipliers.iter().zip(&b.multipliers) {
            assert!((m - n).norm() < 1e-7, "{m} vs {n}");
        }
    }
}
