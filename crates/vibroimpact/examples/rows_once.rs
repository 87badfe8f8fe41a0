//! One simulation of a row of K yielding buildings that pound, under
//! `examples/synthetic-quake.csv` at full scale (the benchmark's rows of
//! issue 39 item 3, for profiling):
//! `cargo run --release -p vibroimpact --example rows_once -- K local|global dopri5|dop853 RTOL`.
use vibroimpact::integrate::Method;
use vibroimpact::model::record::{parse_record, Units};
use vibroimpact::seismic::pounding::parse_row;
use vibroimpact::simulate::{simulate, Integrator, SimulationOptions};

/// The benchmark's row file of `k` buildings (seeded sizes and strengths).
fn row_text(k: usize) -> String {
    let mut seed = 3u64;
    let mut next = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut text = String::from("law = { law = \"hertz\", stiffness = 2e9, exponent = 1.5 }\n");
    for b in 0..k {
        let n = [3usize, 4, 5, 6, 8][(next() * 5.0) as usize % 5];
        let stiffness = (1.0e8 + 2.0e8 * next()) * n as f64 / 5.0;
        let uy = 0.006 + 0.014 * next();
        text += &format!("[[building]]\nname = \"B{b}\"\n");
        if b > 0 {
            text += "gap = 0.04\nfloors = [1, 2, 3]\n";
        }
        let list = |v: String| vec![v; n].join(", ");
        text += &format!(
            "masses = [{}]\nstiffnesses = [{}]\ndamping_ratio = 0.05\nstoreys = [{}]\n",
            list("2e5".into()),
            list(format!("{stiffness}")),
            list(format!(
                "{{ law = \"bilinear\", yield_drift = {uy}, post_yield_ratio = 0.05 }}"
            )),
        );
    }
    text
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: &str| args.get(i).cloned().unwrap_or_else(|| d.to_string());
    let k: usize = arg(1, "16").parse().expect("K");
    let integrator = match arg(2, "local").as_str() {
        "global" => Integrator::Global,
        _ => Integrator::Local,
    };
    let method = match arg(3, "dop853").as_str() {
        "dopri5" => Method::Dopri5,
        _ => Method::Dop853,
    };
    let rtol: f64 = arg(4, "1e-5").parse().expect("rtol");
    let text = include_str!("../../../examples/synthetic-quake.csv");
    let record = parse_record(text, "synthetic-quake.csv", Some(Units::MetersPerSecond2))
        .expect("the example record");
    let row = parse_row(&row_text(k), "row.toml").expect("valid row");
    let model = row
        .model(&record, 1.0, true)
        .expect("the row's model")
        .model;
    let sim = simulate(
        &model,
        &SimulationOptions {
            t_end: record.duration(),
            rtol,
            atol: 1e-4 * rtol,
            output_step: Some(0.01),
            method,
            integrator,
            ..SimulationOptions::default()
        },
    )
    .expect("options");
    let bits = sim
        .final_displacement
        .iter()
        .chain(&sim.final_velocity)
        .fold(0u64, |h, x| h.rotate_left(5) ^ x.to_bits());
    println!(
        "rhs {} steps {} impacts {} final state {bits:016x}",
        sim.stats.rhs_evaluations,
        sim.stats.steps,
        sim.impacts.len()
    );
}
