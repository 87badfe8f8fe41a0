//! The IDA against a hand-checkable collapse, censoring and the median.

use super::*;
use crate::model::hysteresis::StoreySpec;
use crate::seismic::pounding::{Building, Gravity, ShearFrame};

const M: f64 = 1.0e5;
const K: f64 = 4.0e6;
const UY: f64 = 0.05;
const LIMIT: f64 = 0.5;

/// One undamped elastic–perfectly-plastic storey.
fn epp() -> Row {
    Row {
        buildings: vec![Building {
            name: "epp".into(),
            frame: ShearFrame {
                masses: vec![M],
                stiffnesses: vec![K],
                damping_ratio: 0.0,
                storeys: vec![StoreySpec::Bilinear {
                    yield_drift: UY,
                    post_yield_ratio: 0.0,
                }],
                heights: Vec::new(),
                gravity: Gravity::default(),
            },
            isolation: None,
        }],
        joints: Vec::new(),
    }
}

/// A ground acceleration of 1 m/s² from t = 0 for 40 s.
/// The IDA of the EPP storey under the step, collapse at the drift limit
/// (or beyond capacity, or without convergence), sampled every 2 ms at
/// `rtol`.
fn epp_ida(ida: IdaSettings, rtol: f64) -> RecordIda {
    let criterion = Criterion {
        drift: DriftLimit::Drift(LIMIT),
        capacity: true,
        contacts: true,
    };
    let run = RunSettings::new(0.002, rtol);
    record_ida(&epp(), &step(), &criterion, &ida, &run).unwrap()
}

fn step() -> Record {
    Record::from_samples("step", vec![0.0, 40.0], &[1.0, 1.0]).unwrap()
}

/// An undamped EPP storey under a step A of ground acceleration reaches
/// the yield drift u_y with ½ v² = A u_y − ½ ω² u_y², then flows against
/// the net deceleration ω² u_y − A by v²/(2(ω² u_y − A)); it collapses
/// (drift L) from A_c = ω² u_y (2L − u_y) / (2L), here 1.9 m/s² (the
/// strength F_y/m = 2 m/s² less the dynamic overshoot). The IDA's bracket
/// holds A_c and is within its 2 % tolerance.
#[test]
fn an_elastic_perfectly_plastic_storey_collapses_at_its_strength() {
    let w2 = K / M;
    let a_c = w2 * UY * (2.0 * LIMIT - UY) / (2.0 * LIMIT);
    assert!((a_c - 1.9).abs() < 1e-12);
    let r = epp_ida(
        IdaSettings {
            first: 0.5,
            ..IdaSettings::default()
        },
        1e-10,
    );
    let c = r.collapse.unwrap();
    assert!(
        r.survived <= a_c * (1.0 + 1e-6) && c >= a_c * (1.0 - 1e-6),
        "[{}, {c}] against {a_c}",
        r.survived
    );
    assert!(c / r.survived <= 1.02, "{r:?}");
    // The hunt: 0.5, 0.75, 1.125, 1.6875, 2.53 (collapse), then bisection.
    assert_eq!(r.points[4].scale, 0.5 * 1.5f64.powi(4));
    match &r.points[4].verdict {
        Verdict::Drift {
            building, storey, ..
        } => assert_eq!((building.as_str(), *storey), ("epp", 1)),
        v => panic!("{v:?}"),
    }
    assert!(r
        .points
        .iter()
        .all(|p| p.verdict.collapsed() == (p.scale >= c)));
}

/// A record that does not bring the storey down up to the largest scale is
/// censored: no collapse scale, survived = that scale; the median counts
/// it above every collapse and is undetermined once it reaches the middle.
#[test]
fn censored_records_and_the_median() {
    let criterion = Criterion {
        drift: DriftLimit::Drift(LIMIT),
        capacity: true,
        contacts: true,
    };
    let ida = IdaSettings {
        first: 0.5,
        max_scale: 1.5,
        ..IdaSettings::default()
    };
    let run = RunSettings::new(0.002, 1e-8);
    let r = record_ida(&epp(), &step(), &criterion, &ida, &run).unwrap();
    assert_eq!((r.collapse, r.survived), (None, 1.5));
    assert!(r.points.iter().all(|p| !p.verdict.collapsed()));
    let fell = |c: f64| RecordIda {
        source: "x".into(),
        points: Vec::new(),
        survived: c / 1.01,
        collapse: Some(c),
    };
    assert_eq!(
        median_collapse(&[fell(1.0), r.clone(), fell(3.0)]),
        Some(3.0)
    );
    assert_eq!(
        median_collapse(&[fell(1.0), fell(2.0), r.clone(), fell(4.0)]),
        Some(3.0)
    );
    assert_eq!(median_collapse(&[fell(1.0), r.clone(), r.clone()]), None);
    assert_eq!(median_collapse(&[fell(1.0), fell(2.0), r.clone(), r]), None);
    let e = record_ida(
        &epp(),
        &step(),
        &Criterion {
            drift: DriftLimit::Drift(0.0),
            ..criterion
        },
        &ida,
        &run,
    )
    .unwrap_err();
    assert!(e.to_string().contains("drift_limit"), "{e}");
    let e = record_ida(
        &epp(),
        &step(),
        &criterion,
        &IdaSettings { growth: 1.0, ..ida },
        &run,
    )
    .unwrap_err();
    assert!(e.to_string().contains("growth"), "{e}");
}

/// A first scale that collapses already: the IDA goes down by the growth
/// factor until a scale stands, then bisects: the same bracket of 1.9 to
/// the tolerance.
#[test]
fn a_first_scale_that_collapses_goes_down() {
    let r = epp_ida(
        IdaSettings {
            first: 10.0,
            ..IdaSettings::default()
        },
        1e-10,
    );
    let c = r.collapse.unwrap();
    assert!(
        r.survived <= 1.9 && 1.9 <= c && c / r.survived <= 1.02,
        "{r:?}"
    );
    assert!(r.points[0].verdict.collapsed() && r.points[0].scale == 10.0);
}

/// The EPP storey 3.5 m high under P-Δ (P/h = g = 0.2 k): past yield its
/// resistance k u_y − g d falls, so under a step A it stops only if the
/// work left, ((k − g) u_y − m A)²/(2g), covers the kinetic energy at
/// yield, m A u_y − ½ (k − g) u_y²; equality gives the collapse step A_c,
/// the smaller root of x² − 2((k − g) u_y + g u_y) x + ((k − g) u_y)² +
/// g u_y (k − g) u_y = 0 in x = m A. The IDA brackets it, and the collapse
/// is a dynamic instability at the 0.10 drift-ratio limit (0.35 m).
#[test]
fn p_delta_brings_an_epp_storey_down_by_instability() {
    let g = 0.2 * K;
    let h = 3.5;
    let mut row = epp();
    let frame = &mut row.buildings[0].frame;
    frame.heights = vec![h];
    frame.gravity = Gravity {
        p_delta: true,
        leaning_loads: vec![g * h - M * crate::model::record::STANDARD_GRAVITY],
    };
    assert!((frame.geometric_stiffnesses()[0] / g - 1.0).abs() < 1e-12);
    let a = (K - g) * UY;
    let (b, c) = (2.0 * (a + g * UY), a * a + g * UY * a);
    let a_c = (b - (b * b - 4.0 * c).sqrt()) / 2.0 / M;
    assert!((a_c - 1.1056).abs() < 1e-4, "{a_c}");
    let criterion = Criterion {
        drift: DriftLimit::FEMA,
        capacity: true,
        contacts: true,
    };
    let ida = IdaSettings {
        first: 0.5,
        ..IdaSettings::default()
    };
    let run = RunSettings::new(0.002, 1e-10);
    let r = record_ida(&row, &step(), &criterion, &ida, &run).unwrap();
    let c = r.collapse.unwrap();
    assert!(
        r.survived <= a_c * (1.0 + 1e-6) && c >= a_c * (1.0 - 1e-6) && c / r.survived <= 1.02,
        "[{}, {c}] against {a_c}",
        r.survived
    );
    for p in &r.points {
        let ratio = p.max_drift_ratio.unwrap();
        assert!((ratio - p.max_drift / h).abs() < 1e-15);
        match &p.verdict {
            Verdict::Instability { storey, drift, .. } => {
                assert_eq!(*storey, 1);
                assert!(*drift > 0.1 * h && p.scale >= c);
            }
            Verdict::Standing => assert!(p.scale < c && ratio < 0.1),
            v => panic!("{v:?}"),
        }
    }
    // The same storey without heights: a drift-ratio limit is refused by
    // name.
    let e = record_ida(&epp(), &step(), &criterion, &ida, &run).unwrap_err();
    assert!(e.to_string().contains("drift_ratio_limit"), "{e}");
}
