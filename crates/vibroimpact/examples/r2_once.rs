//! One simulation of reference problem R2 (for profiling):
//! `cargo run --release -p vibroimpact --example r2_once -- N PERIODS RTOL`.
use vibroimpact::model::reference::{r2, CLEARANCE, NATURAL_FREQUENCY};
use vibroimpact::simulate::{simulate, SimulationOptions};

fn main() {
    let arg = |i: usize, d: f64| {
        std::env::args()
            .nth(i)
            .and_then(|s| s.parse().ok())
            .unwrap_or(d)
    };
    let (n, periods, rtol) = (arg(1, 3.0) as usize, arg(2, 5.0), arg(3, 1e-10));
    let w0 = NATURAL_FREQUENCY;
    let model = r2(n, CLEARANCE, 0.95 * w0).expect("model");
    let t_end = periods * 2.0 * std::f64::consts::PI / (0.95 * w0);
    let sim = simulate(
        &model,
        &SimulationOptions {
            t_end,
            rtol,
            atol: rtol * 1e-3,
            ..Default::default()
        },
    )
    .expect("options");
    // (The final state's bits folded into one number: a change that
    // should keep the arithmetic keeps it.)
    let bits = sim
        .final_displacement
        .iter()
        .chain(&sim.final_velocity)
        .fold(0u64, |h, x| h.rotate_left(5) ^ x.to_bits());
    // (And the impact log's times, velocities and peaks.)
    let log = sim
        .impacts
        .iter()
        .flat_map(|i| {
            [
                i.start_time,
                i.end_time,
                i.impact_velocity,
                i.rebound_velocity,
                i.peak_force,
                i.peak_time,
            ]
        })
        .fold(0u64, |h, x| h.rotate_left(5) ^ x.to_bits());
    // (Bodies integrated, summed over the right-hand sides: the local
    // integrator's work.)
    if let Some(local) = &sim.local {
        let bodies: u64 = local.body_evaluations.iter().sum();
        print!("body evaluations {bodies} ");
    }
    println!(
        "rhs {} steps {} rejected {} impacts {} final state {bits:016x} log {log:016x}",
        sim.stats.rhs_evaluations,
        sim.stats.steps,
        sim.stats.rejected_steps,
        sim.impacts.len()
    );
}
