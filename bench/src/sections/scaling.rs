//! Section 3: time per period of R2 for N = 10, 100, 1000, 10000 at rtol
//! 1e-8, against ARKODE Verner 8.

use serde_json::{json, Value};

use super::Entries;
use crate::common::{ours, peer_or_exit, Peers};

pub fn run(peers: Option<&Peers>, quick: bool) -> Entries {
    println!("\n== time per period, rtol 1e-8 ==");
    let sizes: &[usize] = if quick {
        &[10, 100, 1000]
    } else {
        &[10, 100, 1000, 10000]
    };
    let mut scaling = Vec::new();
    for &n in sizes {
        let run = ours(n, 1.0, 1e-8, 1e-11, if n >= 10000 { 2 } else { 7 });
        let peer = peers.map(|p| peer_or_exit(p.run("arkode-verner8", n, 1.0, 1e-8, 1e-11, 1)));
        let per_body_us = run.seconds / n as f64 * 1e6;
        match &peer {
            Some(pr) => println!(
                "N = {n:>6}: ours {:>9.3} ms ({per_body_us:.2} µs per body), ARKODE Verner {:>9.3} ms, ratio {:.1}",
                run.seconds * 1e3,
                pr.seconds * 1e3,
                pr.seconds / run.seconds
            ),
            None => println!(
                "N = {n:>6}: ours {:>9.3} ms ({per_body_us:.2} µs per body)",
                run.seconds * 1e3
            ),
        }
        scaling.push(json!({"n": n, "ours_seconds": run.seconds, "ours_rhs": run.rhs, "arkode_verner8_seconds": peer.map(|p| p.seconds)}));
    }
    vec![("scaling", Value::Array(scaling))]
}
