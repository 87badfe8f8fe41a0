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
//! 6. The local integrator with yielding storeys (docs/theory.md §10, §11): a
//!    struck row of yielding frames, rows of buildings under a record.
//!
//! Each section is a file of `sections/` with the same entry; what they
//! share (problem R2, our runs and the peers', errors, robust settings)
//! is in `common.rs`.
//!
//! Run: `cargo run --release -p vibroimpact-bench [-- --quick] [--no-peers]`.
//!
//! `-- --check` reruns the headline comparisons instead (`check.rs`: the
//! ratios beside the recorded ones in `bench/results/`, a non-zero exit
//! where one fell by more than 20 %); `--record` with it makes the new
//! ratios the recorded ones. Run it before a change to a hot path is
//! committed.
//! It builds the peers itself (`bench/peers/build.sh`, which installs
//! libsundials-dev and a Python venv with NumPy and SciPy if missing).

/// The allocator: the rigid period maps build and drop a run's small
/// buffers per evaluation (docs/decisions.md D45).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::path::{Path, PathBuf};

use clap::Parser;
use serde_json::Value;

mod check;
mod common;
mod sections;

use common::{peer_or_exit, Peers};

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
    /// storeys (with --check: one comparison, e.g. auto-n2).
    #[arg(long)]
    only: Option<String>,
    /// Rerun the headline comparisons and compare each ratio with the
    /// recorded one (bench/results/NAME.json); exit 1 where one fell by
    /// more than 20 %.
    #[arg(long)]
    check: bool,
    /// With --check: record the new ratios (the old files go to
    /// bench/results/archive/DATE/).
    #[arg(long, requires = "check")]
    record: bool,
}

fn main() {
    let args = Args::parse();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let peers = (!args.no_peers).then(|| peer_or_exit(Peers::build(&root)));
    if args.check {
        let root = root.canonicalize().unwrap_or(root);
        std::process::exit(check::run(
            &root,
            peers.as_ref(),
            args.record,
            args.only.as_deref(),
        ));
    }
    let mut results = serde_json::Map::new();
    for (name, section) in sections::ALL {
        if args.only.as_deref().is_none_or(|o| o == name) {
            for (key, value) in section(peers.as_ref(), args.quick) {
                results.insert(key.into(), value);
            }
        }
    }
    if let Some(out) = &args.out {
        let text = serde_json::to_string_pretty(&Value::Object(results)).expect("serialisable");
        if let Err(e) = std::fs::write(out, text) {
            eprintln!("error: cannot write {}: {e}", out.display());
            std::process::exit(1);
        }
    }
}
