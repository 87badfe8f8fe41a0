//! Section 1: R2, N = 3, 5 periods, work-precision sweeps of every solver
//! against a tight reference, and each solver's robust setting.

use serde_json::json;

use super::Entries;
use crate::common::{error, ours, peer_or_exit, robust, Peers, Sweep, ATOL_RATIOS, TARGET_ERROR};

/// A solver's fastest robust setting: (solver, atol ratio, rtol, error,
/// seconds).
type Pick<'a> = (&'a str, f64, f64, f64, f64);

pub fn run(peers: Option<&Peers>, quick: bool) -> Entries {
    let repeats = if quick { 5 } else { 30 };
    let mut entries = Entries::new();
    println!("== R2, N = 3, Omega = 0.95 omega0, 5 periods: work-precision (atol = 1e-3 rtol) ==");
    let reference = ours(3, 5.0, 1e-13, 1e-16, 1).state;
    if let Some(p) = peers {
        let cvode = peer_or_exit(p.run("cvode-adams", 3, 5.0, 1e-13, 1e-16, 1));
        let agreement = error(&cvode.state, &reference);
        println!("reference: ours at rtol 1e-13; CVODE-Adams at 1e-13 agrees to {agreement:.1e}");
        entries.push(("reference_agreement_cvode_adams", json!(agreement)));
    }
    let solvers = sweeps(peers, &reference, repeats);
    let picks = robust_picks(&solvers);
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
    entries.push((
        "r2_n3",
        json!({
            "sweep": solvers.iter().map(|(name, q, s)| json!({"solver": name, "atol_ratio": q, "points": s.iter().map(|(r, e, run)| json!({"rtol": r, "error": e, "seconds": run.seconds, "rhs_evaluations": run.rhs, "steps": run.steps})).collect::<Vec<_>>()})).collect::<Vec<_>>(),
            "robust": pick_json,
        }),
    ));
    entries
}

/// The sweeps of every solver (ours, then the peers'), rtol 1e-6 … 1e-12
/// at each atol ratio.
fn sweeps(
    peers: Option<&Peers>,
    reference: &[f64],
    repeats: usize,
) -> Vec<(&'static str, f64, Sweep)> {
    let rtols: Vec<f64> = (6..=12).map(|k| 10f64.powi(-k)).collect();
    let mut solvers: Vec<(&str, f64, Sweep)> = Vec::new();
    for q in ATOL_RATIOS {
        let sweep = rtols
            .iter()
            .map(|&rtol| {
                let run = ours(3, 5.0, rtol, rtol * q, repeats);
                (rtol, error(&run.state, reference), run)
            })
            .collect();
        solvers.push(("vibroimpact-dop853", q, sweep));
    }
    if let Some(p) = peers {
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
                    sweep.push((rtol, error(&run.state, reference), run));
                }
                solvers.push((method, q, sweep));
            }
        }
    }
    solvers
}

/// Prints every point of the sweeps and returns, per solver, the fastest
/// robust setting over the atol ratios (saying which solvers have none).
fn robust_picks<'a>(solvers: &[(&'a str, f64, Sweep)]) -> Vec<Pick<'a>> {
    println!(
        "{:<20} {:>9} {:>8} {:>10} {:>10} {:>9}",
        "solver", "atol/rtol", "rtol", "error", "ms", "rhs"
    );
    let mut picks: Vec<Pick> = Vec::new();
    for (name, q, sweep) in solvers {
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
    for (name, _, _) in solvers {
        if !picks.iter().any(|p| p.0 == *name) {
            println!("{name}: no robust setting reaches error {TARGET_ERROR:e} in the sweep");
        }
    }
    picks
}
