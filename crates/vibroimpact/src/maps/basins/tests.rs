//! Checks of the basins: the linear limit (one attractor, the exact steady
//! state), determinism, bad input.

use super::*;
use crate::model::file::ModelDocument;
use crate::model::reference::r3_response;

const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.05\nfrequency = 8.151\n";

fn loaded(text: &str) -> LoadedModel {
    ModelDocument::from_toml(text, "m.toml")
        .unwrap()
        .build()
        .unwrap()
}

/// Nothing touches (R3): every initial state reaches the one steady state,
/// whose Poincaré sample is the exact response at t = kT.
#[test]
fn linear_limit_has_one_attractor_the_exact_steady_state() {
    let m = loaded(&ROW.replace("clearance = 0.001", "clearance = 1.0"));
    let opts = SweepOptions {
        transient: 500,
        record: 4,
        ..SweepOptions::default()
    };
    let u = [-2e-3, 0.0, 2e-3];
    let b = basins(
        &m,
        (Component::Displacement(0), &u),
        (Component::Velocity(1), &u),
        None,
        &opts,
        &|| {},
    )
    .unwrap();
    assert_eq!(b.attractors.len(), 1, "{:?}", b.attractors);
    assert_eq!(b.cells, vec![Some(0); 9]);
    let a = &b.attractors[0];
    assert_eq!((a.period, a.cells, a.fraction), (Some(1), 9, 1.0));
    // The steady state at a section instant: the exact response from rest
    // 1000 periods on (its free oscillation decayed by e^-770).
    let period = 2.0 * std::f64::consts::PI / 8.151;
    let (ue, ve) = r3_response(1000.0 * period, 8.151);
    let s = &a.section[0];
    for i in 0..2 {
        assert!((s[i] - ue).abs() < 1e-6 * ue.abs(), "{s:?} vs {ue}");
        assert!(
            (s[2 + i] - ve).abs() < 1e-6 * ve.abs().max(ue.abs() * 8.151),
            "{s:?} vs {ve}"
        );
    }
}

/// The same result with one thread and two; an overlapping start is not run.
#[test]
fn deterministic_and_inadmissible_states() {
    let m = loaded(ROW);
    let opts = SweepOptions {
        transient: 10,
        record: 4,
        ..SweepOptions::default()
    };
    let xs = [-1.5e-3, 0.0, 0.5e-3];
    let vs = [-0.01, 0.01];
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let b = pool.install(|| {
            basins(
                &m,
                (Component::Displacement(0), &xs),
                (Component::Velocity(0), &vs),
                None,
                &opts,
                &|| {},
            )
            .unwrap()
        });
        serde_json::to_string(&b).unwrap()
    };
    let one = run(1);
    assert_eq!(one, run(2));
    let b: serde_json::Value = serde_json::from_str(&one).unwrap();
    // u1 = −1.5 mm overlaps the left wall (gap 1 mm).
    assert_eq!(b["inadmissible"], 2);
    assert!(b["cells"][0].is_null() && b["cells"][3].is_null());
}

#[test]
fn bad_input_is_refused() {
    let m = loaded(ROW);
    let opts = SweepOptions::default();
    let v = [0.0];
    let u1 = Component::Displacement(0);
    let run = |x: (Component, &[f64]), y: (Component, &[f64]), base: Option<&[f64]>| {
        basins(&m, x, y, base, &opts, &|| {})
            .unwrap_err()
            .to_string()
    };
    assert!(run((u1, &v), (u1, &v), None).contains("both u1"));
    assert!(run((u1, &[]), (Component::Velocity(0), &v), None).contains("no values"));
    assert!(run((u1, &v), (Component::Velocity(0), &v), Some(&[0.0; 3])).contains("needs 4 values"));
    assert!(Component::parse("w1", 2)
        .unwrap_err()
        .to_string()
        .contains("give u or v"));
    assert!(Component::parse("u3", 2).is_err() && Component::parse("u0", 2).is_err());
    assert_eq!(Component::parse("v2", 2).unwrap(), Component::Velocity(1));
    let big: Vec<f64> = (0..10_000).map(|k| k as f64 * 1e-7).collect();
    assert!(run((u1, &big), (Component::Velocity(0), &big), None).contains("coarser grid"));
    // Issue 38: a grid every start of which overlaps (u1 past the wall's
    // 1 mm gap) exited 0 with no attractors; it is refused, as a sweep's.
    let e = run((u1, &[-2e-3, -1.5e-3]), (Component::Velocity(0), &v), None);
    assert!(
        e.contains("every one of the 2 initial states overlaps a contact"),
        "{e}"
    );
}

/// R2 N = 2 at 1.1 ω0 (8.151 rad/s): beside the symmetric period-1 orbit
/// (6 impacts a period) a period-3 orbit attracts (4.7 impacts a period;
/// 56 % and 13 % of a 40 × 40 grid in (u1, v1), the basins interleaved).
/// Four neighbouring starts of that grid reach the two (the others of the
/// grid reach unsettled or longer-period motions); the period-3
/// attractor's Poincaré sample is a fixed point of the third iterate of
/// the period map, found independently by shooting (subharmonic 3) from
/// it, stable.
#[test]
fn period_three_orbit_beside_the_symmetric_one() {
    use crate::periodic::{shoot, ShootingOptions};
    let m = loaded(ROW);
    let opts = SweepOptions {
        transient: 400,
        record: 30,
        ..SweepOptions::default()
    };
    let xs = [
        -0.0009,
        -0.0008538461538461538,
        -0.0008076923076923077,
        -0.0007615384615384615,
    ];
    let vs = [-0.0046153846153846115];
    let b = basins(
        &m,
        (Component::Displacement(0), &xs),
        (Component::Velocity(0), &vs),
        None,
        &opts,
        &|| {},
    )
    .unwrap();
    // Which start reaches which depends on the last bits (the basins are
    // interleaved at the grid's scale): both attractors, every start.
    assert_eq!(b.attractors.len(), 2, "{:?}", b.attractors);
    assert!(b.cells.iter().all(|c| c.is_some()));
    let find = |p| b.attractors.iter().find(|a| a.period == Some(p)).unwrap();
    let (one, three) = (find(1), find(3));
    assert_eq!(one.impacts_per_period, 6.0);
    assert!((three.impacts_per_period - 14.0 / 3.0).abs() < 1e-12);
    assert_eq!(one.cells + three.cells, 4);
    let sol = shoot(
        &m.model,
        &three.section[0],
        &ShootingOptions {
            subharmonic: 3,
            ..ShootingOptions::default()
        },
    )
    .unwrap();
    assert!(sol.converged && sol.stable(), "{:?}", sol.multipliers);
    let scale = three.max_displacement;
    for (k, (a, b)) in sol.initial_state.iter().zip(&three.section[0]).enumerate() {
        let s = if k < 2 { scale } else { scale * 8.151 };
        assert!((a - b).abs() < 1e-3 * s, "{k}: {a} vs {b}");
    }
}

/// Distributed basins: the runs of rows computed apart (one task each),
/// sent as JSON (a failed run's NaN as null included) and joined, give
/// the basins of one computation bit for bit.
#[test]
fn rows_run_apart_and_joined_are_the_whole() {
    let m = loaded(&ROW.replace("frequency = 8.151", "frequency = 7.45"));
    let opts = SweepOptions {
        transient: 100,
        record: 10,
        ..SweepOptions::default()
    };
    let (xs, ys) = ([-0.9e-3, 0.0, 0.9e-3], [-0.06, -0.02, 0.02, 0.06]);
    let (x, y) = (Component::Displacement(0), Component::Velocity(0));
    let whole = basins(&m, (x, &xs), (y, &ys), None, &opts, &|| {}).unwrap();
    assert!(whole.attractors.len() >= 2, "{:?}", whole.attractors);
    let parts: Vec<BasinRuns> = [&ys[..1], &ys[1..3], &ys[3..]]
        .iter()
        .map(|rows| {
            let runs = basin_runs(&m, (x, &xs), (y, rows), None, &opts, &|| {}).unwrap();
            serde_json::from_str(&serde_json::to_string(&runs).unwrap()).unwrap()
        })
        .collect();
    let joined = basins_of(
        &m,
        ((x, &xs), (y, &ys)),
        None,
        &opts,
        BasinRuns::concat(parts),
    )
    .unwrap();
    let text = |b: &Basins| serde_json::to_string(b).unwrap();
    assert_eq!(text(&joined), text(&whole));
    let failed: Run = serde_json::from_str(
        &serde_json::to_string(&Run::failed(vec![0.0], "stopped".into())).unwrap(),
    )
    .unwrap();
    assert!(failed.impacts_per_period.is_nan() && failed.max_displacement.is_nan());
    // Runs of another plane are refused.
    let short = basin_runs(&m, (x, &xs), (y, &ys[..1]), None, &opts, &|| {}).unwrap();
    let err = basins_of(&m, ((x, &xs), (y, &ys)), None, &opts, short).unwrap_err();
    assert!(
        err.to_string().contains("3 runs for a plane of 3 × 4"),
        "{err}"
    );
}
