//! Pounding studies: frame dynamics, the gap that avoids contact, the code
//! rules (here), and rows of buildings and isolated buildings (`rows.rs`).

use super::*;
use crate::dynamics::ChainDynamics;
use crate::simulate::Integrator;
use nalgebra::{DMatrix, SymmetricEigen};

fn frame(n: usize, m: f64, k: f64) -> ShearFrame {
    ShearFrame {
        masses: vec![m; n],
        stiffnesses: vec![k; n],
        damping_ratio: 0.05,
        storeys: Vec::new(),
        heights: Vec::new(),
        gravity: Gravity::default(),
    }
}

/// A 12-s record: a 1.5 Hz and a 3.2 Hz burst (m/s², dt 0.01).
pub(crate) fn record() -> Record {
    let times: Vec<f64> = (0..=1200).map(|k| k as f64 * 0.01).collect();
    let a: Vec<f64> = times
        .iter()
        .map(|t| {
            let env = (-((t - 4.0) / 2.0).powi(2)).exp();
            env * (2.0 * (2.0 * std::f64::consts::PI * 1.5 * t).sin()
                + 1.2 * (2.0 * std::f64::consts::PI * 3.2 * t).sin())
        })
        .collect();
    Record::from_samples("burst", times, &a).unwrap()
}

/// Two equal storeys: ω² = (k/m)(3 ∓ √5)/2; Rayleigh damping gives ζ in
/// both modes (modal ratios φᵀCφ / 2ωφᵀMφ to 1e-12).
#[test]
fn frame_frequencies_and_rayleigh_damping() {
    let f = frame(2, 2.0e5, 8.0e7);
    let w = f.natural_frequencies();
    let k_over_m: f64 = 8.0e7 / 2.0e5;
    let exact = [
        (k_over_m * (3.0 - 5f64.sqrt()) / 2.0).sqrt(),
        (k_over_m * (3.0 + 5f64.sqrt()) / 2.0).sqrt(),
    ];
    for (a, b) in w.iter().zip(exact) {
        assert!((a - b).abs() < 1e-12 * b, "{a} vs {b}");
    }
    let f3 = ShearFrame {
        masses: vec![3.0e5, 2.5e5, 2.0e5],
        stiffnesses: vec![1.2e8, 1.0e8, 0.7e8],
        damping_ratio: 0.04,
        storeys: Vec::new(),
        heights: Vec::new(),
        gravity: Gravity::default(),
    };
    let (alpha, beta) = f3.rayleigh();
    let k = f3.stiffness_matrix();
    let m = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(f3.masses.clone()));
    let c = &m * alpha + &k * beta;
    // Modes from the generalised problem K φ = ω² M φ.
    let s = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        3,
        f3.masses.iter().map(|m| 1.0 / m.sqrt()),
    ));
    let eig = SymmetricEigen::new(&s * &k * &s);
    let mut modes: Vec<(f64, nalgebra::DVector<f64>)> = (0..3)
        .map(|j| (eig.eigenvalues[j].sqrt(), &s * eig.eigenvectors.column(j)))
        .collect();
    modes.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (w, phi) in modes.iter().take(2) {
        let zeta =
            (phi.transpose() * &c * phi)[(0, 0)] / (2.0 * w * (phi.transpose() * &m * phi)[(0, 0)]);
        assert!((zeta - 0.04).abs() < 1e-12, "{zeta}");
    }
    // The model's body dampers and couplings are C.
    let pair = Row::pair(
        f3.clone(),
        frame(1, 1e5, 1e7),
        1.0,
        vec![1],
        ContactLaw::hertz(1e9, 1.5).unwrap(),
    );
    let model = pair.model(&record(), 1.0, false).unwrap().model;
    let dynamics = ChainDynamics::new(&model, false);
    assert_eq!(dynamics.bodies(), 4);
}

/// The gap that avoids contact: 2 % below the free frames' largest closing
/// they pound, 2 % above they do not, and then the response equals the
/// free one exactly (Hertz's law has no force apart). The code rules are
/// ordered DDC ≤ SRSS ≤ ABS, and ABS bounds the true gap.
#[test]
fn required_gap_and_code_rules() {
    let pair = |gap: f64| {
        Row::pair(
            frame(3, 2.0e5, 6.0e7),
            frame(2, 3.0e5, 1.5e8),
            gap,
            vec![1, 2],
            ContactLaw::hertz(2.0e9, 1.5).unwrap(),
        )
    };
    let rec = record();
    let far = pair(1.0)
        .analyse(&rec, 1.0, &RunSettings::new(0.0025, 1e-9))
        .unwrap();
    assert_eq!(far.pounding.impacts, 0);
    assert_eq!(far.pounding, far.free);
    let need = far.joints[0].required_gap;
    assert!(need > 1e-3, "{need}");
    let below = pair(0.98 * need)
        .analyse(&rec, 1.0, &RunSettings::new(0.0025, 1e-9))
        .unwrap();
    assert!(below.pounding.impacts > 0 && below.pounding.peak_impact_force > 0.0);
    let above = pair(1.02 * need)
        .analyse(&rec, 1.0, &RunSettings::new(0.0025, 1e-9))
        .unwrap();
    assert_eq!(above.pounding.impacts, 0);
    // The history of the pounding run: the same impacts and peak force,
    // its largest sampled drift below the response's exact one and within
    // 1e-3 of it, a sample every 2.5 ms over the record.
    let h = pair(0.98 * need)
        .history(&rec, 1.0, &RunSettings::new(0.0025, 1e-9))
        .unwrap();
    assert_eq!(h.impacts.len(), below.pounding.impacts);
    let peak = h.impacts.iter().fold(0.0f64, |m, i| m.max(i.peak_force));
    assert_eq!(peak, below.pounding.peak_impact_force);
    let duration = *rec.times.last().unwrap();
    assert_eq!(h.times.len(), (duration / 0.0025).round() as usize + 1);
    let top_drift = (0..h.times.len())
        .map(|j| (h.displacement[j * 5 + 2] - h.displacement[j * 5 + 1]).abs())
        .fold(0.0, f64::max);
    let exact = below.pounding.drift[0][2];
    assert!(
        top_drift <= exact * (1.0 + 1e-12) && top_drift >= exact * (1.0 - 1e-3),
        "{top_drift} against {exact}"
    );
    let g = far.joints[0].code_gaps;
    assert!(g.double_difference <= g.srss && g.srss <= g.absolute_sum);
    assert!(need <= g.absolute_sum);
    assert!(g.correlation > 0.0 && g.correlation < 1.0);
    // Identical frames move together: no gap needed, and ρ = 1.
    let mut same = pair(0.01);
    same.buildings[1].frame = frame(3, 2.0e5, 6.0e7);
    let r = same
        .analyse(&rec, 1.0, &RunSettings::new(0.0025, 1e-9))
        .unwrap();
    let j = r.joints[0];
    assert!(j.required_gap.abs() < 1e-12, "{}", j.required_gap);
    assert!((j.code_gaps.correlation - 1.0).abs() < 1e-12);
    // Undamped and of one frequency: ρ = 1, not 0/0.
    assert_eq!(correlation(1.0, 0.0, 0.0), 1.0);
    assert!(j.code_gaps.double_difference < 1e-9);
}

/// A 3-storey and a 2-storey frame, a 1 cm joint at floors 1 and 2, Hertz.
fn storeys_3_and_2() -> Row {
    Row::pair(
        frame(3, 2.0e5, 6.0e7),
        frame(2, 3.0e5, 1.5e8),
        0.01,
        vec![1, 2],
        ContactLaw::hertz(2.0e9, 1.5).unwrap(),
    )
}

/// DOPRI5 at a loose tolerance gives the pounding run's peaks of DOP853 at
/// a tight one to a fraction of the 1 % an earthquake study asks for, with
/// fewer evaluations (a record's samples limit both methods' steps).
#[test]
fn dopri5_at_loose_tolerance_matches_dop853() {
    let pair = storeys_3_and_2();
    let rec = record();
    let reference = pair
        .respond(&rec, 1.0, true, &RunSettings::new(0.005, 1e-10))
        .unwrap();
    assert!(reference.impacts > 0);
    let loose = RunSettings {
        method: Method::Dopri5,
        ..RunSettings::new(0.005, 1e-4)
    };
    let r = pair.respond(&rec, 1.0, true, &loose).unwrap();
    assert_eq!(r.impacts, reference.impacts);
    let rel = |a: f64, b: f64| (a - b).abs() / b;
    let mut worst = rel(r.peak_impact_force, reference.peak_impact_force);
    for side in 0..2 {
        for (a, b) in r.drift[side].iter().zip(&reference.drift[side]) {
            worst = worst.max(rel(*a, *b));
        }
    }
    // Measured 2.1e-4 (33 impacts).
    assert!(worst < 1e-3, "{worst:e}");
}

/// The local integrator (each frame exact per record sample between
/// poundings, the pair integrated while in touch) gives the peaks of the
/// global one at the same tolerance: the same impacts, drifts, floor
/// accelerations and impact force.
#[test]
fn the_local_integrator_matches_the_global_one() {
    let pair = storeys_3_and_2();
    let rec = record();
    let run = RunSettings::new(0.005, 1e-9);
    let local = RunSettings {
        integrator: Integrator::Local,
        ..run.clone()
    };
    for contacts in [true, false] {
        let g = pair.respond(&rec, 1.0, contacts, &run).unwrap();
        let l = pair.respond(&rec, 1.0, contacts, &local).unwrap();
        assert_eq!(l.impacts, g.impacts);
        assert_eq!(contacts, g.impacts > 0);
        let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
        let mut worst = rel(l.peak_impact_force, g.peak_impact_force);
        for side in 0..2 {
            for (a, b) in [
                (&l.drift, &g.drift),
                (&l.acceleration, &g.acceleration),
                (&l.displacement, &g.displacement),
            ] {
                for (x, y) in a[side].iter().zip(&b[side]) {
                    worst = worst.max(rel(*x, *y));
                }
            }
            for (x, y) in l.residual_drift[side].iter().zip(&g.residual_drift[side]) {
                worst = worst.max((x - y).abs() / g.drift[side][0]);
            }
        }
        for (a, b) in l.closing.iter().flatten().zip(g.closing.iter().flatten()) {
            worst = worst.max(rel(*a, *b));
        }
        assert!(worst < 1e-6, "contacts {contacts}: {worst:e}");
    }
}

/// W1: the peaks are read on the dense output, so they do not depend on
/// the output sampling (a 100 s sample gave zero drifts and gaps before),
/// and a sampled history never exceeds them.
#[test]
fn peaks_do_not_depend_on_the_sampling() {
    let pair = storeys_3_and_2();
    let rec = record();
    let at = |sample: f64| {
        pair.analyse(&rec, 1.0, &RunSettings::new(sample, 1e-9))
            .unwrap()
    };
    let (fine, coarse) = (at(0.0025), at(100.0));
    let rel = |a: f64, b: f64| (a - b).abs() / b.abs().max(1e-300);
    let mut worst = rel(coarse.joints[0].required_gap, fine.joints[0].required_gap);
    for (c, f) in [
        (&coarse.pounding, &fine.pounding),
        (&coarse.free, &fine.free),
    ] {
        for side in 0..2 {
            for (a, b) in [
                (&c.drift, &f.drift),
                (&c.acceleration, &f.acceleration),
                (&c.displacement, &f.displacement),
            ] {
                for (x, y) in a[side].iter().zip(&b[side]) {
                    assert!(*y > 0.0);
                    worst = worst.max(rel(*x, *y));
                }
            }
            for (x, y) in c.residual_drift[side].iter().zip(&f.residual_drift[side]) {
                worst = worst.max((x - y).abs() / f.drift[side][0]);
            }
        }
    }
    assert!(worst < 1e-9, "{worst:e}");
    assert!(fine.joints[0].required_gap > 0.0);
    // A history sampled every 0.2 ms stays below every exact peak drift,
    // within 1e-5 of it.
    let h = pair
        .history(&rec, 1.0, &RunSettings::new(2e-4, 1e-9))
        .unwrap();
    let n = 5;
    for (k, first, floors) in [(0, 0, 3), (1, 3, 2)] {
        for i in 0..floors {
            let sampled = (0..h.times.len())
                .map(|j| {
                    let u = &h.displacement[j * n..(j + 1) * n];
                    let below = if i == 0 { 0.0 } else { u[first + i - 1] };
                    (u[first + i] - below).abs()
                })
                .fold(0.0, f64::max);
            let exact = fine.pounding.drift[k][i];
            assert!(
                sampled <= exact * (1.0 + 1e-12) && sampled >= exact * (1.0 - 1e-5),
                "building {k} storey {i}: {sampled} against {exact}"
            );
        }
    }
}

#[test]
fn bad_pairs_are_refused() {
    let ok = Row::pair(
        frame(2, 1e5, 1e7),
        frame(1, 1e5, 1e7),
        0.01,
        vec![1],
        ContactLaw::hertz(1e9, 1.5).unwrap(),
    );
    let with = |f: &dyn Fn(&mut Row)| {
        let mut r = ok.clone();
        f(&mut r);
        r
    };
    let cases = [
        (
            with(&|r| r.joints[0].floors = vec![2]),
            "floor 2 is not a floor of both",
        ),
        (with(&|r| r.joints[0].gap = -1.0), "gap -1"),
        (
            with(&|r| {
                r.buildings[1].frame = frame(2, 1e5, 1e7);
                r.joints[0].floors = vec![1, 2, 1];
            }),
            "floors: floor 1 is given twice",
        ),
        (with(&|r| r.joints[0].floors = vec![]), "at least one"),
        (
            with(&|r| r.buildings[0].frame.stiffnesses = vec![1e7]),
            "left frame: 2 masses and 1 storey",
        ),
        (
            with(&|r| r.buildings[1].name = "left".into()),
            "building name \"left\" is used twice",
        ),
        (with(&|r| r.joints.clear()), "0 joints for 2 buildings"),
        (
            with(&|r| {
                r.buildings.clear();
                r.joints.clear();
            }),
            "no building: give at least one",
        ),
    ];
    for (p, needle) in cases {
        let e = p.check().unwrap_err();
        assert!(e.to_string().contains(needle), "{e}");
        assert!(
            matches!(e, PoundingError::Pair { key: Some(_), .. }),
            "{e:?}"
        );
    }
}

/// The spectrum over gaps × period ratios: the period ratio is set, a cell
/// whose gap exceeds the required one has no impact and an amplification
/// of exactly 1, the smallest gap pounds, and the numbers are the same on
/// one thread and on two.
#[test]
fn pounding_spectrum_cells() {
    let pair = Row::pair(
        frame(3, 2.0e5, 6.0e7),
        frame(2, 3.0e5, 1.5e8),
        0.0,
        vec![1, 2],
        ContactLaw::hertz(2.0e9, 1.5).unwrap(),
    );
    let scaled = with_period_ratio(&pair, 1.7).unwrap();
    assert!((scaled.buildings[0].period() / scaled.buildings[1].period() - 1.7).abs() < 1e-12);
    let records = vec![(record(), 1.0), (record(), 0.5)];
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                pounding_spectrum(
                    &pair,
                    &records,
                    &[0.001, 0.5],
                    &[0.8, 1.7],
                    &RunSettings::new(0.005, 1e-8),
                )
            })
            .unwrap()
    };
    let cells = run(1);
    assert_eq!(cells, run(2));
    assert_eq!(cells.len(), 4);
    for c in &cells {
        for (k, need) in c.required_gap.iter().enumerate() {
            if c.gap > *need {
                assert_eq!(c.impacts[k], 0);
                assert_eq!(c.drift_amplification[k], 1.0);
            }
        }
    }
    assert!(cells[0].impacts[0] > 0, "{:?}", cells[0]);
    assert_eq!(quantile(&[3.0, 1.0, 2.0], 0.5), 2.0);
    assert_eq!(quantile(&[1.0, 2.0], 0.25), 1.25);
}

#[test]
fn pair_files_are_parsed_and_checked() {
    let text =
        "gap = 0.02\nfloors = [1]\nlaw = { law = \"hertz\", stiffness = 1e9, exponent = 1.5 }\n\
                [left]\nmasses = [1e5]\nstiffnesses = [1e7]\ndamping_ratio = 0.05\n\
                [right]\nmasses = [1e5, 1e5]\nstiffnesses = [2e7, 2e7]\ndamping_ratio = 0.02\n";
    let p = parse_row(text, "pair.toml").unwrap();
    assert_eq!(
        (
            p.buildings[0].floors(),
            p.buildings[1].floors(),
            p.joints[0].gap
        ),
        (1, 2, 0.02)
    );
    let e = parse_row(
        &text.replace("damping_ratio = 0.02", "dampingratio = 0.02"),
        "pair.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("pair.toml:11:") && e.contains("dampingratio"),
        "{e}"
    );
    let e = parse_row(
        &text.replace("[right]\n", "[right]\ngap = 0.1\n"),
        "pair.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("pair.toml: right frame: name, gap, floors and law belong to [[building]]"),
        "{e}"
    );
    let e = parse_row(&text.replace("floors = [1]", "floors = [2]"), "pair.toml").unwrap_err();
    assert!(
        matches!(&e, PoundingError::Pair { file: Some(f), key: Some("floors"), .. } if f == "pair.toml"),
        "{e:?}"
    );
    assert!(
        e.to_string().contains("floor 2 is not a floor of both"),
        "{e}"
    );
}

/// Yielding storeys in a pair file: the frame, storey and key of a bad
/// law are named; storeys that never yield give the elastic pair's
/// response; yielding ones cap the drift-driven force and leave a residual
/// drift after the free-vibration tail.
#[test]
fn yielding_storeys_in_the_pair() {
    let text =
        "gap = 0.5\nfloors = [1]\nlaw = { law = \"hertz\", stiffness = 1e9, exponent = 1.5 }\n\
                [left]\nmasses = [1e5, 1e5]\nstiffnesses = [4e7, 3e7]\ndamping_ratio = 0.05\n\
                storeys = [{ law = \"bilinear\", yield_drift = YD, post_yield_ratio = 0.05 }, \
                           { law = \"bilinear\", yield_drift = YD, post_yield_ratio = 0.05 }]\n\
                [right]\nmasses = [1e5]\nstiffnesses = [2e7]\ndamping_ratio = 0.05\n";
    let bad = parse_row(
        &text
            .replace("YD", "0.002")
            .replace("post_yield_ratio = 0.05 }]", "post_yield_ratio = 1.5 }]"),
        "p.toml",
    )
    .unwrap_err()
    .to_string();
    assert!(
        bad.contains("p.toml: left frame: storey 2: post_yield_ratio = 1.5: must be in [0, 1)"),
        "{bad}"
    );
    let plain: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("storeys"))
        .map(|l| format!("{l}\n"))
        .collect();
    let elastic = parse_row(&plain, "e.toml").unwrap();
    let never = parse_row(&text.replace("YD", "10.0"), "n.toml").unwrap();
    let yielding = parse_row(&text.replace("YD", "0.002"), "y.toml").unwrap();
    let run = RunSettings {
        loops: true,
        ..RunSettings::new(0.005, 1e-9)
    };
    let rec = record();
    let a = elastic.respond(&rec, 1.0, false, &run).unwrap();
    let b = never.respond(&rec, 1.0, false, &run).unwrap();
    // The tail extends the run of the pair with storeys: compare the peaks
    // (reached during the record) to 1e-7.
    for (x, y) in a.drift[0].iter().zip(&b.drift[0]) {
        assert!((x - y).abs() < 1e-7 * x, "{x} vs {y}");
    }
    let c = yielding.respond(&rec, 1.0, false, &run).unwrap();
    assert!(
        c.drift[0][0] > 0.002,
        "the first storey yields: {:?}",
        c.drift[0]
    );
    // The first storey's force is capped near k u_y (1 + b mu): the floor
    // accelerations stay below the elastic frame's.
    assert!(
        c.acceleration[0][0] < a.acceleration[0][0],
        "{c:?} vs {a:?}"
    );
    assert!(
        c.residual_drift[0][0].abs() > 1e-5,
        "{:?}",
        c.residual_drift
    );
    assert!(
        b.residual_drift[0][0].abs() < 1e-6,
        "{:?}",
        b.residual_drift
    );
    // The loops: each bilinear storey's force stays within its bounds
    // b k d ± (1 − b) k u_y, and the work ∮ F dd over the sampled loop
    // (trapezoids, ending at rest) is the hysteretic energy from the
    // storey's state to 2 % (the sampling of a 5 ms grid).
    assert_eq!(c.loops.len(), 2);
    // Without the loops, the same peaks to the bit, and no loops.
    let bare = yielding
        .respond(&rec, 1.0, false, &RunSettings::new(0.005, 1e-9))
        .unwrap();
    assert!(bare.loops.is_empty());
    assert_eq!(
        (&bare.drift, &bare.residual_drift, &bare.acceleration),
        (&c.drift, &c.residual_drift, &c.acceleration)
    );
    for l in &c.loops {
        let i = l.storey.unwrap();
        let k = [4e7, 3e7][i];
        let (b, uy) = (0.05, 0.002);
        for (d, f) in l.drift.iter().zip(&l.force) {
            assert!(
                (f - b * k * d).abs() <= (1.0 - b) * k * uy * (1.0 + 1e-8),
                "{d} {f}"
            );
        }
        let work: f64 = l
            .drift
            .windows(2)
            .zip(l.force.windows(2))
            .map(|(d, f)| 0.5 * (f[0] + f[1]) * (d[1] - d[0]))
            .sum();
        let stored = 0.5 * b * k * l.drift.last().unwrap().powi(2);
        let e = c.hysteretic_energy[0][i];
        assert!(e > 0.0, "{e}");
        assert!(
            ((work - stored) - e).abs() < 0.02 * e + 0.5 * (1.0 - b) * k * uy * uy,
            "storey {}: loop work {work} less stored {stored} against {e}",
            i + 1
        );
    }
}

mod rows;
