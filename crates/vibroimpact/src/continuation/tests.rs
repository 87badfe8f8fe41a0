//! Tests of continuation: the linear limit, the R2 branches against
//! AUTO-07p and brute force, branch switching.
use super::*;
use crate::model::family::of;
use crate::model::{Model, ModelError};
use crate::periodic::{orbit_summary, period_map, shoot};
use crate::simulate::{simulate, SimulationOptions};

use crate::model::reference::NATURAL_FREQUENCY as W0;

fn r2(n: usize, clearance: f64, omega: f64) -> Result<Model, ModelError> {
    crate::model::reference::r2(n, clearance, omega)
}

/// Tight tolerances for branches in the linear limit, compared with exact
/// steady states.
fn tight_options() -> ContinuationOptions {
    ContinuationOptions {
        shooting: ShootingOptions {
            rtol: 1e-12,
            tol: 1e-10,
            displacement_scale: 1e-2,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// R2 N = 2 with this clearance, forced at `w` with the base amplitude `a`.
fn r2_forced(clearance: f64, w: f64, a: f64) -> Result<Model, ModelError> {
    crate::model::reference::r2_forced(2, clearance, w, a)
}

/// R2 with N bodies in the linear limit (gaps of 1 km) from 0.8 to 1.2 ω0,
/// tight tolerances.
fn linear_branch(n: usize) -> Branch {
    let opts = tight_options();
    let family = of("frequency", |w: f64| r2(n, 1e3, w));
    continue_branch(family, 0.8 * W0, &vec![0.0; 2 * n], 1.2 * W0, &opts, |_| {
        true
    })
    .unwrap()
}

/// R3 along a branch: amplitude equals the exact steady state, no
/// special points, all stable.
#[test]
fn linear_branch_is_exact() {
    let b = linear_branch(2);
    assert_eq!(b.stop, StopReason::ReachedEnd);
    assert!(
        b.special.is_empty(),
        "{:?}",
        b.special.iter().map(|s| &s.label).collect::<Vec<_>>()
    );
    assert!(b.points.len() > 10);
    for p in &b.points {
        let w = p.parameter;
        let exact = crate::model::reference::r3_steady_amplitude(w);
        // The exact extremum (located on the dense output).
        assert!(
            (p.max_displacement[0] / exact - 1.0).abs() < 1e-8,
            "at {w}: {} vs {exact}",
            p.max_displacement[0]
        );
        assert!(p.stable);
    }
}

/// The arclength counts the state as its root-mean-square over the bodies:
/// in the linear limit a row of 8 identical bodies moves as one body, and
/// its branch takes the same steps in the frequency as a row of two (with
/// the plain Euclidean norm of the scaled state, steps twice as short in
/// the parameter).
#[test]
fn steps_do_not_shrink_with_the_row_length() {
    let (two, eight) = (linear_branch(2), linear_branch(8));
    assert_eq!(two.stop, StopReason::ReachedEnd);
    assert_eq!(eight.stop, StopReason::ReachedEnd);
    assert!(two.points.len() > 10);
    assert_eq!(two.points.len(), eight.points.len());
    for (a, b) in two.points.iter().zip(&eight.points) {
        assert!(
            (a.parameter - b.parameter).abs() < 1e-8 * W0,
            "{} vs {}",
            a.parameter,
            b.parameter
        );
    }
}

/// An amplitude branch from zero forcing (the rest state, an exact
/// periodic orbit) in the linear limit: the response is the exact steady
/// state times A / A_ref at every point, and the parameter's scale is the
/// range's (with the start's |p0| = 0 there was no scale at all; with a
/// start at 1e-3 A_ref, every step moved A by at most ds_max·|p0| =
/// 5e-5 A_ref).
#[test]
fn an_amplitude_branch_from_zero_forcing_is_exact_and_short() {
    let w = 0.9 * W0;
    let family = of("amplitude", |a: f64| {
        r2_forced(crate::model::reference::R3_CLEARANCE, w, a)
    });
    let opts = tight_options();
    let a_ref = crate::model::reference::BASE_AMPLITUDE;
    let b = continue_branch(family, 0.0, &[0.0; 4], a_ref, &opts, |_| true).unwrap();
    assert_eq!(b.stop, StopReason::ReachedEnd);
    // At least 2 / ds_max = 40 steps, and not many more: the state moves
    // with the parameter.
    assert!(
        (40..=60).contains(&b.points.len()),
        "{} points",
        b.points.len()
    );
    assert_eq!(b.points.last().unwrap().parameter, a_ref);
    for p in &b.points {
        let exact = crate::model::reference::r3_steady_amplitude(w) * p.parameter / a_ref;
        assert!(
            (p.max_displacement[0] - exact).abs() < 1e-8 * exact.max(1e-12),
            "at A = {}: {} vs {exact}",
            p.parameter,
            p.max_displacement[0]
        );
        assert!(p.stable);
    }
}

/// Branch switching on a branch that starts at zero: the switch works in
/// the main branch's parameter scale (half its range here), in which the
/// branch point's tangent was stored. With |p0| = 0 as its scale the start
/// off the branch point was NaN and the switch failed.
#[test]
fn a_branch_from_zero_forcing_switches_at_its_branch_point() {
    // The example row (R2 N = 2 at 0.95 ω0) in its forcing amplitude.
    let family = of("amplitude", |a: f64| {
        r2_forced(crate::model::reference::CLEARANCE, 0.95 * W0, a)
    });
    let opts = ContinuationOptions::default();
    let main = continue_branch(family, 0.0, &[0.0; 4], 0.05, &opts, |_| true).unwrap();
    assert_eq!(main.stop, StopReason::ReachedEnd);
    let bp = main.special.iter().find(|s| s.label == "BP1").unwrap();
    let switched = switch_branch(family, &main, "BP1", (0.0, 0.05), &opts, |_| true)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(switched.stop, StopReason::ReachedEnd);
    // A label the branch lacks, or a point that starts no branch: the
    // label and why, for each face to spell.
    let e = switch_branch(family, &main, "BP9", (0.0, 0.05), &opts, |_| true).unwrap_err();
    assert_eq!(e.label, "BP9");
    assert!(
        e.message
            .starts_with("no such special point on the branch (found: "),
        "{e}"
    );
    assert!(e.message.contains("BP1"), "{e}");
    // A start next to the branch point (a step of 0.02 in the scale 0.025)
    // on the crossing branch, whose two bodies move differently (the main
    // branch is symmetric: equal amplitudes).
    let first = &switched.points[0];
    assert!(
        (first.parameter - bp.parameter).abs() < 0.05 * 0.025,
        "{} vs BP1 at {}",
        first.parameter,
        bp.parameter
    );
    let asymmetry = switched
        .points
        .iter()
        .map(|p| (p.max_displacement[0] - p.max_displacement[1]).abs() / p.max_displacement[0])
        .fold(0.0, f64::max);
    assert!(asymmetry > 0.1, "largest relative asymmetry {asymmetry}");
}

/// The iterator on R3 with a user event: the amplitude of body 1 reaching
/// the steady amplitude at 0.9 ω0 is found twice (below and above
/// resonance) and located to the exact amplitude; the first step is the
/// start, the last the stop reason; a user stop (dropping the iterator)
/// needs no special handling.
#[test]
fn iterator_steps_and_user_event() {
    let level = crate::model::reference::r3_steady_amplitude(0.9 * W0);
    let opts = tight_options();
    let family = of("frequency", |w: f64| r2(2, 1e3, w));
    let steps = Continuation::new(family, 0.8 * W0, &[0.0; 4], 1.2 * W0, &opts)
        .unwrap()
        .with_event(Box::new(UserEvent(move |p: &BranchPoint| {
            p.max_displacement[0] - level
        })));
    let all: Vec<BranchStep> = steps.collect();
    match (all.first(), all.last()) {
        (Some(BranchStep::Point { point, special }), Some(BranchStep::Stop(reason))) => {
            assert_eq!(point.parameter, 0.8 * W0);
            assert!(special.is_empty());
            assert_eq!(reason, &StopReason::ReachedEnd);
        }
        other => panic!("unexpected ends {other:?}"),
    }
    let user: Vec<&SpecialPoint> = all
        .iter()
        .flat_map(|s| match s {
            BranchStep::Point { special, .. } => special.iter().collect(),
            BranchStep::Stop(_) => Vec::new(),
        })
        .collect();
    assert_eq!(user.len(), 2, "{user:?}");
    assert_eq!(
        (user[0].label.as_str(), user[1].label.as_str()),
        ("UZ1", "UZ2")
    );
    assert!((user[0].parameter / (0.9 * W0) - 1.0).abs() < 1e-7);
    assert!(user[1].parameter > W0);
    for u in user {
        assert_eq!(u.kind, SpecialKind::User);
        let amplitude = crate::model::reference::r3_steady_amplitude(u.parameter);
        assert!(
            (amplitude / level - 1.0).abs() < 1e-6,
            "{amplitude} vs {level}"
        );
    }
    // Taking only the first three steps computes no more than that.
    let first: Vec<BranchStep> = Continuation::new(family, 0.8 * W0, &[0.0; 4], 1.2 * W0, &opts)
        .unwrap()
        .take(3)
        .collect();
    assert_eq!(first.len(), 3);
}

/// AUTO-07p's special points of the R2, N = 2 branch (bench/auto,
/// Ω/ω0): six symmetry-breaking branch points and a torus bifurcation.
const AUTO_BP: [f64; 6] = [0.983100, 0.949393, 0.794528, 0.552497, 0.534043, 0.509475];
const AUTO_TR: f64 = 0.502479;

/// The periodic state (body order) of [`r2`] at `frequency` on the
/// branch that grows from rest, by the homotopy in the forcing amplitude:
/// a test's start that does not depend on where a long chaotic transient
/// of a simulation ends (at 0.5 ω0 that is the last bits of the step
/// sequence).
fn r2_primary_orbit(n: usize, clearance: f64, frequency: f64) -> Vec<f64> {
    amplitude_homotopy(
        of("amplitude", |a| {
            crate::model::reference::r2_forced(n, clearance, frequency, a)
        }),
        crate::model::reference::BASE_AMPLITUDE,
        &Default::default(),
    )
    .unwrap()
}

/// The start of R2's branches at `from` ω0 (gaps 1 mm): above resonance
/// the impacting orbit a simulation settles on (AUTO-07p's branch; the
/// homotopy from rest gives the in-phase orbit without impacts there),
/// below it the orbit of the homotopy from rest (at 0.5 ω0 a simulation's
/// transient is chaotic, and where it ends depends on the last bits of the
/// step sequence).
fn start_orbit(n: usize, from: f64) -> Vec<f64> {
    if from > 1.0 {
        let start = r2(n, 1e-3, from * W0).unwrap();
        crate::periodic::guess_by_simulation(&start, 200.0, 1e-9).unwrap()
    } else {
        r2_primary_orbit(n, 1e-3, from * W0)
    }
}

fn r2_branch(from: f64, to: f64) -> Branch {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let guess = start_orbit(2, from);
    let opts = ContinuationOptions::default();
    continue_branch(family, from * W0, &guess, to * W0, &opts, |_| true).unwrap()
}

/// Without special points the branch takes the same steps (locating a
/// special point does not move the branch) and its points between the
/// first and the last carry no orbit summary; with them the same window
/// has its special points.
#[test]
fn a_branch_without_special_points_takes_the_same_steps() {
    let (from, to) = (0.56, 0.5);
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let guess = start_orbit(2, from);
    let run = |special_points: bool| {
        let opts = ContinuationOptions {
            special_points,
            ..Default::default()
        };
        continue_branch(family, from * W0, &guess, to * W0, &opts, |_| true).unwrap()
    };
    let (with, without) = (run(true), run(false));
    assert!(with.special.len() >= 2, "{}", with.special.len());
    assert!(without.special.is_empty());
    assert_eq!(with.stop, StopReason::ReachedEnd);
    assert_eq!(without.stop, StopReason::ReachedEnd);
    assert_eq!(with.points.len(), without.points.len());
    for (a, b) in with.points.iter().zip(&without.points) {
        assert!((a.parameter - b.parameter).abs() < 1e-12 * W0);
    }
    assert!(!without.points[0].max_displacement.is_empty());
    let last = without.points.len() - 1;
    assert!(!without.points[last].max_displacement.is_empty());
    assert!(without.points[1..last]
        .iter()
        .all(|p| p.max_displacement.is_empty()));
}

/// R2, N = 2 (a mirror-symmetric row): the branch from 1.5 ω0 down is
/// followed on the half map and has exactly AUTO-07p's special points
/// (plus grazing, which AUTO does not detect), located from either
/// direction to the same values; stable points agree with brute-force
/// simulation.
#[test]
fn r2_symmetric_branch_matches_auto() {
    let down = r2_branch(1.5, 0.5);
    assert_eq!(down.stop, StopReason::ReachedEnd);
    // The branch runs from one end of the range exactly to the other.
    let ends = |b: &Branch| {
        let p = |q: &BranchPoint| q.parameter / W0;
        (p(&b.points[0]), p(b.points.last().expect("points")))
    };
    let (first, last) = ends(&down);
    assert!(
        (first - 1.5).abs() < 1e-12 && (last - 0.5).abs() < 1e-12,
        "{first}..{last}"
    );
    assert!(down.symmetric);
    let of = |b: &Branch, kind| {
        b.special
            .iter()
            .filter(|s| s.kind == kind)
            .map(|s| s.parameter / W0)
            .collect::<Vec<f64>>()
    };
    let bps = of(&down, SpecialKind::BranchPoint);
    assert_eq!(bps.len(), AUTO_BP.len(), "{bps:?}");
    for (ours, auto) in bps.iter().zip(AUTO_BP) {
        // AUTO's collocation (NTST 300) agrees to ~5e-6.
        assert!((ours / auto - 1.0).abs() < 2e-5, "BP {ours} vs AUTO {auto}");
    }
    let ns = of(&down, SpecialKind::NeimarkSacker);
    assert_eq!(ns.len(), 1);
    assert!((ns[0] / AUTO_TR - 1.0).abs() < 2e-5, "NS {}", ns[0]);
    assert!(of(&down, SpecialKind::Fold).is_empty());
    assert!(of(&down, SpecialKind::PeriodDoubling).is_empty());
    for s in down
        .special
        .iter()
        .filter(|s| s.kind == SpecialKind::BranchPoint)
    {
        assert!(s.symmetry_breaking);
        let near_one = s
            .multipliers
            .iter()
            .map(|m| (m - Complex::new(1.0, 0.0)).norm())
            .fold(f64::INFINITY, f64::min);
        assert!(near_one < 1e-4, "{}: {:?}", s.label, s.multipliers);
    }
    // Every point is symmetric: u1 and u2 have the same amplitude (to
    // 1e-7 where the orbit is unstable with multipliers ~200, 4e-8 on
    // stable ones: integration at rtol 1e-10 through contact pulses).
    for p in &down.points {
        let (a, b) = (p.max_displacement[0], p.max_displacement[1]);
        assert!((a - b).abs() < 1e-6 * a, "{}: {a} vs {b}", p.parameter);
    }
    // The same special points from 0.5 ω0 upward.
    let up = r2_branch(0.5, 1.5);
    assert_eq!(up.stop, StopReason::ReachedEnd);
    let (first, last) = ends(&up);
    assert!(
        (first - 0.5).abs() < 1e-12 && (last - 1.5).abs() < 1e-12,
        "{first}..{last}"
    );
    let mut a: Vec<(SpecialKind, f64)> =
        down.special.iter().map(|s| (s.kind, s.parameter)).collect();
    let b: Vec<(SpecialKind, f64)> = up.special.iter().map(|s| (s.kind, s.parameter)).collect();
    a.reverse();
    assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
    for (x, y) in a.iter().zip(&b) {
        assert_eq!(x.0, y.0);
        let tol = if x.0 == SpecialKind::Grazing {
            1e-4
        } else {
            1e-7
        };
        assert!((x.1 / y.1 - 1.0).abs() < tol, "{x:?} vs {y:?}");
    }
    // Stable points agree with brute-force simulation; points within
    // 0.002 ω0 of a special point are left out (next to the Neimark–Sacker
    // point at 0.50248 ω0 the basin is too small for the 0.1 % kick of
    // `assert_brute_force_agrees`).
    let away = |p: &&BranchPoint| {
        down.special
            .iter()
            .all(|s| (s.parameter - p.parameter).abs() > 0.002 * W0)
    };
    let stable: Vec<&BranchPoint> = down
        .points
        .iter()
        .filter(|p| p.stable && p.spectral_radius() < 0.95)
        .filter(away)
        .step_by(10)
        .take(3)
        .collect();
    assert!(stable.len() >= 2);
    for p in stable {
        assert_brute_force_agrees(p);
    }
}

/// Simulation from a 0.1 % perturbation of the orbit settles back on it:
/// max |u_i| to 1e-6. (A larger perturbation can leave the basin: below
/// 0.51 ω0 the symmetric orbit coexists with other attractors, and a 1 %
/// kick lands on one with max |u| 11 % smaller.)
fn assert_brute_force_agrees(p: &BranchPoint) {
    let model = r2(2, 1e-3, p.parameter).unwrap();
    let t = 2.0 * std::f64::consts::PI / p.parameter;
    let sim = simulate(
        &model,
        &SimulationOptions {
            t_end: 400.0 * t,
            rtol: 1e-11,
            atol: 1e-15,
            start: Some(p.state.iter().map(|x| x * 0.999).collect()),
            ..Default::default()
        },
    )
    .unwrap();
    let end: Vec<f64> = sim.final_state();
    let orbit = orbit_summary(&model, &end, t, 256, 1e-11).unwrap();
    for i in 0..2 {
        assert!(
            (orbit.max_displacement[i] - p.max_displacement[i]).abs()
                < 1e-6 * p.max_displacement[i].max(1e-3),
            "at {}: {} vs {}",
            p.parameter,
            orbit.max_displacement[i],
            p.max_displacement[i]
        );
    }
}

/// Switching at the first two pitchforks onto the asymmetric branches:
/// a period doubling confirmed by the period-2 orbit next to it, a fold
/// confirmed by the change of stability on either side.
#[test]
fn r2_asymmetric_branches_fold_and_period_doubling() {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let main = r2_branch(1.5, 0.9);
    let opts = ContinuationOptions {
        max_points: 45,
        bounds: Some((0.5 * W0, 1.5 * W0)),
        ..Default::default()
    };
    let switched = |label: &str| {
        let bp = main.special.iter().find(|s| s.label == label).unwrap();
        let (p, x) = branch_switch_start(family, bp, (1.5 * W0, 0.9 * W0), &opts, 0.02).unwrap();
        let model = r2(2, 1e-3, p).unwrap();
        // Off the symmetric branch: the two bodies move differently.
        let orbit = orbit_summary(&model, &x, 2.0 * std::f64::consts::PI / p, 256, 1e-11).unwrap();
        let (a, b) = (orbit.max_displacement[0], orbit.max_displacement[1]);
        assert!((a - b).abs() > 1e-7, "{label}: still symmetric ({a} {b})");
        let b = continue_branch(family, p, &x, 0.5 * W0, &opts, |_| true).unwrap();
        assert!(!b.symmetric);
        b
    };
    let unstable_count = |p: &BranchPoint| p.multipliers.iter().filter(|m| m.norm() > 1.0).count();
    // BP1 (0.9831 ω0): a period doubling at 0.97820 ω0.
    let b1 = switched("BP1");
    let pd = b1
        .special
        .iter()
        .find(|s| s.kind == SpecialKind::PeriodDoubling)
        .expect("a period doubling");
    assert!(
        (pd.parameter / W0 - 0.978202).abs() < 1e-5,
        "{}",
        pd.parameter / W0
    );
    assert!(
        pd.multipliers
            .iter()
            .any(|m| (m.re + 1.0).abs() < 1e-3 && m.im.abs() < 1e-6),
        "{:?}",
        pd.multipliers
    );
    // Its stable points (between the pitchfork and the period doubling)
    // agree with brute-force simulation as well.
    let stable: Vec<&BranchPoint> = b1
        .points
        .iter()
        .filter(|p| p.stable && p.spectral_radius() < 0.95)
        .collect();
    assert!(!stable.is_empty());
    for p in stable.iter().step_by(stable.len().div_ceil(2).max(1)) {
        assert_brute_force_agrees(p);
    }
    let (p2, x2) = period_doubled_start(family, pd, &opts).unwrap();
    assert!((p2 / pd.parameter - 1.0).abs() < 0.02);
    let model = r2(2, 1e-3, p2).unwrap();
    let two = shoot(
        &model,
        &x2,
        &ShootingOptions {
            subharmonic: 2,
            ..opts.shooting.clone()
        },
    )
    .unwrap();
    assert!(two.converged);
    let one = period_map(&model, &two.initial_state, &opts.shooting).unwrap();
    let gap = one
        .image
        .iter()
        .zip(&two.initial_state)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(gap > 1e-7, "the period-2 orbit is period-1 (gap {gap:e})");
    // BP2 (0.9494 ω0): a fold at 0.91225 ω0, stability changes across it.
    let b2 = switched("BP2");
    let fold = b2
        .special
        .iter()
        .find(|s| s.kind == SpecialKind::Fold)
        .expect("a fold");
    assert!((fold.parameter / W0 - 0.912249).abs() < 1e-5);
    let (a, c) = (
        &b2.points[fold.after_point],
        &b2.points[fold.after_point + 1],
    );
    assert_ne!(
        unstable_count(a),
        unstable_count(c),
        "fold at {}",
        fold.parameter
    );
}

/// The asymmetric branch from BP2 (0.9494 ω0) is a connection: it meets
/// the symmetric branch again at BP3 (AUTO: 0.794528 ω0), where it turns
/// (a fold of the pitchfork) onto its mirror image; the continuation
/// stops there as a closed loop instead of retracing the mirror.
#[test]
fn r2_asymmetric_branch_connects_bp2_to_bp3() {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let main = r2_branch(1.5, 0.9);
    let opts = ContinuationOptions {
        max_points: 3000,
        bounds: Some((0.5 * W0, 1.5 * W0)),
        ..Default::default()
    };
    let bp = main.special.iter().find(|s| s.label == "BP2").unwrap();
    let (p, x) = branch_switch_start(family, bp, (1.5 * W0, 0.9 * W0), &opts, 0.02).unwrap();
    let b = continue_branch(family, p, &x, 0.5 * W0, &opts, |_| true).unwrap();
    assert_eq!(b.stop, StopReason::ClosedLoop);
    let last = b.special.last().expect("special points");
    assert_eq!(last.kind, SpecialKind::Fold);
    assert!(
        (last.parameter / W0 / AUTO_BP[2] - 1.0).abs() < 2e-5,
        "{}",
        last.parameter / W0
    );
    // At the fold the orbit is (nearly) symmetric again.
    let model = r2(2, 1e-3, last.parameter).unwrap();
    let period = 2.0 * std::f64::consts::PI / last.parameter;
    let at = orbit_summary(&model, &last.state, period, 256, 1e-11).unwrap();
    let (u1, u2) = (at.max_displacement[0], at.max_displacement[1]);
    // The asymmetry vanishes like the square root of the distance along
    // the branch from the pitchfork, where the parameter is stationary:
    // the fold, located to 1e-8 in the parameter, is 5e-4 to 2.3e-3 from
    // symmetric depending on the steps that bracket it; the branch itself
    // is 30 % asymmetric.
    assert!((u1 - u2).abs() < 1e-2 * u1, "{u1} vs {u2}");
    assert!(b.points.len() < 1500, "{} points", b.points.len());
}

/// The step control's spectral distance sees modulus changes between
/// 1/2 and 2 only: growth far outside the circle and the turning of a
/// complex pair are free, a multiplier moving toward the circle is not;
/// spectra of different sizes are compared as sets.
#[test]
fn spectral_distance_sees_moduli_near_the_circle() {
    let c = Complex::new;
    let polar = |r: f64, a: f64| Complex::from_polar(r, a);
    let base = [
        c(30.0, 0.0),
        polar(0.85, 1.0),
        polar(0.85, -1.0),
        c(0.01, 0.0),
    ];
    let far = [
        c(600.0, 0.0),
        polar(0.85, 2.5),
        polar(0.85, -2.5),
        c(0.0005, 0.0),
    ];
    assert_eq!(spectral_distance(&base, &far), 0.0);
    let nearer = [
        c(30.0, 0.0),
        polar(0.95, 1.0),
        polar(0.95, -1.0),
        c(0.01, 0.0),
    ];
    let expected = (0.95f64 / 0.85).ln();
    assert!((spectral_distance(&base, &nearer) - expected).abs() < 1e-15);
    let inward = [
        c(1.5, 0.0),
        polar(0.85, 1.0),
        polar(0.85, -1.0),
        c(0.01, 0.0),
    ];
    let expected = (2.0f64 / 1.5).ln();
    assert!((spectral_distance(&base, &inward) - expected).abs() < 1e-15);
    assert_eq!(spectral_distance(&base, &[]), f64::INFINITY);
    // Arnoldi resolved 4 or 8 multipliers of one cluster (R2 N = 100 at
    // 0.6445 ω0): the same spectrum as far as the tests see.
    let resolved = |cluster: usize| {
        let mut s = vec![polar(7.79, 2.1); 4];
        s.extend(vec![polar(0.881, 0.4); cluster]);
        s.extend(vec![polar(0.0968, 1.0); 4]);
        s
    };
    assert_eq!(spectral_distance(&resolved(4), &resolved(8)), 0.0);
    // A multiplier only one of them has, near the circle, is seen.
    let mut more = resolved(4);
    more.push(c(0.95, 0.0));
    let expected = (0.95f64 / 0.881).ln();
    assert!((spectral_distance(&resolved(4), &more) - expected).abs() < 1e-15);
}

/// Matrix-free continuation (GMRES on bordered products, Arnoldi
/// multipliers) against dense on R2 N = 2 from 1.5 ω0 down to 0.5: the same
/// special points to 1e-6 ω0 (measured: 3e-8) and the same largest
/// multiplier at both ends (the same parameter) to 1e-6.
#[test]
fn krylov_branch_matches_dense() {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let guess = start_orbit(2, 1.5);
    let dense = r2_branch(1.5, 0.5);
    let opts = ContinuationOptions {
        krylov: Some(4),
        ..Default::default()
    };
    let krylov = continue_branch(family, 1.5 * W0, &guess, 0.5 * W0, &opts, |_| true).unwrap();
    assert_same_results(&krylov, &dense);
}

/// A matrix-free branch against the dense one over the same range: both
/// reach the end, the same special points (kind, order, parameter to 1e-6
/// ω0) and the same largest multiplier at both ends to 1e-6.
fn assert_same_results(krylov: &Branch, dense: &Branch) {
    assert_eq!(krylov.stop, StopReason::ReachedEnd);
    assert_eq!(krylov.special.len(), dense.special.len());
    for (k, d) in krylov.special.iter().zip(&dense.special) {
        assert_eq!(k.kind, d.kind);
        assert!(
            (k.parameter - d.parameter).abs() < 1e-6 * W0,
            "{} {} vs {} {}",
            k.label,
            k.parameter / W0,
            d.label,
            d.parameter / W0
        );
    }
    for (k, d) in [
        (&krylov.points[0], &dense.points[0]),
        (krylov.points.last().unwrap(), dense.points.last().unwrap()),
    ] {
        assert_eq!(k.parameter, d.parameter);
        let (rk, rd) = (k.spectral_radius(), d.spectral_radius());
        assert!((rk / rd - 1.0).abs() < 1e-6, "{rk} vs {rd}");
    }
}

/// Matrix-free against dense on a row longer than two (the unknowns'
/// state scale then differs from the residual's by √(N/2), D20): R2
/// N = 16 from its stable impacting orbit at 0.5 ω0 to 0.53 ω0 with 12
/// Arnoldi vectors for its 32 multipliers (Ritz values, not the whole
/// spectrum), the same special points to 1e-6 ω0 and the same largest
/// multiplier at both ends to 1e-6 (measured on the CLI's window to 0.537:
/// 2e-9 ω0 and 1.6e-7; with 8 vectors 4e-6).
#[test]
fn krylov_branch_matches_dense_on_a_longer_row() {
    let family = of("frequency", |w: f64| r2(16, 1e-3, w));
    let guess = start_orbit(16, 0.5);
    let run = |krylov| {
        let opts = ContinuationOptions {
            krylov,
            ..Default::default()
        };
        continue_branch(family, 0.5 * W0, &guess, 0.53 * W0, &opts, |_| true).unwrap()
    };
    let (dense, krylov) = (run(None), run(Some(12)));
    assert!(
        dense.points[0].stable,
        "{}",
        dense.points[0].spectral_radius()
    );
    assert!(!dense.special.is_empty());
    assert_same_results(&krylov, &dense);
}

/// `f` run in a pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(f)
}

/// The matrix-free branch computes a point's tangent and multipliers on
/// two threads: the same bytes on one thread and on two.
#[test]
fn krylov_branch_is_the_same_on_any_thread_count() {
    let family = of("frequency", |w: f64| r2(8, 1e-3, w));
    let guess = start_orbit(8, 0.5);
    let opts = ContinuationOptions {
        krylov: Some(12),
        max_points: 40,
        ..Default::default()
    };
    let run = |threads: usize| {
        on_threads(threads, || {
            continue_branch(family, 0.5 * W0, &guess, 0.6 * W0, &opts, |_| true).unwrap()
        })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.points.len(), two.points.len());
    assert!(one.points.len() > 10, "{}", one.points.len());
    for (a, b) in one.points.iter().zip(&two.points) {
        assert_eq!(a.parameter.to_bits(), b.parameter.to_bits());
        assert_eq!(a.state, b.state);
        assert_eq!(a.multipliers, b.multipliers);
    }
}

/// The points are finished (orbit summaries, special points) on one
/// thread while the corrector runs ahead on another: the same bytes on one
/// thread and on two, special points and amplitudes included.
#[test]
fn a_branch_finished_beside_its_corrector_is_the_same_on_any_thread_count() {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    let guess = start_orbit(2, 0.5);
    let opts = ContinuationOptions::default();
    let run = |threads: usize| {
        on_threads(threads, || {
            continue_branch(family, 0.5 * W0, &guess, 0.56 * W0, &opts, |_| true).unwrap()
        })
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.points.len(), two.points.len());
    assert!(one.special.len() >= 4, "{:?}", one.special.len());
    for (a, b) in one.points.iter().zip(&two.points) {
        assert_eq!(a.parameter.to_bits(), b.parameter.to_bits());
        assert_eq!((&a.state, &a.multipliers), (&b.state, &b.multipliers));
        assert_eq!(
            (&a.max_displacement, &a.label),
            (&b.max_displacement, &b.label)
        );
    }
    assert_eq!(one.special.len(), two.special.len());
    for (a, b) in one.special.iter().zip(&two.special) {
        assert_eq!((&a.label, a.after_point), (&b.label, b.after_point));
        assert_eq!(a.parameter.to_bits(), b.parameter.to_bits());
        assert_eq!(a.max_displacement, b.max_displacement);
    }
    assert_eq!(one.stop, two.stop);
    // A consumer that stops at a point reads its own stop, however far the
    // corrector ran ahead.
    let opts = ContinuationOptions {
        max_points: 6,
        ..opts
    };
    for threads in [1, 2] {
        let mut seen = 0;
        let b = on_threads(threads, || {
            continue_branch(family, 0.5 * W0, &guess, 0.56 * W0, &opts, |_| {
                seen += 1;
                seen < 6
            })
            .unwrap()
        });
        assert_eq!((b.points.len(), &b.stop), (6, &StopReason::Interrupted));
    }
}

/// A stop requested while a step is being corrected ends the branch as
/// interrupted, with the points so far, not as a corrector that does not
/// converge (the request fails every integration). On one thread the
/// corrections and the points' summaries take their models in turn, so
/// the stop comes at the same place; on two it comes wherever the
/// corrector has run ahead to (the finished points are then fewer under
/// load), and the points before it are the same.
#[test]
fn a_stop_inside_a_correction_reads_as_interrupted() {
    let run = |threads: usize| {
        let interrupt = crate::integrate::Interrupt::default();
        let mut opts = ContinuationOptions::default();
        opts.shooting.interrupt = Some(interrupt.clone());
        let mut calls = 0;
        let family = of("frequency", move |w: f64| {
            calls += 1;
            if calls == 40 {
                interrupt.request();
            }
            r2(2, 1e-3, w)
        });
        let guess = start_orbit(2, 1.5);
        on_threads(threads, || {
            continue_branch(family, 1.5 * W0, &guess, 0.5 * W0, &opts, |_| true).unwrap()
        })
    };
    let one = run(1);
    assert_eq!(one.stop, StopReason::Interrupted);
    assert!(one.points.len() > 3, "{}", one.points.len());
    let two = run(2);
    assert_eq!(two.stop, StopReason::Interrupted);
    assert!(!two.points.is_empty());
    for (a, b) in two.points.iter().zip(&one.points) {
        assert_eq!(a.parameter.to_bits(), b.parameter.to_bits());
    }
}

/// Matrix-free options that cannot work are refused before anything runs.
#[test]
fn krylov_dimension_is_checked() {
    let family = of("frequency", |w: f64| r2(2, 1e-3, w));
    for m in [1, 5] {
        let opts = ContinuationOptions {
            krylov: Some(m),
            ..Default::default()
        };
        let err = continue_branch(family, 1.4 * W0, &[0.0; 4], 1.5 * W0, &opts, |_| true)
            .expect_err("refused");
        assert!(err.to_string().contains("Arnoldi"), "{err}");
    }
}
