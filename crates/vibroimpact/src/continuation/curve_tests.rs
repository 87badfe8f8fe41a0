//! Two-parameter curves against the one-parameter branches and
//! independent shooting.

use super::*;
use crate::continuation::{continue_branch, ContinuationOptions, SpecialKind};

use crate::reference::NATURAL_FREQUENCY as W0;

fn r2(n: usize, frequency: f64, amplitude: f64) -> Result<Model, String> {
    use crate::model::BaseExcitation;
    let m = crate::reference::r2(n, 1e-3, frequency).map_err(|e| e.to_string())?;
    Ok(m.with_base(BaseExcitation::Harmonic {
        amplitude,
        frequency,
        phase: 0.0,
    }))
}

/// R2 N = 1: the fold curve in (frequency, amplitude) from the fold LP1 of
/// the branch at amplitude 0.05 m/s² turns at a cusp and comes back to
/// 0.05 at the other fold LP2 (to 1e-6 in the frequency); along it the
/// orbit integrated again at the point's parameters is periodic and Φ has
/// a multiplier +1.
#[test]
fn fold_curve_joins_the_two_folds_through_a_cusp() {
    let family = |w: f64| r2(1, w, 0.05);
    let start = r2(1, 0.5 * W0, 0.05).unwrap();
    let guess = crate::periodic::guess_by_simulation(&start, 200.0, 1e-9).unwrap();
    let branch = continue_branch(
        family,
        0.5 * W0,
        &guess,
        1.5 * W0,
        &ContinuationOptions::default(),
        |_| true,
    )
    .unwrap();
    let folds: Vec<&super::super::SpecialPoint> = branch
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
        .collect();
    assert_eq!(folds.len(), 2, "{:?}", branch.special);
    let lp1 = folds
        .iter()
        .max_by(|a, b| a.parameter.total_cmp(&b.parameter))
        .unwrap();
    let lp2 = folds
        .iter()
        .min_by(|a, b| a.parameter.total_cmp(&b.parameter))
        .unwrap();
    let opts = CurveOptions {
        shooting: ShootingOptions {
            symmetric: branch.symmetric,
            ..ShootingOptions::default()
        },
        bounds: [(0.3 * W0, 1.7 * W0), (1e-3, 0.0501)],
        ..CurveOptions::default()
    };
    let curve = continue_curve(
        r2_family,
        CurveKind::Fold,
        (&lp1.state, lp1.parameter, 0.05),
        -1.0,
        &opts,
    )
    .unwrap();
    assert_eq!(
        curve.stop,
        CurveStop::LeftBounds,
        "{} points",
        curve.points.len()
    );
    // The curve ends on the bound q = 0.05 it crossed on the way back.
    let last = curve.points.last().unwrap();
    assert!((last.q - 0.0501).abs() < 1e-15, "{}", last.q);
    let back = continue_curve(
        r2_family,
        CurveKind::Fold,
        (&lp1.state, lp1.parameter, 0.05),
        -1.0,
        &CurveOptions {
            bounds: [(0.3 * W0, 1.7 * W0), (1e-3, 0.05)],
            ..opts.clone()
        },
    )
    .unwrap();
    let end = back.points.last().unwrap();
    assert_eq!(end.q, 0.05);
    assert!(
        (end.p - lp2.parameter).abs() < 1e-6,
        "{} vs {}",
        end.p,
        lp2.parameter
    );
    for point in curve.points.iter().step_by(5) {
        let m = r2(1, point.p, point.q).unwrap();
        // The orbit and its monodromy integrated again (at the tolerance
        // of reported multipliers, 1e-13 against the curve's 1e-12):
        // periodic to 1e-8 of its size, with a multiplier +1 to 2e-7. The
        // curve's own multiplier is 1 to 1e-10; the two monodromies differ
        // by up to 5e-8 (measured), since the variational columns ride on
        // the state's steps outside the error control. (Shooting's Newton
        // is singular at a fold.)
        let fine = ShootingOptions {
            rtol: 1e-13,
            control_monodromy: true,
            ..opts.shooting.clone()
        };
        let map = period_map(&m, &point.state, &fine).unwrap();
        let size = point.max_displacement[0];
        let off = map
            .image
            .iter()
            .zip(&point.state)
            .enumerate()
            .fold(0.0f64, |e, (i, (a, b))| {
                e.max((a - b).abs() / if i == 0 { size } else { size * point.p })
            });
        assert!(
            off < 1e-8,
            "at ({}, {}): off the orbit by {off:e}",
            point.p,
            point.q
        );
        let multipliers = map_multipliers(&map.monodromy, fine.symmetric).unwrap();
        let near_one = multipliers
            .iter()
            .map(|m| (m - 1.0).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(
            near_one < 1e-8,
            "at ({}, {}): {multipliers:?}, own {:?}",
            point.p,
            point.q,
            point.multipliers
        );
    }
}

fn r2_family(p: f64, q: f64) -> Result<Model, String> {
    r2(1, p, q)
}
