//! Attractors reached by simulation: one run from an initial state (a
//! transient, then recorded periods as in a [`sweep`](crate::maps::sweep)),
//! classified by the period of its Poincaré samples, and the test whether
//! two runs reached the same attractor (docs/theory.md §8). Shared by the
//! stability chart and the basins of attraction.

use serde::{Deserialize, Serialize};

use crate::field_error::FieldError;
use crate::maps::sweep::{
    run_value, Direction, Settings, Start, SweepError, SweepOptions, SweepPoint,
};
use crate::model::file::LoadedModel;
use crate::model::Model;

/// Relative tolerance of the integrations of charts and basins unless the
/// options or the model's `[simulation]` give one. The Poincaré samples of
/// an impacting orbit under the seed's stiff law carry an integration
/// noise of ~1e3 × rtol: at 1e-6 it reaches a cluster tolerance of 1e-3
/// (R2 N = 2 at 1.1 ω0: the period-3 orbit classed not periodic; of a 20 ×
/// 20 (frequency, amplitude) chart, 46 period-1 cells against 90 at 1e-8),
/// at 1e-7 the classes are those of 1e-8.
pub const DEFAULT_RTOL: f64 = 1e-7;

/// Input errors of charts and basins (numerical failures are kept in the
/// runs).
#[derive(Debug, thiserror::Error)]
pub enum MapError {
    /// An option refused by name.
    #[error(transparent)]
    Field(#[from] FieldError),
    /// Any other input error.
    #[error("{0}")]
    Input(String),
}

impl From<SweepError> for MapError {
    fn from(e: SweepError) -> Self {
        match e {
            SweepError::Field(f) => Self::Field(f),
            SweepError::Input(m) => Self::Input(m),
        }
    }
}

/// The run settings of charts and basins: `options` for models like
/// `base`, with [`DEFAULT_RTOL`] where neither the options nor the model
/// give one, and a sweep's cluster tolerance, max(1e-5, 1000 rtol): runs
/// still settling are extended or classed so (`periodic::settling`), so a
/// coarser tolerance for the free oscillation 100 periods leave is not
/// needed, and a chart and a sweep agree on which values are periodic.
pub(crate) fn settings(base: &LoadedModel, options: &SweepOptions) -> Result<Settings, SweepError> {
    let options = SweepOptions {
        rtol: options.rtol.or(base.simulation.rtol).or(Some(DEFAULT_RTOL)),
        ..options.clone()
    };
    Settings::new(base, &options)
}

/// The work of a chart or basins on one core: `runs` runs of `options`
/// like one from `base`'s model and initial state (the faces say so up
/// front when it is long: a 200 × 200 chart took 3 to 20 min with no word
/// where standard error was not a terminal). None where the settings or
/// the run are refused (the computation says why).
pub fn map_work(
    base: &LoadedModel,
    options: &SweepOptions,
    runs: usize,
) -> Option<crate::simulate::WorkEstimate> {
    crate::maps::sweep::runs_work(&settings(base, options).ok()?, &base.model, runs)
}

/// Checks the values of a grid axis named `name`: at least one, all finite.
pub(crate) fn check_axis(name: &str, values: &[f64]) -> Result<(), String> {
    if values.is_empty() {
        return Err(format!("{name}: no values"));
    }
    match values.iter().find(|v| !v.is_finite()) {
        Some(v) => Err(format!("{name} = {v}: the values must be finite")),
        None => Ok(()),
    }
}

/// The attractor one run reached (read back by a distributed computation's
/// merge: [`crate::maps::basins::BasinRuns`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Run {
    /// The initial state `[u.., v..]` (m, m/s).
    pub start: Vec<f64>,
    /// Period of the attractor in forcing periods: the smallest p, at most
    /// half the recorded periods, with s_{k+p} = s_k (to the cluster
    /// tolerance) for every pair of recorded Poincaré samples, once they
    /// have settled ([`crate::periodic::settling`]); null when they do not
    /// repeat (quasi-periodic, chaotic, or still settling when the periods
    /// allowed ran out).
    pub period: Option<usize>,
    /// Impacts (all contacts) per forcing period (NaN for a failed run,
    /// null in JSON).
    #[serde(deserialize_with = "nan_if_null")]
    pub impacts_per_period: f64,
    /// Largest |u_i| over the bodies and the recorded periods (m; NaN for
    /// a failed run).
    #[serde(deserialize_with = "nan_if_null")]
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

/// A number written as JSON's null where it was NaN (serde_json writes
/// NaN so), read back as NaN.
fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// A run's Poincaré samples and the scales of their displacements (largest
/// |u| over the window) and velocities (that times the forcing frequency).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
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
    let omega = model.forcing_frequency().unwrap_or(1.0);
    classify(state, point, omega)
}

/// A run's summary from its sweep point, with its samples.
fn classify(start: Vec<f64>, point: SweepPoint, omega: f64) -> (Run, Recorded) {
    if let Some(e) = point.error {
        return (Run::failed(start, e), Recorded::default());
    }
    let max_u = point.max_displacement.iter().copied().fold(0.0, f64::max);
    let scale = (max_u, max_u * omega);
    // Periodic only once the samples repeat (a run still settling, or
    // one whose periods to settle ran out, is not: `periodic::settling`).
    let period = point.period;
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
        scale,
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

/// Whether two periodic runs reached the same attractor: every sample of
/// the last cycle of each lies on the last cycle of the other (to `tol` of
/// the larger scales). A run still spiralling into a fixed point with a
/// third of a turn per period repeats every 3 periods while every sample
/// lies on the fixed point: the same attractor as the settled run.
/// Non-periodic and failed runs are never the same as anything here.
pub(crate) fn same_attractor(a: (&Run, &Recorded), b: (&Run, &Recorded), tol: f64) -> bool {
    let (Some(p), Some(q)) = (a.0.period, b.0.period) else {
        return false;
    };
    let (s, o) = (&a.1.samples, &b.1.samples);
    if s.len() < p || o.len() < q {
        return false;
    }
    let scale = (a.1.scale.0.max(b.1.scale.0), a.1.scale.1.max(b.1.scale.1));
    let on = |x: &[f64], cycle: &[Vec<f64>]| cycle.iter().any(|y| same_sample(x, y, tol, scale));
    let (ca, cb) = (&s[s.len() - p..], &o[o.len() - q..]);
    ca.iter().all(|x| on(x, cb)) && cb.iter().all(|y| on(y, ca))
}

/// The attractor of every run: an index into the list of distinct
/// attractors (the representative run of each is returned too: of the
/// shortest period among its runs). The periodic ones come first, in
/// order of first appearance; a run that is
/// not periodic over its window but whose last sample lies on one of them
/// (a slowly settling transient) belongs to it; the other non-periodic
/// runs share one index, last; failed runs get none.
pub(crate) fn identify(
    runs: &[Run],
    recorded: &[Recorded],
    tol: f64,
) -> (Vec<Option<usize>>, Vec<usize>) {
    let mut reps: Vec<usize> = Vec::new();
    let mut ids: Vec<Option<usize>> = vec![None; runs.len()];
    for (i, run) in runs.iter().enumerate() {
        if run.error.is_some() || run.period.is_none() {
            continue;
        }
        let found = reps
            .iter()
            .position(|&j| same_attractor((&runs[j], &recorded[j]), (run, &recorded[i]), tol));
        ids[i] = Some(match found {
            // The run of the shortest period represents the attractor.
            Some(k) => {
                if run.period < runs[reps[k]].period {
                    reps[k] = i;
                }
                k
            }
            None => {
                reps.push(i);
                reps.len() - 1
            }
        });
    }
    let periodic = reps.len();
    for (i, run) in runs.iter().enumerate() {
        if run.error.is_some() || run.period.is_some() {
            continue;
        }
        let last = recorded[i].samples.last();
        let on = (0..periodic).find(|&k| {
            let (rep, rec) = (&runs[reps[k]], &recorded[reps[k]]);
            let p = rep.period.unwrap_or(1);
            let scale = (
                rec.scale.0.max(recorded[i].scale.0),
                rec.scale.1.max(recorded[i].scale.1),
            );
            last.is_some_and(|l| {
                rec.samples[rec.samples.len() - p..]
                    .iter()
                    .any(|q| same_sample(l, q, tol, scale))
            })
        });
        ids[i] = Some(on.unwrap_or_else(|| {
            if reps.len() == periodic {
                reps.push(i);
            }
            periodic
        }));
    }
    (ids, reps)
}

/// Distinct attractors among runs (see [`identify`]).
pub(crate) fn count_attractors(runs: &[Run], recorded: &[Recorded], tol: f64) -> usize {
    identify(runs, recorded, tol).1.len()
}
