//! Fuzzing of every parser and of the model constructor: seeded,
//! deterministic, bounded in `cargo test`; longer with
//! `VIBROIMPACT_FUZZ_CASES=20000 cargo test --release -p vibroimpact --test fuzz`
//! (and `VIBROIMPACT_FUZZ_SEED=<n>` for another sequence; `FUZZ_TRACE=1`
//! prints each option case's seed before its run, to find one that hangs).
//!
//! Inputs are mutants of the repository's own examples (byte and token
//! edits, extreme numbers, duplicated and swapped lines), so that they pass
//! far enough through the parsers to reach validation, and random
//! well-formed models. Every case must end in a result or an error — never a
//! panic — and a model that builds must simulate a short time (bounded by a
//! step limit) or fail with an error. Parse errors must name the source.

use std::panic::{catch_unwind, AssertUnwindSafe};

use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::integrate::Method;
use vibroimpact::model::file::{parse_accelerogram_csv, ModelDocument, ModelFileError};
use vibroimpact::model::parameter::ParameterizedModel;
use vibroimpact::model::{BaseExcitation, Model};
use vibroimpact::simulate::{simulate, Integrator, SimulationOptions};

use vibroimpact_fuzz::{cases, mutant, no_panics, seed, Rng, NUMBERS};

const ROW: &str = include_str!("../../../examples/fujita-row.toml");
const ROW2: &str = include_str!("../../../examples/fujita-row-n2.toml");
const POUNDING: &str = include_str!("../../../examples/pounding-buildings.toml");
const QUAKE: &str = include_str!("../../../examples/synthetic-quake.csv");
/// Explicit bodies, springs, contacts, forces and an inline record.
const EXPLICIT: &str = r#"
[[body]]
name = "a"
mass = 1.0
stiffness = 100.0
damping_ratio = 0.02
[[body]]
name = "b"
mass = 2.0
natural_frequency = 5.0
[[spring]]
between = ["a", "b"]
stiffness = 10.0
damping = 0.1
[[contact]]
between = ["wall", "a"]
clearance = 0.001
law = { law = "hunt-crossley", stiffness = 1e7, chi = 0.5 }
[[contact]]
between = ["a", "b"]
clearance = 0.002
law = { law = "lankarani-nikravesh", stiffness = 1e7, restitution = 0.7 }
[[force]]
body = "b"
amplitude = 1.0
frequency = 5.0
[excitation]
type = "accelerogram"
time = [0.0, 0.1, 0.2, 0.3]
acceleration = [0.0, 1.0, -1.0, 0.0]
"#;

/// The record loader of the fuzzed model files: the example record, or an
/// error for any other name.
fn loader(name: &str) -> Result<vibroimpact::model::record::Record, ModelFileError> {
    if name == "synthetic-quake.csv" {
        parse_accelerogram_csv(QUAKE, name)
    } else {
        Err(ModelFileError(format!(
            "record:{name}: no such file in the fuzz corpus"
        )))
    }
}

/// A short simulation by both integrators, bounded by a small step limit.
fn short_run(model: &Model, method: Method) {
    let t_end = model
        .forcing_frequency()
        .map_or(0.05, |w| (2.0 * std::f64::consts::PI / w).min(0.5));
    for integrator in [Integrator::Global, Integrator::Local] {
        let opts = SimulationOptions {
            t_end,
            max_steps: 20_000,
            method,
            integrator,
            ..SimulationOptions::default()
        };
        if let Ok(sim) = simulate(model, &opts) {
            if sim.error.is_none() {
                assert!(
                    sim.final_displacement.iter().all(|x| x.is_finite()),
                    "a completed run has a finite state"
                );
            }
        }
    }
}

#[test]
fn model_file_mutants_parse_build_and_simulate_without_panics() {
    let mut rng = Rng(seed());
    let corpus = [ROW, ROW2, POUNDING, EXPLICIT];
    let n = cases(1000);
    let inputs: Vec<String> = (0..n).map(|_| mutant(&mut rng, &corpus)).collect();
    no_panics(
        "model file",
        inputs.into_iter(),
        |text| match ModelDocument::parse(text, "fuzz.toml", &mut |name, _| loader(name)) {
            Err(e) => assert!(
                e.0.starts_with("fuzz.toml") || e.0.starts_with("record:"),
                "unnamed error: {e}"
            ),
            Ok(doc) => {
                if let Ok(loaded) = doc.build() {
                    if loaded.model.bodies().len() <= 50 {
                        short_run(&loaded.model, Method::Auto);
                    }
                }
            }
        },
    );
}

#[test]
fn accelerogram_csv_mutants_never_panic() {
    let mut rng = Rng(seed() ^ 1);
    let corpus = [
        QUAKE,
        "time,acceleration\n0,0\n0.1,1\n",
        "# c\n0 , 0\n1,2\n",
    ];
    let inputs: Vec<String> = (0..cases(1000))
        .map(|_| mutant(&mut rng, &corpus))
        .collect();
    no_panics("accelerogram", inputs.into_iter(), |text| {
        if let Err(e) = parse_accelerogram_csv(text, "fuzz.csv") {
            assert!(e.0.starts_with("fuzz.csv"), "unnamed error: {e}");
        }
    });
}

/// Parameter keys and values, valid or not, on each example.
#[test]
fn parameters_set_or_refuse_without_panics() {
    const KEYS: &[&str] = &[
        "frequency",
        "amplitude",
        "row.clearance",
        "row.count",
        "row.mass",
        "row.contact.alpha",
        "row.contact.a_over_b",
        "body.1.mass",
        "body.2.stiffness",
        "contact.1.clearance",
        "contact.2.law.stiffness",
        "spring.1.stiffness",
        "force.1.amplitude",
        "excitation.scale",
        "row",
        "",
        ".",
        "body.0.mass",
        "body.99999999999999999999.mass",
        "row.contact",
        "row.colour",
        "simulation.rtol",
    ];
    let mut rng = Rng(seed() ^ 2);
    let docs: Vec<ModelDocument> = [ROW, ROW2, POUNDING, EXPLICIT]
        .iter()
        .map(|t| ModelDocument::parse(t, "m.toml", &mut |name, _| loader(name)).unwrap())
        .collect();
    let n = cases(400);
    let inputs: Vec<String> = (0..n)
        .map(|_| {
            let value: f64 = rng.pick(NUMBERS).parse().unwrap_or(0.5);
            {
                let key = *rng.pick(KEYS);
                format!("{}|{key}|{value}", rng.below(docs.len()))
            }
        })
        .collect();
    no_panics("parameter", inputs.into_iter(), |case| {
        let parts: Vec<&str> = case.split('|').collect();
        let doc = docs[parts[0].parse::<usize>().unwrap()].clone();
        let value: f64 = parts[2].parse().unwrap();
        if let Ok(family) = ParameterizedModel::new(doc, parts[1]) {
            let _ = family.model_at(value);
        }
    });
}

/// Random but well-formed rows (every law, wide parameter ranges): each
/// simulates a short time or fails with an error.
#[test]
fn random_models_simulate_or_fail_cleanly() {
    let mut rng = Rng(seed() ^ 3);
    let n = cases(300);
    for k in 0..n {
        let form = if rng.below(2) == 0 {
            ForceForm::Published
        } else {
            ForceForm::NonNegative
        };
        let stiffness = rng.log_uniform(3.0, 12.0);
        let law = match rng.below(5) {
            0 => ContactLaw::exponential_from_ratio(
                rng.log_uniform(-2.0, 2.0),
                rng.log_uniform(2.0, 7.0),
                rng.log_uniform(-2.0, 2.0),
                form,
            ),
            1 => ContactLaw::hertz(stiffness, 1.0 + rng.unit()),
            2 => ContactLaw::kelvin_voigt(stiffness, rng.log_uniform(-3.0, 4.0), form),
            3 => ContactLaw::hunt_crossley(stiffness, 1.5, rng.log_uniform(-3.0, 1.0), form),
            _ => {
                ContactLaw::lankarani_nikravesh(stiffness, 1.5, 0.05 + 0.9 * rng.unit(), 1e-3, form)
            }
        };
        let Ok(law) = law else { continue };
        let mass = rng.log_uniform(-3.0, 3.0);
        let omega = rng.log_uniform(-1.0, 4.0);
        let base = BaseExcitation::Harmonic {
            amplitude: rng.log_uniform(-3.0, 3.0),
            frequency: omega * rng.log_uniform(-0.5, 0.5),
            phase: rng.unit(),
        };
        let model = Model::row(
            1 + rng.below(5),
            mass,
            mass * omega * omega,
            2.0 * rng.log_uniform(-4.0, 0.5) * mass * omega,
            rng.log_uniform(-6.0, -2.0),
            law,
            (rng.below(4) != 0, rng.below(4) != 0),
            base,
        );
        let Ok(model) = model else { continue };
        let method = *rng.pick(&[Method::Dop853, Method::Rodas, Method::Auto]);
        let ran = catch_unwind(AssertUnwindSafe(|| short_run(&model, method)));
        assert!(
            ran.is_ok(),
            "random model {k} panicked: {model:?} with {method:?}"
        );
    }
}

const PAIR: &str = include_str!("../../../examples/pounding-frames.toml");
const ISOLATED: &str = include_str!("../../../examples/isolated-building.toml");
const FIVE: &str = include_str!("../../../examples/pounding-five-storeys.toml");
const ARCHETYPE: &str = include_str!("../../../examples/moment-frame-4.toml");

/// Pair, row and isolated-building files, and the IMK + P-Δ archetype
/// (issue 37): every mutant parses
/// or is refused naming the file; a row that parses runs a short record
/// where its estimate says the run is short (a long one would say so up
/// front), and a run that completes has finite peaks.
#[test]
fn row_file_mutants_parse_and_run_without_panics() {
    use vibroimpact::seismic::pounding::{parse_row, RunSettings};
    let mut rng = Rng(seed() ^ 37);
    let record = {
        let units = Some(vibroimpact::model::record::Units::MetersPerSecond2);
        let r = vibroimpact::model::record::parse_record(QUAKE, "quake.csv", units).unwrap();
        let n = r.times.len().min(201);
        vibroimpact::model::record::Record::from_samples(
            "quake",
            r.times[..n].to_vec(),
            &r.acceleration[..n],
        )
        .unwrap()
    };
    let corpus = [PAIR, ISOLATED, FIVE, ARCHETYPE];
    let inputs: Vec<String> = (0..cases(600)).map(|_| mutant(&mut rng, &corpus)).collect();
    let run = RunSettings::new(0.01, 1e-6);
    no_panics("row file", inputs.into_iter(), |text| {
        match parse_row(text, "row.toml") {
            Err(e) => {
                let m = e.to_string();
                assert!(m.starts_with("row.toml"), "unnamed error: {m}");
            }
            Ok(row) => {
                let short = matches!(row.estimate(&record, 1.0, true, &run),
                Ok(Some(w)) if w.seconds < 0.02 && !w.exceeds_step_limit());
                if let (true, Ok(r)) = (short, row.respond(&record, 1.0, true, &run)) {
                    let peaks = r.drift.iter().chain(&r.acceleration).flatten();
                    assert!(peaks.into_iter().all(|p| p.is_finite()), "a finite run");
                }
            }
        }
    });
}

/// Record and drift files (issue 37): every mutant is read or refused
/// naming the file; a record that is read holds finite samples.
#[test]
fn record_and_drift_file_mutants_never_panic() {
    use vibroimpact::model::hysteresis::parse_drifts;
    use vibroimpact::model::record::parse_record;
    let mut rng = Rng(seed() ^ 38);
    let drifts = "drift\n0.01\n-0.02\n0.015\n# end\n";
    let corpus = [
        QUAKE,
        drifts,
        "time acceleration (g)\n0 0\n0.01 0.1\n0.02 -0.1\n",
    ];
    let inputs: Vec<String> = (0..cases(600)).map(|_| mutant(&mut rng, &corpus)).collect();
    no_panics("record or drift file", inputs.into_iter(), |text| {
        match parse_record(text, "rec.csv", None) {
            Err(e) => assert!(e.to_string().starts_with("rec.csv"), "unnamed error: {e}"),
            Ok(r) => assert!(r.acceleration.iter().all(|a| a.is_finite())),
        }
        match parse_drifts(text, "d.txt") {
            Err(e) => assert!(e.to_string().starts_with("d.txt"), "unnamed error: {e}"),
            Ok(d) => assert!(d.iter().all(|x| x.is_finite()) && !d.is_empty()),
        }
    });
}

/// A number for an option: half the time near its typical value, else one
/// of the probing numbers (zero, negatives, extremes, NaN, infinities).
fn option_value(rng: &mut Rng, typical: f64) -> f64 {
    if rng.below(2) == 0 {
        typical * rng.log_uniform(0.1, 10.0)
    } else {
        rng.pick(NUMBERS).parse().unwrap()
    }
}

/// A count for an option: near its typical value, or an extreme.
fn option_count(rng: &mut Rng, typical: usize) -> usize {
    *rng.pick(&[typical, typical / 2 + 1, 0, 1, 3, usize::MAX, 1 << 40])
}

/// The options of `pounding`, `collapse`, `pushover` and `hysteresis`
/// (issue 37), each drawn near its typical value or from the probing
/// numbers: every combination is refused before any work (`check`), or is
/// priced and, where the estimate says short, runs to a result with
/// finite values or an error; never a panic, never a hang, never a
/// non-finite result presented as success.
#[test]
fn option_mutants_are_refused_or_run_finitely() {
    use vibroimpact::integrate::Method;
    use vibroimpact::model::hysteresis::{cyclic_protocol, under_drift, StoreySpec};
    use vibroimpact::seismic::collapse::{CollapseStudy, Criterion, DriftLimit, IdaSettings};
    use vibroimpact::seismic::pounding::{parse_row, RunSettings};
    use vibroimpact::seismic::pushover::{pushover, PushoverOptions};
    let mut rng = Rng(seed() ^ 39);
    let record = {
        let units = Some(vibroimpact::model::record::Units::MetersPerSecond2);
        let r = vibroimpact::model::record::parse_record(QUAKE, "quake.csv", units).unwrap();
        let n = r.times.len().min(101);
        vibroimpact::model::record::Record::from_samples(
            "quake",
            r.times[..n].to_vec(),
            &r.acceleration[..n],
        )
        .unwrap()
    };
    let rows = [
        parse_row(PAIR, "pair.toml").unwrap(),
        parse_row(ARCHETYPE, "archetype.toml").unwrap(),
    ];
    // Each case's seed is its input: a failing case is reported with it.
    let inputs: Vec<String> = (0..cases(600))
        .map(|_| rng.next_u64().to_string())
        .collect();
    no_panics("options", inputs.into_iter(), |case| {
        let mut rng = Rng(case.parse().unwrap());
        let row = rng.pick(&rows);
        let mut run = RunSettings::new(option_value(&mut rng, 0.01), option_value(&mut rng, 1e-6));
        run.method = *rng.pick(&[Method::Dop853, Method::Dopri5]);
        run.integrator = *rng.pick(&[Integrator::Global, Integrator::Local, Integrator::Auto]);
        let scale = option_value(&mut rng, 1.0);
        let short = |w: Option<vibroimpact::simulate::WorkEstimate>| {
            w.is_some_and(|w| w.seconds < 0.02 && !w.exceeds_step_limit())
        };
        // pounding
        if let Ok(est) = row.estimate(&record, scale, true, &run) {
            if short(est) {
                if std::env::var("FUZZ_TRACE").is_ok() {
                    eprintln!(
                        "CASE {case} {} scale {scale} {:?}",
                        row.buildings.len(),
                        (run.sample, run.rtol, run.method, run.integrator)
                    );
                }
                if let Ok(r) = row.respond(&record, scale, true, &run) {
                    let peaks = r.drift.iter().chain(&r.acceleration).flatten();
                    assert!(peaks.into_iter().all(|p| p.is_finite()), "a finite run");
                    assert!(r.peak_impact_force.is_finite());
                }
            }
        }
        // collapse
        let study = CollapseStudy {
            criterion: Criterion {
                drift: if rng.below(2) == 0 {
                    DriftLimit::Ratio(option_value(&mut rng, 0.1))
                } else {
                    DriftLimit::Drift(option_value(&mut rng, 0.3))
                },
                capacity: rng.below(2) == 0,
                contacts: rng.below(2) == 0,
            },
            ida: IdaSettings {
                first: option_value(&mut rng, 0.25),
                growth: option_value(&mut rng, 1.5),
                max_scale: option_value(&mut rng, 4.0),
                tolerance: option_value(&mut rng, 0.05),
            },
            run: run.clone(),
            period: (rng.below(2) == 0).then(|| option_value(&mut rng, 1.0)),
            damping: option_value(&mut rng, 0.05),
        };
        if study.check().is_ok() {
            if let Ok(Some(w)) = study.estimate(row, &record) {
                if w.seconds < 0.05 && !w.exceeds_step_limit() {
                    if let Ok(part) = study.record(row, &record) {
                        assert!(part.sa.is_none_or(f64::is_finite));
                        for p in &part.ida.points {
                            assert!(p.scale.is_finite() && p.scale > 0.0);
                            assert!(!p.max_drift.is_nan());
                        }
                    }
                }
            }
        }
        // pushover
        let opts = PushoverOptions {
            drift_ratio_limit: option_value(&mut rng, 0.1),
            points: option_count(&mut rng, 400),
            code_period: (rng.below(2) == 0).then(|| option_value(&mut rng, 1.0)),
        };
        if let Ok(p) = pushover(&rows[1].buildings[0].frame, &opts) {
            assert!(p
                .base_shear
                .iter()
                .chain(&p.roof_displacement)
                .all(|v| v.is_finite()));
            assert!(
                p.ductility.is_finite() && p.ductility >= 0.0,
                "{opts:?}: μT {} δy {} δu {}",
                p.ductility,
                p.yield_displacement,
                p.ultimate_displacement
            );
        }
        // hysteresis
        let uy = option_value(&mut rng, 0.01);
        let spec = match rng.below(4) {
            0 => StoreySpec::Elastic {},
            1 => StoreySpec::Bilinear {
                yield_drift: uy,
                post_yield_ratio: option_value(&mut rng, 0.05),
            },
            2 => StoreySpec::BoucWen {
                yield_drift: uy,
                post_yield_ratio: option_value(&mut rng, 0.05),
                exponent: Some(option_value(&mut rng, 2.0)),
                beta: Some(option_value(&mut rng, 0.5)),
                gamma: Some(option_value(&mut rng, 0.5)),
                degradation_a: Some(option_value(&mut rng, 0.01)),
                degradation_nu: Some(option_value(&mut rng, 0.01)),
                degradation_eta: Some(option_value(&mut rng, 0.01)),
            },
            _ => {
                let v = |rng: &mut Rng, t| Some(option_value(rng, t));
                StoreySpec::imk(
                    Some(uy),
                    [
                        v(&mut rng, 1.1),
                        v(&mut rng, 0.03),
                        v(&mut rng, 0.1),
                        v(&mut rng, 0.3),
                        v(&mut rng, 0.2),
                    ],
                    [v(&mut rng, 4.0), v(&mut rng, 4.0), v(&mut rng, 4.0)],
                    [
                        option_value(&mut rng, 1.0),
                        option_value(&mut rng, 1.0),
                        option_value(&mut rng, 1.0),
                    ],
                )
                .unwrap()
            }
        };
        let amplitudes: Vec<f64> = (0..1 + rng.below(3))
            .map(|_| option_value(&mut rng, 0.02))
            .collect();
        let protocol = cyclic_protocol(
            &amplitudes,
            option_count(&mut rng, 2),
            4 * option_count(&mut rng, 25).min(1 << 60),
        );
        let rtol = option_value(&mut rng, 1e-10);
        if let (Ok(law), Ok(drifts)) = (spec.law(option_value(&mut rng, 1e6)), protocol) {
            if drifts.len() <= 20_000 && rtol.is_finite() && rtol > 0.0 {
                if let Ok(rows) = under_drift(&law, &drifts, rtol) {
                    assert!(
                        rows.iter().all(|(f, e)| f.is_finite() && e.is_finite()),
                        "{law:?} {amplitudes:?} rtol {rtol}: {:?}",
                        rows.iter().find(|(f, e)| !(f.is_finite() && e.is_finite()))
                    );
                }
            }
        }
    });
}
