//! Section 5: the local integrator (docs/theory.md §10).
//!
//! 1. R2, N = 1000, 3 periods: every solver's loosest robust rtol (all
//!    tighter ones too) reaching error <= 1e-5 against ARKODE Verner 8 at
//!    rtol 1e-11, timed; the fastest SUNDIALS configuration over ours.
//! 2. The struck Hertzian chain in sonic vacuum (0.0286 kg beads, Hertz
//!    k = 7e9 N/m^1.5, bead 1 at 1 m/s, 0.02 s: the wave reaches bead 605):
//!    time and the wave's peak velocity error at default settings (rtol
//!    1e-8, atol 1e-12) for N = 10³ … 10⁶ (local) and 10³, 10⁴ (global),
//!    against the global integrator at rtol 1e-13 on N = 1000 (the wave
//!    never reaches its end).
//! 3. R2, N = 2 and 3, 20 periods at 0.95 ω0: the loosest robust rtol
//!    reaching 1e-6 against rtol 1e-13, global and local, timed.
//! 4. R2, N = 100 over 50 periods and N = 1000 over 3 periods (issue 39
//!    item 2, a stepper per cluster): the loosest robust rtol reaching
//!    1e-5 against the global integrator at rtol 1e-12, timed (N = 100 is
//!    chaotic over 50 periods: rtol 1e-8, its error after 5 periods).
//! 5. Sweeps of the example row (`examples/fujita-row-n2.toml`, its
//!    `count` set to N) over frequency, with and without Lyapunov
//!    exponents, global and local: the values one after the other (one
//!    thread), timed, with the largest exponents side by side.

use std::time::Instant;

use serde_json::{json, Value};
use vibroimpact::model::reference;
use vibroimpact::model::Model;
use vibroimpact::simulate::Integrator;

use super::Entries;
use crate::common::{error, ours_with, peer_or_exit, r2, robust_to, t_end, Peers, Run, Sweep};

/// The struck chain of `n` beads, bead 1 at 1 m/s.
fn chain(n: usize) -> Model {
    reference::struck_chain(n, 1.0).expect("valid chain")
}

/// Largest bead velocity at the end (the wave's peak).
fn peak(run: &Run) -> f64 {
    let n = run.state.len() / 2;
    run.state[n..].iter().fold(0.0f64, |m, v| m.max(*v))
}

pub fn run(peers: Option<&Peers>, quick: bool) -> Entries {
    let repeats = if quick { 2 } else { 5 };
    let mut out = serde_json::Map::new();
    out.insert("r2_n1000_3_periods".into(), r2_n1000(peers, repeats));
    out.insert("struck_chain".into(), struck_chain(quick, repeats));
    out.insert("small_rows".into(), small_rows(repeats));
    out.insert("sweeps".into(), sweeps(quick));
    vec![("local", Value::Object(out))]
}

/// Section 1: R2 N = 1000, 3 periods, every solver's robust setting.
pub fn r2_n1000(peers: Option<&Peers>, repeats: usize) -> Value {
    println!("\n== local integrator: R2, N = 1000, 3 periods, error <= 1e-5 against ARKODE Verner 8 at rtol 1e-11 ==");
    let model = r2(1000);
    let t = t_end(3.0);
    let reference = match peers {
        Some(p) => peer_or_exit(p.run("arkode-verner8", 1000, 3.0, 1e-11, 1e-14, 1)).state,
        None => ours_with(&model, t, 1e-12, 1e-15, 1, Integrator::Global).state,
    };
    let rtols: Vec<f64> = (6..=11).map(|k| 10f64.powi(-k)).collect();
    let mut rows: Vec<(String, f64, f64, f64, u64)> = Vec::new();
    for (name, integrator) in [
        ("vibroimpact-local", Integrator::Local),
        ("vibroimpact-global", Integrator::Global),
    ] {
        let sweep: Sweep = rtols
            .iter()
            .map(|&rtol| {
                let run = ours_with(&model, t, rtol, rtol * 1e-3, repeats, integrator);
                (rtol, error(&run.state, &reference), run)
            })
            .collect();
        for (rtol, err, run) in &sweep {
            println!(
                "{name:<20} rtol {rtol:.0e} error {err:.2e} {:>9.2} ms rhs {}",
                run.seconds * 1e3,
                run.rhs
            );
        }
        if let Some((rtol, err, run)) = robust_to(&sweep, 1e-5) {
            rows.push((name.into(), *rtol, *err, run.seconds, run.rhs));
        }
    }
    if let Some(p) = peers {
        for method in [
            "arkode-dp5",
            "arkode-verner8",
            "arkode-fehlberg8",
            "cvode-adams",
        ] {
            let mut sweep = Vec::new();
            for &rtol in &rtols[..5] {
                match p.run(method, 1000, 3.0, rtol, rtol * 1e-3, 3) {
                    Ok(run) => sweep.push((rtol, error(&run.state, &reference), run)),
                    Err(e) => eprintln!("{method} at rtol {rtol:e}: {e}"),
                }
            }
            for (rtol, err, run) in &sweep {
                println!(
                    "{method:<20} rtol {rtol:.0e} error {err:.2e} {:>9.2} ms rhs {}",
                    run.seconds * 1e3,
                    run.rhs
                );
            }
            if let Some((rtol, err, run)) = robust_to(&sweep, 1e-5) {
                rows.push((method.into(), *rtol, *err, run.seconds, run.rhs));
            }
        }
    }
    let local_time = rows
        .iter()
        .find(|r| r.0 == "vibroimpact-local")
        .map_or(f64::NAN, |r| r.3);
    let fastest_sundials = rows
        .iter()
        .filter(|r| r.0.starts_with("arkode") || r.0.starts_with("cvode"))
        .map(|r| r.3)
        .fold(f64::INFINITY, f64::min);
    println!("robust settings (atol = 1e-3 rtol):");
    for (name, rtol, err, secs, rhs) in &rows {
        println!(
            "{name:<20} rtol {rtol:.0e} error {err:.2e} {:>9.2} ms rhs {rhs:>7}  time / local = {:.1}",
            secs * 1e3,
            secs / local_time
        );
    }
    println!(
        "fastest SUNDIALS / local = {:.1}",
        fastest_sundials / local_time
    );
    json!({"robust": rows.iter().map(|r| json!({"solver": r.0, "rtol": r.1, "error": r.2, "seconds": r.3, "rhs_evaluations": r.4})).collect::<Vec<_>>(),
           "fastest_sundials_over_local": fastest_sundials / local_time})
}

/// Section 2: the struck chain, local from 10³ beads up, global to 10⁴.
pub fn struck_chain(quick: bool, repeats: usize) -> Value {
    println!("\n== local integrator: struck Hertzian chain, 0.02 s, default settings (rtol 1e-8, atol 1e-12) ==");
    let duration = 0.02;
    let converged = peak(&ours_with(
        &chain(1000),
        duration,
        1e-13,
        1e-17,
        1,
        Integrator::Global,
    ));
    println!("converged peak velocity (global, rtol 1e-13, N = 1000): {converged:.9} m/s");
    let mut chain_rows = Vec::new();
    let sizes: &[usize] = if quick {
        &[1000, 10_000, 100_000]
    } else {
        &[1000, 10_000, 100_000, 1_000_000]
    };
    for &n in sizes {
        let model = chain(n);
        let local = ours_with(
            &model,
            duration,
            1e-8,
            1e-12,
            if n >= 100_000 { 1 } else { repeats },
            Integrator::Local,
        );
        let mut row = json!({"n": n, "local_seconds": local.seconds, "local_error": (peak(&local) - converged).abs(), "local_steps": local.steps});
        let mut line = format!(
            "N = {n:>8}: local {:>9.3} ms, error {:.1e}",
            local.seconds * 1e3,
            (peak(&local) - converged).abs()
        );
        if n <= 10_000 {
            let global = ours_with(&model, duration, 1e-8, 1e-12, 1, Integrator::Global);
            line += &format!(
                "; global {:>9.3} ms, error {:.1e}",
                global.seconds * 1e3,
                (peak(&global) - converged).abs()
            );
            row["global_seconds"] = json!(global.seconds);
            row["global_error"] = json!((peak(&global) - converged).abs());
        }
        println!("{line}");
        chain_rows.push(row);
    }
    let time = |n: usize| {
        chain_rows
            .iter()
            .find(|r| r["n"] == n)
            .and_then(|r| r["local_seconds"].as_f64())
            .unwrap_or(f64::NAN)
    };
    println!(
        "local time(N = 10⁴) / time(N = 10³) = {:.2}",
        time(10_000) / time(1000)
    );
    json!({"converged_peak_velocity": converged, "rows": chain_rows})
}

/// Section 3: R2, N = 2 and 3, 20 periods, global and local.
fn small_rows(repeats: usize) -> Value {
    println!("\n== local integrator: R2, 20 periods, error <= 1e-6 against rtol 1e-13 ==");
    let mut small = Vec::new();
    for n in [2usize, 3] {
        let model = r2(n);
        let t = t_end(20.0);
        let reference = ours_with(&model, t, 1e-13, 1e-16, 1, Integrator::Global).state;
        let mut picks = Vec::new();
        for (name, integrator) in [("global", Integrator::Global), ("local", Integrator::Local)] {
            let sweep: Sweep = (6..=12)
                .map(|k| {
                    let rtol = 10f64.powi(-k);
                    let run = ours_with(&model, t, rtol, rtol * 1e-3, repeats * 4, integrator);
                    (rtol, error(&run.state, &reference), run)
                })
                .collect();
            match robust_to(&sweep, 1e-6) {
                Some((rtol, err, run)) => {
                    println!(
                        "N = {n} {name:<6}: rtol {rtol:.0e} error {err:.2e} {:>8.3} ms rhs {}",
                        run.seconds * 1e3,
                        run.rhs
                    );
                    picks.push((name, run.seconds));
                    small.push(json!({"n": n, "integrator": name, "rtol": rtol, "error": err, "seconds": run.seconds, "rhs_evaluations": run.rhs}));
                }
                None => println!(
                    "N = {n} {name:<6}: no rtol down to 1e-12 keeps the error below 1e-6 (errors {:?})",
                    sweep.iter().map(|s| format!("{:.0e}", s.1)).collect::<Vec<_>>()
                ),
            }
        }
        if let [(_, g), (_, l)] = picks[..] {
            println!("N = {n}: global / local = {:.2}", g / l);
        }
    }
    Value::Array(small)
}

/// Section 4 (its own entry, `--only clusters`): long runs of many
/// clusters, R2 N = 100 over 50 periods and N = 1000 over 3, local at its
/// robust rtol.
pub fn clusters_section(_: Option<&Peers>, quick: bool) -> Entries {
    vec![("clusters", clusters(if quick { 1 } else { 3 }))]
}

/// The runs of [`clusters_section`], best of `repeats`.
pub fn clusters(repeats: usize) -> Value {
    println!("\n== local integrator: many clusters, error <= 1e-5 against global rtol 1e-12 ==");
    let mut rows = Vec::new();
    for (n, periods) in [(100usize, 50.0), (1000, 3.0)] {
        let model = r2(n);
        let t = t_end(periods);
        let reference = ours_with(&model, t, 1e-12, 1e-15, 1, Integrator::Global).state;
        let sweep: Sweep = (6..=11)
            .map(|k| {
                let rtol = 10f64.powi(-k);
                let run = ours_with(&model, t, rtol, rtol * 1e-3, repeats, Integrator::Local);
                (rtol, error(&run.state, &reference), run)
            })
            .collect();
        for (rtol, err, run) in &sweep {
            println!(
                "N = {n:>4}, {periods} periods: rtol {rtol:.0e} error {err:.2e} {:>9.2} ms rhs {} steps {}",
                run.seconds * 1e3,
                run.rhs,
                run.steps
            );
        }
        match robust_to(&sweep, 1e-5) {
            Some((rtol, err, run)) => {
                println!(
                    "N = {n:>4}: robust rtol {rtol:.0e}, error {err:.2e}, {:.2} ms",
                    run.seconds * 1e3
                );
                rows.push(
                    json!({"n": n, "periods": periods, "rtol": rtol, "error": err,
                    "seconds": run.seconds, "rhs_evaluations": run.rhs, "steps": run.steps}),
                );
            }
            None => {
                // Chaotic over the whole run (every rtol errs by O(1) at its
                // end): each rtol's error is taken over the first 5
                // periods, where it is defined, and the run is timed over
                // all 50 at the robust rtol of those errors.
                let short = t_end(5.0);
                let reference = ours_with(&model, short, 1e-12, 1e-15, 1, Integrator::Global);
                let early: Sweep = sweep
                    .iter()
                    .map(|(rtol, _, run)| {
                        let e = ours_with(&model, short, *rtol, rtol * 1e-3, 1, Integrator::Local);
                        (*rtol, error(&e.state, &reference.state), run.clone())
                    })
                    .collect();
                for (rtol, err, _) in &early {
                    println!("N = {n:>4}: rtol {rtol:.0e} error {err:.2e} after 5 periods");
                }
                let (rtol, err, run) =
                    robust_to(&early, 1e-5).expect("a robust rtol over 5 periods");
                println!(
                    "N = {n:>4}: chaotic over {periods} periods; robust rtol over 5 periods {rtol:.0e} (error {err:.2e}): {:.2} ms over {periods}",
                    run.seconds * 1e3
                );
                rows.push(json!({"n": n, "periods": periods, "rtol": rtol,
                    "error_after_5_periods": err, "seconds": run.seconds,
                    "rhs_evaluations": run.rhs, "steps": run.steps}));
            }
        }
    }
    Value::Array(rows)
}

/// A sweep of section 5: bodies, values, transient and recorded periods,
/// Lyapunov exponents.
type SweepCase = (usize, &'static [f64], usize, usize, Option<usize>);

/// Section 5: sweeps of R2 rows, global against local.
fn sweeps(quick: bool) -> Value {
    use vibroimpact::maps::sweep::{sweep, SweepOptions};
    use vibroimpact::model::file::ModelDocument;
    use vibroimpact::model::parameter::ParameterizedModel;
    println!("\n== local integrator: sweeps of R2 (examples/fujita-row-n2.toml), values one after the other ==");
    let cases: &[SweepCase] = if quick {
        &[(100, &[6.0, 14.0], 10, 5, Some(2))]
    } else {
        &[
            (100, &[6.0, 26.0 / 3.0, 34.0 / 3.0, 14.0], 50, 20, None),
            (100, &[6.0, 14.0], 20, 20, Some(2)),
            (1000, &[6.0, 14.0], 10, 5, None),
            (1000, &[6.0, 14.0], 10, 10, Some(2)),
        ]
    };
    let mut rows = Vec::new();
    for &(n, values, transient, record, lyapunov) in cases {
        let text = include_str!("../../../examples/fujita-row-n2.toml")
            .replace("count = 2", &format!("count = {n}"));
        let doc = ModelDocument::from_toml(&text, "row").expect("the example row");
        let family = ParameterizedModel::new(doc, "frequency").expect("a frequency");
        let mut seconds = [0.0f64; 2];
        let mut largest: [Vec<Option<f64>>; 2] = [Vec::new(), Vec::new()];
        for (side, integrator) in [Integrator::Global, Integrator::Local]
            .into_iter()
            .enumerate()
        {
            let options = SweepOptions {
                transient,
                record,
                lyapunov,
                integrator,
                ..SweepOptions::default()
            };
            for &v in values {
                let start = Instant::now();
                let summary = sweep(&family, &[v], &options, &|| {}).expect("sweep");
                seconds[side] += start.elapsed().as_secs_f64();
                let point = &summary.points[0];
                assert!(point.error.is_none(), "{n} {v}: {:?}", point.error);
                largest[side].push(point.lyapunov.as_ref().map(|l| l[0]));
            }
        }
        println!(
            "N = {n:>4}, {} values, {transient} + {record} periods{}: global {:.2} s, local {:.2} s, global / local = {:.1}",
            values.len(),
            if lyapunov.is_some() { ", --lyapunov 2" } else { "" },
            seconds[0],
            seconds[1],
            seconds[0] / seconds[1]
        );
        if lyapunov.is_some() {
            println!(
                "         largest exponents: global {:?}, local {:?}",
                largest[0], largest[1]
            );
        }
        rows.push(
            json!({"n": n, "values": values, "transient": transient, "record": record,
            "lyapunov": lyapunov, "global_seconds": seconds[0], "local_seconds": seconds[1],
            "global_largest_exponent": largest[0], "local_largest_exponent": largest[1]}),
        );
    }
    Value::Array(rows)
}
