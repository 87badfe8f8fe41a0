//! Checks of the chart: classification, attractor counting, agreement with
//! a sweep and with the linear limit, determinism, bad input.

use super::*;
use crate::maps::attractor::{count_attractors, Recorded, Run};
use crate::maps::sweep::sweep;
use crate::model::parameter::ParameterizedModel;

const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.05\nfrequency = 7.0\n";

fn doc(text: &str) -> ModelDocument {
    ModelDocument::from_toml(text, "m.toml").unwrap()
}

#[test]
fn attractors_of_samples() {
    let s = |u: f64| vec![u, 0.5 * u];
    let period2: Vec<Vec<f64>> = (0..10)
        .map(|k| s(if k % 2 == 0 { 1.0 } else { -1.0 }))
        .collect();
    let fixed: Vec<Vec<f64>> = (0..10).map(|_| s(1.0)).collect();
    let run = |period: Option<usize>| Run {
        start: vec![],
        period,
        impacts_per_period: 1.0,
        max_displacement: 1.0,
        lyapunov: None,
        error: None,
    };
    // The same period-2 orbit at the other phase, a different fixed
    // point, and two non-periodic runs: four attractors; a non-periodic
    // run that ends on the fixed point (still settling) belongs to it.
    let shifted: Vec<Vec<f64>> = period2[1..].to_vec();
    let other: Vec<Vec<f64>> = (0..10).map(|_| s(0.3)).collect();
    let wandering: Vec<Vec<f64>> = (0..10).map(|k| s(2.0 + 0.1 * k as f64)).collect();
    let mut settling = wandering.clone();
    settling.push(s(0.3));
    let runs = [
        run(Some(2)),
        run(Some(2)),
        run(Some(1)),
        run(Some(1)),
        run(None),
        run(None),
        run(None),
    ];
    let samples: Vec<Recorded> = [
        period2,
        shifted,
        fixed,
        other,
        wandering.clone(),
        wandering,
        settling,
    ]
    .into_iter()
    .map(|samples| Recorded {
        samples,
        scale: (1.0, 1.0),
    })
    .collect();
    assert_eq!(count_attractors(&runs, &samples, 1e-6), 4);
    let (ids, _) = crate::maps::attractor::identify(&runs, &samples, 1e-6);
    assert_eq!(ids, [0, 0, 1, 2, 3, 3, 2].map(Some));
    assert_eq!(count_attractors(&runs[..2], &samples[..2], 1e-6), 1);
    assert_eq!(count_attractors(&runs[2..4], &samples[2..4], 1e-6), 2);
    // Within a tolerance of 0.8 the two fixed points are one.
    assert_eq!(count_attractors(&runs[2..4], &samples[2..4], 0.8), 1);
}

/// Start 0 of a cell is the sweep's run from the model's initial state:
/// the same numbers; the linear limit (a unique attractor) is period 1
/// without impacts at every cell and start.
#[test]
fn cells_match_the_sweep_and_the_linear_limit() {
    let opts = ChartOptions {
        sweep: SweepOptions {
            transient: 30,
            record: 8,
            rtol: Some(DEFAULT_RTOL),
            ..SweepOptions::default()
        },
        starts: 3,
    };
    let xs = [6.5, 7.5];
    let ys = [0.05, 0.08];
    let c = chart(
        &doc(ROW),
        ("frequency", &xs),
        ("amplitude", &ys),
        &opts,
        &|| {},
    )
    .unwrap();
    assert_eq!(c.cells.len(), 4);
    let mut amplitude = doc(ROW);
    let p = amplitude.parameter("amplitude").unwrap();
    amplitude.set(&p, 0.08).unwrap();
    let family = ParameterizedModel::new(amplitude, "frequency").unwrap();
    let s = sweep(&family, &xs, &opts.sweep, &|| {}).unwrap();
    for (cell, point) in c.cells[2..].iter().zip(&s.points) {
        assert_eq!((cell.x, cell.y), (point.parameter, 0.08));
        let max_u = point.max_displacement.iter().copied().fold(0.0, f64::max);
        assert_eq!(cell.runs[0].max_displacement, max_u);
        assert_eq!(cell.runs[0].impacts_per_period, point.impacts_per_period);
        assert_eq!(cell.runs.len(), 3);
    }
    // The free oscillation decays like exp(−ζω0 t): 400 periods.
    let linear = doc(&ROW.replace("clearance = 0.001", "clearance = 1.0"));
    let settled = ChartOptions {
        sweep: SweepOptions {
            transient: 400,
            ..opts.sweep
        },
        ..opts
    };
    let c = chart(
        &linear,
        ("frequency", &xs),
        ("amplitude", &ys),
        &settled,
        &|| {},
    )
    .unwrap();
    for cell in &c.cells {
        assert_eq!(cell.attractors, 1, "{cell:?}");
        for run in &cell.runs {
            assert_eq!(
                (run.period, run.impacts_per_period),
                (Some(1), 0.0),
                "{run:?}"
            );
        }
    }
}

/// The same bytes with one thread and two.
#[test]
fn deterministic_over_threads() {
    let opts = ChartOptions {
        sweep: SweepOptions {
            transient: 10,
            record: 4,
            ..SweepOptions::default()
        },
        starts: 2,
    };
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let c = pool.install(|| {
            chart(
                &doc(ROW),
                ("frequency", &[6.0, 7.0, 8.0]),
                ("row.clearance", &[1e-3, 2e-3]),
                &opts,
                &|| {},
            )
            .unwrap()
        });
        serde_json::to_string(&c).unwrap()
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn bad_input_is_refused() {
    let opts = ChartOptions::default();
    let run = |x: (&str, &[f64]), y: (&str, &[f64]), opts: &ChartOptions| {
        chart(&doc(ROW), x, y, opts, &|| {})
            .unwrap_err()
            .to_string()
    };
    let v = [7.0];
    assert!(run(("frequency", &v), ("excitation.frequency", &v), &opts).contains("the same key"));
    assert!(run(("frequency", &v), ("row.colour", &v), &opts).contains("does not exist"));
    assert!(run(("frequency", &[]), ("amplitude", &v), &opts).contains("no values"));
    assert!(run(("frequency", &[f64::NAN]), ("amplitude", &v), &opts).contains("finite"));
    assert!(run(("frequency", &v), ("row.mass", &[-1.0]), &opts).contains("mass"));
    let none = ChartOptions {
        starts: 0,
        ..ChartOptions::default()
    };
    assert!(run(("frequency", &v), ("amplitude", &v), &none).contains("starts = 0"));
    let big: Vec<f64> = (0..10_000).map(|k| 6.0 + 1e-4 * k as f64).collect();
    assert!(run(("frequency", &big), ("amplitude", &big), &opts).contains("coarser grid"));
}
