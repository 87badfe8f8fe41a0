//! What the sections share: problem R2, our runs and the peers' (the same
//! [`Run`]), the error of a final state and the robust setting of a sweep.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde_json::Value;
use vibroimpact::model::reference;
use vibroimpact::model::Model;
use vibroimpact::simulate::{simulate, Integrator, SimulationOptions};

pub const OMEGA_RATIO: f64 = 0.95;
pub const TARGET_ERROR: f64 = 1e-6;
pub const ATOL_RATIOS: [f64; 3] = [1e-2, 1e-3, 1e-4];

/// Work-precision points of one solver at one atol ratio: (rtol, error, run).
pub type Sweep = Vec<(f64, f64, Run)>;

pub fn r2(n: usize) -> Model {
    reference::r2(
        n,
        reference::CLEARANCE,
        OMEGA_RATIO * reference::NATURAL_FREQUENCY,
    )
    .expect("valid model")
}

pub fn t_end(periods: f64) -> f64 {
    periods * 2.0 * std::f64::consts::PI / (OMEGA_RATIO * reference::NATURAL_FREQUENCY)
}

/// One solver run: final state [u.., v..], best wall time, work counters.
#[derive(Clone, Debug)]
pub struct Run {
    pub state: Vec<f64>,
    pub seconds: f64,
    pub rhs: u64,
    pub steps: u64,
}

pub fn ours(n: usize, periods: f64, rtol: f64, atol: f64, repeats: usize) -> Run {
    ours_with(
        &r2(n),
        t_end(periods),
        rtol,
        atol,
        repeats,
        Integrator::Global,
    )
}

/// Our run of `model` over `[0, t_end]` with this integrator: the best
/// wall time of `repeats`.
pub fn ours_with(
    model: &Model,
    t_end: f64,
    rtol: f64,
    atol: f64,
    repeats: usize,
    integrator: Integrator,
) -> Run {
    let opts = SimulationOptions {
        t_end,
        rtol,
        atol,
        integrator,
        ..SimulationOptions::default()
    };
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let sim = simulate(model, &opts).expect("valid options");
        best = best.min(start.elapsed().as_secs_f64());
        assert!(
            sim.error.is_none(),
            "our integration failed: {:?}",
            sim.error
        );
        last = Some(sim);
    }
    let sim = last.expect("at least one run");
    Run {
        state: sim.final_state(),
        seconds: best,
        rhs: sim.stats.rhs_evaluations,
        steps: sim.stats.steps,
    }
}

pub struct Peers {
    dir: PathBuf,
}

impl Peers {
    pub fn build(root: &Path) -> Result<Self, String> {
        let dir = root.join("bench/peers");
        let status = Command::new("bash")
            .arg(dir.join("build.sh"))
            .status()
            .map_err(|e| format!("cannot run bench/peers/build.sh: {e}"))?;
        if !status.success() {
            return Err("bench/peers/build.sh failed".into());
        }
        Ok(Self { dir })
    }

    pub fn run(
        &self,
        method: &str,
        n: usize,
        periods: f64,
        rtol: f64,
        atol: f64,
        repeats: usize,
    ) -> Result<Run, String> {
        let args = [
            n.to_string(),
            OMEGA_RATIO.to_string(),
            periods.to_string(),
            format!("{rtol:e}"),
            format!("{atol:e}"),
            repeats.to_string(),
        ];
        let output = if let Some(m) = method.strip_prefix("scipy-") {
            Command::new(self.dir.join("build/venv/bin/python"))
                .arg(self.dir.join("r2_scipy.py"))
                .arg(m)
                .args(&args)
                .output()
        } else {
            Command::new(self.dir.join("build/r2_sundials"))
                .arg(method)
                .args(&args)
                .output()
        }
        .map_err(|e| format!("{method}: {e}"))?;
        if !output.status.success() {
            return Err(format!(
                "{method} failed: {}",
                String::from_utf8_lossy(&output.stderr).trim()
            ));
        }
        let line = String::from_utf8_lossy(&output.stdout);
        let v: Value =
            serde_json::from_str(line.trim()).map_err(|e| format!("{method}: bad output: {e}"))?;
        let state = v["final_state"]
            .as_array()
            .map(|a| a.iter().filter_map(Value::as_f64).collect())
            .unwrap_or_default();
        Ok(Run {
            state,
            seconds: v["seconds"].as_f64().unwrap_or(f64::NAN),
            rhs: v["rhs_evaluations"].as_u64().unwrap_or(0),
            steps: v["steps"].as_u64().unwrap_or(0),
        })
    }
}

/// What a peer gave (the peers built, a run), or the end of the benchmark
/// with its error.
pub fn peer_or_exit<T>(result: Result<T, String>) -> T {
    match result {
        Ok(value) => value,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}

pub fn error(state: &[f64], reference: &[f64]) -> f64 {
    let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    state
        .iter()
        .zip(reference)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / scale
}

/// The robust setting of a sweep (rtol descending): the loosest rtol from
/// which every tighter one meets the target.
pub fn robust(sweep: &[(f64, f64, Run)]) -> Option<&(f64, f64, Run)> {
    robust_to(sweep, TARGET_ERROR)
}

/// The loosest rtol (of a sweep from loose to tight) from which every
/// tighter one meets `target`.
pub fn robust_to(sweep: &[(f64, f64, Run)], target: f64) -> Option<&(f64, f64, Run)> {
    let mut pick = None;
    for entry in sweep.iter().rev() {
        if entry.1 <= target {
            pick = Some(entry);
        } else {
            break;
        }
    }
    pick
}
