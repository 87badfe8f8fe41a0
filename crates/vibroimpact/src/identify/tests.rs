//! Tests of the identification (`mod.rs`).

use super::*;
use crate::impact::closed_form::peak_force_dimensionless;

/// Deterministic pseudo-noise, uniform in [-1, 1) (SplitMix64 hash).
fn noise(i: usize) -> f64 {
    let mut z = (i as u64).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

fn velocities() -> Vec<f64> {
    (0..25).map(|i| 0.02 * 1.12f64.powi(i)).collect()
}

fn bodies() -> TwoBodies {
    crate::model::reference::seed_bodies()
}

fn accel(u: f64, q: f64, alpha: f64) -> f64 {
    peak_force_dimensionless(u / q).unwrap() * 0.5 * alpha * q * q
}

#[test]
fn exact_data_recover_a_over_b_and_alpha() {
    let (q, alpha) = (1.2, 1.3e5);
    let r: Vec<_> = velocities()
        .iter()
        .map(|&u| RestitutionSample {
            impact_velocity: u,
            restitution: restitution(u / q).unwrap(),
        })
        .collect();
    let fit = fit_a_over_b(&r).unwrap();
    assert!(
        (fit.a_over_b.value - q).abs() < 1e-10 * q,
        "{:?}",
        fit.a_over_b
    );
    let a: Vec<_> = velocities()
        .iter()
        .map(|&u| AccelerationSample {
            impact_velocity: u,
            peak_acceleration: accel(u, q, alpha),
        })
        .collect();
    let fa = fit_alpha(&a, bodies(), fit.a_over_b.value).unwrap();
    assert!((fa.alpha.value - alpha).abs() < 1e-8 * alpha);
    // Accelerations alone reach V up to ~0.3 here: enough curvature to
    // identify both from exact data.
    let j = fit_joint(&[], &a, bodies()).unwrap();
    assert!((j.a_over_b.value - q).abs() < 1e-6 * q, "{:?}", j.a_over_b);
    assert!((j.alpha.value - alpha).abs() < 1e-6 * alpha);
}

/// Large data sets: the coarse grid runs on 2000 spread samples, the
/// fit on all 50 000 (noisy, 1 %): the estimates agree with the truth
/// within three standard errors, which shrink like 1/sqrt(n).
#[test]
fn large_data_sets_fit_all_samples() {
    let (q, alpha) = (1.2, 1.3e5);
    let n = 50_000;
    let u = |i: usize| 0.02 * (30.0f64).powf(i as f64 / n as f64);
    let r: Vec<_> = (0..n)
        .map(|i| RestitutionSample {
            impact_velocity: u(i),
            restitution: restitution(u(i) / q).unwrap() * (1.0 + 0.01 * noise(i)),
        })
        .collect();
    let a: Vec<_> = (0..n)
        .map(|i| AccelerationSample {
            impact_velocity: u(i),
            peak_acceleration: accel(u(i), q, alpha) * (1.0 + 0.01 * noise(n + i)),
        })
        .collect();
    let j = fit_joint(&r, &a, bodies()).unwrap();
    for (est, truth) in [(j.a_over_b, q), (j.alpha, alpha)] {
        assert!(est.std_error < 1e-3 * truth, "{est:?}");
        assert!(
            (est.value - truth).abs() < 3.0 * est.std_error,
            "{est:?} vs {truth}"
        );
    }
    assert_eq!(j.acceleration_residuals.len(), n);
}

#[test]
fn noisy_data_give_estimates_within_their_errors() {
    let (q, alpha) = (1.2, 1.3e5);
    let r: Vec<_> = velocities()
        .iter()
        .enumerate()
        .map(|(i, &u)| RestitutionSample {
            impact_velocity: u,
            restitution: restitution(u / q).unwrap() + 0.01 * noise(i),
        })
        .collect();
    let a: Vec<_> = velocities()
        .iter()
        .enumerate()
        .map(|(i, &u)| AccelerationSample {
            impact_velocity: u,
            peak_acceleration: accel(u, q, alpha) * (1.0 + 0.05 * noise(i + 100)),
        })
        .collect();
    let fit = fit_a_over_b(&r).unwrap();
    let e = fit.a_over_b;
    assert!(e.std_error > 0.0 && e.std_error < 0.2 * q);
    assert!((e.value - q).abs() < 3.0 * e.std_error, "{e:?}");
    assert!(
        (fit.residual_std - 0.01 / 3f64.sqrt()).abs() < 0.004,
        "{}",
        fit.residual_std
    );
    let fa = fit_alpha(&a, bodies(), e.value).unwrap();
    assert!(
        (fa.alpha.value - alpha).abs() < 0.1 * alpha,
        "{:?}",
        fa.alpha
    );
    let j = fit_joint(&r, &a, bodies()).unwrap();
    assert!(
        (j.a_over_b.value - q).abs() < 3.0 * j.a_over_b.std_error,
        "{:?}",
        j.a_over_b
    );
    assert!(
        (j.alpha.value - alpha).abs() < 3.0 * j.alpha.std_error + 0.05 * alpha,
        "{:?}",
        j.alpha
    );
    assert!(j.correlation.abs() <= 1.0);
    assert_eq!(j.restitution_residuals.len(), r.len());
}

#[test]
fn unidentifiable_and_invalid_data_are_reported() {
    let elastic: Vec<_> = (1..5)
        .map(|i| RestitutionSample {
            impact_velocity: 0.1 * i as f64,
            restitution: 1.0,
        })
        .collect();
    assert!(matches!(
        fit_a_over_b(&elastic),
        Err(IdentifyError::NotIdentifiable(_))
    ));
    let one = [RestitutionSample {
        impact_velocity: 0.1,
        restitution: 0.9,
    }];
    assert!(matches!(
        fit_a_over_b(&one),
        Err(IdentifyError::TooFewPoints {
            got: 1,
            need: 2,
            ..
        })
    ));
    let bad = [
        RestitutionSample {
            impact_velocity: 0.1,
            restitution: 0.9,
        },
        RestitutionSample {
            impact_velocity: -0.1,
            restitution: 0.9,
        },
    ];
    assert!(matches!(
        fit_a_over_b(&bad),
        Err(IdentifyError::InvalidSample { index: 1, .. })
    ));
    let zero_acc = [
        AccelerationSample {
            impact_velocity: 0.1,
            peak_acceleration: 1.0,
        },
        AccelerationSample {
            impact_velocity: 0.2,
            peak_acceleration: 0.0,
        },
    ];
    assert!(matches!(
        fit_alpha(&zero_acc, bodies(), 1.2),
        Err(IdentifyError::InvalidSample { index: 1, .. })
    ));
}

/// Issue 38: three identical restitution points gave a/b with a standard
/// error of 1e-15 ("0.00 %"). Repeats of one point fix a/b but not its
/// uncertainty: refused, saying how many distinct points there are; two
/// distinct points fit. The same for the acceleration points of α.
#[test]
fn repeated_points_do_not_give_a_standard_error() {
    let point = |u: f64, e: f64| RestitutionSample {
        impact_velocity: u,
        restitution: e,
    };
    let same = vec![point(0.1, 0.5); 3];
    let e = fit_a_over_b(&same).unwrap_err().to_string();
    assert!(
        e.contains("the 3 restitution points hold 1 distinct (impact velocity, value) pair; give 2 distinct points at least"),
        "{e}"
    );
    let two = vec![point(0.1, 0.5), point(0.1, 0.5), point(0.3, 0.45)];
    let fit = fit_a_over_b(&two).unwrap();
    assert!(fit.a_over_b.std_error > 0.0, "{:?}", fit.a_over_b);
    let a = AccelerationSample {
        impact_velocity: 0.1,
        peak_acceleration: 300.0,
    };
    let e = fit_alpha(&[a; 3], bodies(), 1.2).unwrap_err().to_string();
    assert!(e.contains("acceleration points hold 1 distinct"), "{e}");
}
