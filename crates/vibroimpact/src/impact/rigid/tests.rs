//! The rigid limit's restitution against direct integration of each soft
//! law, closed forms and finite differences.

use super::*;
use crate::impact::closed_form;

fn soft(law: &ContactLaw, mu: f64, u: f64) -> DirectImpact {
    direct(law, mu, u).unwrap()
}

/// Whether the map's de/dU is its central difference's, to 1e-6 and the
/// difference's rounding (e to 2e-16 over the step).
fn slope_agrees(rigid: &RigidLaw, u: f64) -> bool {
    let h = 1e-5 * u;
    let e = |u| rigid.impact(u).unwrap().restitution;
    let fd = (e(u + h) - e(u - h)) / (2.0 * h);
    let slope = rigid.impact(u).unwrap().restitution_slope;
    let ok = (slope - fd).abs() <= 1e-6 * fd.abs() + 2e-16 / h;
    if !ok {
        eprintln!("U = {u}: slope {slope}, differences {fd}");
    }
    ok
}

/// The exponential law: e is seed eq. (10) at V = U/(a/b) whatever α (the
/// soft impact integrated at α × 1 and × 1000 gives it to 1e-9), with the
/// closed form's slope and peak force; the duration estimate is the soft
/// impact's (η = 1e-3) to 1e-7 inside the table and out.
#[test]
fn the_exponential_law_gives_seed_eq_10() {
    let mu = 0.7;
    for alpha in [1.3e4, 1.3e7] {
        let law = ContactLaw::exponential(2.0, 0.5, alpha, ForceForm::Published).unwrap();
        let rigid = RigidLaw::new(&law, mu, None).unwrap();
        for u in [1e-5, 0.03, 1.0, 7.0, 40.0, 600.0] {
            let r = rigid.impact(u).unwrap();
            let e = closed_form::restitution(u / 4.0).unwrap();
            assert_eq!(r.restitution, e);
            let d = soft(&law, mu, u);
            assert!(
                (d.restitution - e).abs() < 1e-9,
                "{u}: {} {e}",
                d.restitution
            );
            assert!(slope_agrees(&rigid, u));
            assert!((r.peak_force / d.peak_force - 1.0).abs() < 1e-8);
            assert!(
                (r.duration / d.contact_duration - 1.0).abs() < 1e-7,
                "{u}: {} {}",
                r.duration,
                d.contact_duration
            );
            // (1 − e²) loses digits to cancellation where e → 1: 1e-9.
            let energy = 0.5 * mu * u * u * (1.0 - e * e);
            assert!((r.energy_lost / energy - 1.0).abs() < 1e-9);
            assert!((r.impulse / (mu * (1.0 + e) * u) - 1.0).abs() < 1e-15);
        }
    }
}

/// Hunt–Crossley: e, the peak force and the duration are the soft impact's
/// to 1e-9 (e) and 1e-8 (the estimates) over χU from 1e-8 to 1e3, through
/// the table and both asymptotes, for two exponents and masses; the slope
/// is the differences'; small χU gives 1 − (2/3)χU.
#[test]
fn hunt_crossley_is_a_function_of_chi_u() {
    for (n, k, chi, mu) in [(1.5, 3e9, 0.4, 0.02), (1.0, 7e5, 2.5, 30.0)] {
        let law = ContactLaw::hunt_crossley(k, n, chi, ForceForm::Published).unwrap();
        let rigid = RigidLaw::new(&law, mu, None).unwrap();
        for x in [
            1e-8, 3e-7, 1e-6, 2e-5, 0.013, 0.5, 1.0, 3.7, 42.0, 100.0, 250.0, 1e3,
        ] {
            let u = x / chi;
            let r = rigid.impact(u).unwrap();
            let d = soft(&law, mu, u);
            assert!(
                (r.restitution - d.restitution).abs() < 1e-9,
                "n {n} x {x}: {} {}",
                r.restitution,
                d.restitution
            );
            if x >= 1e-6 {
                assert!((r.peak_force / d.peak_force - 1.0).abs() < 1e-8, "x {x}");
                assert!(
                    (r.duration / d.contact_duration - 1.0).abs() < 1e-8,
                    "x {x}: {} {}",
                    r.duration,
                    d.contact_duration
                );
            }
            assert!(slope_agrees(&rigid, u), "x {x}");
        }
        let u = 1e-7 / chi;
        let r = rigid.impact(u).unwrap();
        assert!((1.0 - r.restitution) / 1e-7 - 2.0 / 3.0 < 1e-6);
    }
}

/// Lankarani–Nikravesh: Hunt–Crossley with χ = 3(1 − e₀²)/(4 v₀): e is the
/// soft impact's to 1e-9, constant above v_min (slope 0), and near its
/// target e₀ (its derivation is first order in 1 − e₀: 0.913 for 0.9).
#[test]
fn lankarani_nikravesh_is_constant_above_its_floor() {
    let law = ContactLaw::lankarani_nikravesh(1e8, 1.5, 0.9, 0.01, ForceForm::Published).unwrap();
    let rigid = RigidLaw::new(&law, 0.5, None).unwrap();
    let e_above = rigid.impact(0.5).unwrap().restitution;
    for u in [0.001, 0.004, 0.02, 0.5, 3.0] {
        let r = rigid.impact(u).unwrap();
        let d = soft(&law, 0.5, u);
        assert!((r.restitution - d.restitution).abs() < 1e-9, "{u}");
        if u > 0.01 {
            assert_eq!(r.restitution, e_above);
            assert_eq!(r.restitution_slope, 0.0);
        } else {
            assert!(slope_agrees(&rigid, u));
        }
    }
    // (0.9132 measured for e₀ = 0.9.)
    assert!((e_above - 0.9).abs() < 0.02, "{e_above}");
}

/// Kelvin–Voigt (published): e = exp(−ζπ/√(1 − ζ²)) and the duration
/// π/ω_d, to 1e-10, at any U; ζ ≥ 1 (no separation) is refused; the
/// non-negative form separates earlier (larger e), as its integration.
#[test]
fn kelvin_voigt_has_the_damped_oscillators_restitution() {
    let (k, mu): (f64, f64) = (4e6, 2.0);
    let omega = (k / mu).sqrt();
    let zeta: f64 = 0.2;
    let c = 2.0 * zeta * (k * mu).sqrt();
    let law = ContactLaw::kelvin_voigt(k, c, ForceForm::Published).unwrap();
    let rigid = RigidLaw::new(&law, mu, None).unwrap();
    let wd = omega * (1.0 - zeta * zeta).sqrt();
    for u in [0.01, 3.0] {
        let r = rigid.impact(u).unwrap();
        let e = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        assert!((r.restitution - e).abs() < 1e-10);
        assert!((r.duration * wd / std::f64::consts::PI - 1.0).abs() < 1e-10);
        assert!((r.peak_force / soft(&law, mu, u).peak_force - 1.0).abs() < 1e-10);
    }
    let clamped = law.with_form(ForceForm::NonNegative);
    let r = RigidLaw::new(&clamped, mu, None)
        .unwrap()
        .impact(1.0)
        .unwrap();
    assert!((r.restitution - soft(&clamped, mu, 1.0).restitution).abs() < 1e-10);
    assert!(r.restitution > rigid.impact(1.0).unwrap().restitution);
    let over = ContactLaw::kelvin_voigt(k, 2.0 * (k * mu).sqrt(), ForceForm::Published).unwrap();
    let e = RigidLaw::new(&over, mu, None).unwrap_err().to_string();
    assert!(e.contains("never separates"), "{e}");
}

/// Hertz is elastic: e = 1, the peak force k L^n at the elastic maximum
/// L, and the duration 2 ∫₀¹ (1 − ξ^{n+1})^{-1/2} dξ · L/U, for n = 3/2
/// `2 √π Γ(7/5)/Γ(9/10) = 2.943275184324706` (Hertz's 2.94), to 1e-10.
#[test]
fn hertz_is_elastic() {
    let law = ContactLaw::hertz(7e9, 1.5).unwrap();
    let rigid = RigidLaw::new(&law, 0.0143, None).unwrap();
    for u in [0.1, 2.0] {
        let r = rigid.impact(u).unwrap();
        let l = law.length_scale(0.0143, u);
        assert_eq!(r.restitution, 1.0);
        assert_eq!(r.energy_lost, 0.0);
        assert!((r.peak_force / (7e9 * l.powf(1.5)) - 1.0).abs() < 1e-12);
        let tau = r.duration * u / l;
        assert!((tau / 2.943275184324706 - 1.0).abs() < 1e-10, "{tau}");
    }
}

/// A Newton coefficient replaces the law's e (slope 0) and keeps its
/// estimates; 0, above 1 and NaN are refused by name.
#[test]
fn a_newton_coefficient_replaces_the_laws() {
    let law = ContactLaw::hertz(1e6, 1.5).unwrap();
    let newton = RigidLaw::new(&law, 1.0, Some(0.8))
        .unwrap()
        .impact(2.0)
        .unwrap();
    let elastic = RigidLaw::new(&law, 1.0, None).unwrap().impact(2.0).unwrap();
    assert_eq!(newton.restitution, 0.8);
    assert_eq!(newton.restitution_slope, 0.0);
    assert_eq!(newton.peak_force, elastic.peak_force);
    assert!((newton.energy_lost - 0.5 * 4.0 * (1.0 - 0.64)).abs() < 1e-15);
    for bad in [0.0, 1.5, f64::NAN] {
        let e = RigidLaw::new(&law, 1.0, Some(bad)).unwrap_err().to_string();
        assert!(e.contains("restitution"), "{e}");
    }
    assert!(RigidLaw::new(&law, 1.0, None).unwrap().impact(0.0).is_err());
}

/// What the judging reads ([`RigidLaw::judging`]) is the impact's own
/// duration and rebound, bit for bit, for every kind of law (the seed's
/// inside its table and beyond it, Hunt–Crossley, Kelvin–Voigt, Hertz, a
/// Newton coefficient), and so is a period map's jump ([`RigidLaw::jump`]:
/// all but the peak force, which the seed's law leaves unsolved, also
/// under a Newton coefficient); a velocity of 0 is refused as by the
/// impact.
#[test]
fn the_judging_reads_the_impacts_own_values() {
    let laws = [
        (
            ContactLaw::exponential(2.0, 0.5, 1e5, ForceForm::Published).unwrap(),
            None,
        ),
        (
            ContactLaw::hunt_crossley(3e9, 1.5, 0.4, ForceForm::Published).unwrap(),
            None,
        ),
        (
            ContactLaw::kelvin_voigt(4e6, 1.0e3, ForceForm::Published).unwrap(),
            None,
        ),
        (ContactLaw::hertz(7e9, 1.5).unwrap(), None),
        (ContactLaw::hertz(7e9, 1.5).unwrap(), Some(0.8)),
        (
            ContactLaw::exponential(2.0, 0.5, 1e5, ForceForm::Published).unwrap(),
            Some(0.6),
        ),
    ];
    for (law, e) in laws {
        let rigid = RigidLaw::new(&law, 0.3, e).unwrap();
        for u in [1e-9, 3e-4, 0.02, 1.7, 400.0] {
            let r = rigid.impact(u).unwrap();
            let (duration, rebound) = rigid.judging(u).unwrap();
            assert_eq!(duration.to_bits(), r.duration.to_bits(), "{law:?} {u}");
            assert_eq!(
                rebound.to_bits(),
                r.rebound_velocity.to_bits(),
                "{law:?} {u}"
            );
            let jump = rigid.jump(u).unwrap();
            let seed = matches!(law.kind(), LawKind::Exponential { .. });
            assert_eq!(jump.peak_force.is_nan(), seed, "{law:?} {u}");
            let peak = if seed { r.peak_force } else { jump.peak_force };
            assert_eq!(
                RigidImpact {
                    peak_force: peak,
                    ..jump
                },
                r,
                "{law:?} {u}"
            );
        }
        assert!(rigid.judging(0.0).is_err());
        assert!(rigid.jump(0.0).is_err());
    }
}
