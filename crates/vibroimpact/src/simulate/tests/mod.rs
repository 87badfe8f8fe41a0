//! Tests of the global run.
//!
//! Files: `mod.rs` (soft contacts, records, outputs), `rigid.rs` (rigid
//! impacts against closed forms, docs/theory.md §12).
use super::*;
use crate::contact::{ContactLaw, ForceForm};
use crate::impact::closed_form::ExponentialImpact;
use crate::impact::TwoBodies;
use crate::model::{Body, Contact, ContactPair};

use crate::model::reference::NATURAL_FREQUENCY as W0;

use crate::model::reference::{r3_response as linear_exact, seed_law as law};

fn r2(n: usize, clearance: f64, omega: f64) -> Model {
    crate::model::reference::r2(n, clearance, omega).unwrap()
}

/// R3: clearances so large nothing touches; displacement equals the exact
/// steady state plus transient to 1e-9 relative.
/// A history that would exhaust memory is refused before anything runs.
#[test]
fn oversized_history_is_refused() {
    let model = Model::row(
        3,
        0.227,
        12.46,
        0.0437,
        1e-3,
        ContactLaw::hertz(1e9, 1.5).unwrap(),
        (true, true),
        BaseExcitation::None,
    )
    .unwrap();
    let opts = SimulationOptions {
        t_end: 1.0,
        output_step: Some(1e-9),
        ..SimulationOptions::default()
    };
    let e = simulate(&model, &opts).unwrap_err().to_string();
    assert!(e.starts_with("output step = 0.000000001 s over 1 s"), "{e}");
}

#[test]
fn r3_linear_limit_matches_exact_solution() {
    let omega = 0.95 * W0;
    let model = r2(3, 1e3, omega);
    let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
    let opts = SimulationOptions {
        t_end,
        rtol: 1e-12,
        atol: 1e-15,
        output_step: Some(t_end / 50.0),
        ..Default::default()
    };
    let sim = simulate(&model, &opts).unwrap();
    assert!(sim.error.is_none() && sim.impacts.is_empty());
    let scale = sim.states.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst: f64 = 0.0;
    for (j, &t) in sim.times.iter().enumerate() {
        let (u, v) = linear_exact(t, omega);
        for i in 0..3 {
            worst = worst.max((sim.states[j * 6 + i] - u).abs());
            worst = worst.max((sim.states[j * 6 + 3 + i] - v).abs() / W0);
        }
    }
    assert!(
        worst < 1e-9 * scale,
        "worst error {worst:e} vs scale {scale:e}"
    );
    assert_eq!(sim.contact_evaluations, 0, "no contact comes near");
}

/// Two free bodies reproduce the two-body impact relations (seed eqs.
/// 10, 16) in the impact log.
#[test]
fn two_free_bodies_reproduce_impact_relations() {
    for (m1, m2, u) in [(0.227, 0.227, 0.3), (0.1, 0.4, 1.5)] {
        let bodies = vec![
            Body {
                name: "a".into(),
                mass: m1,
                stiffness: 0.0,
                damping: 0.0,
            },
            Body {
                name: "b".into(),
                mass: m2,
                stiffness: 0.0,
                damping: 0.0,
            },
        ];
        let contacts = vec![Contact {
            pair: ContactPair::Bodies { left: 0, right: 1 },
            clearance: 1e-3,
            law: law(),
        }];
        let model = Model::new(
            bodies,
            vec![],
            contacts,
            BaseExcitation::None,
            vec![],
            vec![],
            vec![u, 0.0],
        )
        .unwrap();
        let opts = SimulationOptions {
            t_end: 3e-3 / u + 0.01,
            rtol: 1e-12,
            atol: 1e-16,
            ..Default::default()
        };
        let sim = simulate(&model, &opts).unwrap();
        assert_eq!(sim.impacts.len(), 1);
        let imp = &sim.impacts[0];
        let model_cf = ExponentialImpact::new(&law(), TwoBodies::new(m1, m2).unwrap()).unwrap();
        let cf = model_cf.impact(u).unwrap();
        // The law acts (weakly) before s_on: the velocity there is a
        // little below U; eq. (10) holds with the velocity at s_on.
        assert!(
            imp.impact_velocity < u && (imp.impact_velocity / u - 1.0).abs() < 1e-5,
            "{imp:?}"
        );
        let e_cf = model_cf.impact(imp.impact_velocity).unwrap().restitution;
        assert!(
            (imp.restitution() - e_cf).abs() < 1e-9,
            "e {} vs {e_cf}",
            imp.restitution()
        );
        assert!(
            (imp.peak_force / cf.peak_force - 1.0).abs() < 1e-8,
            "F {} vs {}",
            imp.peak_force,
            cf.peak_force
        );
        // Momentum is conserved exactly by the pairwise force.
        let p = m1 * sim.final_velocity[0] + m2 * sim.final_velocity[1];
        assert!((p - m1 * u).abs() < 1e-12);
    }
}

/// R2 (N = 3, 0.95 ω0, 5 periods) agrees with independent integrators:
/// SciPy `solve_ivp` DOP853 and SUNDIALS CVODE (Adams) at rtol 1e-13,
/// atol 1e-16 (bench/peers, results-2026-11-22.json; they agree with each
/// other to 6e-9), to 1e-6 at our rtol 1e-10 and to 1e-7 at rtol 1e-13.
#[test]
fn r2_agrees_with_scipy_and_sundials() {
    let scipy = crate::model::reference::R2_N3_SCIPY;
    let cvode: [f64; 6] = [
        0.00026822439317180995,
        5.387370300603941e-05,
        0.0006982749714192805,
        -0.009959292462598081,
        -0.003504186737318731,
        0.005716496834239027,
    ];
    let omega = 0.95 * W0;
    let model = r2(3, 1e-3, omega);
    let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
    for (rtol, tol) in [(1e-10, 1e-6), (1e-13, 1e-7)] {
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end,
                rtol,
                atol: rtol * 1e-3,
                ..Default::default()
            },
        )
        .unwrap();
        let y: Vec<f64> = sim.final_state();
        for reference in [scipy, cvode] {
            let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let err = y
                .iter()
                .zip(reference)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max)
                / scale;
            assert!(err < tol, "rtol {rtol}: error {err:e} against a peer");
        }
    }
}

/// RODAS (implicit) and automatic switching give the same R2 history as
/// DOP853.
#[test]
fn implicit_and_auto_methods_agree() {
    let omega = 0.95 * W0;
    let model = r2(3, 1e-3, omega);
    let t_end = 2.0 * 2.0 * std::f64::consts::PI / omega;
    let run = |method| {
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end,
                rtol: 1e-9,
                atol: 1e-12,
                method,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(sim.error.is_none());
        sim
    };
    let reference = run(Method::Dop853);
    for method in [Method::Rodas, Method::Auto] {
        let sim = run(method);
        for (a, b) in sim
            .final_displacement
            .iter()
            .zip(&reference.final_displacement)
        {
            assert!((a - b).abs() < 1e-6 * 1e-3, "{method:?}: {a} vs {b}");
        }
        assert_eq!(sim.impacts.len(), reference.impacts.len(), "{method:?}");
    }
}

/// A body pressed against a wall for a long time (constant base
/// acceleration of 100 m/s² toward it, a strongly damped contact,
/// a/b = 0.01 m/s): the contact is a stiff spring-dashpot (α F = 1.3e7
/// N/m and F/(a/b) = 1e4 N s/m on 1 kg, eigenvalues -1.5e3 and -8.5e3
/// 1/s). RODAS reaches the static equilibrium `a e^{α s} = m a_base` in a
/// small fraction of DOP853's steps, and automatic switching finds it.
#[test]
fn pressed_body_implicit_method_is_efficient() {
    let law = ContactLaw::exponential_from_ratio(0.01, 1.3e5, 1.0, ForceForm::Published).unwrap();
    let bodies = vec![Body {
        name: "b".into(),
        mass: 1.0,
        stiffness: 0.0,
        damping: 0.0,
    }];
    let contacts = vec![Contact {
        pair: ContactPair::RightWall { body: 0 },
        clearance: 1e-4,
        law,
    }];
    let base = BaseExcitation::Record(
        crate::model::Accelerogram::new(vec![0.0, 20.0], vec![-100.0, -100.0], 1.0).unwrap(),
    );
    let model = Model::new(bodies, vec![], contacts, base, vec![], vec![1e-4], vec![]).unwrap();
    let run = |method| {
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end: 10.0,
                rtol: 1e-8,
                atol: 1e-12,
                method,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(sim.error.is_none(), "{method:?}: {:?}", sim.error);
        sim
    };
    let s_eq = 1e-4 + (100.0f64).ln() / 1.3e5;
    let (dop, ros, auto) = (run(Method::Dop853), run(Method::Rodas), run(Method::Auto));
    for sim in [&dop, &ros, &auto] {
        assert_eq!(
            sim.impacts.len(),
            1,
            "one impact, engaged from the start: {:?}",
            &sim.impacts[..2.min(sim.impacts.len())]
        );
        assert_eq!(sim.impacts[0].start_time, 0.0);
        assert!(
            (sim.final_displacement[0] - s_eq).abs() < 1e-9,
            "{} vs {s_eq}",
            sim.final_displacement[0]
        );
    }
    assert!(
        ros.stats.steps * 20 < dop.stats.steps,
        "RODAS {} vs DOP853 {} steps",
        ros.stats.steps,
        dop.stats.steps
    );
    assert!(
        auto.stats.steps * 5 < dop.stats.steps,
        "auto {} vs DOP853 {} steps",
        auto.stats.steps,
        dop.stats.steps
    );
}

/// An integration that cannot finish keeps what it computed and says
/// where it stopped.
#[test]
fn failure_keeps_partial_results() {
    let omega = 0.95 * W0;
    let model = r2(3, 1e-3, omega);
    let opts = SimulationOptions {
        t_end: 5.0,
        max_steps: 300,
        output_step: Some(0.01),
        ..Default::default()
    };
    let sim = simulate(&model, &opts).unwrap();
    let err = sim.error.as_ref().expect("must stop early");
    assert!(sim.final_time > 0.0 && sim.final_time < 5.0);
    assert!(!sim.times.is_empty() && *sim.times.last().unwrap() <= sim.final_time);
    assert!(err.contact.is_some());
    assert!(err.to_string().contains("deepest contact"), "{err}");
}

/// Energy balance: W = ΔE + D_c + D_k to the integrator's tolerance, in
/// the seed's row with many impacts.
#[test]
fn energy_balance_with_impacts() {
    let omega = 0.95 * W0;
    let model = r2(3, 1e-3, omega);
    let t_end = 3.0 * 2.0 * std::f64::consts::PI / omega;
    for rtol in [1e-8, 1e-11] {
        let opts = SimulationOptions {
            t_end,
            rtol,
            atol: rtol * 1e-4,
            energy: true,
            ..Default::default()
        };
        let sim = simulate(&model, &opts).unwrap();
        assert!(sim.impacts.len() > 5, "{} impacts", sim.impacts.len());
        let e = sim.energy.unwrap();
        let scale = e.input_work.abs().max(e.contact_dissipation);
        assert!(e.contact_dissipation > 0.0 && e.damping_dissipation > 0.0);
        assert!(
            e.residual().abs() < 100.0 * rtol * scale,
            "rtol {rtol}: residual {:e} of {scale:e}",
            e.residual()
        );
    }
}

/// Impact log bookkeeping in the seed's row: ordered, every impact ends
/// after it starts with its peak inside. (Restitution is not bounded by
/// 1 here: springs and excitation act during a 10 ms contact, and slow
/// impacts can leave faster than they came.)
#[test]
fn impact_log_is_consistent() {
    let omega = 0.95 * W0;
    let model = r2(3, 1e-3, omega);
    let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
    let sim = simulate(
        &model,
        &SimulationOptions {
            t_end,
            rtol: 1e-9,
            atol: 1e-13,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(sim.error.is_none());
    for w in sim.impacts.windows(2) {
        assert!(w[0].start_time <= w[1].start_time);
    }
    for imp in sim.impacts.iter().filter(|i| i.complete()) {
        assert!(
            imp.end_time > imp.start_time
                && imp.peak_time >= imp.start_time
                && imp.peak_time <= imp.end_time
        );
        assert!(
            imp.impact_velocity > 0.0 && imp.rebound_velocity > 0.0 && imp.peak_force > 0.0,
            "{imp:?}"
        );
    }
}

/// Stiffness is met with a reason, not a grind: DOP853 on a body of
/// ω0 = 1e9 rad/s is refused up front naming the body and property, while
/// the automatic method runs it on RODAS throughout (the same result as
/// RODAS); an absurd contact damping (a/b = 1e-300) ends within the first
/// 100 000 steps (stiffness or no progress); a contact stiffer than the motion under DOP853 alone
/// (base amplitude 1e12) ends with the stiffness reason.
#[test]
fn stiff_models_end_early_with_the_reason() {
    let omega = 0.95 * W0;
    let opts = |method| SimulationOptions {
        t_end: 2.0 * std::f64::consts::PI / omega,
        method,
        ..SimulationOptions::default()
    };
    let rows = |n: usize, body: &crate::model::Body, law: ContactLaw, amplitude: f64| {
        let base = BaseExcitation::Harmonic {
            amplitude,
            frequency: omega,
            phase: 0.0,
        };
        Model::row(
            n,
            body.mass,
            body.stiffness,
            body.damping,
            1e-3,
            law,
            (true, true),
            base,
        )
        .unwrap()
    };
    let row =
        |body: crate::model::Body, law: ContactLaw, amplitude: f64| rows(2, &body, law, amplitude);
    let stiff = row(
        crate::model::Body::from_frequency("p", 0.227, 1e9, 0.013),
        law(),
        0.05,
    );
    let err = simulate(&stiff, &opts(Method::Dop853)).unwrap_err();
    assert!(
        err.0
            .contains("body p1 has sqrt(stiffness/mass) = 1.000e9 rad/s")
            && err.0.contains("rodas"),
        "{err}"
    );
    let auto = simulate(&stiff, &opts(Method::Auto)).unwrap();
    let rodas = simulate(&stiff, &opts(Method::Rodas)).unwrap();
    assert!(auto.error.is_none());
    assert_eq!(auto.final_displacement, rodas.final_displacement);
    assert!(auto.stats.steps < 10_000, "{:?}", auto.stats);

    let seed = crate::model::Body::from_frequency("p", 0.227, W0, 0.013);
    let absurd =
        ContactLaw::exponential_from_ratio(1e-300, 1.3e5, 1.0, ForceForm::Published).unwrap();
    // Either integrator (the local one judges its set's pace alike).
    for integrator in [Integrator::Global, Integrator::Local] {
        let o = SimulationOptions {
            integrator,
            ..opts(Method::Dop853)
        };
        let sim = simulate(&row(seed.clone(), absurd, 0.05), &o).unwrap();
        assert!(
            sim.stats.steps <= 100_000,
            "{integrator:?}: {:?}",
            sim.stats
        );
        match sim.error.map(|e| e.source) {
            Some(IntegrationError::NoProgress { .. } | IntegrationError::Stiff { .. }) => {}
            other => panic!("{integrator:?}: expected no progress or stiffness, got {other:?}"),
        }
    }
    // The same law on the three-pendulum row over five periods crawls
    // without a stiffness verdict: the progress check ends it.
    let model = rows(3, &seed, absurd, 0.05);
    let five = SimulationOptions {
        t_end: 5.0 * 2.0 * std::f64::consts::PI / omega,
        ..opts(Method::Dop853)
    };
    match simulate(&model, &five).unwrap().error.map(|e| e.source) {
        Some(IntegrationError::NoProgress {
            steps, projected, ..
        }) => {
            assert_eq!(steps, 100_000);
            assert!(projected > 1e100);
        }
        other => panic!("expected no progress, got {other:?}"),
    }
    let sim = simulate(&row(seed, law(), 1e12), &opts(Method::Dop853)).unwrap();
    match sim.error.map(|e| e.source) {
        Some(IntegrationError::Stiff {
            projected, limit, ..
        }) => {
            assert!(projected > limit as f64)
        }
        other => panic!("expected stiffness, got {other:?}"),
    }
}

/// `Integrator::Auto` is the local integrator from [`AUTO_LOCAL_GROUPS`]
/// groups up (the same bytes as asking for it) and the global one below,
/// where an undamped group is forced harmonically (its free motion may
/// have no steady state), or under a record unless the run's options are
/// those where the local one pays.
#[test]
fn auto_chooses_the_integrator_by_groups() {
    let auto = |m: &Model| Integrator::Auto.resolve(m);
    let large = r2(AUTO_LOCAL_GROUPS, 1e-3, 0.5 * W0);
    assert_eq!(auto(&r2(2, 1e-3, 0.95 * W0)), Integrator::Global);
    assert_eq!(
        auto(&r2(AUTO_LOCAL_GROUPS - 1, 1e-3, 0.5 * W0)),
        Integrator::Global
    );
    assert_eq!(auto(&large), Integrator::Local);
    assert_eq!(Integrator::Global.resolve(&large), Integrator::Global);
    assert_eq!(
        Integrator::Local.resolve(&r2(2, 1e-3, W0)),
        Integrator::Local
    );
    let harmonic = large.base().clone();
    let row = |groups: usize, base: BaseExcitation| {
        Model::row(groups, 0.227, 12.5, 0.0, 1e-3, law(), (true, true), base).unwrap()
    };
    let undamped = |base| row(AUTO_LOCAL_GROUPS, base);
    assert_eq!(auto(&undamped(harmonic)), Integrator::Global);
    assert_eq!(auto(&undamped(BaseExcitation::None)), Integrator::Local);
    // A record moves every group: global by the model alone (docs/
    // decisions.md D26); with the run's options local from 16 groups
    // without exact peaks, with DOP853 or DOPRI5 at rtol 1e-7 or tighter
    // (D41).
    let record = BaseExcitation::Record(
        crate::model::Accelerogram::new(vec![0.0, 0.01, 0.02], vec![0.0, 1.0, 0.0], 1.0).unwrap(),
    );
    let shaken = undamped(record.clone());
    assert_eq!(auto(&shaken), Integrator::Global);
    let smaller = row(AUTO_LOCAL_GROUPS - 1, record);
    let peaks = Some((0.0, 1.0));
    for (model, method, rtol, extrema_window, chosen) in [
        (&shaken, Method::Dop853, 1e-8, None, Integrator::Local),
        (&shaken, Method::Dop853, 1e-4, None, Integrator::Local),
        (&shaken, Method::Dopri5, 1e-7, None, Integrator::Local),
        (&shaken, Method::Dopri5, 1e-6, None, Integrator::Global),
        (&shaken, Method::Rodas, 1e-8, None, Integrator::Global),
        (&shaken, Method::Dop853, 1e-8, peaks, Integrator::Global),
        (&smaller, Method::Dop853, 1e-8, None, Integrator::Global),
    ] {
        let opts = SimulationOptions {
            method,
            rtol,
            extrema_window,
            ..SimulationOptions::default()
        };
        let got = Integrator::Auto.resolve_run(model, &opts);
        assert_eq!(got, chosen, "{method:?} {rtol:e} {extrema_window:?}");
        assert_eq!(
            Integrator::Global.resolve_run(model, &opts),
            Integrator::Global
        );
    }
    let chain = crate::model::reference::struck_chain(AUTO_LOCAL_GROUPS, 1.0).unwrap();
    assert_eq!(auto(&chain), Integrator::Local);
    let opts = |integrator| SimulationOptions {
        t_end: 2.0 * 2.0 * std::f64::consts::PI / (0.5 * W0),
        integrator,
        ..SimulationOptions::default()
    };
    let (a, l) = (
        simulate(&large, &opts(Integrator::Auto)).unwrap(),
        simulate(&large, &opts(Integrator::Local)).unwrap(),
    );
    assert!(a.local.is_some() && a.error.is_none());
    assert_eq!(a.final_displacement, l.final_displacement);
    assert_eq!(a.final_velocity, l.final_velocity);
    let g = simulate(&large, &opts(Integrator::Global)).unwrap();
    for (x, y) in a.final_displacement.iter().zip(&g.final_displacement) {
        assert!((x - y).abs() < 1e-8, "{x} against {y}");
    }
}

pub(crate) mod rigid;
