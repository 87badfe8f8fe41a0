//! Fuzzing of the CLI's own parsers (seeded, bounded; longer with
//! `VIBROIMPACT_FUZZ_CASES=20000 cargo test --release -p vibroimpact-cli fuzz`):
//! measurement CSVs and the impact velocity ranges. No input may panic;
//! every error names its source.

use vibroimpact_fuzz::{cases, mutant, no_panics, seed, Rng};

const RESTITUTION: &str = include_str!("../../../examples/seed-impacts/restitution.csv");
const ACCELERATION: &str = include_str!("../../../examples/seed-impacts/acceleration.csv");

#[test]
fn measurement_csv_mutants_never_panic() {
    let mut rng = Rng(seed() ^ 11);
    let corpus = [
        RESTITUTION,
        ACCELERATION,
        "impact_velocity,restitution\n0.1,0.9\n",
    ];
    let inputs: Vec<String> = (0..cases(600)).map(|_| mutant(&mut rng, &corpus)).collect();
    no_panics("measurement CSV", inputs.into_iter(), |text| {
        let data =
            crate::measurements::Measurements::parse(Some((text, "r.csv")), Some((text, "a.csv")));
        match data {
            Err(e) => {
                let m = e.to_string();
                assert!(m.starts_with("r.csv") || m.starts_with("a.csv"), "{m}");
            }
            Ok(d) => {
                let bodies = vibroimpact::model::reference::seed_bodies();
                let _ = d.identify(bodies, None, rng_flag(text));
            }
        }
    });
}

/// A joint or sequential fit, chosen by the input.
fn rng_flag(text: &str) -> bool {
    text.len() % 2 == 0
}

#[test]
fn velocity_ranges_parse_or_refuse_without_panics() {
    let mut rng = Rng(seed() ^ 12);
    let corpus = [
        "0.001:10:50log",
        "0.1,0.3,1",
        "0.5",
        "1e-3:1e1:200lin",
        "0.1:1:10000000",
    ];
    let inputs: Vec<String> = (0..cases(3000))
        .map(|_| mutant(&mut rng, &corpus))
        .collect();
    no_panics("velocity range", inputs.into_iter(), |spec| {
        match crate::commands::impact::parse_velocities(spec) {
            Ok(v) => assert!(v.len() <= 10_000_000 && v.iter().all(|x| x.is_finite())),
            Err(e) => assert!(e.to_string().starts_with("--velocity"), "{e}"),
        }
    });
}
