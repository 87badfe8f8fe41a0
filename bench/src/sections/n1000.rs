//! Section 2: R2, N = 1000, 1 period: every ARKODE explicit method (and
//! SciPy) at rtol 1e-8, with the achieved errors, against ours at rtol
//! 1e-8 and at equal accuracy: for each peer, our fastest run of rtol
//! 1e-6 … 1e-8 from the loosest rtol whose run and every tighter one have
//! an error at most the peer's. The per-body error norm
//! (docs/theory.md §10) makes our rtol-1e-8 run 100 times more accurate
//! than the peers' (1.9e-9 against 3.2e-7 … 3.7e-6), so equal rtol
//! compares unequal work; the headline is the equal-accuracy ratio.

use serde_json::json;

use super::Entries;
use crate::common::{error, ours, peer_or_exit, Peers, Run};

/// A peer's run: solver, error, the run, our time at equal accuracy.
type PeerRow<'a> = (&'a str, f64, Run, f64);

pub fn run(peers: Option<&Peers>, quick: bool) -> Entries {
    println!("\n== R2, N = 1000, 1 period, atol = 1e-3 rtol ==");
    let reference = ours(1000, 1.0, 1e-12, 1e-15, 1).state;
    let repeats = if quick { 3 } else { 10 };
    let mine: Vec<(f64, f64, Run)> = [1e-6, 3e-7, 1e-7, 3e-8, 1e-8]
        .into_iter()
        .map(|rtol| {
            let run = ours(1000, 1.0, rtol, 1e-3 * rtol, repeats);
            (rtol, error(&run.state, &reference), run)
        })
        .collect();
    let at_1e8 = &mine[4].2;
    for (rtol, err, run) in &mine {
        println!(
            "{:<20} rtol {rtol:.0e} {:>9.2} ms  error {err:.2e}  rhs {:>6}  steps {:>5}",
            "vibroimpact-dop853",
            run.seconds * 1e3,
            run.rhs,
            run.steps,
        );
    }
    let mut rows: Vec<PeerRow> = Vec::new();
    if let Some(p) = peers {
        for method in [
            "arkode-dp5",
            "arkode-verner8",
            "arkode-fehlberg8",
            "scipy-dop853",
        ] {
            let run = peer_or_exit(p.run(method, 1000, 1.0, 1e-8, 1e-11, 3));
            let err = error(&run.state, &reference);
            // Ours at equal accuracy, robustly (impacts make the error
            // erratic in rtol): from the loosest rtol whose run and every
            // tighter one are at least as accurate, the fastest of those.
            let from = (0..mine.len())
                .find(|&i| mine[i..].iter().all(|m| m.1 <= err))
                .unwrap_or(mine.len());
            let equal = mine[from..]
                .iter()
                .map(|m| m.2.seconds)
                .fold(f64::INFINITY, f64::min);
            rows.push((method, err, run, equal));
        }
    }
    for (name, err, run, equal) in &rows {
        println!(
            "{name:<20} rtol 1e-8 {:>9.2} ms  error {err:.2e}  rhs {:>6}  steps {:>5}  time / ours at rtol 1e-8 {:.1}, at equal accuracy {:.1}",
            run.seconds * 1e3,
            run.rhs,
            run.steps,
            run.seconds / at_1e8.seconds,
            run.seconds / equal,
        );
    }
    let best = |f: &dyn Fn(&PeerRow) -> f64| {
        rows.iter()
            .filter(|r| r.0.starts_with("arkode"))
            .map(f)
            .fold(f64::INFINITY, f64::min)
    };
    let (same_rtol, equal) = (
        best(&|r| r.2.seconds / at_1e8.seconds),
        best(&|r| r.2.seconds / r.3),
    );
    if same_rtol.is_finite() {
        println!("fastest ARKODE explicit / ours: {equal:.1} at equal accuracy, {same_rtol:.1} at rtol 1e-8");
    }
    vec![(
        "r2_n1000",
        json!({"ours": mine.iter().map(|(rtol, e, r)| json!({"rtol": rtol, "error": e, "seconds": r.seconds, "rhs_evaluations": r.rhs, "steps": r.steps})).collect::<Vec<_>>(),
               "runs": rows.iter().map(|(n, e, r, eq)| json!({"solver": n, "rtol": 1e-8, "error": e, "seconds": r.seconds, "rhs_evaluations": r.rhs, "steps": r.steps, "ours_at_equal_accuracy_seconds": eq})).collect::<Vec<_>>(),
               "fastest_arkode_over_ours": equal,
               "fastest_arkode_over_ours_at_rtol_1e-8": same_rtol}),
    )]
}
