//! Makes the example impact data set `examples/seed-impacts/*.csv`, which
//! imitates the seed's figures 4–5 (T. Fujita 1977, part III, §3).
//!
//! The seed's rig: pendulums of a 171 mm rod with a 38.1 mm steel ball
//! (m = 0.227 kg each), colliding ball on ball; identified values
//! a/b = 1.2 m/s, α = 1.3e5 1/m. This program draws impact velocities
//! log-uniformly from 0.03 to 0.6 m/s, evaluates the exponential law's exact
//! relations (seed eqs. 10, 14, 16–17) at the identified values, and adds
//! deterministic noise: N(0, 0.015²) to e, a factor exp(N(0, 0.08²)) to the
//! peak acceleration F_max/m1 (the scatter the seed's figures show).
//!
//! Run: `cargo run --release -p vibroimpact-cli --example make_seed_impacts -- examples/seed-impacts`

use std::fmt::Write as _;
use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::impact::closed_form::ExponentialImpact;
use vibroimpact::impact::TwoBodies;

/// SplitMix64: a tiny, well-known deterministic generator.
struct SplitMix64(u64);

impl SplitMix64 {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in (0, 1).
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    /// Standard normal (Box–Muller).
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

const HEADER: &str = "# Synthetic data imitating T. Fujita (1977) part III, figures 4-5: two 38.1 mm steel balls
# (m1 = m2 = 0.227 kg), exponential law with a/b = 1.2 m/s, alpha = 1.3e5 1/m (the seed's identified values).
# Impact velocities log-uniform in [0.03, 0.6] m/s; exact e(V) and f_max(V) (seed eqs. 10, 14, 16-17) plus
# deterministic noise (SplitMix64 seed 1977): e + N(0, 0.015^2); peak acceleration F_max/m1 * exp(N(0, 0.08^2)).
# Made by: cargo run --release -p vibroimpact-cli --example make_seed_impacts -- examples/seed-impacts
";

fn main() {
    let dir = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "examples/seed-impacts".into());
    let law = ContactLaw::exponential_from_ratio(1.2, 1.3e5, 1.0, ForceForm::Published)
        .expect("valid law");
    let bodies = TwoBodies::new(0.227, 0.227).expect("valid masses");
    let model = ExponentialImpact::new(&law, bodies).expect("exponential law");
    let mut rng = SplitMix64(1977);
    let velocity =
        |rng: &mut SplitMix64| (0.03f64.ln() + rng.uniform() * (0.6f64 / 0.03).ln()).exp();
    let mut restitution = format!("{HEADER}impact_velocity,restitution\n");
    let mut acceleration = format!("{HEADER}impact_velocity,peak_acceleration\n");
    for _ in 0..30 {
        let u = velocity(&mut rng);
        let e = model.impact(u).expect("impact").restitution + 0.015 * rng.normal();
        writeln!(restitution, "{u:.4},{e:.4}").expect("string");
    }
    for _ in 0..30 {
        let u = velocity(&mut rng);
        let a = model.impact(u).expect("impact").peak_acceleration[0] * (0.08 * rng.normal()).exp();
        writeln!(acceleration, "{u:.4},{a:.5e}").expect("string");
    }
    std::fs::write(format!("{dir}/restitution.csv"), restitution).expect("write restitution.csv");
    std::fs::write(format!("{dir}/acceleration.csv"), acceleration)
        .expect("write acceleration.csv");
}
