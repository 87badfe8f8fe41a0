//! Tests of the sweep (`mod.rs`).

use super::*;
use crate::model::parameter::ParameterizedModel;
use crate::periodic::settling::Motion;

#[test]
fn values_are_even_with_exact_ends() {
    let v = parameter_values(0.1, 0.7, 7);
    assert_eq!(v.len(), 7);
    assert_eq!(v[0], 0.1);
    assert_eq!(v[6], 0.7);
    assert!((v[3] - 0.4).abs() < 1e-15);
    let v = parameter_values(2.0, 1.0, 2);
    assert_eq!(v, vec![2.0, 1.0]);
}

const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.5\nfrequency = 7.0\n";

fn row_model() -> Model {
    crate::model::file::ModelDocument::from_toml(ROW, "m.toml")
        .unwrap()
        .build()
        .unwrap()
        .model
}

/// A run restarted from a sample in the middle of a period, with the
/// excitation's phase advanced to match, continues the original run.
#[test]
fn restart_at_a_phase_continues_the_trajectory() {
    let model = row_model();
    let period = 2.0 * std::f64::consts::PI / 7.0;
    let dt = period / FINE as f64;
    let opts = SimulationOptions {
        rtol: 1e-11,
        atol: 1e-15,
        ..SimulationOptions::default()
    };
    let whole = simulate(
        &model,
        &SimulationOptions {
            t_end: (3 * FINE) as f64 * dt,
            output_step: Some(dt),
            ..opts.clone()
        },
    )
    .unwrap();
    assert!(whole.impacts.len() > 2, "the test needs impacts");
    let n = 2;
    let j = FINE + 100;
    let row = &whole.states[j * 2 * n..(j + 1) * 2 * n];
    let start = Start {
        u: row[..n].to_vec(),
        v: row[n..].to_vec(),
        phase: j % FINE,
    };
    let m = start_model(&model, &start).unwrap();
    let rest = simulate(
        &m,
        &SimulationOptions {
            t_end: (3 * FINE - j) as f64 * dt,
            ..opts
        },
    )
    .unwrap();
    for i in 0..n {
        let a = whole.final_displacement[i];
        let b = rest.final_displacement[i];
        assert!((a - b).abs() < 1e-7 * 1e-3, "u_{i}: {a} vs {b}");
    }
}

#[test]
fn handover_skips_overlapping_states() {
    let model = row_model();
    // Samples: admissible, admissible, overlapping (p1 into the wall at u = -1 mm).
    let states = vec![
        0.0, 0.0, 0.1, 0.2, //
        -5e-4, 1e-4, 0.3, 0.4, //
        -1.5e-3, 0.0, 0.5, 0.6,
    ];
    let sim = Simulation {
        times: vec![0.0, 1.0, 2.0],
        states: states.clone(),
        final_time: 2.0,
        final_displacement: vec![-1.5e-3, 0.0],
        final_velocity: vec![0.5, 0.6],
        impacts: Vec::new(),
        stats: Default::default(),
        contact_evaluations: 0,
        hysteretic_energy: Vec::new(),
        energy: None,
        error: None,
        extrema: None,
        local: None,
        soft_episodes: Vec::new(),
    };
    let s = handover(&model, &sim, 5, 16, 5 + 32).unwrap();
    assert_eq!(s.u, vec![-5e-4, 1e-4]);
    assert_eq!(s.v, vec![0.3, 0.4]);
    assert_eq!(s.phase, 5 + 16);
    let ok = Simulation {
        final_displacement: vec![1e-4, 0.0],
        final_velocity: vec![0.7, 0.8],
        ..sim.clone()
    };
    let s = handover(&model, &ok, 5, 16, FINE + 5).unwrap();
    assert_eq!((s.u[0], s.v[1], s.phase), (1e-4, 0.8, 5));
    let none = Simulation {
        states: states[8..].repeat(3),
        ..sim
    };
    assert!(handover(&model, &none, 0, 1, 0).is_none());
}

/// Counts that would overflow or exhaust memory are refused up front.
#[test]
fn huge_counts_are_input_errors() {
    let doc = crate::model::file::ModelDocument::from_toml(ROW, "m.toml").unwrap();
    let family = ParameterizedModel::new(doc, "frequency").unwrap();
    let run = |transient, record| {
        let options = SweepOptions {
            transient,
            record,
            ..SweepOptions::default()
        };
        sweep(&family, &[6.0, 7.0], &options, &|| {})
            .unwrap_err()
            .to_string()
    };
    assert!(run(1 << 62, 2).contains("transient = 4611686018427387904: at most 1e9"));
    assert!(run(1, 1 << 40).contains("record = 1099511627776"));
}

/// R2 N = 2 (the rows of `ROW` at 0.05 m/s²) at frequencies where it
/// settles on period-2 orbits with six impacts a period within 150
/// periods: by the local integrator (transient and recorded window) the
/// Poincaré samples are those of the global one to 1e-5 of the motion
/// (the sweep's own cluster tolerance: 150 lightly damped periods leave
/// about e^-12 of the transient, so the two runs end 2.5e-6 apart), and
/// the exact extrema too.
#[test]
fn the_local_integrator_reaches_the_same_attractors() {
    let text = ROW.replace("amplitude = 0.5", "amplitude = 0.05");
    let doc = crate::model::file::ModelDocument::from_toml(&text, "m.toml").unwrap();
    let family = ParameterizedModel::new(doc, "frequency").unwrap();
    let run = |integrator| {
        let options = SweepOptions {
            transient: 150,
            record: 4,
            rtol: Some(1e-10),
            integrator,
            ..SweepOptions::default()
        };
        sweep(&family, &[7.5, 11.0, 12.0], &options, &|| {}).unwrap()
    };
    let (global, local) = (run(Integrator::Global), run(Integrator::Local));
    for (g, l) in global.points.iter().zip(&local.points) {
        assert!(g.error.is_none() && l.error.is_none());
        assert_eq!(
            (g.distinct_section_points, l.distinct_section_points),
            (2, 2)
        );
        assert_eq!(g.impacts_per_period, 6.0);
        assert_eq!(l.impacts_per_period, 6.0);
        let scale = g.max_displacement.iter().fold(0.0f64, |a, b| a.max(*b));
        for (a, b) in g.sections.iter().flatten().zip(l.sections.iter().flatten()) {
            let s = scale * g.parameter;
            assert!((a - b).abs() < 1e-5 * s, "{a} {b} at {}", g.parameter);
        }
        for (a, b) in g.max_displacement.iter().zip(&l.max_displacement) {
            assert!((a - b).abs() < 1e-5 * scale, "{a} {b} at {}", g.parameter);
        }
    }
}

/// The recorded window keeps every section: sampled from its start
/// every period, the last sample is its end (ω = 0.5, j0 = 1, 50
/// periods: (j0 + 50 FINE) dt lies an ulp below that sample, which the
/// window ending there lost).
#[test]
fn the_recorded_window_keeps_its_last_section() {
    let model = row_model();
    for (omega, j0, record) in [(0.5, 1, 50), (7.3, 37, 13), (12.0, 255, 20)] {
        let period = 2.0 * std::f64::consts::PI / omega;
        let (w0, w1) = recorded_window(period, j0, record);
        let opts = SimulationOptions {
            t_end: w1,
            output_step: Some(period),
            output_from: w0,
            ..SimulationOptions::default()
        };
        for integrator in [Integrator::Global, Integrator::Local] {
            let sim = simulate(
                &model,
                &SimulationOptions {
                    integrator,
                    ..opts.clone()
                },
            )
            .unwrap();
            assert_eq!(sim.times.len(), record + 1, "{omega} {j0} {record}");
            assert_eq!(sim.times[record], w1);
        }
    }
}

#[test]
fn clusters() {
    let p = |u: f64, v: f64| vec![u, v];
    let pts = vec![
        p(1.0, 2.0),
        p(-1.0, 0.5),
        p(1.0 + 1e-9, 2.0),
        p(-1.0, 0.5 + 1e-3),
    ];
    assert_eq!(distinct_points(&pts, 1, 1e-6, 1e-6), 3);
    assert_eq!(distinct_points(&pts, 1, 1e-6, 1e-2), 2);
    assert_eq!(distinct_points(&[], 1, 1e-6, 1e-6), 0);
}

/// The lightly damped R2 N = 2 (ζ = 0.013) after the default 100
/// transient periods was "20 distinct" at 7.3 and 7.5 rad/s, where 1000
/// periods give period 1: a slowly settling orbit read as a cloud. Its
/// samples still converge, so the run goes on for the periods the decay
/// needs and the value is periodic (7.3: period 1 after 160 periods;
/// 7.35: period 3), the orbit that 1000 periods find (the same samples
/// to the cluster tolerance). With `settle = 0` the value is "settling"
/// with the periods it still needs, which then suffice. A chart over the
/// same values calls the same cells periodic with the same periods.
#[test]
fn a_value_is_periodic_only_once_it_has_settled() {
    let text = ROW.replace("amplitude = 0.5", "amplitude = 0.05");
    let doc = crate::model::file::ModelDocument::from_toml(&text, "m.toml").unwrap();
    let family = ParameterizedModel::new(doc.clone(), "frequency").unwrap();
    let values = [7.3, 7.35];
    let run = |transient, settle| {
        let options = SweepOptions {
            transient,
            settle: Some(settle),
            ..SweepOptions::default()
        };
        sweep(&family, &values, &options, &|| {}).unwrap().points
    };
    let (unsettled, extended, long) = (run(100, 0), run(100, 900), run(1000, 0));
    for ((u, e), l) in unsettled.iter().zip(&extended).zip(&long) {
        assert_eq!(u.motion, Motion::Settling, "{}", u.parameter);
        assert_eq!(u.distinct_section_points, 20);
        assert_eq!(u.transient_periods, 100);
        assert_eq!((e.motion, l.motion), (Motion::Periodic, Motion::Periodic));
        assert_eq!(e.period, l.period);
        assert!(e.transient_periods > 100 && e.transient_periods < 400);
        let scale = l.max_displacement.iter().fold(0.0f64, |a, b| a.max(*b));
        let (a, b) = (&e.sections[19], &l.sections[19]);
        // The same orbit, its samples perhaps a phase of it apart.
        let close = (0..e.period.unwrap()).any(|shift| {
            let b = &l.sections[19 - shift];
            (0..2).all(|i| (a[i] - b[i]).abs() < 2e-5 * scale)
        });
        assert!(close, "{}: {a:?} vs {b:?}", e.parameter);
        let needed = u.settle_periods.unwrap().ceil() as usize;
        let again = SweepOptions {
            transient: 100 + 20 + needed,
            settle: Some(0),
            ..SweepOptions::default()
        };
        let p = sweep(&family, &[u.parameter], &again, &|| {})
            .unwrap()
            .points;
        assert_eq!(p[0].motion, Motion::Periodic, "{}", u.parameter);
    }
    assert_eq!(extended[0].period, Some(1));
    assert_eq!(extended[1].period, Some(3));
    let chart = crate::maps::chart::chart(
        &doc,
        ("frequency", &values),
        ("amplitude", &[0.05]),
        &crate::maps::chart::ChartOptions {
            sweep: SweepOptions {
                rtol: Some(1e-8),
                ..SweepOptions::default()
            },
            starts: 1,
        },
        &|| {},
    )
    .unwrap();
    for (cell, e) in chart.cells.iter().zip(&extended) {
        assert_eq!(cell.runs[0].period, e.period, "{}", e.parameter);
    }
}
