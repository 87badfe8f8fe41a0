//! Section 6: the local integrator with yielding storeys (docs/theory.md
//! §10, §11; docs/decisions.md D26).
//!
//! 1. A row of N three-storey bilinear frames, the first struck (its
//!    floors at 0.5 m/s, as after a vehicle impact or a blast), pounding
//!    its neighbour at every floor across 1 cm (Hertz), 3 s, no base
//!    motion: the pounding and yielding run down the row and die out.
//!    Local against global at rtol 1e-8 (time, bodies ever integrated,
//!    the first ten frames' final state against the global run at rtol
//!    1e-11) for N = 10, 100, 1000 (global to 100).
//! 2. Rows of K buildings (3–8 storeys, bilinear, Hertz at floors 1–3)
//!    under `examples/synthetic-quake.csv` at 0.1 and 1 of its amplitude,
//!    sampled at the record's step, DOPRI5 rtol 1e-4, with the global run
//!    at DOP853 rtol 1e-8 beside it (the local run's error where nothing
//!    yields). At 0.1 the local run is exact and the faster (modal
//!    envelopes, docs/decisions.md D37); at full scale, where buildings
//!    yield and pound, the two are close (a stepper per cluster, D39;
//!    D40).
//! 3. The pounding study of those rows at full scale (`Row::respond`:
//!    exact peaks by gauges, one set), DOP853 rtol 1e-8, local against
//!    global, with the largest difference of a peak drift: why `auto`
//!    runs a study with exact peaks globally.
//! 4. The rows at full scale at equal error: each integrator's fastest
//!    run (DOPRI5 or DOP853, rtol 1e-4 … 1e-11) within 1e-5, 1e-7 and
//!    1e-9 of global DOP853 at rtol 1e-12: where `auto` runs the local
//!    one under a record (docs/decisions.md D41).

use std::time::Instant;

use serde_json::{json, Value};
use vibroimpact::contact::ContactLaw;
use vibroimpact::integrate::Method;
use vibroimpact::model::hysteresis::{Bilinear, StoreyLaw};
use vibroimpact::model::record::{parse_record, Record, Units};
use vibroimpact::model::{BaseExcitation, Body, Contact, ContactPair, Model, Storey};
use vibroimpact::seismic::pounding::{parse_row, RunSettings};
use vibroimpact::simulate::{Integrator, Simulation, SimulationOptions};

use super::Entries;
use crate::common::Peers;

/// The struck row of `n` frames (bodies frame by frame, floors up).
fn struck_row(n: usize) -> Model {
    let (m, k, floors): (f64, f64, usize) = (1e5, 5e7, 3);
    // Mass-proportional damping, 5 % in the first mode (ω1 ≈ 0.445 √(k/m)).
    let c = 2.0 * 0.05 * 0.445 * (k / m).sqrt() * m;
    let mut bodies = Vec::new();
    let (mut u0, mut v0) = (Vec::new(), Vec::new());
    let mut storeys = Vec::new();
    let mut contacts = Vec::new();
    let law = ContactLaw::hertz(1e9, 1.5).expect("valid law");
    for f in 0..n {
        for j in 0..floors {
            let i = f * floors + j;
            bodies.push(Body {
                name: format!("F{}.{}", f + 1, j + 1),
                mass: m,
                stiffness: 0.0,
                damping: c,
            });
            u0.push(0.0);
            v0.push(if f == 0 { 0.5 } else { 0.0 });
            storeys.push(Storey {
                below: (j > 0).then(|| i - 1),
                above: i,
                law: StoreyLaw::Bilinear(Bilinear {
                    stiffness: k,
                    yield_drift: 0.005,
                    post_yield_ratio: 0.05,
                }),
                p_delta: 0.0,
            });
            if f + 1 < n {
                contacts.push(Contact {
                    pair: ContactPair::Bodies {
                        left: i,
                        right: i + floors,
                    },
                    clearance: 0.01,
                    law,
                });
            }
        }
    }
    Model::new(
        bodies,
        vec![],
        contacts,
        BaseExcitation::None,
        vec![],
        u0,
        v0,
    )
    .and_then(|model| model.with_storeys(storeys))
    .expect("valid row")
}

/// A run of `model` and its result, the best wall time of `repeats`.
fn timed(model: &Model, opts: &SimulationOptions, repeats: usize) -> (f64, Simulation) {
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let sim = vibroimpact::simulate::simulate_streaming(model, opts, |_, _| true)
            .expect("valid options");
        best = best.min(start.elapsed().as_secs_f64());
        assert!(sim.error.is_none(), "{:?}", sim.error);
        last = Some(sim);
    }
    (best, last.expect("a run"))
}

/// The largest difference of the first `bodies` bodies' final (u, v)
/// relative to the largest of each in `reference`.
fn difference(a: &Simulation, reference: &Simulation, bodies: usize) -> f64 {
    let rel = |x: &[f64], y: &[f64]| {
        let scale = y[..bodies].iter().fold(1e-300f64, |m, v| m.max(v.abs()));
        (0..bodies)
            .map(|i| (x[i] - y[i]).abs() / scale)
            .fold(0.0, f64::max)
    };
    rel(&a.final_displacement, &reference.final_displacement)
        .max(rel(&a.final_velocity, &reference.final_velocity))
}

/// A row file of `k` buildings (seeded sizes and strengths).
fn row_text(k: usize) -> String {
    let mut seed = 3u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("law = { law = \"hertz\", stiffness = 2e9, exponent = 1.5 }\n");
    for b in 0..k {
        let n = [3usize, 4, 5, 6, 8][(next() * 5.0) as usize % 5];
        let stiffness = (1.0e8 + 2.0e8 * next()) * n as f64 / 5.0;
        let uy = 0.006 + 0.014 * next();
        text += &format!("[[building]]\nname = \"B{b}\"\n");
        if b > 0 {
            text += "gap = 0.04\nfloors = [1, 2, 3]\n";
        }
        let list = |v: String| vec![v; n].join(", ");
        text += &format!(
            "masses = [{}]\nstiffnesses = [{}]\ndamping_ratio = 0.05\nstoreys = [{}]\n",
            list("2e5".into()),
            list(format!("{stiffness}")),
            list(format!(
                "{{ law = \"bilinear\", yield_drift = {uy}, post_yield_ratio = 0.05 }}"
            )),
        );
    }
    text
}

pub fn run(_peers: Option<&Peers>, quick: bool) -> Entries {
    let repeats = if quick { 1 } else { 3 };
    println!("\n== storeys: a struck row of yielding frames, 3 s, rtol 1e-8 ==");
    let options = |integrator, rtol: f64| SimulationOptions {
        t_end: 3.0,
        rtol,
        atol: rtol * 1e-4,
        integrator,
        ..SimulationOptions::default()
    };
    let reference = timed(&struck_row(10), &options(Integrator::Global, 1e-11), 1).1;
    let mut struck = Vec::new();
    let sizes: &[usize] = if quick { &[10, 100] } else { &[10, 100, 1000] };
    for &n in sizes {
        let model = struck_row(n);
        let (tl, local) = timed(&model, &options(Integrator::Local, 1e-8), repeats);
        let stats = local.local.clone().expect("a local run");
        let err_l = difference(&local, &reference, 30);
        let mut row = json!({"n": n, "local_seconds": tl, "local_error": err_l,
            "bodies_integrated": stats.bodies_integrated(), "largest_set": stats.largest_set,
            "hysteretic_energy": local.hysteretic_energy.iter().sum::<f64>()});
        let mut line = format!(
            "N = {n:>5}: local {:>9.2} ms, error {err_l:.1e}, {} of {} bodies integrated (at most {})",
            tl * 1e3,
            stats.bodies_integrated(),
            3 * n,
            stats.largest_set
        );
        if n <= 100 {
            let (tg, global) = timed(&model, &options(Integrator::Global, 1e-8), repeats);
            let err_g = difference(&global, &reference, 30);
            line += &format!(
                "; global {:>9.2} ms, error {err_g:.1e}; global / local {:.2}",
                tg * 1e3,
                tg / tl
            );
            row["global_seconds"] = json!(tg);
            row["global_error"] = json!(err_g);
        }
        println!("{line}");
        struck.push(row);
    }

    println!(
        "\n== storeys: rows of yielding buildings under the synthetic record, DOPRI5 rtol 1e-4 =="
    );
    let text = include_str!("../../../examples/synthetic-quake.csv");
    let record = parse_record(text, "synthetic-quake.csv", Some(Units::MetersPerSecond2))
        .expect("the example record");
    let mut rows = Vec::new();
    let counts: &[usize] = if quick { &[16] } else { &[16, 64] };
    for &k in counts {
        let row = parse_row(&row_text(k), "row.toml").expect("valid row");
        for scale in [0.1, 1.0] {
            let model = row
                .model(&record, scale, true)
                .expect("the row's model")
                .model;
            let opts = |integrator| SimulationOptions {
                t_end: record.duration(),
                rtol: 1e-4,
                atol: 1e-8,
                output_step: Some(0.01),
                method: Method::Dopri5,
                integrator,
                ..SimulationOptions::default()
            };
            let (tg, global) = timed(&model, &opts(Integrator::Global), repeats);
            let (tl, local) = timed(&model, &opts(Integrator::Local), repeats);
            let tight = |rtol: f64| SimulationOptions {
                rtol,
                atol: 1e-4 * rtol,
                method: Method::Dop853,
                ..opts(Integrator::Global)
            };
            let (_, reference) = timed(&model, &tight(1e-12), 1);
            // The global run at the local one's error, where the local run
            // is exact (no storey leaves its elastic branch).
            let (t8, global8) = timed(&model, &tight(1e-8), repeats);
            let bodies = model.bodies().len();
            let (err_g, err_l, err_g8) = (
                difference(&global, &reference, bodies),
                difference(&local, &reference, bodies),
                difference(&global8, &reference, bodies),
            );
            println!(
                "K = {k:>3}, scale {scale}: global DOP853 rtol 1e-8 {:>8.2} ms (error {err_g8:.1e})",
                t8 * 1e3
            );
            let stats = local.local.clone().expect("a local run");
            println!(
                "K = {k:>3}, scale {scale}: global {:>8.2} ms (error {err_g:.1e}), local {:>8.2} ms (error {err_l:.1e}; local / global {:.2}); {} impacts, {} of {} bodies integrated, {} checks",
                tg * 1e3,
                tl * 1e3,
                tl / tg,
                global.impacts.len(),
                stats.bodies_integrated(),
                model.bodies().len(),
                stats.contact_checks
            );
            rows.push(
                json!({"buildings": k, "scale": scale, "global_seconds": tg, "local_seconds": tl,
                "global_error": err_g, "local_error": err_l,
                "global_dop853_1e-8_seconds": t8, "global_dop853_1e-8_error": err_g8,
                "impacts": global.impacts.len(), "bodies_integrated": stats.bodies_integrated(),
                "bodies": model.bodies().len(), "checks": stats.contact_checks}),
            );
        }
    }
    println!(
        "\n== storeys: the pounding study (exact peaks by gauges) of the rows at full scale, DOP853 rtol 1e-8 =="
    );
    let mut study = Vec::new();
    for &k in counts {
        let row = parse_row(&row_text(k), "row.toml").expect("valid row");
        let respond = |integrator| {
            let settings = RunSettings {
                integrator,
                ..RunSettings::new(0.01, 1e-8)
            };
            let mut best = (f64::INFINITY, None);
            for _ in 0..repeats {
                let start = Instant::now();
                let r = row
                    .respond(&record, 1.0, true, &settings)
                    .expect("a response");
                best = (best.0.min(start.elapsed().as_secs_f64()), Some(r));
            }
            (best.0, best.1.expect("one run"))
        };
        let (tg, global) = respond(Integrator::Global);
        let (tl, local) = respond(Integrator::Local);
        // The largest difference of a peak drift, relative to the row's
        // largest.
        let largest = global
            .drift
            .iter()
            .flatten()
            .fold(0.0f64, |m, d| m.max(d.abs()));
        let difference = (global.drift.iter().flatten())
            .zip(local.drift.iter().flatten())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()))
            / largest;
        println!(
            "K = {k:>3}: global {:>8.2} ms, local {:>8.2} ms (local / global {:.2}); peak drifts differ by {difference:.1e} of the largest",
            tg * 1e3,
            tl * 1e3,
            tl / tg
        );
        study.push(
            json!({"buildings": k, "global_seconds": tg, "local_seconds": tl,
            "peak_drift_difference": difference}),
        );
    }
    let equal = equal_error(&record, counts, repeats);
    vec![(
        "storeys",
        json!({"struck_row": struck, "rows_under_a_record": rows, "pounding_study": study,
            "equal_error": equal}),
    )]
}

/// Part 4: the rows at full scale, each integrator at its fastest for an
/// error: DOPRI5 and DOP853 at rtol 1e-4 … 1e-11, errors against global
/// DOP853 rtol 1e-12; per error bound the fastest run of each within it
/// (docs/decisions.md D41).
fn equal_error(record: &Record, counts: &[usize], repeats: usize) -> Vec<Value> {
    println!(
        "\n== storeys: the rows at full scale at equal error, each integrator at its fastest (DOPRI5 or DOP853, rtol 1e-4 … 1e-11) =="
    );
    let mut out = Vec::new();
    for &k in counts {
        let row = parse_row(&row_text(k), "row.toml").expect("valid row");
        let model = row.model(record, 1.0, true).expect("the row's model").model;
        let opts = |integrator, method, rtol: f64| SimulationOptions {
            t_end: record.duration(),
            rtol,
            atol: 1e-4 * rtol,
            output_step: Some(0.01),
            method,
            integrator,
            ..SimulationOptions::default()
        };
        let reference = timed(&model, &opts(Integrator::Global, Method::Dop853, 1e-12), 1).1;
        let bodies = model.bodies().len();
        let mut runs = Vec::new();
        for integrator in [Integrator::Global, Integrator::Local] {
            for (name, method) in [("DOPRI5", Method::Dopri5), ("DOP853", Method::Dop853)] {
                for e in 4..=11 {
                    let rtol = 10f64.powi(-e);
                    let (t, sim) = timed(&model, &opts(integrator, method, rtol), repeats);
                    let err = difference(&sim, &reference, bodies);
                    runs.push((integrator, name, rtol, t, err));
                }
            }
        }
        for bound in [1e-5, 1e-7, 1e-9] {
            let fastest = |which| {
                runs.iter()
                    .filter(|r| r.0 == which && r.4 <= bound)
                    .min_by(|a, b| a.3.total_cmp(&b.3))
            };
            let (Some(g), Some(l)) = (fastest(Integrator::Global), fastest(Integrator::Local))
            else {
                println!("K = {k:>3}, error <= {bound:.0e}: not reached by both");
                continue;
            };
            println!(
                "K = {k:>3}, error <= {bound:.0e}: global {} rtol {:.0e} {:>8.2} ms ({:.1e}), local {} rtol {:.0e} {:>8.2} ms ({:.1e}); local / global {:.2}",
                g.1, g.2, g.3 * 1e3, g.4, l.1, l.2, l.3 * 1e3, l.4, l.3 / g.3
            );
            out.push(json!({"buildings": k, "error_bound": bound,
                "global": {"method": g.1, "rtol": g.2, "seconds": g.3, "error": g.4},
                "local": {"method": l.1, "rtol": l.2, "seconds": l.3, "error": l.4}}));
        }
    }
    out
}
