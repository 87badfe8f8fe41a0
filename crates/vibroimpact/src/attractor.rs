//! Attractors reached by simulation: one run from an initial state (a
//! transient, then recorded periods as in a [`sweep`](crate::sweep)),
//! classified by the period of its Poincaré samples, and the test whether
//! two runs reached the same attractor (docs/theory.md §8). Shared by the
//! stability chart and the basins of attraction.

use serde::Serialize;

use crate::model::Model;
use crate::sweep::{run_value, Direction, Settings, Start, SweepPoint};

/// The attractor one run reached.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Run {
    /// The initial state `[u.., v..]` (m, m/s).
    pub start: Vec<f64>,
    /// Period of the attractor in forcing periods: the number of distinct
    /// Poincaré samples (clusters to the cluster tolerance, as a sweep
    /// counts them) when at most half the recorded periods; null when the
    /// samples do not repeat (quasi-periodic, chaotic, or not settled).
    pub period: Option<usize>,
    /// Impacts (all contacts) per forcing period.
    pub impacts_per_period: f64,
    /// Largest |u_i| over the bodies and the recorded periods (m).
    pub max_displacement: f64,
    /// The largest Lyapunov exponent (1/s), if requested.
    pub lyapunov: Option<f64>,
    /// The failure, if any.
    pub error: Option<String>,
}

impl Run {
    /// A run that failed with `error`.
    pub(crate) fn failed(start: Vec<f64>, error: String) -> Self {
        Self {
            start,
            period: None,
            impacts_per_period: f64::NAN,
            max_displacement: f64::NAN,
            lyapunov: None,
            error: Some(error),
        }
    }
}

/// A run's Poincaré samples and the scales of their displacements (largest
/// |u| over the window) and velocities (that times the forcing frequency).
#[derive(Clone, Debug, Default)]
pub(crate) struct Recorded {
    pub(crate) samples: Vec<Vec<f64>>,
    pub(crate) scale: (f64, f64),
}

/// Simulates `model` (parameter value `x`, for the sweep's bookkeeping) from
/// `state` (`[u.., v..]` at forcing phase 0) and classifies the attractor.
pub(crate) fn run_from(
    model: &Model,
    x: f64,
    state: Vec<f64>,
    settings: &Settings,
) -> (Run, Recorded) {
    let n = model.bodies().len();
    let start = Start {
        u: state[..n].to_vec(),
        v: state[n..].to_vec(),
        phase: 0,
    };
    let (point, _) = run_value(model, x, Direction::None, Some(start), settings);
    classify(state, point, model.forcing_frequency().unwrap_or(1.0))
}

/// A run's summary from its sweep point, with its samples.
fn classify(start: Vec<f64>, point: SweepPoint, omega: f64) -> (Run, Recorded) {
    if let Some(e) = point.error {
        return (Run::failed(start, e), Recorded::default());
    }
    let max_u = point.max_displacement.iter().copied().fold(0.0, f64::max);
    // The sweep's clusters of samples (to its tolerance): a period-n
    // orbit leaves n of them.
    let distinct = point.distinct_section_points;
    let period = (distinct >= 1 && 2 * distinct <= point.recorded_periods).then_some(distinct);
    let run = Run {
        start,
        period,
        impacts_per_period: point.impacts_per_period,
        max_displacement: max_u,
        lyapunov: point.lyapunov.and_then(|l| l.first().copied()),
        error: None,
    };
    let recorded = Recorded {
        samples: point.sections,
        scale: (max_u, max_u * omega),
    };
    (run, recorded)
}

/// Whether two Poincaré samples are equal: every displacement within
/// `tol` times the displacement scale, every velocity within `tol` times
/// the velocity scale.
fn same_sample(a: &[f64], b: &[f64], tol: f64, scale: (f64, f64)) -> bool {
    let n = a.len() / 2;
    (0..2 * n).all(|i| {
        let s = if i < n { scale.0 } else { scale.1 };
        (a[i] - b[i]).abs() <= tol * s
    })
}

/// Whether two periodic runs reached the same attractor: their periods
/// agree and the last sample of the first is among the last period of
/// samples of the second (to `tol` of the larger scales). Non-periodic
/// and failed runs are never the same as anything here.
pub(crate) fn same_attractor(a: (&Run, &Recorded), b: (&Run, &Recorded), tol: f64) -> bool {
    let (Some(p), Some(q)) = (a.0.period, b.0.period) else {
        return false;
    };
    let (s, o) = (&a.1.samples, &b.1.samples);
    if p != q || s.is_empty() || o.len() < p {
        return false;
    }
    let scale = (a.1.scale.0.max(b.1.scale.0), a.1.scale.1.max(b.1.scale.1));
    o[o.len() - p..]
        .iter()
        .any(|x| same_sample(&s[s.len() - 1], x, tol, scale))
}

/// The attractor of every run: an index into the list of distinct
/// attractors in order of first appearance (the representative run of
/// each is returned too); all non-periodic runs share one index; failed
/// runs get none.
pub(crate) fn identify(
    runs: &[Run],
    recorded: &[Recorded],
    tol: f64,
) -> (Vec<Option<usize>>, Vec<usize>) {
    let mut reps: Vec<usize> = Vec::new();
    let mut non_periodic: Option<usize> = None;
    let ids = runs
        .iter()
        .enumerate()
        .map(|(i, run)| {
            if run.error.is_some() {
                return None;
            }
            if run.period.is_none() {
                return Some(*non_periodic.get_or_insert_with(|| {
                    reps.push(i);
                    reps.len() - 1
                }));
            }
            let found = reps.iter().position(|&j| {
                same_attractor((&runs[j], &recorded[j]), (run, &recorded[i]), tol)
                    || same_attractor((run, &recorded[i]), (&runs[j], &recorded[j]), tol)
            });
            Some(found.unwrap_or_else(|| {
                reps.push(i);
                reps.len() - 1
            }))
        })
        .collect();
    (ids, reps)
}

/// Distinct attractors among runs (see [`identify`]).
pub(crate) fn count_attractors(runs: &[Run], recorded: &[Recorded], tol: f64) -> usize {
    identify(runs, recorded, tol).1.len()
}
