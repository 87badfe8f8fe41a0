//! Brute-force stability charts: a grid over two parameters of a model,
//! every cell simulated from several initial states (a transient, then
//! recorded periods as in a [`sweep`](crate::maps::sweep)), each run classified
//! by the period of its attractor on the Poincaré section (the state once
//! per forcing period), its impacts per period and optionally its largest
//! Lyapunov exponent; the runs of a cell that end on different attractors
//! show coexistence (docs/theory.md §8).
//!
//! Files: `mod.rs` (the chart), `tests.rs` (classification, counting,
//! agreement with the sweep).

use rayon::prelude::*;
use serde::Serialize;

use crate::field_error::FieldError;
use crate::maps::attractor::{
    check_axis, count_attractors, run_from, settings, MapError, Recorded, Run,
};
use crate::maps::sweep::{admissible, Settings, SweepOptions};
use crate::model::file::ModelDocument;
use crate::model::Model;

/// Largest number of runs (cells × starts) of one chart: the result keeps
/// ~200 bytes a run.
pub const MAX_RUNS: usize = 50_000_000;

pub use crate::maps::attractor::DEFAULT_RTOL;

/// Options of a chart.
#[derive(Clone, Debug)]
pub struct ChartOptions {
    /// Transient, recorded periods, tolerances, method, cluster tolerance
    /// and interruption as for a sweep (with the default rtol
    /// [`DEFAULT_RTOL`], so a cluster tolerance of 1e-4);
    /// `lyapunov: Some(1)` adds each run's largest Lyapunov exponent
    /// (`up_down`, `only` unused).
    pub sweep: SweepOptions,
    /// Initial states per cell (≥ 1): the model's own, then points of a
    /// Halton sequence in |u_i| ≤ 0.9 g, |v_i| ≤ 0.9 g Ω (g the smallest
    /// clearance, Ω the forcing frequency) that overlap no contact.
    pub starts: usize,
}

impl Default for ChartOptions {
    fn default() -> Self {
        Self {
            sweep: SweepOptions::default(),
            starts: 1,
        }
    }
}

/// One cell of the grid.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ChartCell {
    /// Value of the first parameter.
    pub x: f64,
    /// Value of the second parameter.
    pub y: f64,
    /// Distinct attractors among the runs (periodic ones differ by period
    /// or by their Poincaré samples; the non-periodic ones count as one).
    pub attractors: usize,
    /// One run per initial state.
    pub runs: Vec<Run>,
}

/// A whole chart.
#[derive(Clone, Debug, Serialize)]
pub struct Chart {
    /// Name of the first parameter (horizontal axis).
    pub x_name: String,
    /// Name of the second parameter (vertical axis).
    pub y_name: String,
    /// Values of the first parameter.
    pub x_values: Vec<f64>,
    /// Values of the second parameter.
    pub y_values: Vec<f64>,
    /// Forcing periods discarded before recording.
    pub transient_periods: usize,
    /// Forcing periods recorded.
    pub record_periods: usize,
    /// Relative tolerance of the integration.
    pub rtol: f64,
    /// Relative tolerance of two equal Poincaré samples.
    pub cluster_tolerance: f64,
    /// The cells, row by row: all x values at the first y value, then the
    /// next y value.
    pub cells: Vec<ChartCell>,
}

/// Why a chart could not be computed (input errors; numerical failures are
/// kept in the runs).
pub type ChartError = MapError;

/// The chart of `document` over `x` (name, values) × `y` (name, values).
/// Every model of the grid's first row and column is built before any
/// run (an invalid value is an input error); the cells run in parallel on
/// rayon's pool, and the result does not depend on the number of threads.
/// `progress` is called after every cell.
pub fn chart(
    document: &ModelDocument,
    x: (&str, &[f64]),
    y: (&str, &[f64]),
    options: &ChartOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<Chart, ChartError> {
    let err = |e: crate::model::file::ModelFileError| ChartError::Input(e.to_string());
    let px = document.parameter(x.0).map_err(err)?;
    let py = document.parameter(y.0).map_err(err)?;
    if px.key == py.key {
        return Err(ChartError::Input(format!(
            "the two parameters `{}` and `{}` are the same key: give two different ones",
            x.0, y.0
        )));
    }
    for (name, values) in [x, y] {
        check_axis(name, values).map_err(ChartError::Input)?;
    }
    if options.starts == 0 {
        return Err(FieldError::new("starts", 0, "at least one initial state per cell").into());
    }
    let runs =
        x.1.len()
            .saturating_mul(y.1.len())
            .saturating_mul(options.starts);
    if runs > MAX_RUNS {
        return Err(ChartError::Input(format!(
            "{} × {} cells × {} starts = {runs} runs: more than {MAX_RUNS}; use a coarser grid",
            x.1.len(),
            y.1.len(),
            options.starts
        )));
    }
    let model_at = |vx: f64, vy: f64| -> Result<Model, ChartError> {
        let mut doc = document.clone();
        doc.set(&py, vy).map_err(err)?;
        Ok(doc.with_parameter(&px, vx).map_err(err)?.model)
    };
    let base = document.with_parameter(&px, x.1[0]).map_err(err)?;
    let settings = settings(&base, &options.sweep)?;
    let first = model_at(x.1[0], y.1[0])?;
    for (vx, vy) in
        x.1.iter()
            .map(|&v| (v, y.1[0]))
            .chain(y.1.iter().map(|&v| (x.1[0], v)))
    {
        let m = model_at(vx, vy)?;
        if m.forcing_frequency().is_none() {
            return Err(ChartError::Input(format!(
                "{} = {vx}, {} = {vy}: the model has no periodic excitation with one frequency",
                x.0, y.0
            )));
        }
        if m.bodies().len() != first.bodies().len() {
            return Err(ChartError::Input(format!(
                "{} = {vx}, {} = {vy}: the number of bodies changes over the chart",
                x.0, y.0
            )));
        }
    }
    let grid: Vec<(f64, f64)> =
        y.1.iter()
            .flat_map(|&vy| x.1.iter().map(move |&vx| (vx, vy)))
            .collect();
    let cells: Vec<ChartCell> = grid
        .par_iter()
        .map(|&(vx, vy)| {
            let cell = match model_at(vx, vy) {
                Ok(m) => run_cell(&m, vx, vy, options.starts, &settings),
                Err(e) => ChartCell {
                    x: vx,
                    y: vy,
                    attractors: 0,
                    runs: vec![Run::failed(Vec::new(), e.to_string())],
                },
            };
            progress();
            cell
        })
        .collect();
    Ok(Chart {
        x_name: x.0.to_string(),
        y_name: y.0.to_string(),
        x_values: x.1.to_vec(),
        y_values: y.1.to_vec(),
        transient_periods: options.sweep.transient,
        record_periods: options.sweep.record,
        rtol: settings.rtol(),
        cluster_tolerance: settings.cluster_tolerance,
        cells,
    })
}

/// The runs of one cell and its attractor count.
fn run_cell(model: &Model, x: f64, y: f64, starts: usize, settings: &Settings) -> ChartCell {
    let (runs, recorded): (Vec<Run>, Vec<Recorded>) = initial_states(model, starts)
        .into_iter()
        .map(|state| run_from(model, x, state, settings))
        .unzip();
    let attractors = count_attractors(&runs, &recorded, settings.cluster_tolerance);
    ChartCell {
        x,
        y,
        attractors,
        runs,
    }
}

/// The initial states of a cell: the model's own, then Halton points
/// (bases 2, 3, 5, … over the 2N components) in |u_i| ≤ 0.9 g,
/// |v_i| ≤ 0.9 g Ω that overlap no contact (candidates that do are
/// skipped), deterministic.
pub fn initial_states(model: &Model, count: usize) -> Vec<Vec<f64>> {
    let n = model.bodies().len();
    let mut own: Vec<f64> = model.initial_displacement().to_vec();
    own.extend_from_slice(model.initial_velocity());
    let mut states = vec![own];
    let gap = model
        .contacts()
        .iter()
        .map(|c| c.clearance)
        .filter(|g| *g > 0.0)
        .fold(f64::INFINITY, f64::min);
    let gap = if gap.is_finite() { gap } else { 1e-3 };
    let omega = model.forcing_frequency().unwrap_or(1.0);
    let primes = primes(2 * n);
    let mut index = 1usize;
    while states.len() < count && index < 1000 * count {
        let state: Vec<f64> = (0..2 * n)
            .map(|c| {
                let h = 2.0 * radical_inverse(index, primes[c]) - 1.0;
                0.9 * gap * h * if c < n { 1.0 } else { omega }
            })
            .collect();
        index += 1;
        if admissible(model, &state[..n]) {
            states.push(state);
        }
    }
    states
}

/// The first `k` primes.
fn primes(k: usize) -> Vec<usize> {
    let mut out = Vec::with_capacity(k);
    let mut c = 2;
    while out.len() < k {
        if out.iter().all(|p| c % p != 0) {
            out.push(c);
        }
        c += 1;
    }
    out
}

/// Van der Corput radical inverse of `i` in base `b`, in [0, 1).
fn radical_inverse(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

#[cfg(test)]
mod tests;
