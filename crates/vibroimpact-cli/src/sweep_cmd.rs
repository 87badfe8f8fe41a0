//! `vibroimpact sweep`: the brute-force bifurcation diagram.
//!
//! Each value of one model parameter is simulated for `--transient` forcing
//! periods, which are discarded, and then for `--record` periods, whose
//! Poincaré samples (the state at the forcing phase of t = 0, once per period
//! T = 2π/Ω) are kept. Plotting the samples against the parameter shows
//! period-1 responses as one point per value, period-n responses as n points
//! and quasi-periodic or chaotic responses as clouds: the independent check
//! of continuation.
//!
//! Without `--up-down` every value starts from the model's initial state and
//! all values run in parallel. With `--up-down` the values are swept from
//! `--from` to `--to` ("up") and from `--to` back to `--from` ("down"), each
//! value starting from the previous value's final state (at the same forcing
//! phase); the two directions run in parallel, each starting from the model's
//! initial state at its first value.
//!
//! A simulation can only start from a state in which no two bodies overlap
//! (every contact's approach s <= 0). When a handed-over state overlaps (a
//! section instant that falls inside an impact), the latest sampled state
//! before it that does not overlap is used instead, and the excitation's
//! phase is shifted to match its instant, so the continuation stays exact.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

use clap::Args;
use rayon::prelude::*;
use serde::Serialize;
use vibroimpact::model::{BaseExcitation, HarmonicForce, Model};
use vibroimpact::simulate::{simulate, Simulation, SimulationOptions};

use crate::error::CliError;
use crate::format::Format;
use crate::output::{ensure_dir, write_atomic};
use crate::parameter::ParameterizedModel;
use crate::plot::{render, Figure, LegendPosition, Marker, Series};
use crate::simulate_cmd::MethodName;

/// Samples per forcing period of the recorded window (for max |u|).
const FINE: usize = 256;
/// Samples per forcing period of the transient (candidate hand-over states).
const COARSE: usize = 16;

/// Options of `vibroimpact sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    /// Model file (TOML, see docs/model.md); its excitation must be periodic
    /// with one frequency at every parameter value.
    model: PathBuf,
    /// The parameter: `frequency`, `amplitude` (of the excitation) or a dotted
    /// key of the model file such as `row.clearance`.
    #[arg(long)]
    parameter: String,
    /// First parameter value.
    #[arg(long)]
    from: f64,
    /// Last parameter value.
    #[arg(long)]
    to: f64,
    /// Number of parameter values (>= 2), evenly spaced, both ends included.
    #[arg(long)]
    points: usize,
    /// Forcing periods simulated and discarded before recording.
    #[arg(long, default_value_t = 100)]
    transient: usize,
    /// Forcing periods recorded (one Poincaré sample at the end of each).
    #[arg(long, default_value_t = 20)]
    record: usize,
    /// Sweep up from --from to --to and down from --to to --from, each value
    /// continuing from the previous value's final state.
    #[arg(long)]
    up_down: bool,
    /// Relative tolerance (default: the model's [simulation] rtol, else 1e-8).
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance in m and m/s (default: [simulation] atol, else rtol × 1e-4).
    #[arg(long)]
    atol: Option<f64>,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = MethodName::Dop853)]
    method: MethodName,
    /// Relative tolerance under which two Poincaré samples count as the same
    /// point (relative to the largest |u| and |v| in the recorded window);
    /// default max(1e-5, 1000 rtol), above the integration noise of
    /// impacting orbits (measured 1–3e-6 at rtol 1e-8).
    #[arg(long)]
    cluster_tolerance: Option<f64>,
    /// Output folder for sweep.csv, summary.json and the figures; without it
    /// only the summary is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Summary format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
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
    /// Poincaré samples `[u_1..u_N, v_1..v_N]`, one per recorded period.
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
struct Start {
    u: Vec<f64>,
    v: Vec<f64>,
    phase: usize,
}

/// Settings shared by all values.
struct Settings {
    transient: usize,
    record: usize,
    opts: SimulationOptions,
    cluster_tolerance: f64,
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
fn start_model(model: &Model, start: &Start) -> Result<Model, String> {
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
    .map_err(|e| e.to_string())
}

/// Whether no contact overlaps at displacements `u`.
fn admissible(model: &Model, u: &[f64]) -> bool {
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
fn run_value(
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
        let m = match start_model(model, &start) {
            Ok(m) => m,
            Err(e) => return fail(point, format!("cannot start: {e}")),
        };
        let dt = period / COARSE as f64;
        let opts = SimulationOptions {
            t_end: (settings.transient * COARSE) as f64 * dt,
            output_step: Some(dt),
            ..settings.opts.clone()
        };
        let sim = match simulate(&m, &opts) {
            Ok(s) => s,
            Err(e) => return fail(point, e.to_string()),
        };
        if let Some(e) = &sim.error {
            return fail(
                point,
                format!(
                    "integration failed {:.9} s into the transient: {e}",
                    sim.final_time
                ),
            );
        }
        match handover(&m, &sim, start.phase, FINE / COARSE, start.phase) {
            Some(s) => start = s,
            None => return fail(
                point,
                "after the transient no sampled state is free of contact overlap to record from"
                    .into(),
            ),
        }
    }
    // Recorded window: the first section instant, then `record` periods.
    let m = match start_model(model, &start) {
        Ok(m) => m,
        Err(e) => return fail(point, format!("cannot start: {e}")),
    };
    let dt = period / FINE as f64;
    let j0 = (FINE - start.phase % FINE) % FINE;
    let j_end = j0 + settings.record * FINE;
    let opts = SimulationOptions {
        t_end: j_end as f64 * dt,
        output_step: Some(dt),
        extrema_window: Some((j0 as f64 * dt, j_end as f64 * dt)),
        ..settings.opts.clone()
    };
    let sim = match simulate(&m, &opts) {
        Ok(s) => s,
        Err(e) => return fail(point, e.to_string()),
    };
    let samples = sim.times.len();
    let row = |j: usize| &sim.states[j * 2 * n..(j + 1) * 2 * n];
    point.sections = (1..=settings.record)
        .map(|k| j0 + k * FINE)
        .filter(|&j| j < samples)
        .map(|j| row(j).to_vec())
        .collect();
    point.recorded_periods = point.sections.len();
    let window_end = (j0 + point.recorded_periods * FINE).min(samples.saturating_sub(1));
    let mut max_v: f64 = 0.0;
    if window_end > j0 {
        // The exact extrema over the recorded periods (dense output).
        if let Some(x) = &sim.extrema {
            point.max_displacement.clone_from(&x.max_displacement);
            max_v = x.max_velocity.iter().copied().fold(0.0, f64::max);
        }
    }
    if point.recorded_periods > 0 {
        let t0 = j0 as f64 * dt;
        let t1 = (j0 + point.recorded_periods * FINE) as f64 * dt;
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
    if let Some(e) = &sim.error {
        let msg = format!(
            "integration failed {:.9} s into the recorded run, after {} recorded periods: {e}",
            sim.final_time, point.recorded_periods
        );
        return fail(point, msg);
    }
    point.completed = true;
    let next = handover(&m, &sim, start.phase, 1, start.phase + j_end);
    (point, next)
}

/// Runs the values in order, each from the previous one's final state; stops
/// at the first failure.
fn run_direction(
    models: &[(f64, Model)],
    direction: Direction,
    settings: &Settings,
    progress: &Progress,
) -> Vec<SweepPoint> {
    let mut out = Vec::with_capacity(models.len());
    let mut start = None;
    for (p, model) in models {
        let (mut point, next) = run_value(model, *p, direction, start, settings);
        progress.tick();
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

/// Progress on standard error when it is a terminal.
struct Progress {
    done: AtomicUsize,
    total: usize,
    show: bool,
}

impl Progress {
    fn new(total: usize) -> Self {
        Self {
            done: AtomicUsize::new(0),
            total,
            show: std::io::stderr().is_terminal(),
        }
    }

    fn tick(&self) {
        let k = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if self.show {
            eprint!("\rsweep: {k}/{} values", self.total);
            if k == self.total {
                eprintln!();
            }
        }
    }
}

/// Axis label of the parameter.
fn parameter_label(name: &str) -> String {
    match name {
        "frequency" | "excitation.frequency" => "forcing frequency Ω  [rad/s]".into(),
        "amplitude" | "excitation.amplitude" => "excitation amplitude".into(),
        other => other.to_string(),
    }
}

/// sweep.csv: one row per Poincaré sample.
fn sweep_csv(summary: &SweepSummary) -> Result<String, CliError> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| CliError::new(format!("cannot format CSV: {e}"));
    let mut header: Vec<String> = vec!["parameter".into(), "direction".into(), "period".into()];
    header.extend(summary.bodies.iter().map(|b| format!("u_{b}")));
    header.extend(summary.bodies.iter().map(|b| format!("v_{b}")));
    w.write_record(&header).map_err(io)?;
    for p in &summary.points {
        for (k, s) in p.sections.iter().enumerate() {
            let mut rec: Vec<String> = vec![
                format!("{:e}", p.parameter),
                p.direction.name().into(),
                (k + 1).to_string(),
            ];
            rec.extend(s.iter().map(|x| format!("{x:e}")));
            w.write_record(&rec).map_err(io)?;
        }
    }
    let bytes = w
        .into_inner()
        .map_err(|e| CliError::new(format!("cannot format CSV: {e}")))?;
    String::from_utf8(bytes).map_err(|e| CliError::new(e.to_string()))
}

/// Writes sweep.csv, summary.json and the figures into `dir`.
fn write_outputs(dir: &Path, summary: &SweepSummary) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(&dir.join("sweep.csv"), sweep_csv(summary)?.as_bytes())?;
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(summary)?.as_bytes(),
    )?;
    let directions: Vec<Direction> = if summary.up_down {
        vec![Direction::Up, Direction::Down]
    } else {
        vec![Direction::None]
    };
    let first = summary.bodies.first().cloned().unwrap_or_default();
    let x_label = parameter_label(&summary.parameter_name);
    let mut fig = Figure::new(
        format!("Poincaré samples of {first}"),
        x_label.clone(),
        format!("u_{first} at t = kT  [mm]"),
    )
    .legend_at(if summary.up_down {
        LegendPosition::Best
    } else {
        LegendPosition::None
    });
    for (c, d) in directions.iter().enumerate() {
        let pts: Vec<(f64, f64)> = summary
            .points
            .iter()
            .filter(|p| p.direction == *d)
            .flat_map(|p| p.sections.iter().map(move |s| (p.parameter, 1e3 * s[0])))
            .collect();
        let label = if summary.up_down { d.name() } else { "" };
        let marker = if *d == Direction::Down {
            Marker::Triangle
        } else {
            Marker::Circle
        };
        fig.push(Series::markers(label, pts, marker).with_color(c));
    }
    render(&fig, &dir.join("sweep"))?;
    let n = summary.bodies.len();
    let shown: Vec<usize> = if n <= 8 {
        (0..n).collect()
    } else {
        (0..8).map(|j| j * (n - 1) / 7).collect()
    };
    let mut fig = Figure::new(
        "Largest displacement over the recorded periods",
        x_label,
        "max |u|  [mm]",
    )
    .legend_at(LegendPosition::Best);
    for (c, &i) in shown.iter().enumerate() {
        for d in &directions {
            let pts: Vec<(f64, f64)> = summary
                .points
                .iter()
                .filter(|p| p.direction == *d)
                .map(|p| (p.parameter, 1e3 * p.max_displacement[i]))
                .collect();
            let label = match d {
                Direction::None => format!("u_{}", summary.bodies[i]),
                _ => format!("u_{} {}", summary.bodies[i], d.name()),
            };
            let s = if *d == Direction::Down {
                Series::dashed(label, pts)
            } else {
                Series::line(label, pts)
            };
            fig.push(s.with_color(c));
        }
    }
    render(&fig, &dir.join("sweep_amplitude"))?;
    Ok(())
}

/// Human-readable table.
fn table_text(summary: &SweepSummary) -> String {
    let first = summary.bodies.first().cloned().unwrap_or_default();
    let header = [
        "parameter".to_string(),
        "direction".to_string(),
        format!("max|u_{first}| [m]"),
        "distinct".to_string(),
        "spread".to_string(),
        "impacts/T".to_string(),
        "status".to_string(),
    ];
    let rows: Vec<[String; 7]> = summary
        .points
        .iter()
        .map(|p| {
            [
                format!("{:.6e}", p.parameter),
                p.direction.name().to_string(),
                p.max_displacement
                    .first()
                    .filter(|x| x.is_finite())
                    .map_or("-".into(), |x| format!("{x:.6e}")),
                p.distinct_section_points.to_string(),
                if p.section_spread.is_finite() {
                    format!("{:.1e}", p.section_spread)
                } else {
                    "-".into()
                },
                if p.impacts_per_period.is_finite() {
                    format!("{:.2}", p.impacts_per_period)
                } else {
                    "-".into()
                },
                if p.completed {
                    "ok".into()
                } else {
                    "FAILED".into()
                },
            ]
        })
        .collect();
    let widths: Vec<usize> = (0..7)
        .map(|c| {
            rows.iter()
                .map(|r| r[c].chars().count())
                .chain([header[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[String]| {
        let parts: Vec<String> = cells
            .iter()
            .zip(&widths)
            .map(|(s, w)| format!("{s:>w$}"))
            .collect();
        format!("{}\n", parts.join("  ").trim_end())
    };
    let mut t = line(&header);
    for r in &rows {
        t.push_str(&line(r));
    }
    t
}

fn check_finite_positive(what: &str, x: f64) -> Result<(), CliError> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(CliError::new(format!(
            "{what} = {x}: must be finite and > 0"
        )))
    }
}

/// Runs `vibroimpact sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    if !args.from.is_finite() || !args.to.is_finite() {
        return Err(CliError::new(format!(
            "--from {} --to {}: the values must be finite",
            args.from, args.to
        )));
    }
    if args.from == args.to {
        return Err(CliError::new(format!(
            "--from and --to are both {}: give a range",
            args.from
        )));
    }
    if args.points < 2 {
        return Err(CliError::new(format!(
            "--points {}: a sweep needs at least 2 values",
            args.points
        )));
    }
    if args.record < 1 {
        return Err(CliError::new("--record 0: record at least one period"));
    }

    let pm = ParameterizedModel::read(&args.model, &args.parameter)?;
    let base = pm.loaded_at(pm.initial)?;
    let rtol = args.rtol.or(base.simulation.rtol).unwrap_or(1e-8);
    let atol = args.atol.or(base.simulation.atol).unwrap_or(rtol * 1e-4);
    check_finite_positive("rtol", rtol)?;
    let cluster_tolerance = args.cluster_tolerance.unwrap_or(1e-5_f64.max(1e3 * rtol));
    check_finite_positive("--cluster-tolerance", cluster_tolerance)?;
    check_finite_positive("atol", atol)?;
    let values = parameter_values(args.from, args.to, args.points);
    // Every model first: bad values are input errors, before anything runs.
    let bodies: Vec<String> = base.model.bodies().iter().map(|b| b.name.clone()).collect();
    let mut models: Vec<(f64, Model)> = Vec::with_capacity(values.len());
    for &p in &values {
        let m = pm.model_at(p)?;
        if m.forcing_frequency().is_none() {
            return Err(CliError::new(format!(
                "{} = {p}: the model has no periodic excitation with one frequency (a sweep samples once per forcing period)",
                args.parameter
            )));
        }
        let names: Vec<&str> = m.bodies().iter().map(|b| b.name.as_str()).collect();
        if names != bodies.iter().map(String::as_str).collect::<Vec<_>>() {
            return Err(CliError::new(format!(
                "{} = {p}: the bodies change along the sweep ({} instead of {}); sweep a parameter that keeps them",
                args.parameter,
                names.len(),
                bodies.len()
            )));
        }
        models.push((p, m));
    }
    let impact_force_threshold = base.simulation.impact_force_threshold.unwrap_or(1e-3);
    let settings = Settings {
        transient: args.transient,
        record: args.record,
        opts: SimulationOptions {
            rtol,
            atol,
            impact_force_threshold,
            method: args.method.method(),
            ..SimulationOptions::default()
        },
        cluster_tolerance,
    };
    let mut points: Vec<SweepPoint> = if args.up_down {
        let progress = Progress::new(2 * models.len());
        let reversed: Vec<(f64, Model)> = models.iter().rev().cloned().collect();
        let (mut up, down) = rayon::join(
            || run_direction(&models, Direction::Up, &settings, &progress),
            || run_direction(&reversed, Direction::Down, &settings, &progress),
        );
        up.extend(down);
        up
    } else {
        let progress = Progress::new(models.len());
        models
            .par_iter()
            .map(|(p, m)| {
                let point = run_value(m, *p, Direction::None, None, &settings).0;
                progress.tick();
                point
            })
            .collect()
    };
    points.sort_by(|a, b| {
        a.parameter
            .total_cmp(&b.parameter)
            .then(a.direction.cmp(&b.direction))
    });
    let summary = SweepSummary {
        parameter_name: args.parameter.clone(),
        bodies,
        from: args.from,
        to: args.to,
        transient_periods: args.transient,
        record_periods: args.record,
        up_down: args.up_down,
        rtol,
        atol,
        cluster_tolerance,
        points,
    };
    if let Some(dir) = &args.out {
        write_outputs(dir, &summary)?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&summary)?),
        _ => print!("{}", table_text(&summary)),
    }
    let failed: Vec<String> = summary
        .points
        .iter()
        .filter(|p| p.error.is_some())
        .map(|p| {
            format!(
                "{} = {} ({}): {}",
                summary.parameter_name,
                p.parameter,
                p.direction.name(),
                p.error.as_deref().unwrap_or("failed")
            )
        })
        .collect();
    let expected = if args.up_down { 2 } else { 1 } * values.len();
    let skipped = expected - summary.points.len();
    if failed.is_empty() {
        return Ok(());
    }
    Err(CliError::new(format!(
        "{} of {expected} sweep values failed{} (the computed values are kept{}); {}",
        failed.len(),
        if skipped > 0 {
            format!(", {skipped} not run after a failure ended their direction")
        } else {
            String::new()
        },
        if args.out.is_some() {
            " in the output folder"
        } else {
            ""
        },
        failed.join("; ")
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_are_even_with_exact_ends() {
        let v = parameter_values(0.1, 0.7, 7);
        assert_eq!(v.len(), 7);
        assert_eq!(v[0], 0.1);
        assert_eq!(v[6], 0.7);
        assert!((v[3] - 0.4).abs() < 1e-15);
        let v = parameter_values(2.0, 1.0, 2);
        assert_eq!(v, vec![2.0, 1.0]);
    }

    const ROW: &str = "[row]\ncount = 2\nmass = 0.227\nnatural_frequency = 7.41\ndamping_ratio = 0.013\nclearance = 0.001\ncontact = { law = \"exponential\", a_over_b = 1.2, alpha = 1.3e5 }\n[excitation]\ntype = \"harmonic-base\"\namplitude = 0.5\nfrequency = 7.0\n";

    fn row_model() -> Model {
        ParameterizedModel::parse(ROW, "m.toml", Path::new("."), "frequency")
            .unwrap()
            .model_at(7.0)
            .unwrap()
    }

    /// A run restarted from a sample in the middle of a period, with the
    /// excitation's phase advanced to match, continues the original run.
    #[test]
    fn restart_at_a_phase_continues_the_trajectory() {
        let model = row_model();
        let period = 2.0 * std::f64::consts::PI / 7.0;
        let dt = period / FINE as f64;
        let opts = SimulationOptions {
            rtol: 1e-11,
            atol: 1e-15,
            ..SimulationOptions::default()
        };
        let whole = simulate(
            &model,
            &SimulationOptions {
                t_end: (3 * FINE) as f64 * dt,
                output_step: Some(dt),
                ..opts.clone()
            },
        )
        .unwrap();
        assert!(whole.impacts.len() > 2, "the test needs impacts");
        let n = 2;
        let j = FINE + 100;
        let row = &whole.states[j * 2 * n..(j + 1) * 2 * n];
        let start = Start {
            u: row[..n].to_vec(),
            v: row[n..].to_vec(),
            phase: j % FINE,
        };
        let m = start_model(&model, &start).unwrap();
        let rest = simulate(
            &m,
            &SimulationOptions {
                t_end: (3 * FINE - j) as f64 * dt,
                ..opts
            },
        )
        .unwrap();
        for i in 0..n {
            let a = whole.final_displacement[i];
            let b = rest.final_displacement[i];
            assert!((a - b).abs() < 1e-7 * 1e-3, "u_{i}: {a} vs {b}");
        }
    }

    #[test]
    fn handover_skips_overlapping_states() {
        let model = row_model();
        // Samples: admissible, admissible, overlapping (p1 into the wall at u = -1 mm).
        let states = vec![
            0.0, 0.0, 0.1, 0.2, //
            -5e-4, 1e-4, 0.3, 0.4, //
            -1.5e-3, 0.0, 0.5, 0.6,
        ];
        let sim = Simulation {
            times: vec![0.0, 1.0, 2.0],
            states: states.clone(),
            final_time: 2.0,
            final_displacement: vec![-1.5e-3, 0.0],
            final_velocity: vec![0.5, 0.6],
            impacts: Vec::new(),
            stats: Default::default(),
            contact_evaluations: 0,
            energy: None,
            error: None,
            extrema: None,
        };
        let s = handover(&model, &sim, 5, 16, 5 + 32).unwrap();
        assert_eq!(s.u, vec![-5e-4, 1e-4]);
        assert_eq!(s.v, vec![0.3, 0.4]);
        assert_eq!(s.phase, 5 + 16);
        let ok = Simulation {
            final_displacement: vec![1e-4, 0.0],
            final_velocity: vec![0.7, 0.8],
            ..sim.clone()
        };
        let s = handover(&model, &ok, 5, 16, FINE + 5).unwrap();
        assert_eq!((s.u[0], s.v[1], s.phase), (1e-4, 0.8, 5));
        let none = Simulation {
            states: states[8..].repeat(3),
            ..sim
        };
        assert!(handover(&model, &none, 0, 1, 0).is_none());
    }

    #[test]
    fn clusters() {
        let p = |u: f64, v: f64| vec![u, v];
        let pts = vec![
            p(1.0, 2.0),
            p(-1.0, 0.5),
            p(1.0 + 1e-9, 2.0),
            p(-1.0, 0.5 + 1e-3),
        ];
        assert_eq!(distinct_points(&pts, 1, 1e-6, 1e-6), 3);
        assert_eq!(distinct_points(&pts, 1, 1e-6, 1e-2), 2);
        assert_eq!(distinct_points(&[], 1, 1e-6, 1e-6), 0);
    }
}
