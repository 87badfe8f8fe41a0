//! One value of a sweep (or one run of a chart or basins): the transient,
//! the recorded window with its Poincaré samples and exact extrema, and the
//! settling check that extends the transient while the samples still
//! converge (docs/theory.md §8).

use super::*;
use crate::periodic::settling::{verdict, Motion};

/// `model` started from `(u, v)` at the instant whose forcing phase is
/// `phase`/[`FINE`] of a period: every harmonic excitation's phase is advanced
/// by that fraction of 2π.
pub(super) fn start_model(model: &Model, start: &Start) -> Result<Model, ModelError> {
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
pub(super) fn handover(
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
pub(super) fn distinct_points(points: &[Vec<f64>], n: usize, tol_u: f64, tol_v: f64) -> usize {
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
///
/// While the recorded samples still converge onto an orbit
/// ([`verdict`]), the run goes on from the window's end for the periods
/// the convergence still needs and records again, as long as the periods
/// added stay within `settings.settle`: a value is called periodic only
/// once its samples repeat to the cluster tolerance, and one that ran out
/// of periods says how many more it needs.
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
        motion: Motion::Irregular,
        period: None,
        settle_periods: None,
        transient_periods: settings.transient,
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
    let mut transient = settings.transient;
    let (m, sim, w0, next) = loop {
        // Transient: discarded, sampled coarsely for a hand-over state.
        if transient > 0 {
            match run_transient(model, &start, period, transient, settings) {
                Ok(s) => start = s,
                Err(msg) => return fail(point, msg),
            }
        }
        let window = match record(model, &start, period, settings) {
            Ok(w) => w,
            Err(msg) => return fail(point, msg),
        };
        let (m, sim, w0) = window;
        let scale = measure(&mut point, &sim, (period, w0), settings);
        if let Some(e) = &sim.error {
            let msg = format!(
                "integration failed {:.9} s into the recorded run, after {} recorded periods: {e}",
                sim.final_time, point.recorded_periods
            );
            return fail(point, msg);
        }
        let v = verdict(&point.sections, scale, settings.cluster_tolerance);
        point.motion = v.motion;
        point.period = v.period.filter(|_| v.motion == Motion::Periodic);
        point.settle_periods = v.periods_needed;
        // Every sample is a section instant (phase 0).
        let j_end = (FINE - start.phase % FINE) % FINE + settings.record * FINE;
        let next = handover(&m, &sim, 0, FINE, start.phase + j_end);
        let added = point.transient_periods - settings.transient;
        match (v.periods_needed, &next) {
            (Some(more), Some(from))
                if added + settings.record + more.ceil() as usize <= settings.settle =>
            {
                transient = more.ceil() as usize;
                point.transient_periods += settings.record + transient;
                start = from.clone();
            }
            _ => break (m, sim, w0, next),
        }
    };
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
    (point, next)
}

/// The recorded window from `start`: the first section instant, then
/// `record` periods sampled at the section instants, with the exact
/// extrema over them. Returns the model started there, the run and the
/// window's first instant.
fn record(
    model: &Model,
    start: &Start,
    period: f64,
    settings: &Settings,
) -> Result<(Model, Simulation, f64), String> {
    let m = start_model(model, start).map_err(|e| format!("cannot start: {e}"))?;
    let j0 = (FINE - start.phase % FINE) % FINE;
    let (w0, w1) = recorded_window(period, j0, settings.record);
    let opts = SimulationOptions {
        t_end: w1,
        output_step: Some(period),
        output_from: w0,
        extrema_window: Some((w0, w1)),
        integrator: settings.integrator,
        ..settings.opts.clone()
    };
    let sim = simulate(&m, &opts).map_err(|e| e.to_string())?;
    Ok((m, sim, w0))
}

/// The transient of `periods` forcing periods from `start`: simulated,
/// sampled coarsely, and the state to record from (or why there is none).
fn run_transient(
    model: &Model,
    start: &Start,
    period: f64,
    periods: usize,
    settings: &Settings,
) -> Result<Start, String> {
    let m = match start_model(model, start) {
        Ok(m) => m,
        Err(e) => return Err(format!("cannot start: {e}")),
    };
    let dt = period / COARSE as f64;
    let opts = SimulationOptions {
        t_end: (periods * COARSE) as f64 * dt,
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
/// period, spread and distinct section points. Returns the scales of the
/// samples: the largest |u| and |v| over the window.
fn measure(
    point: &mut SweepPoint,
    sim: &Simulation,
    (period, w0): (f64, f64),
    settings: &Settings,
) -> (f64, f64) {
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
    let max_u = point.max_displacement.iter().copied().fold(0.0, f64::max);
    (max_u, max_v)
}

/// The recorded window from section sample `j0` (of `FINE` a period) over
/// `record` periods, sampled at the section instants only: its end is the
/// last sample's time as the sampling computes it, `from + record ·
/// period` (`(j0 + record FINE) dt` may differ from it by an ulp, and the
/// last section would be lost).
pub(super) fn recorded_window(period: f64, j0: usize, record: usize) -> (f64, f64) {
    let from = j0 as f64 * (period / FINE as f64);
    (from, from + record as f64 * period)
}
