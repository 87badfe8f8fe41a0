//! Two-parameter curves against the one-parameter branches and
//! independent shooting.

use super::*;
use crate::continuation::{continue_branch, ContinuationOptions, SpecialKind};
use crate::model::family::{of, of2};
use crate::model::ModelError;
use crate::periodic::{map_multipliers, period_map};

use crate::model::reference::NATURAL_FREQUENCY as W0;

fn r2(n: usize, frequency: f64, amplitude: f64) -> Result<Model, ModelError> {
    crate::model::reference::r2_forced(n, 1e-3, frequency, amplitude)
}

/// R2 N = 1: the fold curve in (frequency, amplitude) from the fold LP1 of
/// the branch at amplitude 0.05 m/s² turns at a cusp and comes back to
/// 0.05 at the other fold LP2 (to 1e-6 in the frequency); along it the
/// orbit integrated again at the point's parameters is periodic and Φ has
/// a multiplier +1.
#[test]
fn fold_curve_joins_the_two_folds_through_a_cusp() {
    let family = of("frequency", |w: f64| r2(1, w, 0.05));
    let start = r2(1, 0.5 * W0, 0.05).unwrap();
    let guess = crate::periodic::guess_by_simulation(&start, 200.0, 1e-9).unwrap();
    let one = continue_branch(
        family,
        0.5 * W0,
        &guess,
        1.5 * W0,
        &ContinuationOptions::default(),
        |_| true,
    )
    .unwrap();
    let folds: Vec<&super::super::SpecialPoint> = one
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::Fold)
        .collect();
    assert_eq!(folds.len(), 2, "{:?}", one.special);
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
            symmetric: one.symmetric,
            ..ShootingOptions::default()
        },
        bounds: [(0.3 * W0, 1.7 * W0), (1e-3, 0.0501)],
        ..CurveOptions::default()
    };
    let curve = continue_curve(
        of2(["frequency", "amplitude"], r2_family),
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
    // The first cusp (near 0.336 ω0, 0.0447 m/s²: the amplitude is
    // largest there along the curve's lower part) is where the hysteresis
    // region ends: independently, the one-parameter branch 1 % below its
    // amplitude has two folds within 0.03 ω0 of it, and 1 % above none
    // (AUTO-07p's fold curve has its cusp at 0.33579 ω0, 0.04466 m/s²).
    // (Near 0.496 ω0 the curve turns within 4e-4 in frequency, where one
    // or two more cusps are found depending on the step sequence.)
    let cusps: Vec<_> = curve
        .special
        .iter()
        .filter(|s| s.kind == Codim2Kind::Cusp)
        .collect();
    assert!(!cusps.is_empty(), "{:?}", curve.special);
    let cusp = curve.points[cusps[0].point].clone();
    assert!((cusp.p / W0 - 0.3358).abs() < 1e-3, "{}", cusp.p / W0);
    for (factor, folds) in [(0.99, 2), (1.01, 0)] {
        let b = branch_over(1, (true, true), factor * cusp.q, (0.3 * W0, 0.4 * W0));
        let count = b
            .special
            .iter()
            .filter(|s| s.kind == SpecialKind::Fold && (s.parameter - cusp.p).abs() < 0.03 * W0)
            .count();
        assert_eq!(count, folds, "at {factor} × the cusp: {:?}", b.special);
    }
    // The curve ends on the bound q = 0.05 it crossed on the way back.
    let last = curve.points.last().unwrap();
    assert!((last.q - 0.0501).abs() < 1e-15, "{}", last.q);
    let back = continue_curve(
        of2(["frequency", "amplitude"], r2_family),
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
    // The orbit and its monodromy integrated again (at the tolerance of
    // reported multipliers, 1e-13 against the curve's 1e-12): periodic to
    // 1e-8 of its size, with a multiplier +1 to 1e-8. The curve's own
    // multiplier is 1 to 1e-10; the two monodromies differ by up to 5e-8
    // (measured), since the variational columns ride on the state's steps
    // outside the error control. (Shooting's Newton is singular at a fold.)
    check_points(
        &curve,
        (true, true),
        opts.shooting.symmetric,
        5,
        1e-8,
        |m| {
            m.iter()
                .map(|m| (m - 1.0).norm())
                .fold(f64::INFINITY, f64::min)
        },
    );
}

fn r2_family(p: f64, q: f64) -> Result<Model, ModelError> {
    r2(1, p, q)
}

/// A row of `n` seed pendulums (walls `(left, right)`) at base amplitude q
/// and frequency p.
fn row(n: usize, walls: (bool, bool), p: f64, q: f64) -> Result<Model, ModelError> {
    use crate::model::reference::{seed_law, DAMPING_RATIO, MASS};
    use crate::model::BaseExcitation;
    Model::row(
        n,
        MASS,
        MASS * W0 * W0,
        2.0 * DAMPING_RATIO * MASS * W0,
        1e-3,
        seed_law(),
        walls,
        BaseExcitation::Harmonic {
            amplitude: q,
            frequency: p,
            phase: 0.0,
        },
    )
}

/// The branch 0.5 → 1.5 ω0 of the row at amplitude q, from a 200-period
/// simulation at 0.5 ω0.
fn branch(n: usize, walls: (bool, bool), q: f64) -> crate::continuation::Branch {
    branch_over(n, walls, q, (0.5 * W0, 1.5 * W0))
}

/// The branch over `(from, to)` of the row at amplitude q, from a
/// 200-period simulation at `from`.
fn branch_over(
    n: usize,
    walls: (bool, bool),
    q: f64,
    (from, to): (f64, f64),
) -> crate::continuation::Branch {
    let guess = crate::continuation::amplitude_homotopy(
        of("amplitude", |a| row(n, walls, from, a)),
        q,
        &ContinuationOptions::default(),
    )
    .unwrap();
    continue_branch(
        of("frequency", |w: f64| row(n, walls, w, q)),
        from,
        &guess,
        to,
        &ContinuationOptions::default(),
        |_| true,
    )
    .unwrap()
}

/// The special point of `kind` with the largest (or smallest) parameter.
fn special(
    branch: &crate::continuation::Branch,
    kind: SpecialKind,
    largest: bool,
) -> super::super::SpecialPoint {
    let mut list: Vec<_> = branch.special.iter().filter(|s| s.kind == kind).collect();
    list.sort_by(|a, b| a.parameter.total_cmp(&b.parameter));
    let pick = if largest { list.last() } else { list.first() };
    (*pick.unwrap_or_else(|| panic!("no {kind:?} in {:?}", branch.special))).clone()
}

/// The orbit of every `step`-th point recomputed at the tolerance of
/// reported multipliers, with the monodromy's columns in the step control:
/// periodic to 1e-8 of its size, and `critical(multipliers)` (the distance
/// of the critical multiplier from its value) below `tol`.
fn check_points(
    curve: &Curve,
    walls: (bool, bool),
    symmetric: bool,
    step: usize,
    tol: f64,
    critical: impl Fn(&[Complex<f64>]) -> f64,
) {
    let fine = ShootingOptions {
        rtol: 1e-13,
        control_monodromy: true,
        symmetric,
        ..ShootingOptions::default()
    };
    let n = curve.points[0].state.len() / 2;
    for point in curve.points.iter().step_by(step) {
        let m = row(n, walls, point.p, point.q).unwrap();
        let map = period_map(&m, &point.state, &fine).unwrap();
        let size = point.max_displacement.iter().fold(0.0f64, |a, b| a.max(*b));
        let off = map
            .image
            .iter()
            .zip(&point.state)
            .enumerate()
            .fold(0.0f64, |e, (i, (a, b))| {
                e.max((a - b).abs() / if i < n { size } else { size * point.p })
            });
        assert!(
            off < 1e-8,
            "at ({}, {}): off the orbit by {off:e}",
            point.p,
            point.q
        );
        let multipliers = map_multipliers(&map.monodromy, symmetric).unwrap();
        let miss = critical(&multipliers);
        assert!(
            miss < tol,
            "at ({}, {}): {multipliers:?} misses by {miss:e}",
            point.p,
            point.q
        );
    }
}

/// A period-doubling curve of the impact oscillator with one wall (R2's
/// pendulum, N = 1, right wall only: no mirror symmetry) from the first
/// flip of the branch at 0.05 m/s²: along it Φ has a multiplier −1 to
/// 1e-8 on the orbit integrated again.
#[test]
fn period_doubling_curve_keeps_a_multiplier_minus_one() {
    let walls = (false, true);
    let b = branch(1, walls, 0.05);
    assert!(!b.symmetric);
    let pd = special(&b, SpecialKind::PeriodDoubling, false);
    let opts = CurveOptions {
        bounds: [(0.3 * W0, 1.7 * W0), (0.045, 0.055)],
        ..CurveOptions::default()
    };
    for direction in [1.0, -1.0] {
        let curve = continue_curve(
            of2(["frequency", "amplitude"], |p, q| row(1, walls, p, q)),
            CurveKind::PeriodDoubling,
            (&pd.state, pd.parameter, 0.05),
            direction,
            &opts,
        )
        .unwrap();
        assert_eq!(curve.stop, CurveStop::LeftBounds);
        assert!(curve.points.len() > 3);
        check_points(&curve, walls, false, 2, 1e-8, |m| {
            m.iter()
                .map(|m| (m + 1.0).norm())
                .fold(f64::INFINITY, f64::min)
        });
    }
}

/// A Neimark–Sacker curve of R2 N = 2 from the torus point near 1.15 ω0
/// at 0.02 m/s² (a pair at angle ±2.86): along it a pair of multipliers
/// has modulus 1 to 1e-8 on the orbit integrated again, at an angle that
/// moves with the parameters.
#[test]
fn neimark_sacker_curve_keeps_a_pair_on_the_unit_circle() {
    let walls = (true, true);
    let b = branch(2, walls, 0.02);
    let ns = special(&b, SpecialKind::NeimarkSacker, true);
    assert!((ns.parameter / W0 - 1.147).abs() < 1e-3, "{}", ns.parameter);
    let opts = CurveOptions {
        shooting: ShootingOptions {
            symmetric: b.symmetric,
            ..ShootingOptions::default()
        },
        bounds: [(0.3 * W0, 1.7 * W0), (0.018, 0.022)],
        ..CurveOptions::default()
    };
    let curve = continue_curve(
        of2(["frequency", "amplitude"], |p, q| row(2, walls, p, q)),
        CurveKind::NeimarkSacker,
        (&ns.state, ns.parameter, 0.02),
        1.0,
        &opts,
    )
    .unwrap();
    assert_eq!(curve.stop, CurveStop::LeftBounds);
    let angle = |pt: &CurvePoint| {
        pt.multipliers
            .iter()
            .filter(|m| m.im > 0.0)
            .min_by(|a, b| (a.norm() - 1.0).abs().total_cmp(&(b.norm() - 1.0).abs()))
            .unwrap()
            .arg()
    };
    let (first, last) = (&curve.points[0], curve.points.last().unwrap());
    assert!(
        (angle(first) - angle(last)).abs() > 0.02,
        "{} {}",
        angle(first),
        angle(last)
    );
    check_points(&curve, walls, b.symmetric, 2, 1e-8, |m| {
        m.iter()
            .filter(|m| m.im.abs() > 1e-3)
            .map(|m| (m.norm() - 1.0).abs())
            .fold(f64::INFINITY, f64::min)
    });
}

/// A grazing curve of R2 N = 2 from the grazing near 0.505 ω0 at 0.05
/// m/s²: along it the orbit integrated again grazes (a contact's closest
/// approach at the impact threshold) to 1e-11 m.
#[test]
fn grazing_curve_keeps_a_contact_at_the_threshold() {
    let walls = (true, true);
    let b = branch(2, walls, 0.05);
    let shooting = ShootingOptions {
        symmetric: b.symmetric,
        ..ShootingOptions::default()
    };
    let gr = b
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::Grazing)
        .find(|s| {
            let m = row(2, walls, s.parameter, 0.05).unwrap();
            starts_grazing(grazing_margin(&m, &s.state, &shooting).unwrap(), &shooting)
        })
        .unwrap_or_else(|| panic!("no grazing in {:?}", b.special));
    let opts = CurveOptions {
        shooting: shooting.clone(),
        bounds: [(0.3 * W0, 1.7 * W0), (0.045, 0.055)],
        ..CurveOptions::default()
    };
    let curve = continue_curve(
        of2(["frequency", "amplitude"], |p, q| row(2, walls, p, q)),
        CurveKind::Grazing,
        (&gr.state, gr.parameter, 0.05),
        1.0,
        &opts,
    )
    .unwrap();
    assert_eq!(curve.stop, CurveStop::LeftBounds);
    let fine = ShootingOptions {
        rtol: 1e-13,
        ..shooting
    };
    for pt in curve.points.iter().step_by(2) {
        let m = row(2, walls, pt.p, pt.q).unwrap();
        let margin = grazing_margin(&m, &pt.state, &fine).unwrap();
        assert!(
            margin.abs() < 1e-11,
            "at ({}, {}): margin {margin:e} m",
            pt.p,
            pt.q
        );
    }
}

/// A Neimark–Sacker curve ends on the real axis: on R2 N = 2 at 0.05
/// m/s², the curve from NS1 reaches κ = −1, where the half map's pair
/// meets at −1 (a double branch point: the curve of symmetry-breaking
/// points passes there). Independently, the orbit integrated again there
/// has two eigenvalues of DG with sum −2 and product 1 to 1e-6 (each alone
/// is only defined to the square root of the error at a double root).
#[test]
fn neimark_sacker_curve_ends_at_a_double_branch_point() {
    let walls = (true, true);
    let b = branch(2, walls, 0.05);
    let shooting = ShootingOptions {
        symmetric: b.symmetric,
        ..ShootingOptions::default()
    };
    let opts = CurveOptions {
        shooting: shooting.clone(),
        bounds: [(0.45 * W0, 0.6 * W0), (0.03, 0.06)],
        ..CurveOptions::default()
    };
    let ns = special(&b, SpecialKind::NeimarkSacker, false);
    let curve = continue_curve(
        of2(["frequency", "amplitude"], |p, q| row(2, walls, p, q)),
        CurveKind::NeimarkSacker,
        (&ns.state, ns.parameter, 0.05),
        -1.0,
        &opts,
    )
    .unwrap();
    let s = curve
        .special
        .iter()
        .find(|s| s.kind == Codim2Kind::DoubleBranchPoint)
        .unwrap_or_else(|| panic!("{:?} {:?}", curve.special, curve.stop));
    let pt = &curve.points[s.point];
    let fine = ShootingOptions {
        rtol: 1e-13,
        control_monodromy: true,
        ..shooting
    };
    let m = row(2, walls, pt.p, pt.q).unwrap();
    let map = period_map(&m, &pt.state, &fine).unwrap();
    let mut eig = crate::periodic::floquet_multipliers(&map.monodromy).unwrap();
    eig.sort_by(|a, b| (a + 1.0).norm().total_cmp(&(b + 1.0).norm()));
    let (sum, product) = (eig[0] + eig[1], eig[0] * eig[1]);
    assert!((sum + 2.0).norm() < 1e-6, "{eig:?}");
    assert!((product - 1.0).norm() < 1e-6, "{eig:?}");
}

/// The run settings of charts (transient, record) for the rows above.
fn chart_settings(transient: usize, record: usize) -> crate::maps::sweep::Settings {
    let text = include_str!("../../../../../examples/fujita-row-n2.toml");
    let loaded = crate::model::file::ModelDocument::from_toml(text, "fujita-row-n2.toml")
        .unwrap()
        .build()
        .unwrap();
    crate::maps::attractor::settings(
        &loaded,
        &crate::maps::sweep::SweepOptions {
            transient,
            record,
            ..crate::maps::sweep::SweepOptions::default()
        },
    )
    .unwrap()
}

/// The chart's cells agree with the curves. Either side of the
/// period-doubling curve of the one-wall oscillator (2 % in frequency), a
/// cell run from the period-1 orbit there, displaced by 1 % of its size
/// (300 transient, 20 recorded periods), shows period 1 where shooting
/// finds that orbit stable, and period 2 where its multiplier has passed
/// −1 (down to −2: further out the flip's period-2 orbit need not be the
/// attractor). Either side of the fold curve LP1 of R2 N = 1: 2 % below,
/// where shooting from the fold's orbit finds a stable orbit (not the
/// saddle; at 3 points or more), a cell run from it (displaced by 1 %)
/// returns to it (period 1, to 1e-3 of its size); 2 % above, where no
/// orbit continues the fold's, the run from the fold's orbit ends more
/// than one orbit size away (on the other branch).
#[test]
fn chart_cells_agree_with_the_curves() {
    let settings = chart_settings(300, 20);
    let walls = (false, true);
    let b = branch(1, walls, 0.05);
    let pd = special(&b, SpecialKind::PeriodDoubling, false);
    let opts = CurveOptions {
        bounds: [(0.3 * W0, 1.7 * W0), (0.04, 0.06)],
        ..CurveOptions::default()
    };
    let curve = continue_curve(
        of2(["frequency", "amplitude"], |p, q| row(1, walls, p, q)),
        CurveKind::PeriodDoubling,
        (&pd.state, pd.parameter, 0.05),
        1.0,
        &opts,
    )
    .unwrap();
    let (mut period1, mut period2) = (0, 0);
    for pt in curve.points.iter().step_by(2) {
        for f in [0.98, 1.02] {
            let m = row(1, walls, f * pt.p, pt.q).unwrap();
            let orbit = crate::periodic::shoot(&m, &pt.state, &ShootingOptions::default()).unwrap();
            assert!(orbit.converged);
            let start: Vec<f64> = orbit.initial_state.iter().map(|x| 1.01 * x).collect();
            let (run, _) = crate::maps::attractor::run_from(&m, f * pt.p, start, &settings);
            let flip = orbit.multipliers.iter().map(|m| m.re).fold(0.0, f64::min);
            if orbit.stable() {
                assert_eq!(run.period, Some(1), "at ({}, {})", f * pt.p, pt.q);
                period1 += 1;
            } else if flip > -2.0 {
                assert_eq!(run.period, Some(2), "at ({}, {}): {flip}", f * pt.p, pt.q);
                period2 += 1;
            }
        }
    }
    assert!(period1 >= 3 && period2 >= 3, "{period1} {period2}");
    let walls = (true, true);
    let b = branch(1, walls, 0.05);
    let lp = special(&b, SpecialKind::Fold, true);
    let fold = continue_curve(
        of2(["frequency", "amplitude"], |p, q| row(1, walls, p, q)),
        CurveKind::Fold,
        (&lp.state, lp.parameter, 0.05),
        1.0,
        &CurveOptions {
            shooting: ShootingOptions {
                symmetric: b.symmetric,
                ..ShootingOptions::default()
            },
            bounds: [(0.3 * W0, 1.7 * W0), (0.05, 0.07)],
            ..CurveOptions::default()
        },
    )
    .unwrap();
    let mut stable = 0;
    for pt in fold.points.iter().step_by(3) {
        let size = pt.max_displacement[0];
        // Distance (in orbit sizes, u and v/Ω) of a state from another.
        let dist = |a: &[f64], b: &[f64]| {
            (0..2).fold(0.0f64, |m, i| {
                m.max((a[i] - b[i]).abs() / if i == 0 { size } else { size * pt.p })
            })
        };
        let inside = row(1, walls, 0.98 * pt.p, pt.q).unwrap();
        let orbit =
            crate::periodic::shoot(&inside, &pt.state, &ShootingOptions::default()).unwrap();
        // Shooting may land on the saddle of the pair instead, or nowhere
        // (its Newton is nearly singular by the fold).
        if !(orbit.converged && orbit.stable()) {
            continue;
        }
        stable += 1;
        let start: Vec<f64> = orbit.initial_state.iter().map(|x| 1.01 * x).collect();
        let (run, rec) = crate::maps::attractor::run_from(&inside, 0.98 * pt.p, start, &settings);
        assert_eq!(run.period, Some(1));
        let back = dist(rec.samples.last().unwrap(), &orbit.initial_state);
        assert!(back < 1e-3, "at ({}, {}): {back}", pt.p, pt.q);
        let outside = row(1, walls, 1.02 * pt.p, pt.q).unwrap();
        let (_, rec) =
            crate::maps::attractor::run_from(&outside, 1.02 * pt.p, pt.state.clone(), &settings);
        let jump = dist(rec.samples.last().unwrap(), &pt.state);
        assert!(jump > 1.0, "at ({}, {}): {jump}", pt.p, pt.q);
    }
    assert!(stable >= 3, "{stable}");
}

/// The matrix-free form follows the same curves as the dense one: R2
/// N = 1's fold curve from LP1 and R2 N = 4's branch-point curve from its
/// highest branch point end on the same bound at the same first parameter
/// to 1e-7 (relative), with the same largest multiplier to 1e-6.
#[test]
fn krylov_curves_match_dense() {
    for (n, kind, special_kind) in [
        (1, CurveKind::Fold, SpecialKind::Fold),
        (4, CurveKind::BranchPoint, SpecialKind::BranchPoint),
    ] {
        let walls = (true, true);
        let b = branch(n, walls, 0.05);
        let sp = special(&b, special_kind, true);
        let dense_opts = CurveOptions {
            shooting: ShootingOptions {
                symmetric: b.symmetric,
                ..ShootingOptions::default()
            },
            bounds: [(0.3 * W0, 1.7 * W0), (0.05, 0.052)],
            ..CurveOptions::default()
        };
        let krylov_opts = CurveOptions {
            krylov: Some(2 * n),
            ..dense_opts.clone()
        };
        let mut ends = Vec::new();
        for opts in [&dense_opts, &krylov_opts] {
            let c = continue_curve(
                of2(["frequency", "amplitude"], |p, q| row(n, walls, p, q)),
                kind,
                (&sp.state, sp.parameter, 0.05),
                1.0,
                opts,
            )
            .unwrap();
            assert_eq!(c.stop, CurveStop::LeftBounds);
            ends.push(c.points.last().unwrap().clone());
        }
        let (a, k) = (&ends[0], &ends[1]);
        assert_eq!(a.q, k.q);
        assert!(
            (a.p - k.p).abs() < 1e-7 * a.p,
            "N = {n}: {} vs {}",
            a.p,
            k.p
        );
        let (ma, mk) = (a.multipliers[0].norm(), k.multipliers[0].norm());
        assert!((ma - mk).abs() < 1e-6, "N = {n}: {ma} vs {mk}");
    }
}
