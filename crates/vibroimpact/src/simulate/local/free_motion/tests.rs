use super::*;
use crate::model::{Accelerogram, Body, Coupling, HarmonicForce, Model};
use crate::simulate::{simulate, SimulationOptions};
use modal::Modal;
use nalgebra::DMatrix;

/// The model's state at `t_end` by the global integrator at a tight
/// tolerance, interleaved.
fn integrated(model: &Model, t_end: f64) -> Vec<f64> {
    let opts = SimulationOptions {
        t_end,
        rtol: 1e-13,
        atol: 1e-16,
        integrator: crate::simulate::Integrator::Global,
        ..SimulationOptions::default()
    };
    let sim = simulate(model, &opts).unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    let n = model.bodies().len();
    (0..n)
        .flat_map(|i| [sim.final_displacement[i], sim.final_velocity[i]])
        .collect()
}

/// The model's state at `t_end` by exact propagation from its initial
/// state in `pieces` equal steps, interleaved.
fn exact(model: &Model, t_end: f64, pieces: usize) -> Vec<f64> {
    let free = FreeMotion::new(model).unwrap();
    let n = model.bodies().len();
    let mut y = vec![0.0; 2 * n];
    for (g, group) in free.groups().iter().enumerate() {
        let mut x: Vec<f64> = group
            .bodies()
            .iter()
            .flat_map(|&i| [model.initial_displacement()[i], model.initial_velocity()[i]])
            .collect();
        for k in 0..pieces {
            let (t0, t1) = (
                t_end * k as f64 / pieces as f64,
                t_end * (k + 1) as f64 / pieces as f64,
            );
            free.propagate(g, t0, t1, &mut x);
        }
        for (j, &i) in group.bodies().iter().enumerate() {
            y[2 * i] = x[2 * j];
            y[2 * i + 1] = x[2 * j + 1];
        }
    }
    y
}

/// Largest difference relative to the largest displacement (rows u) and
/// velocity (rows v).
fn assert_close(a: &[f64], b: &[f64], tol: f64) {
    let scale = |k: usize| {
        a.iter()
            .skip(k)
            .step_by(2)
            .fold(1e-300f64, |m, x| m.max(x.abs()))
    };
    let (su, sv) = (scale(0), scale(1));
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        let s = if i % 2 == 0 { su } else { sv };
        assert!(
            (x - y).abs() <= tol * s,
            "component {i}: {x} vs {y} (scale {s:e})\n{a:?}\n{b:?}"
        );
    }
}

fn body(name: &str, mass: f64, omega0: f64, zeta: f64) -> Body {
    Body::from_frequency(name, mass, omega0, zeta)
}

fn free_model(
    bodies: Vec<Body>,
    couplings: Vec<Coupling>,
    base: BaseExcitation,
    forces: Vec<HarmonicForce>,
) -> Model {
    let n = bodies.len();
    let u0: Vec<f64> = (0..n).map(|i| 1e-3 * (i as f64 + 1.0)).collect();
    let v0: Vec<f64> = (0..n).map(|i| -2e-3 * (i as f64 - 0.5)).collect();
    Model::new(bodies, couplings, vec![], base, forces, u0, v0).unwrap()
}

/// Two bodies joined by a spring and a damper under `base`.
fn coupled_pair(base: BaseExcitation) -> Model {
    joined(
        [body("a", 1.0, 12.0, 0.02), body("b", 1.2, 9.0, 0.02)],
        (40.0, 0.3),
        base,
        vec![],
    )
}

/// `bodies` joined by a spring and a damper `(stiffness, damping)`, under
/// `base` and `forces`.
fn joined(
    bodies: [Body; 2],
    (stiffness, damping): (f64, f64),
    base: BaseExcitation,
    forces: Vec<HarmonicForce>,
) -> Model {
    let coupling = Coupling {
        a: 0,
        b: 1,
        stiffness,
        damping,
    };
    free_model(bodies.to_vec(), vec![coupling], base, forces)
}

fn harmonic(amplitude: f64, frequency: f64, phase: f64) -> BaseExcitation {
    BaseExcitation::Harmonic {
        amplitude,
        frequency,
        phase,
    }
}

/// Single bodies under every damping regime, with a harmonic base and a
/// harmonic force of another frequency: the closed form equals the
/// integrated motion to 1e-9 after several periods, in one step or in
/// many.
#[test]
fn single_bodies_in_every_damping_regime_match_integration() {
    for (omega0, zeta) in [
        (7.41, 0.013),
        (7.41, 0.0),
        (7.41, 1.0),
        (7.41, 3.0),
        (0.0, 0.0),
        (7.41, 0.9999999),
    ] {
        let mut b = body("p", 0.227, omega0, zeta);
        if omega0 == 0.0 {
            b.damping = 0.05;
        }
        let force = HarmonicForce {
            body: 0,
            amplitude: 0.01,
            frequency: 5.3,
            phase: 0.4,
        };
        let m = free_model(vec![b], vec![], harmonic(0.05, 6.0, 0.2), vec![force]);
        let reference = integrated(&m, 4.0);
        assert_close(&exact(&m, 4.0, 1), &reference, 1e-9);
        assert_close(&exact(&m, 4.0, 37), &reference, 1e-9);
    }
    // Free and undamped, unforced: exactly linear motion.
    let b = Body {
        name: "bead".into(),
        mass: 0.0286,
        stiffness: 0.0,
        damping: 0.0,
    };
    let m = free_model(vec![b], vec![], BaseExcitation::None, vec![]);
    let x = exact(&m, 2.5, 1);
    assert_eq!(x, vec![1e-3 + 2.5 * 1e-3, 1e-3]);
}

/// A group of three bodies joined by spring–dampers (non-proportional
/// damping), a harmonic base and a force on the middle body: the matrix
/// exponential's motion equals the integrated one to 1e-9.
#[test]
fn a_coupled_group_matches_integration() {
    let bodies = vec![
        body("a", 0.2, 7.0, 0.01),
        body("b", 0.3, 5.0, 0.05),
        body("c", 0.25, 0.0, 0.0),
    ];
    let couplings = vec![
        Coupling {
            a: 0,
            b: 1,
            stiffness: 3.0,
            damping: 0.1,
        },
        Coupling {
            a: 1,
            b: 2,
            stiffness: 8.0,
            damping: 0.0,
        },
    ];
    let force = HarmonicForce {
        body: 1,
        amplitude: 0.02,
        frequency: 9.0,
        phase: -0.3,
    };
    let m = free_model(bodies, couplings, harmonic(0.05, 6.5, 0.0), vec![force]);
    let free = FreeMotion::new(&m).unwrap();
    assert_eq!(free.groups().len(), 1);
    let reference = integrated(&m, 3.0);
    assert_close(&exact(&m, 3.0, 1), &reference, 1e-9);
    assert_close(&exact(&m, 3.0, 11), &reference, 1e-9);
}

/// A recorded accelerogram (linear between samples, zero before and after
/// the record), on a single body and a coupled pair, propagated across
/// many samples at once and in pieces that end between samples: equal to
/// the integration (stopped at every sample) to 1e-9.
#[test]
fn a_record_is_exact_under_first_order_hold() {
    let times: Vec<f64> = (0..200).map(|k| 0.1 + 0.01 * k as f64).collect();
    let values: Vec<f64> = times
        .iter()
        .map(|t| (7.0 * t).sin() + 0.5 * (23.0 * t).cos())
        .collect();
    let rec = BaseExcitation::Record(Accelerogram::new(times, values, 0.3).unwrap());
    let single = free_model(
        vec![body("p", 0.227, 7.41, 0.05)],
        vec![],
        rec.clone(),
        vec![],
    );
    let pair = coupled_pair(rec);
    for m in [single, pair] {
        let t_end = 2.09;
        let reference = integrated(&m, t_end);
        assert_close(&exact(&m, t_end, 1), &reference, 1e-9);
        assert_close(&exact(&m, t_end, 13), &reference, 1e-9);
    }
}

/// A record's times and values, 1.5 s at 0.01 s, with a free-vibration
/// tail appended as a pounding row's: 1.5 s, then 3 s.
fn record_with_a_tail() -> (Vec<f64>, Vec<f64>) {
    let mut times: Vec<f64> = (0..150).map(|k| 0.01 * k as f64).collect();
    let mut values: Vec<f64> = times.iter().map(|t| (8.0 * t).sin()).collect();
    times.extend([1.5, 3.0]);
    values.extend([0.0, 0.0]);
    (times, values)
}

/// A record with a free-vibration tail appended (one sample step down to
/// rest, then one long interval, as a pounding row's): its typical step is
/// the record's own, whole steps take the precomputed coefficients (modes,
/// and the matrix form for short runs), and the motion across the record
/// and the tail in pieces of one to five samples, each ending between
/// samples or on them, equals the integration to 1e-9.
#[test]
fn a_record_with_a_tail_keeps_its_whole_steps() {
    let (times, values) = record_with_a_tail();
    let near = |h: Option<f64>| h.is_some_and(|h| (h - 0.01).abs() < 1e-15);
    assert!(near(hold::typical_step(&times)));
    let rec = BaseExcitation::Record(Accelerogram::new(times, values, 0.4).unwrap());
    let m = coupled_pair(rec);
    let free = FreeMotion::new(&m).unwrap();
    let group = &free.groups()[0];
    let modal = group.modal.as_ref().expect("modes");
    assert!(near(modal.whole_step()));
    assert!(near(group.hold_step().map(|h| h.tau)));
    let reference = integrated(&m, 2.2);
    for pieces in [2200 / 5, 2200 / 3, 2200 / 2, 2200] {
        assert_close(&exact(&m, 2.2, pieces), &reference, 1e-9);
    }
    assert_close(&exact(&m, 2.2, 93), &reference, 1e-9);
}

/// The modal envelope of a drift and of a velocity bounds them over its
/// horizon: along the exact motion of a coupled pair under a record, from
/// several states and horizons (shorter and longer than the slow period),
/// every state on a fine grid is within `reach(H, F)` of rest, with F the
/// record's peak over the horizon; at H = 0 the envelope is Σ|w||z|, no
/// less than the quantity itself, and it grows with H.
#[test]
fn the_modal_envelope_bounds_the_motion_over_its_horizon() {
    let times: Vec<f64> = (0..400).map(|k| 0.01 * k as f64).collect();
    let values: Vec<f64> = times
        .iter()
        .map(|t| (9.0 * t).sin() + 0.6 * (13.0 * t).cos())
        .collect();
    let rec = BaseExcitation::Record(Accelerogram::new(times, values, 1.0).unwrap());
    let m = coupled_pair(rec);
    let free = FreeMotion::new(&m).unwrap();
    let drift = [(0usize, 1.0), (2usize, -1.0)];
    let speed = [(1usize, 1.0)];
    let mut tightest = f64::INFINITY;
    for (t0, x0) in [
        (0.0, [0.0, 0.0, 0.0, 0.0]),
        (0.37, [0.01, -0.2, -0.004, 0.1]),
        (1.5, [-0.002, 0.03, 0.006, 0.0]),
    ] {
        for horizon in [0.05, 0.3, 2.0] {
            let peak = free.base_peak(t0, t0 + horizon);
            for rows in [&drift[..], &speed[..]] {
                let q = |x: &[f64]| rows.iter().map(|&(r, c)| c * x[r]).sum::<f64>();
                let [envelope] = free.envelopes(0, &x0, [rows]).unwrap();
                let reach = envelope.reach(horizon, peak);
                assert!(q(&x0).abs() <= envelope.reach(0.0, peak) * (1.0 + 1e-12));
                assert!(envelope.reach(0.0, peak) <= reach);
                let mut largest = 0.0f64;
                for i in 1..=400 {
                    let mut x = x0.to_vec();
                    free.propagate(0, t0, t0 + horizon * i as f64 / 400.0, &mut x);
                    largest = largest.max(q(&x).abs());
                }
                assert!(
                    largest <= reach,
                    "t0 {t0}, H {horizon}: {largest} > {reach}"
                );
                tightest = tightest.min(reach / largest.max(1e-300));
            }
        }
    }
    // Not vacuous: somewhere the envelope is within a factor 3 of the motion.
    assert!(tightest < 3.0, "{tightest}");
}

/// The modal form against the matrix exponential of the augmented matrix:
/// a coupled pair's whole-sample, partial, tiny and long steps (both
/// branches of the φ functions) agree to 1e-12; a critically damped body
/// (a double eigenvalue) has no modal form, and under a record its
/// propagation by the exponential still matches the integration.
#[test]
fn modes_agree_with_the_matrix_exponential() {
    let pair = coupled_pair(BaseExcitation::None);
    let free = FreeMotion::new(&pair).unwrap();
    let a = FreeMotion::matrix(&free.groups()[0]);
    let modal = Modal::new(&a, Some(0.01)).unwrap();
    let x0 = [0.003, -0.02, -0.001, 0.05];
    for tau in [0.01, 0.0037, 1e-9, 0.5] {
        let (fa, slope) = (0.7, -30.0);
        let (phi, g0, g1) = hold::matrices(&a, tau);
        let (mut by_matrix, mut y) = (x0.to_vec(), vec![0.0; 4]);
        hold::step((&phi, &g0, &g1), fa, slope, &mut by_matrix, &mut y);
        let mut z = Vec::new();
        modal.to_modes(&x0, &mut z);
        modal.hold(tau, fa, slope, &mut z);
        let mut by_modes = vec![0.0; 4];
        modal.to_state(&z, &mut by_modes);
        assert_close(&by_modes, &by_matrix, 1e-12);
    }
    let critical = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -4.0, -4.0]);
    assert!(Modal::new(&critical, Some(0.01)).is_none());
    let times: Vec<f64> = (0..200).map(|k| 0.01 * k as f64).collect();
    let values: Vec<f64> = times.iter().map(|t| (9.0 * t).sin()).collect();
    let rec = BaseExcitation::Record(Accelerogram::new(times, values, 1.0).unwrap());
    // ω0 = 2 rad/s, ζ = 1.
    let m = free_model(vec![body("c", 0.5, 2.0, 1.0)], vec![], rec, vec![]);
    assert!(FreeMotion::new(&m).unwrap().groups()[0].modal.is_none());
    assert_close(&exact(&m, 1.2, 7), &integrated(&m, 1.2), 1e-9);
}

/// An undamped body forced at its natural frequency has no bounded steady
/// state: refused with its name.
#[test]
fn an_undamped_resonance_is_refused_by_name() {
    let m = free_model(
        vec![body("p7", 1.0, 5.0, 0.0)],
        vec![],
        harmonic(0.1, 5.0, 0.0),
        vec![],
    );
    let e = FreeMotion::new(&m).unwrap_err();
    assert!(e.to_string().contains("p7"), "{e}");
}

/// The bounds hold along an exact trajectory: √E grows at most by G per
/// second and every acceleration stays below the bound for that energy.
#[test]
fn energy_and_acceleration_bounds_hold() {
    let force = HarmonicForce {
        body: 0,
        amplitude: 0.3,
        frequency: 4.0,
        phase: 0.0,
    };
    let m = joined(
        [body("a", 0.2, 7.0, 0.01), body("b", 0.3, 5.0, 0.0)],
        (3.0, 0.1),
        harmonic(0.5, 6.0, 0.0),
        vec![force],
    );
    let free = FreeMotion::new(&m).unwrap();
    let g = &free.groups()[0];
    let mut x = vec![1e-3, 0.0, -2e-3, 0.01];
    let e0 = g.energy(&x);
    let growth = g.growth(0.5);
    let (mut t, dt) = (0.0, 1e-3);
    for _ in 0..3000 {
        free.propagate(0, t, t + dt, &mut x);
        t += dt;
        let bound = e0.sqrt() + growth * t;
        assert!(g.energy(&x).sqrt() <= bound, "t = {t}");
        // The acceleration from the equations of motion at (t, x).
        let zdd = 0.5 * (6.0 * t).sin();
        let acc_a = (-g.stiffness[0] * x[0] - g.damping[0] * x[1]
            + 3.0 * (x[2] - x[0])
            + 0.1 * (x[3] - x[1])
            + 0.3 * (4.0 * t).sin())
            / 0.2
            - zdd;
        assert!(
            acc_a.abs() <= g.acceleration_bound(0, bound * bound, 0.5),
            "t = {t}"
        );
    }
}

/// A record's peak over a stretch is the largest |z̈| of the samples that
/// bracket it: equal to a scan of those samples for 3000 stretches (within
/// a block, across many, reaching past the record's ends), and never below
/// the interpolant on a fine grid of the stretch.
#[test]
fn a_records_peak_over_a_stretch() {
    let times: Vec<f64> = (0..1000).map(|k| 0.5 + 0.01 * k as f64).collect();
    let values: Vec<f64> = times
        .iter()
        .map(|t| (3.0 * t).sin() * (0.7 * t * t).cos() + 0.3 * (41.0 * t).sin())
        .collect();
    let rec = Accelerogram::new(times.clone(), values, -0.8).unwrap();
    let model = free_model(
        vec![body("p", 1.0, 5.0, 0.05)],
        vec![],
        BaseExcitation::Record(rec.clone()),
        vec![],
    );
    let free = FreeMotion::new(&model).unwrap();
    let mut next = crate::numeric::uniform(7);
    for k in 0..3000 {
        let a = -0.5 + 11.5 * next();
        let len = [0.003, 0.05, 0.4, 12.0][k % 4] * next();
        let b = a + len;
        let scan = times
            .iter()
            .enumerate()
            .filter(|&(i, &t)| {
                (t >= a || times.get(i + 1).is_some_and(|&n| n > a))
                    && (t <= b || i == 0 || times[i - 1] < b)
            })
            .map(|(_, &t)| rec.at(t).abs())
            .fold(0.0f64, f64::max);
        let got = free.base_peak(a, b);
        let inside = a <= times[999] && b >= times[0];
        if inside {
            assert_eq!(got, scan, "[{a}, {b}]");
        }
        for j in 0..=50 {
            let t = a + len * j as f64 / 50.0;
            assert!(rec.at(t).abs() <= got, "[{a}, {b}] at {t}");
        }
    }
}

/// A storey's constant force sets the rest state: a body on a spring k
/// under a constant force F oscillates about F/k, u(t) = F/k + (u₀ − F/k)
/// cos ωt to 1e-12; a free pair under equal and opposite forces F rests
/// stretched by F/k (the least-squares rest), its centre moving on at its
/// own speed, and stays so; unbalanced forces on it are refused.
#[test]
fn constant_forces_set_the_rest_state() {
    let undamped = |name: &str, mass: f64, stiffness: f64| Body {
        name: name.into(),
        mass,
        stiffness,
        damping: 0.0,
    };
    let motion = |bodies: Vec<Body>, couplings: Vec<Coupling>| {
        let none = BaseExcitation::None;
        let model = Model::new(bodies, couplings, vec![], none, vec![], vec![], vec![]).unwrap();
        FreeMotion::new(&model).unwrap()
    };
    let mut free = motion(vec![undamped("m", 2.0, 50.0)], vec![]);
    free.set_rest(0, &[3.0]).unwrap();
    let (rest, w) = (3.0 / 50.0, 5.0f64);
    for t in [0.1, 1.3, 7.7] {
        let mut x = vec![0.01, 0.0];
        free.propagate(0, 0.0, t, &mut x);
        let u = rest + (0.01 - rest) * (w * t).cos();
        assert!((x[0] - u).abs() < 1e-12, "{} vs {u}", x[0]);
    }
    let coupling = Coupling {
        a: 0,
        b: 1,
        stiffness: 40.0,
        damping: 0.5,
    };
    let bodies = vec![undamped("a", 1.0, 0.0), undamped("b", 1.0, 0.0)];
    let mut free = motion(bodies, vec![coupling]);
    free.set_rest(0, &[-2.0, 2.0]).unwrap();
    let mut x = vec![-0.025, 0.3, 0.025, 0.3];
    free.propagate(0, 0.0, 2.0, &mut x);
    let want = [-0.025 + 0.6, 0.3, 0.025 + 0.6, 0.3];
    assert_close(&x, &want, 1e-12);
    assert!(free.set_rest(0, &[1.0, 1.0]).is_err());
}

/// A group given another branch's storey stiffness moves as a group whose
/// storey has that stiffness from the start: a two-storey frame with its
/// first storey at the post-yield stiffness (5 % of 4e7) under a record,
/// against a frame built with an elastic storey of 2e6 N/m, to 1e-12
/// over 1.3 s in pieces; its rest state under the same forces is set
/// again for the new stiffness; given back its initial stiffness it moves
/// exactly as before (the kept propagators).
#[test]
fn another_branchs_stiffness_moves_as_that_frame() {
    use crate::model::hysteresis::{Bilinear, StoreyLaw};
    use crate::simulate::local::tests::storeys::two_storey_frame;
    let bilinear = |k| {
        StoreyLaw::Bilinear(Bilinear {
            stiffness: k,
            yield_drift: 0.01,
            post_yield_ratio: 0.05,
        })
    };
    let frame = |first: StoreyLaw| {
        let times: Vec<f64> = (0..300).map(|k| 0.01 * k as f64).collect();
        let values: Vec<f64> = times.iter().map(|t| 3.0 * (5.0 * t).sin()).collect();
        let base = BaseExcitation::Record(Accelerogram::new(times, values, 1.0).unwrap());
        two_storey_frame([first, bilinear(3e7)], 2e5, base, Vec::new())
    };
    let yielding = frame(bilinear(4e7));
    let soft = frame(StoreyLaw::Elastic { stiffness: 2e6 });
    let mut free = FreeMotion::new(&yielding).unwrap();
    let fresh = FreeMotion::new(&soft).unwrap();
    let before = FreeMotion::new(&yielding).unwrap();
    let walk = |free: &FreeMotion| {
        let mut x = vec![0.01, -0.2, 0.015, 0.1];
        for k in 0..13 {
            free.propagate(0, 0.1 * k as f64, 0.1 * (k + 1) as f64, &mut x);
        }
        x
    };
    free.set_storey_stiffness(0, &[2e6, 3e7]).unwrap();
    assert_close(&walk(&free), &walk(&fresh), 1e-12);
    // The same forces at another stiffness: another rest state.
    free.set_rest(0, &[1e4, 0.0]).unwrap();
    let soft_rest = free.groups()[0].rest(0);
    free.set_storey_stiffness(0, &[4e7, 3e7]).unwrap();
    free.set_rest(0, &[1e4, 0.0]).unwrap();
    let stiff_rest = free.groups()[0].rest(0);
    assert!(
        (soft_rest / stiff_rest - 20.0).abs() < 1e-9,
        "{soft_rest} {stiff_rest}"
    );
    free.set_rest(0, &[0.0, 0.0]).unwrap();
    assert_eq!(walk(&free), walk(&before));
}

/// φ's series, cut where its table says, against the series summed
/// forward to 40 terms, and e^s, φ₁ from them against `exp`: to 5e-16
/// (a few roundings) from |s| = 1e-3 to 1, on and off the real axis.
#[test]
fn phi_series_to_rounding() {
    use nalgebra::Complex;
    for r in [
        1e-3, 0.009, 0.011, 0.09, 0.11, 0.24, 0.26, 0.49, 0.51, 0.99, 1.0,
    ] {
        for angle in [0.0, 1.0, 2.0, 3.1, 4.5] {
            let s = Complex::from_polar(r, angle);
            let (e, p1, p2) = modal::phi(s);
            let (mut sum, mut term) = (Complex::new(0.0, 0.0), Complex::new(0.5, 0.0));
            for j in 0..40 {
                sum += term;
                term *= s / (j as f64 + 3.0);
            }
            assert!(
                (p2 - sum).norm() <= 5e-16 * sum.norm(),
                "{s}: {p2} vs {sum}"
            );
            assert!((p1 - (1.0 + s * sum)).norm() <= 5e-16, "{s}");
            assert!((e - s.exp()).norm() <= 4e-16 * s.exp().norm(), "{s}");
        }
    }
}

/// The exact extrema's grid under a record with a tail: every sample in
/// `(a, b)` is a piece's end, the pieces of a whole step are its kept
/// equal parts (to 1e-10: their coefficients serve them), none longer
/// than a sixteenth of the fastest period, the last ends at b; and the
/// motion carried piece by piece along it equals the integration to
/// 1e-9 (the parts' coefficients are the motion's).
#[test]
fn the_extrema_grid_parts_whole_steps() {
    let (times, values) = record_with_a_tail();
    let rec = Accelerogram::new(times.clone(), values, 0.4).unwrap();
    let m = joined(
        [body("a", 1.0, 120.0, 0.02), body("b", 1.2, 90.0, 0.02)],
        (4000.0, 0.3),
        BaseExcitation::Record(rec),
        vec![],
    );
    let free = FreeMotion::new(&m).unwrap();
    let group = &free.groups()[0];
    let natural = FreeMotion::natural_piece(group.rate());
    let part = group.modal.as_ref().and_then(|m| m.part()).expect("parts");
    assert!((2.0..=8.0).contains(&(0.01 / part).round()), "{part}");
    assert!(part <= natural * (1.0 + 1e-12));
    let (a, b) = (0.0137, 2.2);
    let grid = free.grid(0, a, b, natural);
    assert_eq!(*grid.last().unwrap(), b);
    let mut last = a;
    for &t in &grid {
        assert!(t > last && t - last <= natural * (1.0 + 1e-9), "{last} {t}");
        let inside = times.iter().any(|&s| s <= last) && t <= 1.49;
        let starts_on_sample = times.iter().any(|&s| (s - last).abs() < 1e-12);
        if inside && starts_on_sample {
            assert!((t - last - part).abs() <= 1e-10 * part, "{last} {t}");
        }
        last = t;
    }
    for &s in times.iter().filter(|&&s| s > a && s < b) {
        assert!(grid.iter().any(|&t| (t - s).abs() < 1e-12), "{s}");
    }
    let mut x: Vec<f64> = (0..2)
        .flat_map(|i| [m.initial_displacement()[i], m.initial_velocity()[i]])
        .collect();
    let mut t0 = 0.0;
    for t in std::iter::once(a).chain(grid) {
        free.propagate(0, t0, t, &mut x);
        t0 = t;
    }
    assert_close(&x, &integrated(&m, b), 1e-9);
}

/// A harmonic base or force of zero amplitude is left out of the free
/// motion (no steady state to solve for, no system matrix for a single
/// body): a single body and a coupled pair under both move as unforced,
/// to the last bit, and as integrated.
#[test]
fn zero_amplitude_terms_are_left_out() {
    let silent = |body| HarmonicForce {
        body,
        amplitude: 0.0,
        frequency: 5.3,
        phase: 0.4,
    };
    let single = |base, forces| free_model(vec![body("a", 1.0, 12.0, 0.02)], vec![], base, forces);
    let pair = |base, forces| {
        joined(
            [body("a", 1.0, 12.0, 0.02), body("b", 1.2, 9.0, 0.02)],
            (40.0, 0.3),
            base,
            forces,
        )
    };
    for (unforced, silenced) in [
        (
            single(BaseExcitation::None, vec![]),
            single(harmonic(0.0, 6.0, 0.2), vec![silent(0)]),
        ),
        (
            pair(BaseExcitation::None, vec![]),
            pair(harmonic(0.0, 6.0, 0.2), vec![silent(1)]),
        ),
    ] {
        let (a, b) = (exact(&unforced, 2.0, 7), exact(&silenced, 2.0, 7));
        assert_eq!(a, b);
        assert_close(&b, &integrated(&silenced, 2.0), 1e-9);
    }
}
