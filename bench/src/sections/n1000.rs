//! Section 2: R2, N = 1000, 1 period, rtol 1e-8: our time against every
//! ARKODE explicit method (and SciPy), with the achieved errors.

use serde_json::json;

use super::Entries;
use crate::common::{error, ours, peer_or_exit, Peers};

pub fn run(peers: Option<&Peers>, quick: bool) -> Entries {
    println!("\n== R2, N = 1000, 1 period, rtol 1e-8, atol 1e-11 ==");
    let reference = ours(1000, 1.0, 1e-12, 1e-15, 1).state;
    let mine = ours(1000, 1.0, 1e-8, 1e-11, if quick { 3 } else { 10 });
    let mut rows = vec![(
        "vibroimpact-dop853",
        error(&mine.state, &reference),
        mine.clone(),
    )];
    if let Some(p) = peers {
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
    vec![(
        "r2_n1000",
        json!({"runs": rows.iter().map(|(n, e, r)| json!({"solver": n, "error": e, "seconds": r.seconds, "rhs_evaluations": r.rhs, "steps": r.steps})).collect::<Vec<_>>(),
               "fastest_arkode_over_ours": best_arkode / mine.seconds}),
    )]
}
