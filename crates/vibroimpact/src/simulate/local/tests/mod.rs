//! The local integrator against the global one and against exact
//! solutions (here), and with hysteretic storeys (`storeys.rs`).

use super::*;
use crate::contact::{ContactLaw, ForceForm};
use crate::model::reference::NATURAL_FREQUENCY as W0;
use crate::model::{Accelerogram, Impacts};

fn r2(n: usize, omega: f64) -> Model {
    crate::model::reference::r2(n, 1e-3, omega).unwrap()
}

fn run(model: &Model, t_end: f64, rtol: f64, integrator: Integrator) -> Simulation {
    let sim = simulate(
        model,
        &SimulationOptions {
            t_end,
            rtol,
            atol: rtol * 1e-3,
            integrator,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    sim
}

/// `examples/fujita-row-n2.toml`.
fn example_row() -> Model {
    crate::model::file::ModelDocument::from_toml(
        include_str!("../../../../../../examples/fujita-row-n2.toml"),
        "fujita-row-n2.toml",
    )
    .unwrap()
    .build()
    .unwrap()
    .model
}

/// Two pounding storeys under a `duration`-second record (a 9 rad/s burst
/// at 3 s, 0.01 s samples), Lankarani–Nikravesh across a 2 cm gap.
fn pounding_pair(duration: f64) -> Model {
    let samples = (duration / 0.01).round() as usize;
    let times: Vec<f64> = (0..=samples).map(|k| 0.01 * k as f64).collect();
    let quake: Vec<f64> = times
        .iter()
        .map(|t| 3.0 * (-(t - 3.0) * (t - 3.0) / 4.0).exp() * (9.0 * t).sin())
        .collect();
    Model::new(
        vec![
            crate::model::Body::from_frequency("A", 2e5, 12.566, 0.05),
            crate::model::Body::from_frequency("B", 3e5, 6.0, 0.05),
        ],
        vec![],
        vec![crate::model::Contact {
            pair: crate::model::ContactPair::Bodies { left: 0, right: 1 },
            clearance: 0.02,
            law: ContactLaw::lankarani_nikravesh(2.75e9, 1.5, 0.65, 1e-3, ForceForm::Published)
                .unwrap(),
        }],
        BaseExcitation::Record(Accelerogram::new(times, quake, 1.0).unwrap()),
        vec![],
        vec![],
        vec![],
    )
    .unwrap()
}

/// Largest difference of two final states relative to the largest
/// displacement (u rows) and velocity (v rows) of the first.
pub(super) fn difference(a: &Simulation, b: &Simulation) -> f64 {
    let rel = |x: &[f64], y: &[f64]| {
        let scale = x.iter().fold(1e-300f64, |m, v| m.max(v.abs()));
        x.iter()
            .zip(y)
            .map(|(p, q)| (p - q).abs() / scale)
            .fold(0.0, f64::max)
    };
    rel(&a.final_displacement, &b.final_displacement).max(rel(&a.final_velocity, &b.final_velocity))
}

/// R2 (N = 3, 0.95 ω0, 5 periods) by the local integrator against SciPy's
/// DOP853 at rtol 1e-13 (the reference of
/// `r2_agrees_with_scipy_and_sundials`, which agrees with SUNDIALS' CVODE
/// to 6e-9): to 1e-6 at rtol 1e-10 and 1e-7 at rtol 1e-13, the global
/// integrator's bounds. (This motion is irregular: the error of one run
/// scatters between 2e-10 and 6e-7 with the rtol, in both integrators.)
#[test]
fn r2_by_the_local_integrator_agrees_with_scipy() {
    let scipy = crate::model::reference::R2_N3_SCIPY;
    let omega = 0.95 * W0;
    let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
    for (rtol, tol) in [(1e-10, 1e-6), (1e-13, 1e-7)] {
        let sim = run(&r2(3, omega), t_end, rtol, Integrator::Local);
        let scale = scipy.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = sim
            .final_state()
            .iter()
            .zip(scipy)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
            / scale;
        assert!(err < tol, "rtol {rtol}: error {err:e} against SciPy");
        assert_eq!(sim.local.unwrap().bodies_integrated(), 3);
    }
}

/// The examples' rows and the pounding pair under a record: the local
/// integrator logs the same impacts (count, and start times to 1e-6 s) and
/// ends in the same state as the global one at rtol 1e-10, to 1e-5 of the
/// state's size.
#[test]
fn local_matches_global_on_the_examples() {
    let row = example_row();
    let t_row = 10.0 * 2.0 * std::f64::consts::PI / row.forcing_frequency().unwrap();
    let pair = pounding_pair(10.0);
    for (model, t_end) in [(row, t_row), (pair, 10.0)] {
        let global = run(&model, t_end, 1e-10, Integrator::Global);
        let local = run(&model, t_end, 1e-10, Integrator::Local);
        assert!(!global.impacts.is_empty());
        assert_eq!(global.impacts.len(), local.impacts.len());
        for (g, l) in global.impacts.iter().zip(&local.impacts) {
            assert_eq!(g.contact, l.contact);
            assert!((g.start_time - l.start_time).abs() < 1e-6, "{g:?} {l:?}");
            assert!(
                (g.peak_force - l.peak_force).abs() < 1e-5 * g.peak_force,
                "{g:?} {l:?}"
            );
        }
        let d = difference(&global, &local);
        assert!(d < 1e-5, "{d:e}");
    }
}

/// Exact extrema over a window: the local integrator's (the set's steps
/// on its dense output, the exact motion on its own grid) equal the global
/// integrator's at rtol 1e-10, every |u|, |v| to 1e-6 of the largest and
/// every contact's impact margin to 1e-6 of its clearance: the example
/// row, soft and rigid (to its first episode, 1.0145 s), a spring-coupled
/// pair beside a single body (harmonic base; one wall never reached), a
/// pounding pair under a record, and R2 N = 3 with gaps never closed
/// (scanned at the run's end alone); windows from the start and inside.
#[test]
fn extrema_match_the_global_integrator() {
    use crate::model::{Body, Contact, ContactPair, Coupling};
    let row = example_row();
    let t_row = 2.0 * std::f64::consts::PI / row.forcing_frequency().unwrap();
    let hertz = || ContactLaw::hertz(1e7, 1.5).unwrap();
    let coupled = Model::new(
        vec![
            Body::from_frequency("a", 0.2, 9.0, 0.02),
            Body::from_frequency("b", 0.3, 7.0, 0.02),
            Body::from_frequency("c", 0.25, 12.0, 0.02),
        ],
        vec![Coupling {
            a: 0,
            b: 1,
            stiffness: 5.0,
            damping: 0.05,
        }],
        vec![
            Contact {
                pair: ContactPair::Bodies { left: 1, right: 2 },
                clearance: 1e-3,
                law: hertz(),
            },
            Contact {
                pair: ContactPair::LeftWall { body: 0 },
                clearance: 1.5e-3,
                law: hertz(),
            },
            // Never reached: its margin comes from the exact motion alone.
            Contact {
                pair: ContactPair::RightWall { body: 2 },
                clearance: 0.05,
                law: hertz(),
            },
        ],
        BaseExcitation::Harmonic {
            amplitude: 0.4,
            frequency: 8.0,
            phase: 0.0,
        },
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    let pair = pounding_pair(6.0);
    // No contact ever near: the exact motion's references never move, and
    // its extrema are scanned at the end of the run alone.
    let linear = crate::model::reference::r2(3, 1.0, 0.9 * W0).unwrap();
    let t_linear = 3.0 * 2.0 * std::f64::consts::PI / (0.9 * W0);
    let rigid = Impacts::Rigid { restitution: None };
    for (model, t_end) in [
        (row.clone().with_all_impacts(rigid).unwrap(), 1.0),
        (row, 6.0 * t_row),
        (coupled, 6.0),
        (pair, 6.0),
        (linear, t_linear),
    ] {
        for window in [(0.0, t_end), (0.37 * t_end, 0.81 * t_end)] {
            let extrema = |integrator, output_step| {
                let sim = simulate(
                    &model,
                    &SimulationOptions {
                        t_end,
                        rtol: 1e-10,
                        atol: 1e-13,
                        extrema_window: Some(window),
                        output_step,
                        integrator,
                        ..Default::default()
                    },
                )
                .unwrap();
                assert!(sim.error.is_none(), "{:?}", sim.error);
                sim.extrema.unwrap()
            };
            let g = extrema(Integrator::Global, None);
            let l = extrema(Integrator::Local, None);
            // Samples (under a record they move the exact groups' references)
            // change no extremum.
            let sampled = extrema(Integrator::Local, Some(t_end / 457.0));
            for (a, b) in [
                (&g.max_displacement, &l.max_displacement),
                (&g.max_velocity, &l.max_velocity),
                (&g.max_displacement, &sampled.max_displacement),
                (&g.max_velocity, &sampled.max_velocity),
            ] {
                let scale = a.iter().fold(0.0f64, |m, x| m.max(*x));
                assert!(scale > 0.0);
                for (x, y) in a.iter().zip(b) {
                    assert!((x - y).abs() <= 1e-6 * scale, "{window:?}: {a:?} vs {b:?}");
                }
            }
            for (k, (x, y)) in g.impact_margin.iter().zip(&l.impact_margin).enumerate() {
                let c = model.contacts()[k].clearance;
                assert!(
                    (x - y).abs() <= 1e-6 * c.max(x.abs()),
                    "{window:?}: contact {k}: {x:e} vs {y:e}"
                );
            }
        }
    }
}

/// Random well-formed rows (every law, walls or not, 1–4 bodies), one
/// forcing period each: at rtol 1e-13 the local integrator ends where the
/// global one does (to 1e-6 of the state); at rtol 1e-10 it logs the same
/// impacts as the global one, and its error against the rtol-1e-13
/// solution is no larger than the global one's, in the median over the
/// cases (single cases scatter: a run of impacts amplifies an error by up
/// to 1e4 here, in both integrators).
#[test]
fn local_matches_global_on_random_rows() {
    let mut seed = 0x9e3779b97f4a7c15u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut compared = 0;
    let (mut local_errors, mut global_errors) = (Vec::new(), Vec::new());
    for case in 0..40 {
        let form = if next() < 0.5 {
            ForceForm::Published
        } else {
            ForceForm::NonNegative
        };
        let stiffness = 10f64.powf(6.0 + 3.0 * next());
        let law = match case % 5 {
            0 => ContactLaw::exponential_from_ratio(1.0, 1e5 * (1.0 + next()), 1.2, form),
            1 => ContactLaw::hertz(stiffness, 1.0 + next()),
            2 => ContactLaw::kelvin_voigt(stiffness, 10.0 * next(), form),
            3 => ContactLaw::hunt_crossley(stiffness, 1.5, next(), form),
            _ => ContactLaw::lankarani_nikravesh(stiffness, 1.5, 0.3 + 0.6 * next(), 1e-3, form),
        }
        .unwrap();
        let omega = 5.0 + 10.0 * next();
        let model = Model::row(
            1 + case % 4,
            0.1 + next(),
            0.0,
            0.0,
            1e-3,
            law,
            (next() < 0.8, next() < 0.8),
            BaseExcitation::None,
        )
        .unwrap();
        let n = model.bodies().len();
        let bodies: Vec<crate::model::Body> = model
            .bodies()
            .iter()
            .map(|b| {
                crate::model::Body::from_frequency(
                    &b.name,
                    b.mass,
                    omega * (0.8 + 0.4 * next()),
                    0.02 * next(),
                )
            })
            .collect();
        let base = BaseExcitation::Harmonic {
            amplitude: 0.2 + next(),
            frequency: omega * (0.7 + 0.6 * next()),
            phase: next(),
        };
        let model = Model::new(
            bodies,
            vec![],
            model.contacts().to_vec(),
            base,
            vec![],
            vec![0.0; n],
            (0..n).map(|_| 0.05 * (next() - 0.5)).collect(),
        )
        .unwrap();
        let t_end = 2.0 * std::f64::consts::PI / omega;
        let fine = run(&model, t_end, 1e-13, Integrator::Global);
        let fine_local = run(&model, t_end, 1e-13, Integrator::Local);
        let d = difference(&fine, &fine_local);
        assert!(d < 1e-6, "case {case}: {d:e}");
        let global = run(&model, t_end, 1e-10, Integrator::Global);
        let local = run(&model, t_end, 1e-10, Integrator::Local);
        assert_eq!(global.impacts.len(), local.impacts.len(), "case {case}");
        compared += global.impacts.len();
        global_errors.push(difference(&fine, &global));
        local_errors.push(difference(&fine, &local));
    }
    assert!(compared > 40, "{compared} impacts compared");
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (l, g) = (median(&mut local_errors), median(&mut global_errors));
    assert!(l <= 2.0 * g, "median error: local {l:e}, global {g:e}");
}

/// A body that only just reaches the wall (a peak penetration of 1e-12
/// of the gap, a force far above the negligible level) is caught: the bound
/// holds over the whole interval, not only where it is sampled.
#[test]
fn a_grazing_contact_is_never_missed() {
    let gap = 1e-3;
    for depth in [1e-8, 1e-6, 1e-4] {
        let law = ContactLaw::hertz(1e10, 1.5).unwrap();
        let w = 7.0;
        // Undamped, unforced: u = A sin(w t), A = gap (1 + depth).
        let amplitude = gap * (1.0 + depth);
        let model = Model::new(
            vec![crate::model::Body::from_frequency("p", 1.0, w, 0.0)],
            vec![],
            vec![crate::model::Contact {
                pair: crate::model::ContactPair::RightWall { body: 0 },
                clearance: gap,
                law,
            }],
            BaseExcitation::None,
            vec![],
            vec![0.0],
            vec![amplitude * w],
        )
        .unwrap();
        let t_end = 3.0 * 2.0 * std::f64::consts::PI / w;
        let global = run(&model, t_end, 1e-10, Integrator::Global);
        let local = run(&model, t_end, 1e-10, Integrator::Local);
        assert_eq!(global.impacts.len(), 3, "depth {depth}");
        assert_eq!(local.impacts.len(), 3, "depth {depth}: {:?}", local.impacts);
    }
}

/// Two identical bodies shaken by the same base: their difference is a
/// free oscillator, so the contact between them is judged by its energy
/// for all time. Short of the gap (by 1e-3 of it) the contact is checked
/// once and never again, with no impact (and none by the global
/// integrator); a difference that just reaches the gap (1e-8 beyond it)
/// is caught three times, as the global integrator catches it.
#[test]
fn bodies_that_move_alike_are_judged_by_their_difference() {
    let gap = 1e-3;
    let w = 7.0;
    let t_end = 3.0 * 2.0 * std::f64::consts::PI / w;
    for (reach, impacts) in [(1.0 - 1e-3, 0), (1.0 + 1e-8, 3)] {
        // Undamped: Δ = A sin(w t) with A = reach · gap, from the
        // velocity of the left body alone.
        let model = Model::new(
            vec![
                crate::model::Body::from_frequency("a", 1.0, w, 0.0),
                crate::model::Body::from_frequency("b", 1.0, w, 0.0),
            ],
            vec![],
            vec![crate::model::Contact {
                pair: crate::model::ContactPair::Bodies { left: 0, right: 1 },
                clearance: gap,
                law: ContactLaw::hertz(1e10, 1.5).unwrap(),
            }],
            BaseExcitation::Harmonic {
                amplitude: 0.5,
                frequency: 5.0,
                phase: 0.0,
            },
            vec![],
            vec![0.0, 0.0],
            vec![reach * gap * w, 0.0],
        )
        .unwrap();
        let global = run(&model, t_end, 1e-10, Integrator::Global);
        let local = run(&model, t_end, 1e-10, Integrator::Local);
        assert_eq!(global.impacts.len(), impacts, "reach {reach}");
        assert_eq!(
            local.impacts.len(),
            impacts,
            "reach {reach}: {:?}",
            local.impacts
        );
        let checks = local.local.as_ref().unwrap().contact_checks;
        if impacts == 0 {
            assert_eq!(checks, 1, "reach {reach}");
            assert!(difference(&global, &local) < 1e-9, "reach {reach}");
        }
    }
}

/// The energy audit by the local integrator: the balance closes to the
/// tolerance as the global integrator's does, and each term (work of the
/// base, the dampers' and the contacts' dissipation) is the global
/// integrator's to its tolerance, on R2 N = 3 under harmonic forcing (the
/// free motion's terms by quadrature, the set's integrated) and on the
/// pounding pair under a record (panels ending at the samples).
#[test]
fn the_energy_audit_closes_as_the_global_one() {
    let omega = 0.95 * W0;
    let period = 2.0 * std::f64::consts::PI / omega;
    for (name, model, t_end, rtol) in [
        ("R2 N = 3", r2(3, omega), 3.0 * period, 1e-10),
        ("pounding pair", pounding_pair(6.0), 6.0, 1e-8),
    ] {
        let opts = |integrator| SimulationOptions {
            t_end,
            rtol,
            atol: rtol * 1e-4,
            energy: true,
            integrator,
            ..Default::default()
        };
        let global = simulate(&model, &opts(Integrator::Global)).unwrap();
        let local = simulate(&model, &opts(Integrator::Local)).unwrap();
        assert!(global.error.is_none() && local.error.is_none(), "{name}");
        let (g, l) = (global.energy.unwrap(), local.energy.unwrap());
        let scale = g.input_work.abs().max(g.contact_dissipation).max(g.initial);
        assert!(
            l.contact_dissipation > 0.0 && l.damping_dissipation > 0.0,
            "{name}"
        );
        assert!(
            l.residual().abs() < 100.0 * rtol * scale,
            "{name}: residual {:e} of {scale:e}",
            l.residual()
        );
        for (a, b) in [
            (g.input_work, l.input_work),
            (g.damping_dissipation, l.damping_dissipation),
            (g.contact_dissipation, l.contact_dissipation),
            (g.mechanical, l.mechanical),
        ] {
            assert!((a - b).abs() < 1e4 * rtol * scale, "{name}: {a} vs {b}");
        }
    }
}

/// The struck Hertzian chain in sonic vacuum: the beads the wave has not
/// reached are never evaluated, and the motion is the same (to the last
/// bit) whether 800 more beads rest beyond them or not.
#[test]
fn bodies_at_rest_are_never_evaluated() {
    let chain = |n: usize| crate::model::reference::struck_chain(n, 1.0).unwrap();
    let opts = SimulationOptions {
        t_end: 2e-3,
        integrator: Integrator::Local,
        ..Default::default()
    };
    let short = simulate(&chain(200), &opts).unwrap();
    let long = simulate(&chain(1000), &opts).unwrap();
    assert!(short.error.is_none() && long.error.is_none());
    let evaluations = &long.local.as_ref().unwrap().body_evaluations;
    let reached = evaluations.iter().rposition(|&e| e > 0).unwrap();
    assert!(
        (40..150).contains(&reached),
        "the wave reached bead {reached}"
    );
    assert!(evaluations[reached + 1..].iter().all(|&e| e == 0));
    assert!(long.final_velocity[reached + 1..].iter().all(|&v| v == 0.0));
    assert_eq!(short.final_displacement[..], long.final_displacement[..200]);
    assert_eq!(short.final_velocity[..], long.final_velocity[..200]);
    assert_eq!(short.impacts.len(), long.impacts.len());
    assert!(long.local.unwrap().largest_set < 20);
}

/// A model without an exact free motion (an undamped body forced at its
/// natural frequency) is refused by the local integrator with the body's
/// name.
#[test]
fn what_the_local_integrator_cannot_do_is_refused() {
    let model = crate::model::Model::new(
        vec![crate::model::Body::from_frequency("p9", 1.0, 5.0, 0.0)],
        vec![],
        vec![],
        BaseExcitation::Harmonic {
            amplitude: 0.1,
            frequency: 5.0,
            phase: 0.0,
        },
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    let opts = SimulationOptions {
        integrator: Integrator::Local,
        ..Default::default()
    };
    let e = simulate(&model, &opts).unwrap_err();
    assert!(e.0.contains("p9"), "{e}");
}

/// Checks that crawl end the run and name their contact: a stiff body
/// (ω0 = 2e4 rad/s, 1 mm amplitude) beside a wall 2 mm away is checked
/// several times a period; with a step limit of 100 the projected 10⁶
/// checks are taken for a crawl. The error names that contact, not the
/// deepest one (a slow body resting 0.1 mm from its wall).
#[test]
fn crawling_checks_name_their_contact() {
    let contact = |body| Contact {
        pair: ContactPair::RightWall { body },
        clearance: 2e-3,
        law: ContactLaw::hertz(1e9, 1.5).unwrap(),
    };
    let model = Model::new(
        vec![
            Body::from_frequency("slow", 1.0, 0.01, 0.01),
            Body::from_frequency("fast", 1.0, 2e4, 0.0),
        ],
        vec![],
        vec![contact(0), contact(1)],
        BaseExcitation::None,
        vec![],
        vec![1.9e-3, 1e-3],
        vec![0.0, 0.0],
    )
    .unwrap();
    let sim = simulate(
        &model,
        &SimulationOptions {
            t_end: 100.0,
            max_steps: 100,
            // (Implicit: an explicit method is refused for so stiff a body
            // within 100 steps before the run starts.)
            method: Method::Rodas,
            integrator: Integrator::Local,
            ..Default::default()
        },
    )
    .unwrap();
    let e = sim.error.expect("a crawl");
    assert!(
        matches!(e.source, IntegrationError::ChecksCrawl { .. }),
        "{e}"
    );
    assert_eq!(e.contact.as_deref(), Some("fast|wall"), "{e}");
    assert!(e.to_string().contains("fast|wall"), "{e}");
    assert!(sim.final_time < 100.0);
}

/// The example's struck chain (examples/granular-chain.toml, sonic
/// vacuum): a solitary wave forms whose speed scales as the 1/5 power of
/// its peak particle velocity (Nesterenko, *Dynamics of Heterogeneous
/// Materials*, 2001, §1.2), to 1 % over striker velocities 1 and 0.1 m/s,
/// and which is five beads wide: as its peak passes a bead, the velocities
/// are 0.009, 0.33, 1, 0.32, 0.009 of the peak over five beads and below
/// 1e-5 beyond (counted above 1e-3).
#[test]
fn nesterenko_solitary_wave_in_the_granular_chain() {
    let chain = crate::model::file::ModelDocument::from_toml(
        include_str!("../../../../../../examples/granular-chain.toml"),
        "granular-chain.toml",
    )
    .unwrap()
    .build()
    .unwrap()
    .model;
    let n = chain.bodies().len();
    assert_eq!(chain.initial_velocity()[0], 1.0);
    assert!(chain.initial_velocity()[1..].iter().all(|&v| v == 0.0));
    let dt = 1e-6;
    // (speed in beads per second, peak velocity, width in beads)
    let wave = |striker: f64| {
        let mut v0 = vec![0.0; n];
        v0[0] = striker;
        let model = chain.clone().with_initial_state(vec![], v0).unwrap();
        let t_end = 0.004 / striker.powf(0.2);
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end,
                output_step: Some(dt),
                integrator: Integrator::Local,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(sim.error.is_none(), "{:?}", sim.error);
        let samples = sim.times.len();
        let v = |k: usize, i: usize| sim.states[k * 2 * n + n + i];
        // The time of bead i's largest velocity, refined by a parabola.
        let peak = |i: usize| {
            let k = (1..samples - 1)
                .max_by(|&a, &b| v(a, i).total_cmp(&v(b, i)))
                .unwrap();
            let (a, b, c) = (v(k - 1, i), v(k, i), v(k + 1, i));
            let shift = 0.5 * (a - c) / (a - 2.0 * b + c);
            (sim.times[k] + shift * dt, b - 0.25 * (a - c) * shift)
        };
        let (t30, _) = peak(30);
        let (t80, vm) = peak(80);
        // The width when the peak is at bead 60.
        let (t60, vm60) = peak(60);
        let k60 = (t60 / dt).round() as usize;
        let width = (0..n).filter(|&i| v(k60, i) > 1e-3 * vm60).count();
        (50.0 / (t80 - t30), vm, width)
    };
    let (c1, v1, w1) = wave(1.0);
    let (c2, v2, w2) = wave(0.1);
    let ratio = (c1 / c2) / (v1 / v2).powf(0.2);
    assert!(
        (ratio - 1.0).abs() < 0.01,
        "speed ratio / velocity ratio^(1/5) = {ratio}"
    );
    // The peak is a fixed part of the striker's velocity (a solitary wave
    // of the same shape), and about five beads move.
    assert!((v1 / v2 / 10.0 - 1.0).abs() < 0.01, "{v1} {v2}");
    assert_eq!((w1, w2), (5, 5));
}

/// Sampled histories equal the global integrator's at every sample, for
/// every body, also while some bodies move exactly and others are
/// integrated: R2 N = 3 (harmonic) and a row of four under a record (the
/// exact motion sample by sample), 1e-5 of the motion at rtol 1e-10 (a
/// sample taken from a later reference state would be off by 1e-3).
#[test]
fn histories_match_the_global_integrator() {
    let times: Vec<f64> = (0..=300).map(|k| 0.01 * k as f64).collect();
    let quake: Vec<f64> = times
        .iter()
        .map(|t| 2.0 * (7.0 * t).sin() * (-t).exp())
        .collect();
    let record = BaseExcitation::Record(Accelerogram::new(times, quake, 1.0).unwrap());
    let row4 = crate::model::reference::r2(4, 1e-3, W0)
        .unwrap()
        .with_base(record);
    let omega = 0.95 * W0;
    for (model, t_end) in [
        (r2(3, omega), 2.0 * 2.0 * std::f64::consts::PI / omega),
        (row4, 3.0),
    ] {
        let runs: Vec<Simulation> = [Integrator::Global, Integrator::Local]
            .into_iter()
            .map(|integrator| {
                simulate(
                    &model,
                    &SimulationOptions {
                        t_end,
                        rtol: 1e-10,
                        atol: 1e-13,
                        output_step: Some(t_end / 500.0),
                        integrator,
                        ..Default::default()
                    },
                )
                .unwrap()
            })
            .collect();
        let (g, l) = (&runs[0], &runs[1]);
        assert!(g.error.is_none() && l.error.is_none());
        assert!(!g.impacts.is_empty());
        assert_eq!(g.times, l.times);
        let scale = g.states.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let worst = g
            .states
            .iter()
            .zip(&l.states)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-5 * scale, "{worst:e} of {scale:e}");
        assert!(l.local.as_ref().unwrap().set_changes > 2);
    }
}

/// The first check of every contact at t = 0 is not taken for a crawl: a
/// chain of 150 000 beads (more first checks than the pace test's period)
/// runs to the end.
#[test]
fn a_long_chain_is_not_taken_for_a_crawl() {
    let model = crate::model::reference::struck_chain(150_000, 1.0).unwrap();
    let opts = SimulationOptions {
        t_end: 2e-4,
        integrator: Integrator::Local,
        ..Default::default()
    };
    let sim = simulate(&model, &opts).unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    assert!(sim.local.unwrap().bodies_integrated() < 20);
}

pub(super) mod storeys;

/// Clusters of a long row step side by side, each with its own step, and
/// end where the global run ends: R2 N = 100 at 0.95 ω0 over 5 periods
/// (before its motion turns chaotic; 1.3e-7 of the state apart), the same
/// 694 impacts, logged in time order.
#[test]
fn clusters_step_side_by_side_and_end_where_the_global_run_ends() {
    let omega = 0.95 * W0;
    let model = r2(100, omega);
    let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
    let global = run(&model, t_end, 1e-10, Integrator::Global);
    let local = run(&model, t_end, 1e-10, Integrator::Local);
    let stats = local.local.clone().unwrap();
    // (16 at once here.)
    assert!(stats.most_sets >= 8, "{stats:?}");
    let d = difference(&global, &local);
    assert!(d < 1e-6, "{d:e}");
    assert_eq!(global.impacts.len(), local.impacts.len());
    assert!(local
        .impacts
        .windows(2)
        .all(|w| w[0].start_time <= w[1].start_time));
    // The history, sampled from the sets' open steps and the exact motion:
    // every displacement within 1e-6 of the largest (6e-8 here).
    let sampled = |integrator| {
        let opts = SimulationOptions {
            t_end,
            rtol: 1e-10,
            atol: 1e-13,
            output_step: Some(0.005),
            integrator,
            ..Default::default()
        };
        simulate(&model, &opts).unwrap()
    };
    let (g, l) = (sampled(Integrator::Global), sampled(Integrator::Local));
    assert_eq!(g.times, l.times);
    let n = model.bodies().len();
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for (a, b) in g.states.chunks(2 * n).zip(l.states.chunks(2 * n)) {
        for i in 0..n {
            worst = worst.max((a[i] - b[i]).abs());
            largest = largest.max(a[i].abs());
        }
    }
    assert!(worst < 1e-6 * largest, "{worst:e} of {largest:e}");
}

/// A set whose stepping fails names its bodies: R2 N = 100 with a limit
/// of 200 steps stops inside a cluster of a few of them; the global run's
/// failure names none (it integrates them all).
#[test]
fn a_failing_set_names_its_bodies() {
    let omega = 0.95 * W0;
    let model = r2(100, omega);
    let opts = |integrator| SimulationOptions {
        t_end: 5.0 * 2.0 * std::f64::consts::PI / omega,
        max_steps: 200,
        integrator,
        ..Default::default()
    };
    let local = simulate(&model, &opts(Integrator::Local)).unwrap();
    let failure = local.error.expect("the step limit");
    assert!(
        matches!(failure.source, IntegrationError::TooManySteps { .. }),
        "{failure}"
    );
    assert!((1..100).contains(&failure.cluster.len()), "{failure}");
    let names: Vec<&str> = model.bodies().iter().map(|b| b.name.as_str()).collect();
    assert!(failure.cluster.iter().all(|c| names.contains(&c.as_str())));
    assert!(
        failure.to_string().contains(&format!(
            "the failing set integrated {}",
            failure.cluster.join(", ")
        )),
        "{failure}"
    );
    let global = simulate(&model, &opts(Integrator::Global)).unwrap();
    assert!(global.error.expect("the step limit").cluster.is_empty());
}
