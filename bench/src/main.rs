//! `vibroimpact-bench`: the project's performance claims, measured against
//! peers on the same problem in one run (ratios, not absolute times).
//!
//! Problem R2 (docs/theory.md §6): N pendulums between walls, exponential law,
//! base acceleration 0.05 sin(0.95 ω0 t), from rest. Peers (bench/peers):
//! SUNDIALS 6.4.1 (CVODE, ARKODE explicit tables) with a C right-hand side
//! and SciPy `solve_ivp` with a vectorised NumPy right-hand side.
//!
//! 1. N = 3, 5 periods: work-precision sweep for every solver (rtol 1e-6 …
//!    1e-12, atol = q rtol for q in 1e-2, 1e-3, 1e-4), error =
//!    max |y - y_ref| / max |y_ref| of the final state against a tight
//!    reference. For each solver and q the *robust* setting is the loosest
//!    rtol from which every tighter rtol meets error <= 1e-6 (impacts make
//!    the error erratic in rtol); each solver is timed at its best q, and
//!    the ratios compare those times.
//! 2. N = 1000, 1 period, rtol 1e-8: time against every ARKODE explicit
//!    method, with the achieved errors.
//! 3. Time per period for N = 10, 100, 1000, 10000 at rtol 1e-8.
//! 4. Cost of one shooting period map with the full monodromy (dense
//!    variational equations, banded Jacobian) for N = 10 … 160 at rtol
//!    1e-8, with the fitted growth exponent (issue: no faster than N²).
//! 5. The local integrator (docs/theory.md §10, `simulate/local/`): R2 N = 1000
//!    over 3 periods against SUNDIALS at equal accuracy, the struck
//!    Hertzian chain from 10³ to 10⁶ beads, R2 N = 2 and 3 at equal
//!    accuracy against the global integrator.
//!
//! Run: `cargo run --release -p vibroimpact-bench [-- --quick] [--no-peers]`.
//! It builds the peers itself (`bench/peers/build.sh`, which installs
//! libsundials-dev and a Python venv with NumPy and SciPy if missing).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use clap::Parser;
use serde_json::{json, Value};
use vibroimpact::model::reference;
use vibroimpact::model::Model;
use vibroimpact::simulate::{simulate, Integrator, SimulationOptions};

mod local;
mod storeys;

#[derive(Parser, Debug)]
#[command(about = "Benchmarks of vibroimpact against SUNDIALS and SciPy on reference problem R2")]
struct Args {
    /// Fewer repeats, no N = 10000.
    #[arg(long)]
    quick: bool,
    /// Only our own solver (no peers).
    #[arg(long)]
    no_peers: bool,
    /// Write the results as JSON here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Run only one section: n3, n1000, scaling, shooting, local or
    /// storeys.
    #[arg(long)]
    only: Option<String>,
}

const OMEGA_RATIO: f64 = 0.95;
const TARGET_ERROR: f64 = 1e-6;
const ATOL_RATIOS: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// Work-precision points of one solver at one atol ratio: (rtol, error, run).
type Sweep = Vec<(f64, f64, Run)>;

fn r2(n: usize) -> Model {
    reference::r2(
        n,
        reference::CLEARANCE,
        OMEGA_RATIO * reference::NATURAL_FREQUENCY,
    )
    .expect("valid model")
}

fn t_end(periods: f64) -> f64 {
    periods * 2.0 * std::f64::consts::PI / (OMEGA_RATIO * reference::NATURAL_FREQUENCY)
}

/// One solver run: final state [u.., v..], best wall time, work counters.
#[derive(Clone, Debug)]
struct Run {
    state: Vec<f64>,
    seconds: f64,
    rhs: u64,
    steps: u64,
}

fn ours(n: usize, periods: f64, rtol: f64, atol: f64, repeats: usize) -> Run {
    ours_with(
        &r2(n),
        t_end(periods),
        rtol,
        atol,
        repeats,
        Integrator::Global,
    )
}

/// Our run of `model` over `[0, t_end]` with this integrator: the best
/// wall time of `repeats`.
fn ours_with(
    model: &Model,
    t_end: f64,
    rtol: f64,
    atol: f64,
    repeats: usize,
    integrator: Integrator,
) -> Run {
    let opts = SimulationOptions {
        t_end,
        rtol,
        atol,
        integrator,
        ..SimulationOptions::default()
    };
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let sim = simulate(model, &opts).expect("valid options");
        best = best.min(start.elapsed().as_secs_f64());
        assert!(
            sim.error.is_none(),
            "our integration failed: {:?}",
            sim.error
        );
        last = Some(sim);
    }
    let sim = last.expect("at least one run");
    Run {
        state: sim.final_state(),
        seconds: best,
        rhs: sim.stats.rhs_evaluations,
        steps: sim.stats.steps,
    }
}

struct Peers {
    dir: PathBuf,
}

impl Peers {
    fn build(root: &Path) -> Result<Self, String> {
        let dir = root.join("bench/peers");
        let status = Command::new("bash")
            .arg(dir.join("build.sh"))
            .status()
            .map_err(|e| format!("cannot run bench/peers/build.sh: {e}"))?;
        if !status.success() {
            return Err("bench/peers/build.sh failed".into());
        }
        Ok(Self { dir })
    }

    fn run(
        &self,
        method: &str,
        n: usize,
        periods: f64,
        rtol: f64,
        atol: f64,
        repeats: usize,
    ) -> Result<Run, String> {
        let args = [
            n.to_string(),
            OMEGA_RATIO.to_string(),
            periods.to_string(),
            format!("{rtol:e}"),
            format!("{atol:e}"),
            repeats.to_string(),
        ];
        let output = if let Some(m) = method.strip_prefix("scipy-") {
            Command::new(self.dir.join("build/venv/bin/python"))
                .arg(self.dir.join("r2_scipy.py"))
                .arg(m)
                .args(&args)
                .output()
        } else {
            Command::new(self.dir.join("build/r2_sundials"))
                .arg(method)
                .args(&args)
                .output()
        }
        .map_err(|e| format!("{method}: {e}"))?;
        if !output.status.success() {
            return Err(format!(
                "{method} failed: {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ));
        }
        let line = String::from_utf8_lossy(&output.stdout);
        let v: Value =
            serde_json::from_str(line.trim()).map_err(|e| format!("{method}: bad output: {e}"))?;
        let state = v["final_state"]
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_f64).collect())
            .unwrap_or_default();
        Ok(Run {
            state,
            seconds: v["seconds"].as_f64().unwrap_or(f64::NAN),
            rhs: v["rhs_evaluations"].as_u64().unwrap_or(0),
            steps: v["steps"].as_u64().unwrap_or(0),
        })
    }
}

fn error(state: &[f64], reference: &[f64]) -> f64 {
    let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    state
        .iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale
}

/// The robust setting of a sweep (rtol descending): the loosest rtol from
/// which every tighter one meets the target.
fn robust(sweep: &[(f64, f64, Run)]) -> Option<&(f64, f64, Run)> {
    robust_to(sweep, TARGET_ERROR)
}

/// The loosest rtol (of a sweep from loose to tight) from which every
/// tighter one meets `target`.
fn robust_to(sweep: &[(f64, f64, Run)], target: f64) -> Option<&(f64, f64, Run)> {
    let mut pick = None;
    for entry in sweep.iter().rev() {
        if entry.1 <= target {
            pick = Some(entry);
        } else {
            break;
        }
    }
    pick
}

fn main() {
    let args = Args::parse();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let peers = if args.no_peers {
        None
    } else {
        match Peers::build(&root) {
            Ok(p) => Some(p),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
    };
    let peer_or_exit = |r: Result<Run, String>| match r {
        Ok(run) => run,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    };
    let repeats = if args.quick { 5 } else { 30 };
    let mut results = serde_json::Map::new();

    let run = |name: &str| args.only.as_deref().is_none_or(|o| o == name);
    if run("n3") {
        // 1. N = 3, 5 periods, work-precision.
        println!(
            "== R2, N = 3, Omega = 0.95 omega0, 5 periods: work-precision (atol = 1e-3 rtol) =="
        );
        let reference = ours(3, 5.0, 1e-13, 1e-16, 1).state;
        if let Some(p) = &peers {
            let cvode = peer_or_exit(p.run("cvode-adams", 3, 5.0, 1e-13, 1e-16, 1));
            let agreement = error(&cvode.state, &reference);
            println!(
                "reference: ours at rtol 1e-13; CVODE-Adams at 1e-13 agrees to {agreement:.1e}"
            );
            results.insert("reference_agreement_cvode_adams".into(), json!(agreement));
        }
        let rtols: Vec<f64> = (6..=12).map(|k| 10f64.powi(-k)).collect();
        let mut solvers: Vec<(&str, f64, Sweep)> = Vec::new();
        for q in ATOL_RATIOS {
            let sweep = rtols
                .iter()
                .map(|&rtol| {
                    let run = ours(3, 5.0, rtol, rtol * q, repeats);
                    (rtol, error(&run.state, &reference), run)
                })
                .collect();
            solvers.push(("vibroimpact-dop853", q, sweep));
        }
        if let Some(p) = &peers {
            for method in [
                "arkode-dp5",
                "arkode-verner8",
                "arkode-fehlberg8",
                "cvode-adams",
                "scipy-dop853",
            ] {
                let scipy = method.starts_with("scipy");
                for q in ATOL_RATIOS {
                    let mut sweep = Vec::new();
                    for &rtol in &rtols {
                        if scipy && rtol < 1e-11 {
                            continue; // seconds per point; its robust setting is found before
                        }
                        let reps = if scipy { 3 } else { repeats };
                        let run = peer_or_exit(p.run(method, 3, 5.0, rtol, rtol * q, reps));
                        sweep.push((rtol, error(&run.state, &reference), run));
                    }
                    solvers.push((method, q, sweep));
                }
            }
        }
        println!(
            "{:<20} {:>9} {:>8} {:>10} {:>10} {:>9}",
            "solver", "atol/rtol", "rtol", "error", "ms", "rhs"
        );
        // Per solver: the fastest robust setting over the atol ratios.
        let mut picks: Vec<(&str, f64, f64, f64, f64)> = Vec::new();
        for (name, q, sweep) in &solvers {
            for (rtol, err, run) in sweep {
                println!(
                    "{name:<20} {q:>9.0e} {rtol:>8.0e} {err:>10.2e} {:>10.3} {:>9}",
                    run.seconds * 1e3,
                    run.rhs
                );
            }
            if let Some((rtol, err, run)) = robust(sweep) {
                match picks.iter_mut().find(|p| p.0 == *name) {
                    Some(p) if p.4 <= run.seconds => {}
                    Some(p) => *p = (name, *q, *rtol, *err, run.seconds),
                    None => picks.push((name, *q, *rtol, *err, run.seconds)),
                }
            }
        }
        for (name, _, _) in &solvers {
            if !picks.iter().any(|p| p.0 == *name) {
                println!("{name}: no robust setting reaches error {TARGET_ERROR:e} in the sweep");
            }
        }
        let our_time = picks
            .iter()
            .find(|p| p.0 == "vibroimpact-dop853")
            .map_or(f64::NAN, |p| p.4);
        println!("\nrobust settings (loosest rtol from which all tighter meet error <= 1e-6; best atol ratio):");
        let mut pick_json = Vec::new();
        for (name, q, rtol, err, secs) in &picks {
            let ratio = secs / our_time;
            println!(
            "{name:<20} atol/rtol {q:.0e} rtol {rtol:.0e}  error {err:.2e}  {:.3} ms  peer/ours = {ratio:.1}",
            secs * 1e3
        );
            pick_json.push(json!({"solver": name, "atol_ratio": q, "rtol": rtol, "error": err, "seconds": secs, "ratio_to_ours": ratio}));
        }
        results.insert(
        "r2_n3".into(),
        json!({
            "sweep": solvers.iter().map(|(name, q, s)| json!({"solver": name, "atol_ratio": q, "points": s.iter().map(|(r, e, run)| json!({"rtol": r, "error": e, "seconds": run.seconds, "rhs_evaluations": run.rhs, "steps": run.steps})).collect::<Vec<_>>()})).collect::<Vec<_>>(),
            "robust": pick_json,
        }),
    );
    }
    if run("n1000") {
        // 2. N = 1000, 1 period, rtol 1e-8.
        println!("\n== R2, N = 1000, 1 period, rtol 1e-8, atol 1e-11 ==");
        let reference = ours(1000, 1.0, 1e-12, 1e-15, 1).state;
        let mine = ours(1000, 1.0, 1e-8, 1e-11, if args.quick { 3 } else { 10 });
        let mut rows = vec![(
            "vibroimpact-dop853",
            error(&mine.state, &reference),
            mine.clone(),
        )];
        if let Some(p) = &peers {
            for method in [
                "arkode-dp5",
                "arkode-verner8",
                "arkode-fehlberg8",
                "scipy-dop853",
            ] {
                let run = peer_or_exit(p.run(method, 1000, 1.0, 1e-8, 1e-11, 3));
                rows.push((method, error(&run.state, &reference), run));
            }
        }
        let best_arkode = rows
            .iter()
            .filter(|r| r.0.starts_with("arkode"))
            .map(|r| r.2.seconds)
            .fold(f64::INFINITY, f64::min);
        for (name, err, run) in &rows {
            println!(
                "{name:<20} {:>9.2} ms  error {err:.2e}  rhs {:>6}  steps {:>5}  time/ours {:.1}",
                run.seconds * 1e3,
                run.rhs,
                run.steps,
                run.seconds / mine.seconds
            );
        }
        if best_arkode.is_finite() {
            println!(
                "fastest ARKODE explicit / ours = {:.1}",
                best_arkode / mine.seconds
            );
        }
        results.insert(
        "r2_n1000".into(),
        json!({"runs": rows.iter().map(|(n, e, r)| json!({"solver": n, "error": e, "seconds": r.seconds, "rhs_evaluations": r.rhs, "steps": r.steps})).collect::<Vec<_>>(),
               "fastest_arkode_over_ours": best_arkode / mine.seconds}),
    );
    }
    if run("scaling") {
        // 3. Scaling.
        println!("\n== time per period, rtol 1e-8 ==");
        let sizes: &[usize] = if args.quick {
            &[10, 100, 1000]
        } else {
            &[10, 100, 1000, 10000]
        };
        let mut scaling = Vec::new();
        for &n in sizes {
            let run = ours(n, 1.0, 1e-8, 1e-11, if n >= 10000 { 2 } else { 7 });
            let peer = peers
                .as_ref()
                .map(|p| peer_or_exit(p.run("arkode-verner8", n, 1.0, 1e-8, 1e-11, 1)));
            let per_body_us = run.seconds / n as f64 * 1e6;
            match &peer {
            Some(pr) => println!(
                "N = {n:>6}: ours {:>9.3} ms ({per_body_us:.2} µs per body), ARKODE Verner {:>9.3} ms, ratio {:.1}",
                run.seconds * 1e3,
                pr.seconds * 1e3,
                pr.seconds / run.seconds
            ),
            None => println!("N = {n:>6}: ours {:>9.3} ms ({per_body_us:.2} µs per body)", run.seconds * 1e3),
        }
            scaling.push(json!({"n": n, "ours_seconds": run.seconds, "ours_rhs": run.rhs, "arkode_verner8_seconds": peer.map(|p| p.seconds)}));
        }
        results.insert("scaling".into(), Value::Array(scaling));
    }
    if run("shooting") {
        // 4. Shooting cost per period map with the full monodromy.
        println!("\n== shooting: one period map with the full monodromy, rtol 1e-8 ==");
        let mut rows = Vec::new();
        for n in [10usize, 20, 40, 80, 160] {
            let model = r2(n);
            let opts = vibroimpact::periodic::ShootingOptions {
                rtol: 1e-8,
                ..Default::default()
            };
            let x = vec![0.0; 2 * n];
            let mut best = f64::INFINITY;
            for _ in 0..if n >= 160 { 1 } else { 3 } {
                let start = Instant::now();
                vibroimpact::periodic::period_map(&model, &x, &opts).expect("period map");
                best = best.min(start.elapsed().as_secs_f64());
            }
            println!("N = {n:>4}: {:>10.3} ms", best * 1e3);
            rows.push((n as f64, best));
        }
        // Least-squares slope of log(time) against log(N) over the largest three.
        let tail = &rows[rows.len() - 3..];
        let (mx, my) = tail.iter().fold((0.0, 0.0), |a, r| {
            (a.0 + r.0.ln() / 3.0, a.1 + r.1.ln() / 3.0)
        });
        let (sxy, sxx) = tail.iter().fold((0.0, 0.0), |a, r| {
            (
                a.0 + (r.0.ln() - mx) * (r.1.ln() - my),
                a.1 + (r.0.ln() - mx).powi(2),
            )
        });
        let exponent = sxy / sxx;
        println!("growth exponent (N = 40 … 160): {exponent:.2}");
        // Matrix-free Newton–Krylov for the R2 N = 1000 orbit at 0.5 ω0 (the
        // end pendulums strike the walls), against the dense Newton step it
        // replaces (one period map with Φ, extrapolated from N = 160 with
        // the measured exponent).
        let model = reference::r2(
            1000,
            reference::CLEARANCE,
            0.5 * reference::NATURAL_FREQUENCY,
        )
        .expect("valid model");
        let start = Instant::now();
        let guess = vibroimpact::periodic::guess_by_simulation(&model, 200.0, 1e-9).expect("guess");
        let guess_seconds = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let opts = vibroimpact::periodic::ShootingOptions::default();
        let sol = vibroimpact::periodic::shoot_krylov(&model, &guess, &opts, 20).expect("shooting");
        let krylov_seconds = start.elapsed().as_secs_f64();
        let (n_last, t_last) = rows[rows.len() - 1];
        let dense_step = t_last * (1000.0 / n_last).powf(exponent);
        println!(
            "N = 1000, 0.5 ω0, Newton–Krylov: {krylov_seconds:.2} s ({} Newton steps, converged {}, stable {}, |μ|max {:.4}) after a {guess_seconds:.2} s guess (200 periods); one dense Newton step ≈ {dense_step:.0} s (extrapolated): ratio {:.0}",
            sol.residual_history.len() - 1,
            sol.converged,
            sol.stable(),
            sol.spectral_radius(),
            dense_step / krylov_seconds
        );
        results.insert(
            "shooting".into(),
            json!({"rows": rows.iter().map(|r| json!({"n": r.0, "seconds": r.1})).collect::<Vec<_>>(), "exponent": exponent,
                "n1000_krylov": {"seconds": krylov_seconds, "guess_seconds": guess_seconds, "newton_steps": sol.residual_history.len() - 1,
                    "converged": sol.converged, "stable": sol.stable(), "spectral_radius": sol.spectral_radius(), "dense_step_extrapolated_seconds": dense_step}}),
        );
    }
    if run("local") {
        results.insert("local".into(), local::run(peers.as_ref(), args.quick));
    }
    if run("storeys") {
        results.insert("storeys".into(), storeys::run(args.quick));
    }
    if let Some(out) = &args.out {
        let text = serde_json::to_string_pretty(&Value::Object(results)).expect("serialisable");
        if let Err(e) = std::fs::write(out, text) {
            eprintln!("error: cannot write {}: {e}", out.display());
            std::process::exit(1);
        }
    }
}
