//! One building row under a record, timed (for profiling the seismic
//! runs): `cargo run --release -p vibroimpact --example frame_once --
//! ROW.toml RECORD.txt SCALE METHOD RTOL REPEATS [INTEGRATOR]` (the
//! record in m/s²; METHOD dopri5 or dop853; INTEGRATOR auto, global or
//! local, default RunSettings::new's). Prints the median time of `REPEATS` runs
//! without the contacts' twin, and the peak drifts.
use std::time::Instant;
use vibroimpact::integrate::Method;
use vibroimpact::model::record::{parse_record, Units};
use vibroimpact::seismic::pounding::{parse_row, RunSettings};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let read = |i: usize| std::fs::read_to_string(&args[i]).expect("file");
    let row = parse_row(&read(1), &args[1]).expect("row");
    let record = parse_record(&read(2), &args[2], Some(Units::MetersPerSecond2)).expect("record");
    let num = |i: usize| args[i].parse::<f64>().expect("number");
    let mut run = RunSettings::new(record.dt.unwrap_or(0.01), num(5));
    run.method = if args[4] == "dopri5" {
        Method::Dopri5
    } else {
        Method::Dop853
    };
    if let Some(name) = args.get(7) {
        run.integrator = name.parse().expect("integrator");
    }
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..num(6) as usize {
        let t0 = Instant::now();
        last = Some(row.respond(&record, num(3), true, &run).expect("run"));
        times.push(t0.elapsed().as_secs_f64());
    }
    times.sort_by(f64::total_cmp);
    println!("median {:.3} ms", 1e3 * times[times.len() / 2]);
    println!("{:?}", last.map(|r| r.drift));
}
