//! The brute-force bifurcation diagram (`vibroimpact sweep`).
//!
//! Files: `mod.rs` (the sweep, its options and settings), `value.rs` (one
//! value's run, which every map shares: transient, recorded window,
//! settling), `tests.rs` (the checks).
//!
//! Each value of one model parameter is simulated for `transient` forcing
//! periods, which are discarded, and then for `record` periods, whose
//! Poincaré samples (the state at the forcing phase of t = 0, once per period
//! T = 2π/Ω) are kept. Plotting the samples against the parameter shows
//! period-1 responses as one point per value, period-n responses as n points
//! and quasi-periodic or chaotic responses as clouds: the independent check
//! of continuation.
//!
//! Without `up_down` every value starts from the model's initial state and
//! all values run in parallel. With `up_down` the values are swept from
//! the first to the last ("up") and from the last back to the first ("down"), each
//! value starting from the previous value's final state (at the same forcing
//! phase); the two directions run in parallel, each starting from the model's
//! initial state at its first value.
//!
//! A simulation can only start from a state in which no two bodies overlap
//! (every contact's approach s <= 0). When a handed-over state overlaps (a
//! section instant that falls inside an impact), the latest sampled state
//! before it that does not overlap is used instead, and the excitation's
//! phase is shifted to match its instant, so the continuation stays exact.

use serde::Serialize;

use crate::field_error::FieldError;
use crate::integrate::{Interrupt, Method};
use crate::maps::lyapunov::{lyapunov_spectrum, LyapunovOptions};
use crate::model::family::{Family, FamilyError};
use crate::model::file::LoadedModel;
use crate::model::{BaseExcitation, HarmonicForce, Model, ModelError};
use crate::periodic::settling::Motion;
use crate::simulate::{simulate, Integrator, Simulation, SimulationOptions};

mod value;
pub(crate) use value::{admissible, run_value};
#[cfg(test)]
use value::{distinct_points, handover, recorded_window, start_model};

/// Samples per forcing period of the recorded window (for max |u|).
const FINE: usize = 256;
/// Samples per forcing period of the transient (candidate hand-over states).
const COARSE: usize = 16;

/// A sweep that cannot start (bad options or parameter values).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SweepError {
    /// An option refused by name.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// Any other input error (a model, a value).
    #[error("{0}")]
    Input(String),
}

/// Options of a sweep; `None` takes the model's `[simulation]` setting, else
/// the default stated.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepOptions {
    /// Forcing periods simulated and discarded before recording (default 100).
    pub transient: usize,
    /// At most this many forcing periods added to a value's transient while
    /// its Poincaré samples still converge onto an orbit (the recorded
    /// windows in between included); default 9 × `transient`; 0: only say
    /// so.
    pub settle: Option<usize>,
    /// Forcing periods recorded, one Poincaré sample at the end of each
    /// (default 20).
    pub record: usize,
    /// Sweep up and down, each value continuing from the previous one's
    /// final state.
    pub up_down: bool,
    /// With `up_down`, run only this direction (`Up` or `Down`; `None`:
    /// both). The two chains are independent, so two such runs (e.g. two
    /// tasks of a cluster) together give exactly the points of one run with
    /// both directions.
    pub only: Option<Direction>,
    /// Relative tolerance (default 1e-8).
    pub rtol: Option<f64>,
    /// Absolute tolerance in m and m/s (default rtol × 1e-4).
    pub atol: Option<f64>,
    /// Integration method.
    pub method: Method,
    /// Relative tolerance under which two Poincaré samples are the same
    /// point (relative to the largest |u| and |v| in the recorded window);
    /// default max(1e-5, 1000 rtol), above the integration noise of
    /// impacting orbits (measured 1–3e-6 at rtol 1e-8).
    pub cluster_tolerance: Option<f64>,
    /// The `k` largest Lyapunov exponents of every value
    /// ([`lyapunov_spectrum`]), averaged over the recorded periods from the
    /// first Poincaré sample (`None`: not computed).
    pub lyapunov: Option<usize>,
    /// Stop request (see [`Interrupt`]).
    pub interrupt: Option<Interrupt>,
    /// The integrator of the transient, the recorded window with its exact
    /// extrema, and the Lyapunov exponents (docs/theory.md §10).
    pub integrator: Integrator,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self {
            transient: 100,
            settle: None,
            record: 20,
            up_down: false,
            only: None,
            rtol: None,
            atol: None,
            method: Method::Dop853,
            cluster_tolerance: None,
            lyapunov: None,
            interrupt: None,
            integrator: Integrator::Global,
        }
    }
}

/// Direction of a sweep value.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Every value from the model's initial state (no --up-down).
    None,
    /// From --from towards --to, continuing.
    Up,
    /// From --to towards --from, continuing.
    Down,
}

impl Direction {
    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            Direction::None => "none",
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }
}

/// The result at one parameter value.
#[derive(Clone, Debug, Serialize)]
pub struct SweepPoint {
    /// Parameter value.
    pub parameter: f64,
    /// Sweep direction.
    pub direction: Direction,
    /// Largest |u_i| over the recorded periods, body order (m); null if
    /// nothing was recorded.
    pub max_displacement: Vec<f64>,
    /// Number of distinct Poincaré samples (1: period-1, 2: period-2, …,
    /// as many as recorded: quasi-periodic, chaotic or not yet settled).
    pub distinct_section_points: usize,
    /// Whether the samples repeat (`periodic`), still converge onto an
    /// orbit (`settling`: the periods `settle` allowed ran out) or neither
    /// (`irregular`).
    pub motion: Motion,
    /// The period in forcing periods of a periodic value: the smallest p
    /// with every sample equal to the one p periods later, to the cluster
    /// tolerance; null otherwise.
    pub period: Option<usize>,
    /// A settling value: about how many more forcing periods its samples
    /// need to repeat (extrapolated from their geometric decay).
    pub settle_periods: Option<f64>,
    /// Forcing periods before the recorded window: the transient, and
    /// those the settling check added.
    pub transient_periods: usize,
    /// Spread of the Poincaré samples: the largest (max - min) of a
    /// component over the samples, relative to the largest |u| (for
    /// displacements) or |v| (for velocities) in the recorded window. About
    /// the integration noise (~100 × rtol) or a decaying transient for a
    /// periodic response; of order 1 for period-n and chaotic ones.
    pub section_spread: f64,
    /// Impacts (all contacts) per forcing period over the recorded periods.
    pub impacts_per_period: f64,
    /// Number of Poincaré samples recorded (--record unless it failed).
    pub recorded_periods: usize,
    /// Whether every period was simulated.
    pub completed: bool,
    /// The failure, if any (also set when a completed value leaves no state
    /// to continue from, which ends its direction).
    pub error: Option<String>,
    /// Lyapunov exponents over the recorded periods (1/s), largest first,
    /// if requested ([`SweepOptions::lyapunov`]): a positive largest one
    /// marks chaos.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lyapunov: Option<Vec<f64>>,
    /// Convergence estimate of each exponent (1/s), see
    /// [`LyapunovSpectrum::uncertainty`](crate::maps::lyapunov::LyapunovSpectrum::uncertainty).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lyapunov_uncertainty: Option<Vec<f64>>,
    /// Poincaré samples `[u_1..u_N, v_1..v_N]`, one per recorded period
    /// (not in the JSON summary; `sweep.csv` holds them).
    #[serde(skip)]
    pub sections: Vec<Vec<f64>>,
}

/// The whole sweep (summary.json and the JSON on standard output).
#[derive(Debug, Serialize)]
pub struct SweepSummary {
    /// Parameter name as given.
    pub parameter_name: String,
    /// Body names, the order of `max_displacement`.
    pub bodies: Vec<String>,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Forcing periods discarded per value.
    pub transient_periods: usize,
    /// Forcing periods recorded per value.
    pub record_periods: usize,
    /// Whether the values were swept up and down with continuation.
    pub up_down: bool,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Clustering tolerance of the Poincaré samples.
    pub cluster_tolerance: f64,
    /// One entry per value and direction, sorted by parameter, then direction.
    pub points: Vec<SweepPoint>,
}

/// A state to start from: displacements, velocities and the forcing phase of
/// its instant in 1/[`FINE`] of a period.
#[derive(Clone, Debug)]
pub(crate) struct Start {
    pub(crate) u: Vec<f64>,
    pub(crate) v: Vec<f64>,
    pub(crate) phase: usize,
}

/// Settings shared by all values (of a sweep, or all cells of a chart).
pub(crate) struct Settings {
    transient: usize,
    settle: usize,
    record: usize,
    lyapunov: Option<usize>,
    opts: SimulationOptions,
    /// The integrator of the transient and the recorded window.
    integrator: Integrator,
    pub(crate) cluster_tolerance: f64,
}

impl Settings {
    /// The options of one run of `model` from its initial state: the
    /// transient and the recorded periods as one simulation (None where
    /// the model has no forcing period).
    fn run_options(&self, model: &Model) -> Option<SimulationOptions> {
        let w = model.forcing_frequency()?;
        Some(SimulationOptions {
            t_end: (self.transient + self.record) as f64 * 2.0 * std::f64::consts::PI / w,
            integrator: self.integrator,
            ..self.opts.clone()
        })
    }

    /// The estimated work of one run ([`Settings::run_options`];
    /// [`estimate_work`](crate::simulate::estimate_work)); None where
    /// there is no run or its checks refuse it.
    pub(crate) fn run_work(&self, model: &Model) -> Option<crate::simulate::WorkEstimate> {
        crate::simulate::estimate_work(model, &self.run_options(model)?)
    }

    /// One run ([`Settings::run_options`]) simulated and timed: its steps
    /// and seconds (None if it failed or was stopped).
    pub(crate) fn timed_run(&self, model: &Model) -> Option<crate::simulate::WorkEstimate> {
        let opts = self.run_options(model)?;
        let clock = std::time::Instant::now();
        let sim = simulate(model, &opts).ok().filter(|s| s.error.is_none())?;
        Some(crate::simulate::WorkEstimate {
            steps: sim.stats.steps as f64,
            seconds: clock.elapsed().as_secs_f64(),
            probed: sim.final_time,
            max_steps: opts.max_steps,
        })
    }

    /// The relative tolerance of the integration.
    pub(crate) fn rtol(&self) -> f64 {
        self.opts.rtol
    }

    /// The settings of `options` for models like `base` (its
    /// `[simulation]` tolerances where the options leave them open),
    /// checked.
    pub(crate) fn new(base: &LoadedModel, options: &SweepOptions) -> Result<Self, SweepError> {
        if options.record < 2 {
            return Err(FieldError::new(
                "record",
                options.record,
                "record at least two periods: one Poincaré sample is always one distinct point, whatever the orbit's period",
            )
            .into());
        }
        if options.transient > 1_000_000_000 {
            return Err(
                FieldError::new("transient", options.transient, "at most 1e9 periods").into(),
            );
        }
        let rtol = options.rtol.or(base.simulation.rtol).unwrap_or(1e-8);
        let atol = options.atol.or(base.simulation.atol).unwrap_or(rtol * 1e-4);
        FieldError::tolerance("rtol", rtol)?;
        let cluster_tolerance = options
            .cluster_tolerance
            .unwrap_or(1e-5_f64.max(1e3 * rtol));
        finite_positive("cluster_tolerance", cluster_tolerance)?;
        finite_positive("atol", atol)?;
        let d = 2 * base.model.bodies().len();
        let window = (options.record as f64 * FINE as f64 + 1.0) * (d + 1) as f64;
        if window > crate::simulate::MAX_HISTORY_VALUES {
            return Err(FieldError::new(
                "record",
                options.record,
                format!(
                    "the recorded window ({FINE} samples per period) would hold {window:.3e} values, more than {:e}",
                    crate::simulate::MAX_HISTORY_VALUES
                ),
            )
            .into());
        }
        if let Some(k) = options.lyapunov {
            if k == 0 || k > d {
                return Err(FieldError::new(
                    "lyapunov",
                    k,
                    format!("between 1 and the state dimension {d}"),
                )
                .into());
            }
            if options.record < 2 {
                return Err(FieldError::new(
                    "record",
                    options.record,
                    "Lyapunov exponents are averaged over at least 2 recorded periods",
                )
                .into());
            }
        }
        let settle = options.settle.unwrap_or(9 * options.transient);
        if settle > 1_000_000_000 {
            return Err(FieldError::new("settle", settle, "at most 1e9 periods").into());
        }
        Ok(Self {
            transient: options.transient,
            settle,
            record: options.record,
            lyapunov: options.lyapunov,
            opts: SimulationOptions {
                rtol,
                atol,
                impact_force_threshold: base.simulation.impact_force_threshold.unwrap_or(1e-3),
                method: options.method,
                interrupt: options.interrupt.clone(),
                ..SimulationOptions::default()
            },
            integrator: options.integrator,
            cluster_tolerance,
        })
    }
}

/// The work of `runs` runs like one of `model` with `settings` on one
/// core: the bound of one run, or from [`PROBED_FROM_RUNS`] runs on one
/// run timed (the bound knows the free flight, not the impacts: a 40 × 40
/// basins grid of the row of two was bound at 7.5 s, measured 180 s).
pub(crate) fn runs_work(
    settings: &Settings,
    model: &Model,
    runs: usize,
) -> Option<crate::simulate::WorkEstimate> {
    let bound = settings.run_work(model)?;
    if runs < PROBED_FROM_RUNS {
        return Some(bound.times(runs as f64));
    }
    Some(
        settings
            .timed_run(model)
            .unwrap_or(bound)
            .times(runs as f64),
    )
}

/// From this many runs on, [`runs_work`] times one (at most 2 % of the
/// work).
const PROBED_FROM_RUNS: usize = 50;

/// The work of a sweep of `values` values of models like `base` with
/// `options` on one core (both directions with `up_down`), for the faces
/// to announce when long; the periods a settling value adds are not
/// priced. None where the options are refused (the sweep says why).
pub fn sweep_work(
    base: &LoadedModel,
    options: &SweepOptions,
    values: usize,
) -> Option<crate::simulate::WorkEstimate> {
    let settings = Settings::new(base, options).ok()?;
    let runs = if options.up_down && options.only.is_none() {
        2 * values
    } else {
        values
    };
    runs_work(&settings, &base.model, runs)
}

/// The parameter values: `k` evenly spaced from `from` to `to`, ends exact.
pub fn parameter_values(from: f64, to: f64, k: usize) -> Vec<f64> {
    (0..k)
        .map(|i| {
            if i + 1 == k {
                to
            } else {
                from + (to - from) * (i as f64) / ((k - 1) as f64)
            }
        })
        .collect()
}

/// Runs the values in order, each from the previous one's final state; stops
/// at the first failure.
fn run_direction(
    models: &[(f64, Model)],
    direction: Direction,
    settings: &Settings,
    progress: &(dyn Fn() + Sync),
) -> Vec<SweepPoint> {
    let mut out = Vec::with_capacity(models.len());
    let mut start = None;
    for (p, model) in models {
        let (mut point, next) = run_value(model, *p, direction, start, settings);
        progress();
        if point.completed && next.is_none() {
            point.error = Some(
                "no recorded state is free of contact overlap to continue from; this direction stops here"
                    .into(),
            );
        }
        let stop = next.is_none();
        out.push(point);
        if stop {
            break;
        }
        start = next;
    }
    out
}

fn finite_positive(what: &'static str, x: f64) -> Result<(), SweepError> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(FieldError::new(what, x, "must be finite and > 0").into())
    }
}

/// Sweeps `family` over `values` (finite; one or more: a distributed
/// sweep runs chunks of them). Every model is
/// built first, so a bad value is an input error before anything runs; a
/// value that fails numerically is kept in the result with its `error`.
/// `progress` is called after every value, from any thread. The values run
/// in parallel on rayon's current pool (up and down in parallel with
/// `up_down`); the result does not depend on the number of threads.
pub fn sweep<F: Family>(
    mut family: F,
    values: &[f64],
    options: &SweepOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<SweepSummary, SweepError> {
    use rayon::prelude::*;
    if values.is_empty() {
        return Err(SweepError::Input("no parameter values to sweep".into()));
    }
    if let Some(x) = values.iter().find(|x| !x.is_finite()) {
        return Err(SweepError::Input(format!(
            "parameter value {x}: the values must be finite"
        )));
    }
    let err = |e: FamilyError| SweepError::Input(e.to_string());
    let base = LoadedModel {
        model: family.model_at(values[0]).map_err(err)?,
        simulation: family.simulation(),
        record: None,
    };
    let settings = Settings::new(&base, options)?;
    let name = family.name().to_string();
    let bodies: Vec<String> = base.model.bodies().iter().map(|b| b.name.clone()).collect();
    let mut models: Vec<(f64, Model)> = Vec::with_capacity(values.len());
    for &p in values {
        let m = family.model_at(p).map_err(err)?;
        if m.forcing_frequency().is_none() {
            return Err(SweepError::Input(format!(
                "{name} = {p}: the model has no periodic excitation with one frequency (a sweep samples once per forcing period)"
            )));
        }
        let names: Vec<&str> = m.bodies().iter().map(|b| b.name.as_str()).collect();
        if names != bodies.iter().map(String::as_str).collect::<Vec<_>>() {
            return Err(SweepError::Input(format!(
                "{name} = {p}: the bodies change along the sweep ({} instead of {}); sweep a parameter that keeps them",
                names.len(),
                bodies.len()
            )));
        }
        models.push((p, m));
    }
    let mut points: Vec<SweepPoint> = if options.up_down {
        let reversed: Vec<(f64, Model)> = models.iter().rev().cloned().collect();
        let up = || run_direction(&models, Direction::Up, &settings, progress);
        let down = || run_direction(&reversed, Direction::Down, &settings, progress);
        match options.only {
            Some(Direction::Up) => up(),
            Some(Direction::Down) => down(),
            _ => {
                let (mut up, down) = rayon::join(up, down);
                up.extend(down);
                up
            }
        }
    } else {
        models
            .par_iter()
            .map(|(p, m)| {
                let point = run_value(m, *p, Direction::None, None, &settings).0;
                progress();
                point
            })
            .collect()
    };
    points.sort_by(|a, b| {
        a.parameter
            .total_cmp(&b.parameter)
            .then(a.direction.cmp(&b.direction))
    });
    Ok(SweepSummary {
        parameter_name: name.to_string(),
        bodies,
        from: values[0],
        to: values[values.len() - 1],
        transient_periods: options.transient,
        record_periods: options.record,
        up_down: options.up_down,
        rtol: settings.opts.rtol,
        atol: settings.opts.atol,
        cluster_tolerance: settings.cluster_tolerance,
        points,
    })
}

#[cfg(test)]
mod tests;
