//! The exact run against closed forms and the global integrator.

use super::*;
use crate::dynamics::Added;
use crate::model::{Accelerogram, Body};
use crate::seismic::pounding::tests::record;
use crate::seismic::pounding::{parse_row, RunSettings};

/// u'' + 2ζω u' + ω² u = −(a₀ + s τ) from (u₀, v₀): (u, v) at τ.
fn damped_ramp(
    (w, z): (f64, f64),
    (a0, s): (f64, f64),
    (u0, v0): (f64, f64),
    tau: f64,
) -> (f64, f64) {
    let wd = w * (1.0 - z * z).sqrt();
    let b = -s / (w * w);
    let a = (-a0 - 2.0 * z * w * b) / (w * w);
    let c1 = u0 - a;
    let c2 = (v0 - b + z * w * c1) / wd;
    let (e, (sn, cs)) = ((-z * w * tau).exp(), (wd * tau).sin_cos());
    let u = a + b * tau + e * (c1 * cs + c2 * sn);
    let v = b + e * ((-z * w) * (c1 * cs + c2 * sn) + wd * (-c1 * sn + c2 * cs));
    (u, v)
}

/// One body on a spring under a base of two ramps (0 → 2 m/s² over 1 s,
/// then to −1 m/s² over 2 s): the exact run's samples are the closed
/// form's, ramp by ramp, to 1e-13 of the motion's size; its peak |u| is
/// the closed form's largest on a fine grid (from below, to 1e-9); and
/// the local integrator runs it this way (no local statistics).
#[test]
fn a_body_under_two_ramps_moves_as_the_closed_form() {
    let (w, z) = (2.0 * std::f64::consts::PI, 0.05);
    let base = Accelerogram::new(vec![0.0, 1.0, 3.0], vec![0.0, 2.0, -1.0], 1.0).unwrap();
    let model = Model::new(
        vec![Body::from_frequency("b", 1.0, w, z)],
        Vec::new(),
        Vec::new(),
        BaseExcitation::Record(base),
        Vec::new(),
        vec![0.0],
        vec![0.0],
    )
    .unwrap();
    let opts = SimulationOptions {
        t_end: 3.0,
        output_step: Some(0.125),
        integrator: Integrator::Local,
        extrema_window: Some((0.0, 3.0)),
        ..Default::default()
    };
    assert!(qualifies(&model, &opts));
    let sim = simulate(&model, &opts).unwrap();
    assert!(
        sim.error.is_none() && sim.local.is_none(),
        "{:?}",
        sim.error
    );
    let at_one = damped_ramp((w, z), (0.0, 2.0), (0.0, 0.0), 1.0);
    let closed = |t: f64| match t <= 1.0 {
        true => damped_ramp((w, z), (0.0, 2.0), (0.0, 0.0), t),
        false => damped_ramp((w, z), (2.0, -1.5), at_one, t - 1.0),
    };
    let size = 0.1;
    for (k, &t) in sim.times.iter().enumerate() {
        let (u, v) = closed(t);
        let (su, sv) = (sim.states[2 * k], sim.states[2 * k + 1]);
        assert!((su - u).abs() < 1e-13 * size, "t {t}: u {su} against {u}");
        assert!(
            (sv - v).abs() < 1e-12 * size * w,
            "t {t}: v {sv} against {v}"
        );
    }
    assert_eq!(sim.times.len(), 25);
    let fine = (0..=300_000)
        .map(|k| closed(3.0 * k as f64 / 300_000.0).0.abs())
        .fold(0.0, f64::max);
    let peak = sim.extrema.unwrap().max_displacement[0];
    assert!(
        peak >= fine * (1.0 - 1e-12) && peak - fine < 1e-9 * fine,
        "{peak} against {fine}"
    );
}

/// A record that starts at 0.1 s (zero before, where it jumps to its
/// first sample): the exact run's end state is the global integrator's
/// at rtol 1e-13 to 1e-10 of its size. (It was not: the first interval
/// ramped from zero to the first sample.)
#[test]
fn a_record_that_starts_late() {
    let times: Vec<f64> = (0..200).map(|k| 0.1 + 0.01 * k as f64).collect();
    let values = times.iter().map(|t| (7.0 * t).sin() + 0.5).collect();
    let base = BaseExcitation::Record(Accelerogram::new(times, values, 0.3).unwrap());
    let model = Model::new(
        vec![Body::from_frequency("b", 0.227, 7.41, 0.05)],
        Vec::new(),
        Vec::new(),
        base,
        Vec::new(),
        vec![0.0],
        vec![0.0],
    )
    .unwrap();
    let run = |integrator| {
        let opts = SimulationOptions {
            t_end: 2.09,
            rtol: 1e-13,
            atol: 1e-16,
            integrator,
            ..Default::default()
        };
        simulate(&model, &opts).unwrap()
    };
    let (g, x) = (run(Integrator::Global), run(Integrator::Local));
    assert!(x.local.is_none());
    let size = g.final_displacement[0].abs().max(1e-3);
    assert!((g.final_displacement[0] - x.final_displacement[0]).abs() < 1e-10 * size);
    assert!((g.final_velocity[0] - x.final_velocity[0]).abs() < 1e-10 * size * 7.41);
}

/// A two-storey building alone, `law` storeys with P-Δ, under a burst
/// that yields it: peaks, residual drifts and floor accelerations (exact
/// on either motion), the storeys' dissipated energy and the time of
/// every switch (through the loops' hysteretic energy) as the global
/// integrator gives them at rtol 1e-11, to 1e-8 of their size.
fn as_the_global_integrator(law: &str) {
    let text = format!(
        "[[building]]\nname = \"F\"\nmasses = [1e5, 1e5]\nstiffnesses = [4e7, 3e7]\n\
         damping_ratio = 0.05\nheights = [4.0, 3.5]\np_delta = true\n\
         storeys = [{law}, {law}]\n"
    );
    let yielded = as_the_global_integrator_in(&text, law, 1.5);
    assert_eq!(yielded, 2, "{law}");
}

/// [`as_the_global_integrator`] on the row `text` under the test record
/// × `scale`: how many storeys yielded.
fn as_the_global_integrator_in(text: &str, law: &str, scale: f64) -> usize {
    let row = parse_row(text, "frame.toml").unwrap();
    let run = |integrator| {
        let mut settings = RunSettings::new(0.01, 1e-11);
        settings.integrator = integrator;
        row.respond(&record(), scale, true, &settings).unwrap()
    };
    let (g, x) = (run(Integrator::Global), run(Integrator::Local));
    let close = |a: &[Vec<f64>], b: &[Vec<f64>], what: &str| {
        for (a, b) in a.iter().flatten().zip(b.iter().flatten()) {
            // (A residual drift not judged is NaN on both.)
            let same = (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-8 * a.abs().max(1e-6);
            assert!(same, "{law}, {what}: {a} against {b}");
        }
    };
    close(&g.drift, &x.drift, "peak drifts");
    close(&g.residual_drift, &x.residual_drift, "residual drifts");
    close(&g.acceleration, &x.acceleration, "accelerations");
    close(
        &g.hysteretic_energy,
        &x.hysteretic_energy,
        "hysteretic energy",
    );
    g.hysteretic_energy
        .iter()
        .flatten()
        .filter(|e| **e > 0.0)
        .count()
}

/// The 4-storey IMK frame of the examples (P-Δ, leaning loads) yielding
/// in three storeys or more: its storeys switch one while the others
/// carry their bounds, and the exact run finds every switch as the
/// global integrator does (see [`as_the_global_integrator`]).
#[test]
fn the_imk_frame_runs_as_the_global_integrator() {
    let path = format!(
        "{}/../../examples/moment-frame-4.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let yielded = as_the_global_integrator_in(&text, "the IMK frame", 40.0);
    assert!(yielded >= 3, "{yielded} storeys yielded");
}

#[test]
fn a_bilinear_building_runs_as_the_global_integrator() {
    as_the_global_integrator(
        "{ law = \"bilinear\", yield_drift = 0.004, post_yield_ratio = 0.05 }",
    );
}

#[test]
fn an_imk_building_runs_as_the_global_integrator() {
    as_the_global_integrator(
        "{ law = \"imk\", yield_drift = 0.004, cap_ratio = 1.1, plastic_drift = 0.01, \
         post_capping_drift = 0.05, residual_ratio = 0.4, ultimate_drift = 0.1, \
         lambda_s = 0.5, lambda_c = 0.5, lambda_k = 0.5 }",
    );
}

/// An IMK law whose hardening line, drawn back, falls below its residual
/// (cap 3 F_y one yield drift past yield, residual 0.2 F_y): off the
/// backbone its bound of the direction of motion has a convex corner
/// where that line meets the residual, so the elastic line meets the
/// bound at 0.2 u_y and the hardening line takes over at u_y. A storey
/// sent from 0.025 u_y at 0.5 m/s crosses that stretch within its first
/// 0.01 s with its drift terms positive at both ends; the exact run must
/// find the yield at 0.2 u_y, as the global integrator does, and end on
/// the hardening line 2 k u − F_y (before the drift terms' shortcut was
/// kept to a minimum of lines, it stayed on the elastic line k u).
#[test]
fn a_yield_between_two_positive_ends_is_found() {
    use crate::model::hysteresis::StoreySpec;
    let k = 4e6;
    let spec = StoreySpec::imk(
        Some(0.004),
        [Some(3.0), Some(0.004), Some(0.05), Some(0.2), Some(0.1)],
        [None; 3],
        [1.0; 3],
    )
    .unwrap();
    let model = Model::new(
        vec![Body {
            name: "floor".into(),
            mass: 1e5,
            stiffness: 0.0,
            damping: 0.0,
        }],
        Vec::new(),
        Vec::new(),
        BaseExcitation::None,
        Vec::new(),
        vec![1e-4],
        vec![0.5],
    )
    .unwrap()
    .with_storeys(vec![crate::model::Storey {
        below: None,
        above: 0,
        law: spec.law(k).unwrap(),
        p_delta: 0.0,
    }])
    .unwrap();
    let run = |integrator, rtol| {
        let opts = SimulationOptions {
            t_end: 0.01,
            rtol,
            atol: rtol * 1e-4,
            output_step: Some(0.01),
            storey_forces: true,
            integrator,
            ..Default::default()
        };
        let mut last = Vec::new();
        let sim = simulate_streaming(&model, &opts, |_, row| {
            last = row.to_vec();
            true
        })
        .unwrap();
        assert!(sim.error.is_none(), "{:?}", sim.error);
        last
    };
    let (exact, global) = (run(Integrator::Local, 1e-8), run(Integrator::Global, 1e-12));
    // [u, v, force]: the force on the hardening line at the end.
    let fy = k * 0.004;
    let on_bound = 2.0 * k * exact[0] - fy;
    assert!(
        (exact[2] - on_bound).abs() <= 1e-6 * fy,
        "force {} F_y",
        exact[2] / fy
    );
    for (a, b) in exact.iter().zip(&global) {
        assert!(
            (a - b).abs() <= 1e-7 * b.abs().max(1e-3),
            "{exact:?} against {global:?}"
        );
    }
}

/// What does not qualify: a contact, harmonic base motion, a Bouc–Wen
/// storey, the energy audit.
#[test]
fn the_exact_run_is_for_linear_pieces_under_a_record() {
    let text = |storey: &str| {
        format!(
            "[[building]]\nname = \"F\"\nmasses = [1e5]\nstiffnesses = [4e7]\n\
             damping_ratio = 0.05\nstoreys = [{storey}]\n"
        )
    };
    let model = |storey: &str| {
        let row = parse_row(&text(storey), "f.toml").unwrap();
        row.model(&record(), 1.0, true).unwrap().model
    };
    let opts = SimulationOptions::default();
    let bilinear = model("{ law = \"bilinear\", yield_drift = 0.004, post_yield_ratio = 0.05 }");
    assert!(qualifies(&bilinear, &opts));
    assert!(!qualifies(
        &bilinear,
        &SimulationOptions {
            energy: true,
            ..opts.clone()
        }
    ));
    let bouc_wen =
        model("{ law = \"bouc-wen\", yield_drift = 0.004, post_yield_ratio = 0.05, exponent = 2 }");
    assert!(!qualifies(&bouc_wen, &opts));
    let harmonic = bilinear.clone().with_base(BaseExcitation::Harmonic {
        amplitude: 1.0,
        frequency: 10.0,
        phase: 0.0,
    });
    assert!(!qualifies(&harmonic, &opts));
    let pair = crate::model::reference::r2(2, crate::model::reference::CLEARANCE, 1.0).unwrap();
    assert!(!qualifies(&pair, &opts));
}

/// A building's storeys are a chain: a term of its series (a product
/// with `A` in one pass over the floors, with each kind of forcing) is the
/// links' one by one (P-Δ, Rayleigh damping and IMK storeys of the
/// 4-storey frame) to 1e-15 of its size, with its rows' sizes, and its
/// arrays' product ([`crate::dynamics::FixedChain`]) is its own bit for
/// bit; a row of two buildings without their contacts is one too (no
/// link between them).
#[test]
fn a_chain_multiplies_as_its_links() {
    for file in ["moment-frame-4.toml", "pounding-frames.toml"] {
        let path = format!("{}/../../examples/{file}", env!("CARGO_MANIFEST_DIR"));
        let row = parse_row(&std::fs::read_to_string(&path).unwrap(), file).unwrap();
        let model = row.model(&record(), 1.0, false).unwrap().model;
        let sys = ChainDynamics::new(&model, false);
        let mut form = PiecewiseForm::default();
        assert!(sys.piecewise_form(&mut form), "{file}");
        assert!(form.is_chain(), "{file}");
        let plain = form.unchained();
        let n = model.bodies().len();
        let at = |k: usize| -> Vec<f64> {
            (0..n)
                .map(|i| ((i * 7 + k) % 11) as f64 / 11.0 - 0.4)
                .collect()
        };
        let (x, z) = (at(3), at(5));
        for added in [
            Added::Nothing,
            Added::ConstantLess(0.7, 0.2),
            Added::Less(-1.3),
        ] {
            let (mut a, mut b) = (vec![0.0; n], vec![0.0; n]);
            // (Each row weighted into sums that hold a row already.)
            let w = [2.0, -0.5, 3.0];
            let mut sums_a: Vec<[f64; 4]> = x.iter().map(|&v| [v, 0.0, -v, 1.0]).collect();
            let mut sums_b = sums_a.clone();
            let top = form.displacement_term((&x, 0.3), (&z, 0.6), &mut a, added, (&mut sums_a, w));
            plain.displacement_term((&x, 0.3), (&z, 0.6), &mut b, added, (&mut sums_b, w));
            let size = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (p, q) in a.iter().zip(&b) {
                assert!(
                    (p - q).abs() <= 1e-15 * size,
                    "{file} {added:?}: {p} against {q}"
                );
            }
            for ((s, t), (&v, &o)) in sums_a.iter().zip(&sums_b).zip(x.iter().zip(&b)) {
                let by_hand = [v + o, 2.0 * o, -v - 0.5 * o, 1.0 + 3.0 * o];
                for ((p, q), r) in s.iter().zip(t).zip(by_hand) {
                    assert!(
                        (p - r).abs() <= 1e-15 * (size + 1.0)
                            && (q - r).abs() <= 1e-15 * (size + 1.0),
                        "{file} {added:?}: sums {p} and {q} against {r}"
                    );
                }
            }
            let largest = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert_eq!(top, largest, "{file} {added:?}");
            // (The chain's arrays: bit for bit the chain's product.)
            let fixed = match n {
                4 => fixed_term::<4>(&form, (&x, &z), added),
                5 => fixed_term::<5>(&form, (&x, &z), added),
                _ => panic!("{file}: {n} bodies"),
            };
            assert_eq!(fixed, (a, top), "{file} {added:?}: by arrays");
        }
    }
}

/// [`FixedChain::term`] of `form`, a chain of N bodies, on `x` and `z` (as
/// the test above gives them): the row and the largest.
fn fixed_term<const N: usize>(
    form: &PiecewiseForm,
    (x, z): (&[f64], &[f64]),
    added: Added,
) -> (Vec<f64>, f64) {
    let chain = form.fixed::<N>().expect("a chain of N bodies");
    let mut out = [0.0; N];
    let (x, z): (&[f64; N], &[f64; N]) = (x.try_into().unwrap(), z.try_into().unwrap());
    let top = chain.term((x, 0.3), (z, 0.6), &mut out, added);
    (out.to_vec(), top)
}

/// A series is cut where the bound on its tail falls below rounding, not
/// where a term vanishes: an undamped oscillator from rest (every odd
/// term zero) over ω h = 0.5, 2 and 4 moves as cos ω τ to 1e-14 at the
/// end and inside, with its velocity and acceleration, and keeps more
/// terms the longer the interval (a cut at the first zero term kept 6 at
/// ω h = 127 and let the run grow without bound).
#[test]
fn a_series_runs_past_terms_that_vanish() {
    let w = 3.0;
    let body = Body {
        name: "b".into(),
        mass: 2.0,
        stiffness: 2.0 * w * w,
        damping: 0.0,
    };
    let model = Model::new(
        vec![body],
        vec![],
        vec![],
        BaseExcitation::None,
        vec![],
        vec![],
        vec![],
    )
    .unwrap();
    let mut form = PiecewiseForm::default();
    assert!(ChainDynamics::new(&model, false).piecewise_form(&mut form));
    let mut series = Series::new(2);
    let mut terms = 0;
    for wh in [0.5, 2.0, 4.0] {
        let h = wh / w;
        assert_eq!(series.build(&form, &[1.0, 0.0], (0.0, 0.0), h), Built::Done);
        assert!(series.terms() > terms, "ω h {wh}: {} terms", series.terms());
        terms = series.terms();
        for tau in [h, h / 3.0] {
            let mut y = [0.0; 2];
            series.state(tau, &mut y);
            let (s, c) = (w * tau).sin_cos();
            let (u, v, a) = series.component(0, tau);
            for (got, want, size) in [
                (y[0], c, 1.0),
                (y[1], -w * s, w),
                (u, c, 1.0),
                (v, -w * s, w),
                (a, -w * w * c, w * w),
            ] {
                assert!(
                    (got - want).abs() <= 1e-14 * size,
                    "ω h {wh}, τ {tau}: {got} against {want}"
                );
            }
        }
    }
}

/// Inside an interval, the state of every body read in one pass
/// ([`Series::state`]) is each body's own reading
/// ([`Series::value_rate`]) bit for bit, and so are a storey's two
/// floors read side by side ([`Series::two_states`]): the 4-storey frame
/// and a row of two buildings, from a state away from rest over a
/// record's step.
#[test]
fn a_state_inside_is_each_bodys_reading() {
    for file in ["moment-frame-4.toml", "pounding-frames.toml"] {
        let path = format!("{}/../../examples/{file}", env!("CARGO_MANIFEST_DIR"));
        let row = parse_row(&std::fs::read_to_string(&path).unwrap(), file).unwrap();
        let model = row.model(&record(), 1.0, false).unwrap().model;
        let mut form = PiecewiseForm::default();
        assert!(ChainDynamics::new(&model, false).piecewise_form(&mut form));
        let n = model.bodies().len();
        let y0: Vec<f64> = (0..2 * n)
            .map(|i| ((i * 5 + 2) % 7) as f64 / 70.0 - 0.04)
            .collect();
        let mut series = Series::new(2 * n);
        let h = 0.02;
        assert_eq!(series.build(&form, &y0, (0.3, -2.0), h), Built::Done);
        for tau in [0.1 * h, h / 3.0, 0.75 * h] {
            let mut y = vec![0.0; 2 * n];
            series.state(tau, &mut y);
            for b in 0..n {
                let (u, v) = series.value_rate(2 * b, None, tau);
                assert_eq!(
                    (y[2 * b], y[2 * b + 1]),
                    (u, v),
                    "{file}: body {b} at {tau}"
                );
                // (A storey's two floors read side by side.)
                let mut two = vec![f64::NAN; 2 * n];
                let below = b.checked_sub(1);
                series.two_states(b, below, tau, &mut two);
                for i in [Some(b), below].into_iter().flatten() {
                    assert_eq!(
                        (two[2 * i], two[2 * i + 1]),
                        (y[2 * i], y[2 * i + 1]),
                        "{file}: storey {b}'s body {i} at {tau}"
                    );
                }
            }
            assert!(y.iter().zip(&y0).any(|(p, q)| p != q), "{file}: it moved");
        }
    }
}
