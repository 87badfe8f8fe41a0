//! Tests of the model (`mod.rs`).

use super::*;

use crate::model::reference::seed_law as law;

#[test]
fn row_layout_and_names() {
    let m = Model::row(
        3,
        0.227,
        12.0,
        0.04,
        1e-3,
        law(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap();
    assert_eq!(m.contacts().len(), 4);
    assert_eq!(m.contact_name(0), "wall|p1");
    assert_eq!(m.contact_name(1), "p1|p2");
    assert_eq!(m.contact_name(3), "p3|wall");
    let u = [1e-4, -2e-4, 5e-4];
    assert!((m.approach(0, &u) - (-1e-4 - 1e-3)).abs() < 1e-18);
    assert!((m.approach(1, &u) - (3e-4 - 1e-3)).abs() < 1e-18);
    assert!((m.approach(3, &u) - (5e-4 - 1e-3)).abs() < 1e-18);
}

#[test]
fn invalid_models_are_named() {
    let e = Model::row(
        2,
        -1.0,
        1.0,
        0.0,
        1e-3,
        law(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap_err();
    assert!(e.message.contains("mass = -1"), "{e}");
    assert_eq!(
        (e.kind, e.key.as_str()),
        (ModelErrorKind::InvalidValue, "body.1.mass")
    );
    let e = Model::row(
        2,
        1.0,
        1.0,
        0.0,
        -1e-3,
        law(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap_err();
    assert!(e.message.contains("clearance"), "{e}");
    let m = Model::row(
        2,
        1.0,
        1.0,
        0.0,
        1e-3,
        law(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap();
    let e = m.with_initial_state(vec![2e-3, 0.0], vec![]).unwrap_err();
    assert!(e.message.contains("overlap"), "{e}");
    assert_eq!(e.kind, ModelErrorKind::Overlap);
}

#[test]
fn accelerogram_interpolates_and_validates() {
    let r = Accelerogram::new(vec![0.0, 1.0, 3.0], vec![0.0, 2.0, -2.0], 0.5).unwrap();
    assert_eq!(r.at(0.5), 0.5);
    assert_eq!(r.at(2.0), 0.0);
    assert_eq!(r.at(3.0), -1.0);
    assert_eq!(r.at(3.5), 0.0);
    assert_eq!(r.at(-1.0), 0.0);
    assert!(Accelerogram::new(vec![0.0, 1.0, 1.0], vec![0.0; 3], 1.0).is_err());
    assert_eq!(r.peak(), 1.0);
}

#[test]
fn accelerogram_segment_is_the_bisections() {
    // A uniform record with rounding in its times, a record with a
    // slow stretch (long walks fall back to bisection) and one with
    // only two samples; every sample time, the midpoints and the ends.
    let uniform: Vec<f64> = (0..2001).map(|k| k as f64 * 0.005).collect();
    let mut uneven: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
    uneven.extend((1..50).map(|k| 1.99 + k as f64 * 0.2));
    for times in [uniform, uneven, vec![-1.0, 2.0]] {
        let n = times.len();
        let r = Accelerogram::new(times.clone(), vec![0.0; n], 1.0).unwrap();
        let mut probes = times.clone();
        probes.extend(times.windows(2).map(|w| 0.5 * (w[0] + w[1])));
        probes.extend(times.iter().map(|t| t - 1e-12));
        for t in probes.into_iter().filter(|t| *t >= times[0]) {
            let bisection = times.partition_point(|&x| x <= t).clamp(1, n - 1);
            assert_eq!(r.segment(t), bisection, "t = {t}");
        }
    }
}

#[test]
fn mirror_symmetry() {
    let base = BaseExcitation::Harmonic {
        amplitude: 0.05,
        frequency: 7.0,
        phase: 0.3,
    };
    let row = |walls| Model::row(3, 1.0, 1.0, 0.1, 1e-3, law(), walls, base.clone()).unwrap();
    assert!(row((true, true)).is_mirror_symmetric());
    assert!(row((false, false)).is_mirror_symmetric());
    // One wall only: not symmetric.
    assert!(!row((true, false)).is_mirror_symmetric());
    // No periodic forcing: no spatio-temporal symmetry.
    assert!(!row((true, true))
        .with_base(BaseExcitation::None)
        .is_mirror_symmetric());
    // A heavier end body breaks it.
    let mut m = row((true, true));
    m.bodies[0].mass = 1.1;
    assert!(!m.is_mirror_symmetric());
    // A different clearance at one wall breaks it.
    let mut m = row((true, true));
    m.contacts[0].clearance = 2e-3;
    assert!(!m.is_mirror_symmetric());
}

#[test]
fn forcing_frequency() {
    let base = BaseExcitation::Harmonic {
        amplitude: 0.05,
        frequency: 7.0,
        phase: 0.0,
    };
    let m = Model::row(1, 1.0, 1.0, 0.0, 1e-3, law(), (true, true), base).unwrap();
    assert_eq!(m.forcing_frequency(), Some(7.0));
    let m = m.with_base(BaseExcitation::None);
    assert_eq!(m.forcing_frequency(), None);
}

/// A record with its tail appended (a pounding run's ramp to rest: one
/// long last segment): the segment guess keeps the record's own rate (the
/// average one sent every guess to bisection: 21 % of a frame's run), and
/// the values equal the linear interpolation, scale included, to 1e-15.
#[test]
fn a_record_with_a_tail_interpolates_exactly() {
    let mut times: Vec<f64> = (0..3000).map(|k| k as f64 * 0.01).collect();
    times.push(36.4);
    let values: Vec<f64> = (0..times.len())
        .map(|k| {
            if k + 1 == times.len() {
                0.0
            } else {
                (0.37 * k as f64).sin()
            }
        })
        .collect();
    let r = Accelerogram::new(times.clone(), values.clone(), 1.7).unwrap();
    for j in 0..20_000 {
        let t = 36.4 * j as f64 / 20_000.0;
        let k = times.partition_point(|&x| x <= t).clamp(1, times.len() - 1);
        let w = (t - times[k - 1]) / (times[k] - times[k - 1]);
        let expected = 1.7 * (values[k - 1] + w * (values[k] - values[k - 1]));
        assert!(
            (r.at(t) - expected).abs() <= 1e-15 * 1.7 + 1e-15 * expected.abs(),
            "t = {t}"
        );
        assert_eq!(r.segment(t), k);
    }
    assert_eq!(r.at(times[5]), 1.7 * values[5]);
}

/// A value looked up from a hint ([`Accelerogram::at_from`]) is the
/// value itself, bit for bit, whatever the hint: at every sample, inside
/// segments, before and after the record, walking forward as a run does
/// (a step's stages, its end on the next sample) and jumping about.
#[test]
fn a_hinted_record_value_is_the_value() {
    let mut times: Vec<f64> = (0..500).map(|k| k as f64 * 0.01).collect();
    times.push(7.3);
    let values: Vec<f64> = (0..times.len()).map(|k| (0.37 * k as f64).sin()).collect();
    let r = Accelerogram::new(times.clone(), values, 1.7).unwrap();
    let mut hint = 0;
    let stages = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0];
    for k in 0..times.len() - 1 {
        for c in stages {
            let t = times[k] + c * (times[k + 1] - times[k]);
            assert_eq!(
                r.at_from(t, &mut hint).to_bits(),
                r.at(t).to_bits(),
                "t = {t}"
            );
        }
    }
    let mut seed = 3u64;
    for _ in 0..20_000 {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let u = (seed >> 11) as f64 / (1u64 << 53) as f64;
        let t = if seed % 7 == 0 {
            times[(seed >> 20) as usize % times.len()]
        } else {
            9.0 * u - 1.0
        };
        if seed % 5 == 0 {
            hint = (seed >> 30) as usize % (times.len() + 3);
        }
        assert_eq!(
            r.at_from(t, &mut hint).to_bits(),
            r.at(t).to_bits(),
            "t = {t}"
        );
    }
}

/// The rigid limits of a row built at once (a copy where a contact is
/// like the one before) are those built one by one: the walls' reduced
/// mass is the body's, the pairs' half of it, and a soft contact has none.
/// They are built once for a model and its clones, again where a clone's
/// contacts change.
#[test]
fn rigid_laws_at_once_equal_those_built_one_by_one() {
    let m = Model::row(
        4,
        0.227,
        12.0,
        0.04,
        1e-3,
        law(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap()
    .with_all_impacts(Impacts::Rigid { restitution: None })
    .unwrap()
    .with_impacts(2, Impacts::Soft)
    .unwrap();
    let laws = m.rigid_laws().unwrap();
    assert_eq!(laws.len(), 5);
    for (k, law) in laws.iter().enumerate() {
        let alone = m.rigid_law(k).unwrap();
        assert_eq!(law.is_some(), k != 2, "contact {k}");
        let (Some(law), Some(alone)) = (law, alone) else {
            continue;
        };
        let mu = if k == 0 || k == 4 { 0.227 } else { 0.1135 };
        assert!((law.reduced_mass() - mu).abs() < 1e-15, "contact {k}");
        assert_eq!(law.reduced_mass(), alone.reduced_mass(), "contact {k}");
        for u in [1e-3, 0.1, 2.0] {
            let (a, b) = (law.impact(u).unwrap(), alone.impact(u).unwrap());
            assert_eq!(a.restitution, b.restitution, "contact {k}, U {u}");
            assert_eq!(a.impulse, b.impulse, "contact {k}, U {u}");
        }
    }
    // Built once for the model and its clones (a reforced model shares
    // them); a clone whose contacts change builds its own.
    let same = |a: &Model, b: &Model| {
        let (a, b) = (a.rigid_laws().unwrap(), b.rigid_laws().unwrap());
        std::sync::Arc::ptr_eq(a[0].as_ref().unwrap(), b[0].as_ref().unwrap())
    };
    let base = BaseExcitation::Harmonic {
        amplitude: 0.05,
        frequency: 7.0,
        phase: 0.0,
    };
    assert!(same(&m, &m.reforced(base).unwrap()));
    let newton = m
        .clone()
        .with_impacts(
            0,
            Impacts::Rigid {
                restitution: Some(0.5),
            },
        )
        .unwrap();
    assert!(!same(&m, &newton));
    assert_eq!(
        newton.rigid_laws().unwrap()[0]
            .as_ref()
            .unwrap()
            .impact(0.1)
            .unwrap()
            .restitution,
        0.5
    );
    let other = crate::contact::ContactLaw::exponential_from_ratio(
        0.6,
        2.6e5,
        1.0,
        crate::contact::ForceForm::Published,
    )
    .unwrap();
    let harder = m.clone().with_contact_law(other);
    let [e, e_harder] = [&m, &harder].map(|m| {
        m.rigid_laws().unwrap()[0]
            .as_ref()
            .unwrap()
            .impact(0.1)
            .unwrap()
            .restitution
    });
    assert!(!same(&m, &harder));
    assert_eq!(
        e_harder,
        harder
            .rigid_law(0)
            .unwrap()
            .unwrap()
            .impact(0.1)
            .unwrap()
            .restitution
    );
    assert_ne!(e, e_harder);
}
