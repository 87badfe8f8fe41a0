//! Section 4: the cost of one shooting period map with the full monodromy
//! (dense variational equations, banded Jacobian) for N = 10 … 160 at rtol
//! 1e-8, with the fitted growth exponent (issue: no faster than N²), and
//! matrix-free Newton–Krylov on R2 N = 1000 against the dense step.

use std::time::Instant;

use serde_json::json;
use vibroimpact::model::reference;
use vibroimpact::periodic::{guess_by_simulation, period_map, shoot_krylov, ShootingOptions};

use super::Entries;
use crate::common::{r2, Peers};

pub fn run(_peers: Option<&Peers>, _quick: bool) -> Entries {
    println!("\n== shooting: one period map with the full monodromy, rtol 1e-8 ==");
    let mut rows = Vec::new();
    for n in [10usize, 20, 40, 80, 160] {
        let model = r2(n);
        let opts = ShootingOptions {
            rtol: 1e-8,
            ..Default::default()
        };
        let x = vec![0.0; 2 * n];
        let mut best = f64::INFINITY;
        for _ in 0..if n >= 160 { 1 } else { 3 } {
            let start = Instant::now();
            period_map(&model, &x, &opts).expect("period map");
            best = best.min(start.elapsed().as_secs_f64());
        }
        println!("N = {n:>4}: {:>10.3} ms", best * 1e3);
        rows.push((n as f64, best));
    }
    let exponent = growth_exponent(&rows[rows.len() - 3..]);
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
    let guess = guess_by_simulation(&model, 200.0, 1e-9).expect("guess");
    let guess_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let opts = ShootingOptions::default();
    let sol = shoot_krylov(&model, &guess, &opts, 20).expect("shooting");
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
    vec![(
        "shooting",
        json!({"rows": rows.iter().map(|r| json!({"n": r.0, "seconds": r.1})).collect::<Vec<_>>(), "exponent": exponent,
            "n1000_krylov": {"seconds": krylov_seconds, "guess_seconds": guess_seconds, "newton_steps": sol.residual_history.len() - 1,
                "converged": sol.converged, "stable": sol.stable(), "spectral_radius": sol.spectral_radius(), "dense_step_extrapolated_seconds": dense_step}}),
    )]
}

/// Least-squares slope of log(time) against log(N) over three rows
/// (N, seconds).
fn growth_exponent(tail: &[(f64, f64)]) -> f64 {
    let (mx, my) = tail.iter().fold((0.0, 0.0), |a, r| {
        (a.0 + r.0.ln() / 3.0, a.1 + r.1.ln() / 3.0)
    });
    let (sxy, sxx) = tail.iter().fold((0.0, 0.0), |a, r| {
        (
            a.0 + (r.0.ln() - mx) * (r.1.ln() - my),
            a.1 + (r.0.ln() - mx).powi(2),
        )
    });
    sxy / sxx
}
