//! Periodic orbits from simulation: a start guess after a transient, and
//! the summary of an orbit over its first period (samples, exact extrema,
//! impacts).

use std::collections::VecDeque;

use super::settling::{self, Motion};
use super::*;
use crate::simulate::simulate_streaming;

/// A start guess by simulation: the state after `periods` forcing periods
/// from the model's initial state.
pub fn guess_by_simulation(
    model: &Model,
    periods: f64,
    rtol: f64,
) -> Result<Vec<f64>, PeriodicError> {
    guess_by_simulation_with(model, periods, rtol, None)
}

/// [`guess_by_simulation`] that stops when `interrupt` is requested.
///
/// The guess is simulated by the integrator [`Integrator::Auto`] picks for
/// the model, whichever integrator then shoots: near chaotic motion or
/// coexisting orbits two integrators' transients part at the tolerance
/// and land on different orbits (R2 N = 2 at 0.5 ω0: a stable two-impact
/// orbit by one, an unstable four-impact one by the other), so one start
/// lets the shooting integrators find the same orbit and branch.
pub fn guess_by_simulation_with(
    model: &Model,
    periods: f64,
    rtol: f64,
    interrupt: Option<Interrupt>,
) -> Result<Vec<f64>, PeriodicError> {
    simulated(model, periods, rtol, interrupt)
}

/// Forcing periods of samples [`settled_guess`] judges.
const GUESS_WINDOW: usize = 24;

/// The largest scaled difference of samples n periods apart at the end of
/// a simulated guess from which Newton is tried whatever the samples'
/// verdict. R2 N = 2 (`examples/fujita-row-n2.toml`, 200 periods):
/// guesses from which Newton converged ended at 6e-6 to 2e-5 (at 1.2 to
/// 1.5 ω0, still settling too slowly for the verdict's window); those on
/// period-4 or chaotic motion at 0.3 to 1.1, and Newton stalled there.
const NEWTON_REACH: f64 = 1e-2;

/// [`guess_by_simulation_with`], and whether a Newton solve for an orbit
/// of `n` forcing periods is worth starting from it, by its last
/// [`GUESS_WINDOW`] Poincaré samples: yes where samples n periods apart
/// end within [`NEWTON_REACH`] of each other, or where the sweeps' test
/// (docs/theory.md §8, at their cluster tolerance max(1e-5, 1000 rtol))
/// finds them periodic or settling with a period that divides n. At 0.5 ω0
/// on R2 N = 2 the 200-period guess at rtol 1e-9 settled onto period 4,
/// and Newton from it stalled after 23 variational period maps, a fifth of the whole
/// branch's time, before the homotopy started. Yes where the run is
/// shorter than the window.
///
/// The run stops early, at a sample, once its window is periodic by that
/// test: the rest of the `periods` would only shrink a residual Newton
/// removes anyway (R2 N = 2 at rtol 1e-9: periodic after 170 periods at
/// ω0, after 137 at 1.2 ω0). Motion that stays irregular runs them all: a
/// chaotic transient can still end on an orbit (at 0.8 ω0 after 140
/// periods).
pub(crate) fn settled_guess(
    model: &Model,
    periods: f64,
    rtol: f64,
    interrupt: Option<Interrupt>,
    n: usize,
) -> Result<(Vec<f64>, bool), PeriodicError> {
    let t = forcing_period(model)?;
    let tol = 1e-5_f64.max(1e3 * rtol);
    let n = n.max(1);
    let sampled = periods >= GUESS_WINDOW as f64;
    let opts = guess_options(model, periods, rtol, interrupt, sampled.then_some(t))?;
    let mut window: VecDeque<Vec<f64>> = VecDeque::with_capacity(GUESS_WINDOW + 1);
    let mut settled = None;
    let sim = simulate_streaming(model, &opts, |_, y| {
        if window.len() == GUESS_WINDOW {
            window.pop_front();
        }
        window.push_back(y.to_vec());
        if window.len() < GUESS_WINDOW {
            return true;
        }
        let samples = window.make_contiguous();
        let scale = scales(samples);
        // A cheap necessary condition first: the last sample repeats.
        let last = &samples[GUESS_WINDOW - 1];
        let repeats = (1..=GUESS_WINDOW / 2)
            .any(|p| settling::difference(&samples[GUESS_WINDOW - 1 - p], last, scale) <= tol);
        if !repeats || settling::verdict(samples, scale, tol).motion != Motion::Periodic {
            return true;
        }
        settled = Some((y.to_vec(), worth(samples, scale, tol, n)));
        false
    })
    .map_err(|e: OptionsError| PeriodicError::Options(e.0))?;
    if let Some(found) = settled {
        return Ok(found);
    }
    if let Some(e) = sim.error {
        return Err(PeriodicError::Integration {
            iteration: 0,
            source: e.source,
        });
    }
    let samples = window.make_contiguous();
    let worth = !sampled || samples.len() < GUESS_WINDOW || worth(samples, scales(samples), tol, n);
    Ok((sim.final_state(), worth))
}

/// Whether Newton for an orbit of `n` periods is worth starting after the
/// Poincaré samples `s` with their scales, as [`settled_guess`] judges.
fn worth(s: &[Vec<f64>], scale: (f64, f64), tol: f64, n: usize) -> bool {
    let len = s.len();
    let near = n < len
        && (len.saturating_sub(2 * n)..len - n)
            .all(|k| settling::difference(&s[k], &s[k + n], scale) <= NEWTON_REACH);
    let v = settling::verdict(s, scale, tol);
    near || (v.motion != Motion::Irregular && v.period.is_some_and(|p| n % p == 0))
}

/// The scales of Poincaré samples `[u.., v..]`: largest |u|, largest |v|.
fn scales(s: &[Vec<f64>]) -> (f64, f64) {
    let d = s.first().map_or(0, Vec::len);
    let largest = |r: std::ops::Range<usize>| {
        s.iter()
            .flat_map(|x| x[r.clone()].iter().map(|x| x.abs()))
            .fold(f64::MIN_POSITIVE, f64::max)
    };
    (largest(0..d / 2), largest(d / 2..d))
}

/// The options of a simulated guess over `periods` forcing periods, with
/// a sample every `step` from the start where given.
fn guess_options(
    model: &Model,
    periods: f64,
    rtol: f64,
    interrupt: Option<Interrupt>,
    step: Option<f64>,
) -> Result<SimulationOptions, PeriodicError> {
    Ok(SimulationOptions {
        t_end: periods * forcing_period(model)?,
        rtol,
        atol: rtol * 1e-4,
        interrupt,
        integrator: Integrator::Auto,
        output_step: step,
        ..SimulationOptions::default()
    })
}

/// The state after `periods` forcing periods.
fn simulated(
    model: &Model,
    periods: f64,
    rtol: f64,
    interrupt: Option<Interrupt>,
) -> Result<Vec<f64>, PeriodicError> {
    let opts = guess_options(model, periods, rtol, interrupt, None)?;
    let sim = simulate(model, &opts).map_err(|e: OptionsError| PeriodicError::Options(e.0))?;
    if let Some(e) = sim.error {
        return Err(PeriodicError::Integration {
            iteration: 0,
            source: e.source,
        });
    }
    Ok(sim.final_state())
}

/// Impacts of one contact over one period of an orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactImpacts {
    /// Contact index.
    pub contact: usize,
    /// Impact velocities (m/s) of the impacts starting within the period.
    pub impact_velocities: Vec<f64>,
    /// Their peak forces (N).
    pub peak_forces: Vec<f64>,
}

/// Amplitudes and impacts of a periodic orbit.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitSummary {
    /// max |u_i| over the period, body order (m).
    pub max_displacement: Vec<f64>,
    /// max |v_i| over the period (m/s).
    pub max_velocity: Vec<f64>,
    /// Impacts per period per contact.
    pub impacts: Vec<ContactImpacts>,
    /// Per contact, how far the approach passed the impact threshold over
    /// the period (m; [`Extrema::impact_margin`](crate::simulate::Extrema)).
    pub impact_margin: Vec<f64>,
    /// Sampled orbit over one period: times and states (body order).
    pub times: Vec<f64>,
    /// States at `times`, `[u.., v..]` each.
    pub states: Vec<f64>,
}

impl OrbitSummary {
    /// Total impacts per period.
    pub fn impacts_per_period(&self) -> usize {
        self.impacts.iter().map(|c| c.impact_velocities.len()).sum()
    }
}

/// Integrates from a periodic state and summarises the first period: the
/// samples and extrema of [0, T], and the impacts that start in (0, T] (an
/// impact in progress at t = 0 is the one that starts before T; the
/// integration runs on to 2T to complete it, so it is counted once, with
/// its true impact velocity, rebound and peak). The first period, not the
/// second: on an unstable orbit the state's error grows by the largest
/// multiplier each period (~500 on R2's symmetric branch near 0.55 ω0). `samples` points per
/// period (at least 10) are kept for plots, none for `samples = 0` (a
/// summary of amplitudes and impacts alone: the output costs a quarter
/// of a rigid orbit's one-period run); the amplitudes max |u_i|, max |v_i| are the
/// exact extrema of the second period, located on the dense output (see
/// [`crate::simulate::Extrema`]), independent of `samples`.
pub fn orbit_summary(
    model: &Model,
    state: &[f64],
    period: f64,
    samples: usize,
    rtol: f64,
) -> Result<OrbitSummary, PeriodicError> {
    orbit_summary_by(model, state, (period, samples), rtol, Integrator::Global)
}

/// [`orbit_summary`] by the given integrator (`(period, samples)`).
pub fn orbit_summary_by(
    model: &Model,
    state: &[f64],
    (period, samples): (f64, usize),
    rtol: f64,
    integrator: Integrator,
) -> Result<OrbitSummary, PeriodicError> {
    let n = model.bodies().len();
    // One period; a second only when an impact is still under way at its
    // end (its rebound and peak lie beyond).
    let run = |periods: f64| {
        let opts = SimulationOptions {
            t_end: periods * period,
            rtol,
            atol: rtol * 1e-4,
            output_step: (samples > 0).then(|| period / samples.max(10) as f64),
            start: Some(state.to_vec()),
            extrema_window: Some((0.0, period)),
            integrator,
            ..SimulationOptions::default()
        };
        simulate(model, &opts).map_err(|e| PeriodicError::Options(e.0))
    };
    let mut sim = run(1.0)?;
    if sim.error.is_none() && sim.impacts.iter().any(|i| !i.complete()) {
        sim = run(2.0)?;
    }
    if let Some(e) = sim.error {
        return Err(PeriodicError::Integration {
            iteration: 0,
            source: e.source,
        });
    }
    let mut times = Vec::new();
    let mut states = Vec::new();
    for (j, &t) in sim.times.iter().enumerate() {
        if t > period * (1.0 + 1e-12) {
            break;
        }
        let row = &sim.states[j * 2 * n..(j + 1) * 2 * n];
        times.push(t);
        states.extend_from_slice(row);
    }
    let impacts = (0..model.contacts().len())
        .map(|k| {
            let list: Vec<_> = sim
                .impacts
                .iter()
                .filter(|i| i.contact == k && i.start_time > 0.0 && i.start_time <= period)
                .collect();
            ContactImpacts {
                contact: k,
                impact_velocities: list.iter().map(|i| i.impact_velocity).collect(),
                peak_forces: list.iter().map(|i| i.peak_force).collect(),
            }
        })
        .collect();
    let extrema = sim
        .extrema
        .ok_or_else(|| PeriodicError::Options("the orbit's extrema were not tracked".into()))?;
    Ok(OrbitSummary {
        max_displacement: extrema.max_displacement,
        max_velocity: extrema.max_velocity,
        impacts,
        impact_margin: extrema.impact_margin,
        times,
        states,
    })
}
