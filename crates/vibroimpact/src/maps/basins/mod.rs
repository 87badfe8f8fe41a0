//! Basins of attraction: a grid of initial states in a plane of state space
//! (two components varied, the others fixed), every state run to its
//! attractor in parallel (a transient, then recorded periods as in a
//! [`sweep`](crate::maps::sweep)), the attractors recognised on the Poincaré
//! section and numbered in order of first appearance over the grid, and
//! the fraction of the plane each attracts (docs/theory.md §8).
//!
//! Files: `mod.rs` (the basins), `tests.rs` (the linear limit and
//! coexisting attractors).

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::field_error::FieldError;
use crate::maps::attractor::{check_axis, identify, run_from, settings, MapError, Recorded, Run};
use crate::maps::sweep::{admissible, SweepOptions};
use crate::model::file::LoadedModel;

/// Largest number of initial states of one basin computation.
pub const MAX_CELLS: usize = 50_000_000;

/// A component of the state `[u.., v..]`: the displacement or the velocity
/// of a body (0-based).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Component {
    /// u of the body.
    Displacement(usize),
    /// v of the body.
    Velocity(usize),
}

impl Component {
    /// Parses `u1`, `v2`, … (1-based body numbers, as in the CSV columns'
    /// body order).
    pub fn parse(text: &str, bodies: usize) -> Result<Self, BasinError> {
        let bad = || {
            BasinError::Input(format!(
                "component `{text}`: give u or v and a body number from 1 to {bodies} (e.g. u1, v2)"
            ))
        };
        let (kind, number) = text.split_at(text.len().min(1));
        let k: usize = number.parse().map_err(|_| bad())?;
        if k == 0 || k > bodies {
            return Err(bad());
        }
        match kind {
            "u" => Ok(Component::Displacement(k - 1)),
            "v" => Ok(Component::Velocity(k - 1)),
            _ => Err(bad()),
        }
    }

    /// Index in the state `[u.., v..]` of `n` bodies.
    pub fn index(self, n: usize) -> usize {
        match self {
            Component::Displacement(i) => i,
            Component::Velocity(i) => n + i,
        }
    }

    /// The name (`u1`, `v2`, …).
    pub fn name(self) -> String {
        match self {
            Component::Displacement(i) => format!("u{}", i + 1),
            Component::Velocity(i) => format!("v{}", i + 1),
        }
    }
}

/// One axis of the plane of initial states: the component and its values.
pub type Axis<'a> = (Component, &'a [f64]);

/// One attractor found.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Attractor {
    /// Its period in forcing periods (null: not periodic).
    pub period: Option<usize>,
    /// Impacts per forcing period (of its first run).
    pub impacts_per_period: f64,
    /// Largest |u_i| over the recorded periods (of its first run, m).
    pub max_displacement: f64,
    /// One period of its Poincaré samples `[u.., v..]` (the last recorded
    /// ones of its first run; empty if not periodic).
    pub section: Vec<Vec<f64>>,
    /// Initial states of the grid that reach it.
    pub cells: usize,
    /// That over the admissible, completed initial states.
    pub fraction: f64,
}

/// Basins of attraction in a plane of initial states.
#[derive(Clone, Debug, Serialize)]
pub struct Basins {
    /// The component varied along the horizontal axis (`u1`, …).
    pub x_component: String,
    /// The component varied along the vertical axis.
    pub y_component: String,
    /// Its values (m or m/s).
    pub x_values: Vec<f64>,
    /// Its values.
    pub y_values: Vec<f64>,
    /// The other components of every initial state (`[u.., v..]`; the two
    /// varied ones as given there are replaced).
    pub base_state: Vec<f64>,
    /// Forcing periods discarded before recording.
    pub transient_periods: usize,
    /// Forcing periods recorded.
    pub record_periods: usize,
    /// The attractors, in order of first appearance over the grid (row by
    /// row).
    pub attractors: Vec<Attractor>,
    /// The attractor of every initial state, row by row (all x at the
    /// first y, …): an index into `attractors`; null where the state
    /// overlaps a contact (`inadmissible`) or the run failed.
    pub cells: Vec<Option<usize>>,
    /// Initial states that overlap a contact (not run).
    pub inadmissible: usize,
    /// Runs that failed (their errors in `errors`, at most 10).
    pub failed: usize,
    /// The first failures, with their initial states.
    pub errors: Vec<String>,
}

/// Input errors of a basin computation (numerical failures are counted in
/// the result).
pub type BasinError = MapError;

/// The runs of the initial states of a plane, row by row (None where the
/// state overlaps a contact and is not run): all of them, or one task's
/// rows of a distributed computation, which [`BasinRuns::concat`] joins in
/// order and [`basins_of`] identifies. Its JSON reads back bit for bit.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct BasinRuns(Vec<Option<(Run, Recorded)>>);

impl BasinRuns {
    /// The runs of consecutive rows, joined in order.
    pub fn concat(parts: Vec<BasinRuns>) -> Self {
        Self(parts.into_iter().flat_map(|p| p.0).collect())
    }
}

/// The checked inputs of a basin computation: the base state, the
/// forcing frequency and the run settings.
struct Plane {
    base_state: Vec<f64>,
    omega: f64,
    settings: crate::maps::sweep::Settings,
}

/// Checks the plane `x` × `y` through `base` of `loaded`'s model.
fn plane(
    loaded: &LoadedModel,
    (x, y): (Axis<'_>, Axis<'_>),
    base: Option<&[f64]>,
    options: &SweepOptions,
) -> Result<Plane, BasinError> {
    let model = &loaded.model;
    let n = model.bodies().len();
    if x.0 == y.0 {
        return Err(BasinError::Input(format!(
            "the two components are both {}: give two different ones",
            x.0.name()
        )));
    }
    for (c, values) in [x, y] {
        check_axis(&c.name(), values).map_err(BasinError::Input)?;
    }
    let cells = x.1.len().saturating_mul(y.1.len());
    if cells > MAX_CELLS {
        return Err(BasinError::Input(format!(
            "{} × {} initial states: more than {MAX_CELLS}; use a coarser grid",
            x.1.len(),
            y.1.len()
        )));
    }
    let base_state = match base {
        Some(b) if b.len() != 2 * n => {
            return Err(FieldError::about(
                "base",
                format!("needs {} values (u then v), got {}", 2 * n, b.len()),
            )
            .into())
        }
        Some(b) if b.iter().any(|v| !v.is_finite()) => {
            return Err(FieldError::about("base", "the values must be finite").into())
        }
        Some(b) => b.to_vec(),
        None => {
            let mut s = model.initial_displacement().to_vec();
            s.extend_from_slice(model.initial_velocity());
            s
        }
    };
    let Some(omega) = model.forcing_frequency() else {
        return Err(BasinError::Input(
            "the model has no periodic excitation with one frequency (attractors are recognised once per forcing period)".into(),
        ));
    };
    Ok(Plane {
        base_state,
        omega,
        settings: settings(loaded, options)?,
    })
}

/// The basins of `loaded`'s model over the plane `x` × `y` (component and
/// values) through `base` (`[u.., v..]`; None: the model's initial state),
/// with the transient, recording, tolerances and method of `options` (rtol
/// and cluster tolerance default to the chart's). In parallel on rayon's
/// pool; the result does not depend on the number of threads. `progress`
/// is called after every initial state.
pub fn basins(
    loaded: &LoadedModel,
    x: Axis<'_>,
    y: Axis<'_>,
    base: Option<&[f64]>,
    options: &SweepOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<Basins, BasinError> {
    let runs = basin_runs(loaded, x, y, base, options, progress)?;
    basins_of(loaded, (x, y), base, options, runs)
}

/// The runs of [`basins`] without their identification: of every initial
/// state of `x` × `y`, row by row (a task of a distributed computation
/// gives its rows of `y`).
pub fn basin_runs(
    loaded: &LoadedModel,
    x: Axis<'_>,
    y: Axis<'_>,
    base: Option<&[f64]>,
    options: &SweepOptions,
    progress: &(dyn Fn() + Sync),
) -> Result<BasinRuns, BasinError> {
    let Plane {
        base_state,
        omega,
        settings,
    } = plane(loaded, (x, y), base, options)?;
    let model = &loaded.model;
    let n = model.bodies().len();
    let states: Vec<Vec<f64>> =
        y.1.iter()
            .flat_map(|&vy| {
                let base_state = &base_state;
                x.1.iter().map(move |&vx| {
                    let mut s = base_state.clone();
                    s[x.0.index(n)] = vx;
                    s[y.0.index(n)] = vy;
                    s
                })
            })
            .collect();
    Ok(BasinRuns(
        states
            .into_par_iter()
            .map(|state| {
                let out = admissible(model, &state[..n])
                    .then(|| run_from(model, omega, state, &settings));
                progress();
                out
            })
            .collect(),
    ))
}

/// The basins from the `runs` of every initial state of the plane
/// ([`basin_runs`], or its rows joined by [`BasinRuns::concat`]): the
/// attractors identified over all of them, in order of first appearance.
pub fn basins_of(
    loaded: &LoadedModel,
    (x, y): (Axis<'_>, Axis<'_>),
    base: Option<&[f64]>,
    options: &SweepOptions,
    runs: BasinRuns,
) -> Result<Basins, BasinError> {
    let Plane {
        base_state,
        settings,
        ..
    } = plane(loaded, (x, y), base, options)?;
    let results = runs.0;
    if results.len() != x.1.len() * y.1.len() {
        return Err(BasinError::Input(format!(
            "{} runs for a plane of {} × {} initial states",
            results.len(),
            x.1.len(),
            y.1.len()
        )));
    }
    // Nothing to run is an input error, as for a sweep (it exited 0 with
    // no attractors).
    if results.iter().all(Option::is_none) {
        return Err(BasinError::Input(format!(
            "every one of the {} initial states overlaps a contact, so none can be run: choose values within the clearances",
            results.len()
        )));
    }
    let ran: Vec<bool> = results.iter().map(Option::is_some).collect();
    let (runs, recorded): (Vec<Run>, Vec<Recorded>) = results.into_iter().flatten().unzip();
    let (ids, reps) = identify(&runs, &recorded, settings.cluster_tolerance);
    // The attractor of every state of the grid: the runs are those of the
    // admissible states, in order.
    let mut next = ids.iter();
    let cells = ran
        .iter()
        .map(|&r| {
            if r {
                next.next().copied().flatten()
            } else {
                None
            }
        })
        .collect();
    Ok(summarise(
        (x, y),
        base_state,
        options,
        (runs, recorded, reps),
        cells,
        ran.iter().filter(|r| !**r).count(),
    ))
}

/// The result from the runs of the admissible states and their attractor
/// indices.
fn summarise(
    (x, y): (Axis<'_>, Axis<'_>),
    base_state: Vec<f64>,
    options: &SweepOptions,
    (runs, recorded, reps): (Vec<Run>, Vec<Recorded>, Vec<usize>),
    cells: Vec<Option<usize>>,
    inadmissible: usize,
) -> Basins {
    let mut counts = vec![0usize; reps.len()];
    for id in cells.iter().flatten() {
        counts[*id] += 1;
    }
    let completed: usize = counts.iter().sum();
    let attractors = reps
        .iter()
        .zip(&counts)
        .map(|(&i, &c)| {
            let r = &runs[i];
            let s = &recorded[i].samples;
            Attractor {
                period: r.period,
                impacts_per_period: r.impacts_per_period,
                max_displacement: r.max_displacement,
                section: r.period.map_or(Vec::new(), |p| s[s.len() - p..].to_vec()),
                cells: c,
                fraction: c as f64 / completed.max(1) as f64,
            }
        })
        .collect();
    let failures: Vec<&Run> = runs.iter().filter(|r| r.error.is_some()).collect();
    Basins {
        x_component: x.0.name(),
        y_component: y.0.name(),
        x_values: x.1.to_vec(),
        y_values: y.1.to_vec(),
        base_state,
        transient_periods: options.transient,
        record_periods: options.record,
        attractors,
        cells,
        inadmissible,
        failed: failures.len(),
        errors: failures
            .iter()
            .take(10)
            .map(|r| format!("from {:?}: {}", r.start, r.error.as_deref().unwrap_or("")))
            .collect(),
    }
}

#[cfg(test)]
mod tests;
