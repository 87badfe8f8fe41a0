//! Tests of the equations of motion (`mod.rs`).

use super::*;
use crate::integrate::{BandMatrix, RecordedJacobian};
use crate::model::{Body, Contact, ContactPair, Coupling};

use crate::model::reference::seed_law as law;

/// The right-hand side by hand for two bodies with a coupling, a contact
/// and base excitation.
#[test]
fn rhs_matches_hand_computation() {
    let bodies = vec![
        Body::from_frequency("a", 0.2, 7.0, 0.01),
        Body::from_frequency("b", 0.3, 5.0, 0.02),
    ];
    let couplings = vec![Coupling {
        a: 0,
        b: 1,
        stiffness: 3.0,
        damping: 0.1,
    }];
    let contacts = vec![Contact {
        pair: ContactPair::Bodies { left: 0, right: 1 },
        clearance: 1e-4,
        law: law(),
    }];
    let base = BaseExcitation::Harmonic {
        amplitude: 0.5,
        frequency: 6.0,
        phase: 0.3,
    };
    let model = Model::new(
        bodies.clone(),
        couplings,
        contacts,
        base,
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    let mut sys = ChainDynamics::new(&model, false);
    let y = [5e-5, 0.1, -2e-5, -0.05];
    let mut dy = [0.0; 4];
    let t = 0.7;
    sys.rhs(t, &y, &mut dy);
    let zdd = 0.5 * (6.0 * t + 0.3f64).sin();
    let s: f64 = 5e-5 + 2e-5 - 1e-4;
    // (a + b ṡ) e^{αs} with a = 1, b = 1/1.2, ṡ = 0.1 - (-0.05).
    let f = (1.0 + 0.15 / 1.2) * (1.3e5 * s).exp();
    let coupling = 3.0 * (-2e-5 - 5e-5) + 0.1 * (-0.05 - 0.1);
    let fa = -bodies[0].stiffness * 5e-5 - bodies[0].damping * 0.1 - 0.2 * zdd + coupling - f;
    let fb = -bodies[1].stiffness * -2e-5 - bodies[1].damping * -0.05 - 0.3 * zdd - coupling + f;
    assert_eq!(dy[0], 0.1);
    assert!((dy[1] - fa / 0.2).abs() < 1e-12 * (fa / 0.2).abs().max(1.0));
    assert!((dy[3] - fb / 0.3).abs() < 1e-12 * (fb / 0.3).abs().max(1.0));
    assert_eq!(sys.bandwidth(), (3, 2));
}

/// The time-only part of the right-hand side is the difference between
/// the forced and the unforced equations at any state (contacts
/// engaged), for a harmonic base and a harmonic force on one body.
#[test]
fn source_is_the_forced_minus_the_unforced_rhs() {
    let bodies = vec![
        Body::from_frequency("a", 0.2, 7.0, 0.01),
        Body::from_frequency("b", 0.3, 5.0, 0.02),
    ];
    let contacts = vec![Contact {
        pair: ContactPair::Bodies { left: 0, right: 1 },
        clearance: 1e-4,
        law: law(),
    }];
    let build = |base, forces| {
        Model::new(
            bodies.clone(),
            vec![],
            contacts.clone(),
            base,
            forces,
            vec![],
            vec![],
        )
        .unwrap()
    };
    let base = BaseExcitation::Harmonic {
        amplitude: 0.5,
        frequency: 6.0,
        phase: 0.3,
    };
    let force = crate::model::HarmonicForce {
        body: 1,
        amplitude: 0.2,
        frequency: 6.0,
        phase: -0.4,
    };
    let forced = build(base.clone(), vec![force]);
    let unforced = build(BaseExcitation::None, vec![]);
    assert!(forced.differs_only_in_forcing(&unforced));
    let (mut a, mut b) = (
        ChainDynamics::new(&forced, false),
        ChainDynamics::new(&unforced, false),
    );
    let y = [5e-5, 0.1, -2e-5, -0.05];
    let (mut fa, mut fb, mut q) = ([0.0; 4], [0.0; 4], [0.0; 4]);
    let t = 0.7;
    a.rhs(t, &y, &mut fa);
    b.rhs(t, &y, &mut fb);
    a.source(t, &mut q);
    let zdd = 0.5 * (6.0 * t + 0.3f64).sin();
    let by_hand = [0.0, -zdd, 0.0, -zdd + 0.2 * (6.0 * t - 0.4f64).sin() / 0.3];
    for i in 0..4 {
        assert!((fa[i] - fb[i] - q[i]).abs() < 1e-12, "component {i}");
        assert!((q[i] - by_hand[i]).abs() < 1e-15, "component {i}");
    }
    let mut stiffer = bodies.clone();
    stiffer[0].stiffness *= 1.01;
    let other = Model::new(
        stiffer,
        vec![],
        contacts.clone(),
        base,
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    assert!(!forced.differs_only_in_forcing(&other));
}

/// The analytic banded Jacobian equals central differences of the
/// right-hand side, with contacts engaged.
/// Three bodies between walls, coupled, their four contacts of two laws.
fn three_bodies() -> Model {
    let bodies = vec![
        Body::from_frequency("a", 0.2, 7.0, 0.01),
        Body::from_frequency("b", 0.3, 5.0, 0.02),
        Body::from_frequency("c", 0.25, 6.0, 0.03),
    ];
    let couplings = vec![Coupling {
        a: 0,
        b: 1,
        stiffness: 3.0,
        damping: 0.1,
    }];
    let contacts = vec![
        Contact {
            pair: ContactPair::LeftWall { body: 0 },
            clearance: 1e-5,
            law: law(),
        },
        Contact {
            pair: ContactPair::Bodies { left: 0, right: 1 },
            clearance: 1e-4,
            law: law(),
        },
        Contact {
            pair: ContactPair::Bodies { left: 1, right: 2 },
            clearance: 1e-5,
            law: ContactLaw::hertz(1e9, 1.5).unwrap(),
        },
        Contact {
            pair: ContactPair::RightWall { body: 2 },
            clearance: 1e-5,
            law: law(),
        },
    ];
    Model::new(
        bodies,
        couplings,
        contacts,
        BaseExcitation::None,
        vec![],
        vec![],
        vec![],
    )
    .unwrap()
}

/// Their state with every contact near or in touch: u = (-1e-5, 5e-5, 3e-5).
const IN_TOUCH: [f64; 6] = [-1.2e-5, 0.01, 6e-5, -0.02, 1e-5, 0.03];

#[test]
fn jacobian_matches_finite_differences() {
    let model = three_bodies();
    let mut sys = ChainDynamics::new(&model, false);
    let y = IN_TOUCH;
    let (kl, ku) = sys.jacobian_bandwidth().unwrap();
    let mut jac = BandMatrix::new(6, kl, ku);
    assert!(sys.jacobian(0.0, &y, &mut jac));
    let mut f0 = [0.0; 6];
    let mut f1 = [0.0; 6];
    for j in 0..6 {
        let h = if j % 2 == 0 { 1e-10 } else { 1e-7 };
        let mut yp = y;
        yp[j] += h;
        sys.rhs(0.0, &yp, &mut f1);
        let mut ym = y;
        ym[j] -= h;
        sys.rhs(0.0, &ym, &mut f0);
        for i in 0..6 {
            let fd = (f1[i] - f0[i]) / (2.0 * h);
            let an = if jac.in_band(i, j) {
                jac.get(i, j)
            } else {
                0.0
            };
            // Round-off of the differences scales with the row's largest entry.
            let row = (0..6)
                .filter(|&c| jac.in_band(i, c))
                .map(|c| jac.get(i, c).abs())
                .fold(1.0, f64::max);
            assert!(
                (an - fd).abs() <= 1e-6 * row,
                "J[{i}][{j}] = {an} vs {fd} (row scale {row:e})"
            );
        }
    }
}

/// A system without partials gives the same right-hand side, bit for bit,
/// and a Jacobian after it (evaluated afresh) equal to the one that kept
/// them; its recorded tangent entries too.
#[test]
fn a_system_without_partials_answers_as_one_with_them() {
    let model = three_bodies();
    let mut kept = ChainDynamics::new(&model, false);
    let mut bare = ChainDynamics::new(&model, false).without_partials();
    let (mut f_kept, mut f_bare) = ([0.0; 6], [0.0; 6]);
    kept.rhs(0.1, &IN_TOUCH, &mut f_kept);
    bare.rhs(0.1, &IN_TOUCH, &mut f_bare);
    assert_eq!(f_kept.map(f64::to_bits), f_bare.map(f64::to_bits));
    let (kl, ku) = kept.jacobian_bandwidth().unwrap();
    let (mut j_kept, mut j_bare) = (BandMatrix::new(6, kl, ku), BandMatrix::new(6, kl, ku));
    assert!(kept.jacobian_after_rhs(0.1, &IN_TOUCH, &mut j_kept));
    assert!(bare.jacobian_after_rhs(0.1, &IN_TOUCH, &mut j_bare));
    let mut in_touch = 0;
    for i in 0..6 {
        for j in (0..6).filter(|&j| j_kept.in_band(i, j)) {
            assert_eq!(j_kept.get(i, j), j_bare.get(i, j), "J[{i}][{j}]");
            in_touch += usize::from(i % 2 == 1 && j_kept.get(i, j) != 0.0);
        }
    }
    // (Not only the springs: the contacts' terms are there.)
    assert!(in_touch >= 8, "{in_touch} rate rows' entries");
    let (mut r_kept, mut r_bare) = (Vec::new(), Vec::new());
    kept.record_jacobian_after_rhs(&IN_TOUCH, &mut r_kept);
    bare.record_jacobian_after_rhs(&IN_TOUCH, &mut r_bare);
    r_kept.sort_by_key(|e| e.0);
    r_bare.sort_by_key(|e| e.0);
    assert_eq!(r_kept, r_bare);
    assert_eq!(r_kept.len(), 4);
}

/// A skipped contact's force is below 1e-3 ε of the force scale.
#[test]
fn far_contacts_are_skipped_only_when_negligible() {
    let base = BaseExcitation::Harmonic {
        amplitude: 0.05,
        frequency: 7.0,
        phase: 0.0,
    };
    let model = Model::row(2, 0.227, 12.46, 0.04, 1e-3, law(), (true, true), base).unwrap();
    let mut sys = ChainDynamics::new(&model, false);
    let mut dy = [0.0; 4];
    sys.rhs(0.0, &[0.0; 4], &mut dy);
    assert_eq!(
        sys.contact_evaluations(),
        0,
        "at rest every 1 mm gap is far"
    );
    let f_ref = 12.46 * 1e-3 + 0.227 * 0.05;
    // Scan s where contacts switch on: below the switch, the force is negligible.
    for &(s, sdot) in &[(-3.6e-4, 0.0), (-3.0e-4, 0.5), (-2e-4, -1.0)] {
        let skipped = ChainDynamics::skip(sys.contacts[0].screen, s, sdot);
        let f = law().force(s, sdot, 0.0).abs();
        if skipped {
            assert!(f < 1e-3 * f64::EPSILON * f_ref, "s={s}: F={f} skipped");
        }
    }
    assert!(!ChainDynamics::skip(sys.contacts[0].screen, -1e-4, 0.0));
}

/// The claim the switch screen rests on (simulate/switches): over a step
/// whose drift moves smoothly (here a sinusoid with ωh ≤ 1, the steps a
/// record's samples allow), a part of a storey's switch function
/// ([`StoreyTerms::switch_parts`]) positive at both ends and further from
/// zero there than twice its rate bound times the step
/// ([`StoreyTerms::switch_rate_bounds`], from the ends alone) stays
/// positive inside, at 200 points. IMK storeys (deteriorating, on and off
/// the backbone, along a growing cyclic history) and a bilinear one, on
/// both of its branches.
#[test]
fn a_switch_part_the_screen_passes_over_stays_positive_in_the_step() {
    use crate::model::hysteresis::{imk::Imk, Bilinear, StoreyLaw};
    use crate::model::Storey;
    use storeys::{Branch, StoreyTerms};
    let imk = Imk {
        stiffness: 1e7,
        yield_drift: 0.02,
        cap_ratio: 1.1,
        plastic_drift: 0.03,
        post_capping_drift: 0.1,
        residual_ratio: 0.3,
        ultimate_drift: 0.2,
        lambda: [0.5; 3],
        exponent: [1.0; 3],
    };
    let bilinear = Bilinear {
        stiffness: 1e7,
        yield_drift: 0.02,
        post_yield_ratio: 0.05,
    };
    let mut rand = crate::numeric::uniform(7);
    let (mut passed_over, mut cases) = (0, 0);
    let mut state = imk.rest();
    for j in 0..600 {
        let law = if j % 3 == 2 {
            StoreyLaw::Bilinear(bilinear)
        } else {
            StoreyLaw::Imk(imk)
        };
        let storey = Storey {
            below: None,
            above: 0,
            law,
            p_delta: 0.0,
        };
        let mut terms = StoreyTerms::new(&[storey], 2, &[0.0]);
        let anchor = match law {
            StoreyLaw::Imk(_) => {
                let reach = 0.16 * j as f64 / 600.0;
                imk.advance(&mut state, reach * (2.0 * rand() - 1.0));
                terms.set_branch(0, Branch::Imk(state));
                state.u
            }
            _ => {
                let d0 = 0.04 * (2.0 * rand() - 1.0);
                let z = if rand() < 0.5 { 0.02 } else { -0.02 };
                let branch = if rand() < 0.5 {
                    Branch::Elastic {
                        d0,
                        z0: z * rand(),
                        e0: 0.0,
                    }
                } else {
                    Branch::Plastic { z, d0, e0: 0.0 }
                };
                terms.set_branch(0, branch);
                d0
            }
        };
        for _ in 0..40 {
            let h = 1e-3 + 0.019 * rand();
            let w = rand() / h;
            let (amp, phase) = (0.05 * rand(), 2.0 * std::f64::consts::PI * rand());
            let start = anchor + 0.05 * (2.0 * rand() - 1.0);
            let at = |t: f64| {
                let x = w * t + phase;
                (
                    [start + amp * (x.sin() - phase.sin()), amp * w * x.cos()],
                    [amp * w * x.cos(), -amp * w * w * x.sin()],
                )
            };
            let ((y0, f0), (y1, f1)) = (at(0.0), at(h));
            let ends = [terms.switch_parts(0, &y0), terms.switch_parts(0, &y1)];
            let (ld, lr) = terms.switch_rate_bounds(0, (&y0, &f0), (&y1, &f1), h);
            for (which, rate) in [(0, ld), (1, lr)] {
                let part = |p: (f64, f64)| if which == 0 { p.0 } else { p.1 };
                let (g0, g1) = (part(ends[0]), part(ends[1]));
                if !(g0 > 0.0 && g1 > 0.0 && g0.is_finite()) {
                    continue;
                }
                cases += 1;
                if g0.min(g1) > 2.0 * rate * h {
                    passed_over += 1;
                    for i in 1..200 {
                        let t = h * i as f64 / 200.0;
                        let g = part(terms.switch_parts(0, &at(t).0));
                        assert!(
                            g > 0.0,
                            "{law:?}: part {g} at t = {t} of h = {h} (ends {g0}, {g1}, rate {rate})"
                        );
                    }
                }
            }
        }
    }
    // Both outcomes are exercised (about 3,900 of 14,000 passed over).
    assert!(
        passed_over > 2000 && passed_over < cases,
        "{passed_over} of {cases}"
    );
}
