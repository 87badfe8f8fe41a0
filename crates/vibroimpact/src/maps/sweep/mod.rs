//! The brute-force bifurcation diagram (`vibroimpact sweep`).
//!
//! Files: `mod.rs` (the sweep and the runs every map shares), `tests.rs`
//! (the checks).
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
use crate::simulate::{simulate, Integrator, Simulation, SimulationOptions};

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
        Ok(Self {
            transient: options.transient,
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

/// `model` started from `(u, v)` at the instant whose forcing phase is
/// `phase`/[`FINE`] of a period: every harmonic excitation's phase is advanced
/// by that fraction of 2π.
fn start_model(model: &Model, start: &Start) -> Result<Model, ModelError> {
    let shift = 2.0 * std::f64::consts::PI * (start.phase % FINE) as f64 / FINE as f64;
    let base = match model.base() {
        BaseExcitation::Harmonic {
            amplitude,
            frequency,
            phase,
        } => BaseExcitation::Harmonic {
            amplitude: *amplitude,
            frequency: *frequency,
            phase: phase + shift,
        },
        other => other.clone(),
    };
    let forces: Vec<HarmonicForce> = model
        .forces()
        .iter()
        .map(|f| HarmonicForce {
            phase: f.phase + shift,
            ..f.clone()
        })
        .collect();
    Model::new(
        model.bodies().to_vec(),
        model.couplings().to_vec(),
        model.contacts().to_vec(),
        base,
        forces,
        start.u.clone(),
        start.v.clone(),
    )
}

/// Whether no contact overlaps at displacements `u`.
pub(crate) fn admissible(model: &Model, u: &[f64]) -> bool {
    (0..model.contacts().len()).all(|k| model.approach(k, u) <= 0.0)
}

/// The state to continue from after `sim`, which started at forcing phase
/// `phase0` with output every `stride` fine phase steps: the final state
/// (at forcing phase `phase_end`) if it does not overlap, else the latest
/// sample that does not.
fn handover(
    model: &Model,
    sim: &Simulation,
    phase0: usize,
    stride: usize,
    phase_end: usize,
) -> Option<Start> {
    if admissible(model, &sim.final_displacement) {
        return Some(Start {
            u: sim.final_displacement.clone(),
            v: sim.final_velocity.clone(),
            phase: phase_end % FINE,
        });
    }
    let n = model.bodies().len();
    (0..sim.times.len()).rev().find_map(|j| {
        let row = &sim.states[j * 2 * n..(j + 1) * 2 * n];
        admissible(model, &row[..n]).then(|| Start {
            u: row[..n].to_vec(),
            v: row[n..].to_vec(),
            phase: (phase0 + j * stride) % FINE,
        })
    })
}

/// Number of clusters of `points` (greedy, in order): two points are the same
/// when every displacement differs by at most `tol_u` and every velocity by
/// at most `tol_v`.
fn distinct_points(points: &[Vec<f64>], n: usize, tol_u: f64, tol_v: f64) -> usize {
    let mut reps: Vec<&Vec<f64>> = Vec::new();
    for p in points {
        let same = |r: &&Vec<f64>| {
            (0..n).all(|i| (p[i] - r[i]).abs() <= tol_u)
                && (n..2 * n).all(|i| (p[i] - r[i]).abs() <= tol_v)
        };
        if !reps.iter().any(same) {
            reps.push(p);
        }
    }
    reps.len()
}

/// Largest (max - min) of a component over `points`, relative to `scale_u`
/// (displacements) or `scale_v` (velocities); 0 for a zero scale.
fn spread(points: &[Vec<f64>], n: usize, scale_u: f64, scale_v: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for c in 0..2 * n {
        let (lo, hi) = points
            .iter()
            .map(|p| p[c])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                (lo.min(x), hi.max(x))
            });
        let scale = if c < n { scale_u } else { scale_v };
        if hi > lo && scale > 0.0 {
            worst = worst.max((hi - lo) / scale);
        }
    }
    worst
}

/// Simulates one parameter value from `start` (None: the model's initial
/// state). Returns the point and the state to continue from (None after a
/// failure).
pub(crate) fn run_value(
    model: &Model,
    parameter: f64,
    direction: Direction,
    start: Option<Start>,
    settings: &Settings,
) -> (SweepPoint, Option<Start>) {
    let n = model.bodies().len();
    let mut point = SweepPoint {
        parameter,
        direction,
        max_displacement: vec![f64::NAN; n],
        distinct_section_points: 0,
        section_spread: f64::NAN,
        impacts_per_period: f64::NAN,
        recorded_periods: 0,
        completed: false,
        error: None,
        lyapunov: None,
        lyapunov_uncertainty: None,
        sections: Vec::new(),
    };
    let fail = |mut point: SweepPoint, msg: String| {
        point.error = Some(msg);
        (point, None)
    };
    let Some(w) = model.forcing_frequency() else {
        return fail(point, "no periodic forcing with one frequency".into());
    };
    let period = 2.0 * std::f64::consts::PI / w;
    let mut start = start.unwrap_or_else(|| Start {
        u: model.initial_displacement().to_vec(),
        v: model.initial_velocity().to_vec(),
        phase: 0,
    });
    // Transient: discarded, sampled coarsely for a hand-over state.
    if settings.transient > 0 {
        match run_transient(model, &start, period, settings) {
            Ok(s) => start = s,
            Err(msg) => return fail(point, msg),
        }
    }
    // Recorded window: the first section instant, then `record` periods.
    let m = match start_model(model, &start) {
        Ok(m) => m,
        Err(e) => return fail(point, format!("cannot start: {e}")),
    };
    let j0 = (FINE - start.phase % FINE) % FINE;
    let j_end = j0 + settings.record * FINE;
    let (w0, w1) = recorded_window(period, j0, settings.record);
    let opts = SimulationOptions {
        t_end: w1,
        output_step: Some(period),
        output_from: w0,
        extrema_window: Some((w0, w1)),
        integrator: settings.integrator,
        ..settings.opts.clone()
    };
    let sim = match simulate(&m, &opts) {
        Ok(s) => s,
        Err(e) => return fail(point, e.to_string()),
    };
    measure(&mut point, &sim, (period, w0), settings);
    if let Some(e) = &sim.error {
        let msg = format!(
            "integration failed {:.9} s into the recorded run, after {} recorded periods: {e}",
            sim.final_time, point.recorded_periods
        );
        return fail(point, msg);
    }
    if let Some(count) = settings.lyapunov {
        let opts = LyapunovOptions {
            count: Some(count),
            transient: 0,
            periods: settings.record,
            rtol: settings.opts.rtol,
            interrupt: settings.opts.interrupt.clone(),
            integrator: settings.integrator,
        };
        match lyapunov_spectrum(&m, &sim.states[..2 * n], w0, &opts) {
            Ok(ly) => {
                point.lyapunov = Some(ly.exponents);
                point.lyapunov_uncertainty = Some(ly.uncertainty);
            }
            Err(e) => return fail(point, format!("Lyapunov exponents: {e}")),
        }
    }
    point.completed = true;
    // Every sample is a section instant (phase 0).
    let next = handover(&m, &sim, 0, FINE, start.phase + j_end);
    (point, next)
}

/// The transient from `start`: simulated, sampled coarsely, and the
/// state to record from (or why there is none).
fn run_transient(
    model: &Model,
    start: &Start,
    period: f64,
    settings: &Settings,
) -> Result<Start, String> {
    let m = match start_model(model, start) {
        Ok(m) => m,
        Err(e) => return Err(format!("cannot start: {e}")),
    };
    let dt = period / COARSE as f64;
    let opts = SimulationOptions {
        t_end: (settings.transient * COARSE) as f64 * dt,
        output_step: Some(dt),
        integrator: settings.integrator,
        ..settings.opts.clone()
    };
    let sim = match simulate(&m, &opts) {
        Ok(s) => s,
        Err(e) => return Err(e.to_string()),
    };
    if let Some(e) = &sim.error {
        return Err(format!(
            "integration failed {:.9} s into the transient: {e}",
            sim.final_time
        ));
    }
    handover(&m, &sim, start.phase, FINE / COARSE, start.phase).ok_or_else(|| {
        "after the transient no sampled state is free of contact overlap to record from".into()
    })
}

/// The point's measures from the recorded run `sim` (its window from
/// `w0`, `period` apart): Poincaré sections, exact extrema, impacts per
/// period, spread and distinct section points.
fn measure(
    point: &mut SweepPoint,
    sim: &Simulation,
    (period, w0): (f64, f64),
    settings: &Settings,
) {
    let n = point.max_displacement.len();
    let samples = sim.times.len();
    let row = |k: usize| &sim.states[k * 2 * n..(k + 1) * 2 * n];
    point.sections = (1..=settings.record)
        .filter(|&k| k < samples)
        .map(|k| row(k).to_vec())
        .collect();
    point.recorded_periods = point.sections.len();
    let mut max_v: f64 = 0.0;
    if point.recorded_periods > 0 {
        // The exact extrema over the recorded periods (dense output).
        if let Some(x) = &sim.extrema {
            point.max_displacement.clone_from(&x.max_displacement);
            max_v = x.max_velocity.iter().copied().fold(0.0, f64::max);
        }
    }
    if point.recorded_periods > 0 {
        let t0 = w0;
        let t1 = w0 + point.recorded_periods as f64 * period;
        let count = sim
            .impacts
            .iter()
            .filter(|i| i.start_time > t0 && i.start_time <= t1 && i.start_time > 0.0)
            .count();
        point.impacts_per_period = count as f64 / point.recorded_periods as f64;
        let max_u = point.max_displacement.iter().copied().fold(0.0, f64::max);
        point.section_spread = spread(&point.sections, n, max_u, max_v);
        point.distinct_section_points = distinct_points(
            &point.sections,
            n,
            settings.cluster_tolerance * max_u,
            settings.cluster_tolerance * max_v,
        );
    }
}

/// The recorded window from section sample `j0` (of `FINE` a period) over
/// `record` periods, sampled at the section instants only: its end is the
/// last sample's time as the sampling computes it, `from + record ·
/// period` (`(j0 + record FINE) dt` may differ from it by an ulp, and the
/// last section would be lost).
fn recorded_window(period: f64, j0: usize, record: usize) -> (f64, f64) {
    let from = j0 as f64 * (period / FINE as f64);
    (from, from + record as f64 * period)
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
