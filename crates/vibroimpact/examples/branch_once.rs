//! The R2 N = 2 frequency-response branch from 0.95 ω0 to 1.5 ω0, soft or
//! rigid (issue 40's comparison, for profiling):
//! `cargo run --release -p vibroimpact --example branch_once -- rigid|soft REPEATS`.
use std::time::Instant;

use vibroimpact::continuation::{amplitude_homotopy, continue_branch, ContinuationOptions};
use vibroimpact::model::file::ModelDocument;
use vibroimpact::model::parameter::ParameterizedModel;
use vibroimpact::model::reference::NATURAL_FREQUENCY;

const ROW_N2: &str = include_str!("../../../examples/fujita-row-n2.toml");

fn main() {
    let impacts = std::env::args().nth(1).unwrap_or_else(|| "rigid".into());
    let repeats: usize = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let (from, to) = (0.95 * NATURAL_FREQUENCY, 1.5 * NATURAL_FREQUENCY);
    let text = ROW_N2.replace("frequency = 7.0395 ", &format!("frequency = {from} "));
    let opts = ContinuationOptions::default();
    let doc = ModelDocument::from_toml(&text, "fujita-row-n2.toml")
        .and_then(|d| {
            d.with_impact_options(Some(&impacts), None)
                .map_err(|e| vibroimpact::model::file::ModelFileError(e.to_string()))
        })
        .expect("the example row");
    let (amplitude, target) = ParameterizedModel::in_amplitude(doc.clone()).expect("family");
    let start = amplitude_homotopy(&amplitude, target, &opts).expect("homotopy");
    let family = ParameterizedModel::new(doc, "frequency").expect("family");
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        let t0 = Instant::now();
        let branch = continue_branch(&family, from, &start, to, &opts, |_| true).expect("branch");
        best = best.min(t0.elapsed().as_secs_f64());
        if repeats == 1 {
            let special: Vec<_> = branch
                .special
                .iter()
                .map(|s| (s.label.clone(), s.parameter))
                .collect();
            println!("{} points, special {special:?}", branch.points.len());
        }
    }
    println!("{impacts}: best {:.3} ms", best * 1e3);
}
