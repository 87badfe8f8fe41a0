//! The Rust side of the Python-overhead benchmark (`bench/python/bench.py`):
//! times `simulate` of a model file, as `vibroimpact.simulate(model,
//! periods=P, rtol=R, output_step=0)` does from Python.
//!
//! `cargo run --release -p vibroimpact-bench --bin time_simulate -- MODEL PERIODS RTOL REPEATS`
//! prints one JSON line: the median and best wall time of the repeats (s)
//! and the final displacement (to check that both sides computed the same).

/// The allocator: the rigid period maps build and drop a run's small
/// buffers per evaluation (docs/decisions.md D45).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

use std::time::Instant;

use vibroimpact::model::file::ModelDocument;
use vibroimpact::simulate::{simulate, SimulationOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 5 {
        eprintln!("usage: time_simulate MODEL PERIODS RTOL REPEATS");
        std::process::exit(2);
    }
    let text = std::fs::read_to_string(&args[1]).unwrap_or_else(|e| {
        eprintln!("{}: {e}", args[1]);
        std::process::exit(2)
    });
    let number = |i: usize| -> f64 {
        args[i].parse().unwrap_or_else(|_| {
            eprintln!("argument {i} `{}` is not a number", args[i]);
            std::process::exit(2)
        })
    };
    let (periods, rtol, repeats) = (number(2), number(3), number(4) as usize);
    let loaded = ModelDocument::from_toml(&text, &args[1])
        .and_then(|d| d.build())
        .unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(2)
        });
    let model = loaded.model;
    let w = model.forcing_frequency().unwrap_or_else(|| {
        eprintln!("{}: no periodic forcing", args[1]);
        std::process::exit(2)
    });
    let opts = SimulationOptions {
        t_end: periods * 2.0 * std::f64::consts::PI / w,
        rtol,
        atol: rtol * 1e-4,
        ..SimulationOptions::default()
    };
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        let sim = simulate(&model, &opts).expect("options");
        times.push(t0.elapsed().as_secs_f64());
        last = Some(sim);
    }
    times.sort_by(f64::total_cmp);
    let sim = last.expect("one run");
    println!(
        "{{\"median_s\": {:e}, \"best_s\": {:e}, \"final_displacement\": {:?}}}",
        times[times.len() / 2],
        times[0],
        sim.final_displacement
    );
}
