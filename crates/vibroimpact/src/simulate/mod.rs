//! Time histories of a [`Model`] with an impact log.
//!
//! ## Files
//! - `mod.rs` — [`simulate`], options, the impact log;
//! - `global.rs` — the global run, streamed sample by sample;
//! - `events.rs`, `switches/` — impact onsets and ends; events that change
//!   the right-hand side or the state inside a step (storey branches,
//!   onsets, rigid impacts);
//! - `extrema.rs`, `gauges.rs` — exact extrema on the dense output, of
//!   the bodies and of the gauges (drifts, closings, accelerations);
//! - `integrator.rs`, `estimate.rs` — which integrator runs; the work of a
//!   run, estimated before it starts;
//! - `local/` — the local integrator, exact motion between contacts;
//! - `exact/` — the exact run of a model linear between its storeys'
//!   switches (a building alone under a record), which the local
//!   integrator hands such a model;
//! - `tests/` — the checks of the global run.
//!
//! ## Impacts
//! A rigid contact's impact (docs/theory.md §12) is an event: where its
//! approach reaches zero the velocities jump, and the log records the
//! instant, U, eU and the map's estimates. A soft contact's impact of
//! contact k starts when its approach coordinate s rises
//! through the threshold `s_on` and ends when s falls back through it. For
//! laws with compact support `s_on = 0` (first touch). The exponential law
//! never vanishes, so `s_on` is where its static force `a e^{α s}` equals the
//! impact force threshold `F_on` ([`SimulationOptions::impact_force_threshold`],
//! default 1e-3 N): `s_on = ln(F_on/a)/α`. There the force is negligible next
//! to an impact's (for the seed's pendulums the work done between
//! `s = -∞` and `s_on` is below 1e-9 of the kinetic energy of a 1 cm/s
//! impact), and measuring impact and rebound velocity at the same `s_on`
//! keeps the seed's definition of the coefficient of restitution (eq. 10
//! holds at any common distance).
//!
//! Each accepted step is checked for every contact: crossings of `s_on` are
//! located on the 7th-order dense output (Brent); a contact whose relative
//! velocity turns from approach to separation inside the step is checked at
//! its maximum of s, so an impact that starts and ends within one step is
//! not missed. The peak force is located by Brent's parabolic search on the
//! dense output in the step that contains it.
//!
//! Contacts are independent: impacts of different pairs that overlap in
//! time (simultaneous impacts, e.g. a ball pressed between two neighbours)
//! are logged separately, each with its own start, velocities and peak; the
//! log is ordered by start time, then by contact index.
//!
//! ## Failure
//! If the integrator fails (step size underflow: the state and contact are
//! in the message), the result keeps everything computed up to the failure
//! and carries the error.

use crate::dynamics::{Chain, ChainDynamics};
use crate::impact::rigid::RigidImpact;
use crate::integrate::events::EventLocator;
use crate::integrate::{IntegrationError, IntegratorOptions, Interrupt, Method, Stats, Stepper};
use crate::model::{BaseExcitation, Model};
use crate::numeric::maximum;

/// Options of a simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct SimulationOptions {
    /// End time (s); the simulation starts at t = 0.
    pub t_end: f64,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (m and m/s).
    pub atol: f64,
    /// Output sampling interval (s) for the time history; None: no history.
    pub output_step: Option<f64>,
    /// Time of the first output sample (s, in `[0, t_end]`; default 0), the
    /// others every `output_step` after it: a history at chosen instants
    /// (a sweep's Poincaré sections) without the samples in between.
    pub output_from: f64,
    /// Force level F_on (N) delimiting impacts of the exponential law.
    pub impact_force_threshold: f64,
    /// Integrate the energy audit.
    pub energy: bool,
    /// Step budget.
    pub max_steps: u64,
    /// Start from this state, `[u_1..u_N, v_1..v_N]`, instead of the model's
    /// initial state (a state on a trajectory, e.g. of a periodic orbit:
    /// contacts may be engaged; the overlap check of model files does not
    /// apply).
    pub start: Option<Vec<f64>>,
    /// Integration method: DOP853 (default), DOPRI5 (loose tolerances with
    /// steps limited by a record's samples), RODAS (implicit, for bodies
    /// pressed together for long times), or automatic switching on a
    /// stiffness test.
    pub method: Method,
    /// Locate the exact extrema of every |u_i| and |v_i| over this time
    /// window (see [`Extrema`]).
    pub extrema_window: Option<(f64, f64)>,
    /// Further quantities whose extrema (and means) are located over the
    /// extrema window: drifts, closings, absolute accelerations.
    pub gauges: Vec<Gauge>,
    /// Whether the extrema cover the bodies' |u|, |v| and the contacts'
    /// margins (default true); false: the gauges alone (a study that reads
    /// only what its gauges give skips the rest).
    pub extrema_of_bodies: bool,
    /// Stop request checked at every step (see [`Interrupt`]): the
    /// simulation then ends early with [`IntegrationError::Interrupted`] as
    /// its error, keeping what was computed.
    pub interrupt: Option<Interrupt>,
    /// The whole state integrated at every step ([`Integrator::Global`]),
    /// or exact motion between contacts and the bodies in touch integrated
    /// ([`Integrator::Local`], docs/theory.md §10).
    pub integrator: Integrator,
    /// Streamed samples carry the bodies' accelerations after their
    /// displacements and velocities, `[u.., v.., a..]`, from the run's own
    /// right-hand side (with its storeys' history and its contacts' onset
    /// velocities); [`simulate_streaming`] only.
    pub accelerations: bool,
    /// Streamed samples end with the hysteretic storeys' forces F(d, z)
    /// (N, the model's storey order), after everything else;
    /// [`simulate_streaming`] only.
    pub storey_forces: bool,
}

impl Default for SimulationOptions {
    fn default() -> Self {
        Self {
            t_end: 1.0,
            rtol: 1e-8,
            atol: 1e-12,
            output_step: None,
            output_from: 0.0,
            impact_force_threshold: 1e-3,
            energy: false,
            max_steps: 50_000_000,
            start: None,
            method: Method::Dop853,
            extrema_window: None,
            gauges: Vec::new(),
            extrema_of_bodies: true,
            interrupt: None,
            integrator: Integrator::Auto,
            accelerations: false,
            storey_forces: false,
        }
    }
}

/// One logged impact.
#[derive(Clone, Debug, PartialEq)]
pub struct ImpactRecord {
    /// Contact index in the model.
    pub contact: usize,
    /// Start time (s): s rises through s_on.
    pub start_time: f64,
    /// End time (s): s falls through s_on; NaN if the impact had not ended.
    pub end_time: f64,
    /// Approach velocity ṡ at the start (m/s).
    pub impact_velocity: f64,
    /// Separation velocity -ṡ at the end (m/s); NaN if not ended.
    pub rebound_velocity: f64,
    /// Peak contact force (N).
    pub peak_force: f64,
    /// Time of the peak force (s).
    pub peak_time: f64,
    /// A rigid impact (docs/theory.md §12): its e, impulse, energy lost
    /// and the soft law's estimates; its start and end are the instant of
    /// the jump, `peak_force` the estimate. None for a soft impact.
    pub rigid: Option<RigidImpact>,
}

impl ImpactRecord {
    /// Rigid contact k's impact `r` at `t`: an instant.
    pub(crate) fn jump(k: usize, t: f64, r: RigidImpact) -> Self {
        Self {
            contact: k,
            start_time: t,
            end_time: t,
            impact_velocity: r.impact_velocity,
            rebound_velocity: r.rebound_velocity,
            peak_force: r.peak_force,
            peak_time: t,
            rigid: Some(r),
        }
    }

    /// Coefficient of restitution, rebound / impact velocity.
    pub fn restitution(&self) -> f64 {
        self.rebound_velocity / self.impact_velocity
    }
    /// Duration (s).
    pub fn duration(&self) -> f64 {
        self.end_time - self.start_time
    }
    /// Whether the impact ended before the simulation did.
    pub fn complete(&self) -> bool {
        self.end_time.is_finite()
    }
}

/// Energy audit at the end of a simulation (J).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnergyBalance {
    /// Mechanical energy at the start.
    pub initial: f64,
    /// Mechanical energy at the end.
    pub mechanical: f64,
    /// Work of the excitation.
    pub input_work: f64,
    /// Dissipation of the dampers.
    pub damping_dissipation: f64,
    /// Dissipation of the contacts.
    pub contact_dissipation: f64,
    /// Dissipation by the hysteretic storeys (their hysteretic parts' work
    /// less what those store; the stored part is in `mechanical`).
    pub hysteretic_dissipation: f64,
}

impl EnergyBalance {
    /// `E(t) + D_c + D_k + D_h - W - E(0)`: zero up to the integration
    /// error.
    pub fn residual(&self) -> f64 {
        self.mechanical
            + self.damping_dissipation
            + self.contact_dissipation
            + self.hysteretic_dissipation
            - self.input_work
            - self.initial
    }
}

/// A simulation's results.
#[derive(Clone, Debug)]
pub struct Simulation {
    /// Output times (s).
    pub times: Vec<f64>,
    /// Output states: for each time, `[u_1..u_N, v_1..v_N]` (2N values).
    pub states: Vec<f64>,
    /// Time reached.
    pub final_time: f64,
    /// Final displacements (m).
    pub final_displacement: Vec<f64>,
    /// Final velocities (m/s).
    pub final_velocity: Vec<f64>,
    /// Impacts in order of start time.
    pub impacts: Vec<ImpactRecord>,
    /// Integrator statistics.
    pub stats: Stats,
    /// Contact law evaluations (skipped contacts not counted).
    pub contact_evaluations: u64,
    /// The energy audit, if requested.
    pub energy: Option<EnergyBalance>,
    /// The energy each hysteretic storey has dissipated by the end (J, the
    /// model's storey order; empty without storeys).
    pub hysteretic_energy: Vec<f64>,
    /// The integration failure that stopped the simulation early, if any.
    pub error: Option<SimulationFailure>,
    /// Exact extrema over the requested window (up to `final_time`).
    pub extrema: Option<Extrema>,
    /// The local integrator's work (None for the global one).
    pub local: Option<local::LocalStats>,
    /// Rigid contacts' soft episodes, in order (docs/theory.md §12).
    pub soft_episodes: Vec<SoftEpisode>,
}

impl Simulation {
    /// The state reached, `[u_1..u_N, v_1..v_N]` (e.g. the start of a
    /// continuation or of a periodic-orbit summary).
    pub fn final_state(&self) -> Vec<f64> {
        self.final_displacement
            .iter()
            .chain(&self.final_velocity)
            .copied()
            .collect()
    }
}

/// Why and where a simulation stopped early.
#[derive(Clone, Debug, thiserror::Error)]
#[error("{source}{}{}", contact_text(.contact, .approach), cluster_text(.cluster))]
pub struct SimulationFailure {
    /// The integrator's error (time, step size, state and reason; the
    /// state of the bodies integrated, `cluster`'s under the local
    /// integrator).
    #[source]
    pub source: IntegrationError,
    /// The contact engaged deepest at the failure (relative to its impact
    /// threshold), by name.
    pub contact: Option<String>,
    /// Its approach coordinate s (m).
    pub approach: f64,
    /// Under the local integrator, the bodies of the set whose step
    /// failed, by name (empty: the whole model was integrated).
    pub cluster: Vec<String>,
}

fn contact_text(contact: &Option<String>, approach: &f64) -> String {
    match contact {
        Some(c) => format!("; deepest contact {c} at s = {approach:e} m"),
        None => String::new(),
    }
}

fn cluster_text(cluster: &[String]) -> String {
    if cluster.is_empty() {
        String::new()
    } else {
        format!("; the failing set integrated {}", cluster.join(", "))
    }
}

/// Errors in the options, before anything runs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct OptionsError(pub String);

fn check_options(opts: &SimulationOptions) -> Result<(), OptionsError> {
    let bad = |what: &str, v: f64| {
        Err(OptionsError(format!(
            "{what} = {v}: must be finite and > 0"
        )))
    };
    if !(opts.t_end > 0.0 && opts.t_end.is_finite()) {
        return bad("duration", opts.t_end);
    }
    if let Err(e) = crate::field_error::FieldError::tolerance("rtol", opts.rtol) {
        return Err(OptionsError(e.to_string()));
    }
    if !(opts.atol > 0.0 && opts.atol.is_finite()) {
        return bad("atol", opts.atol);
    }
    if !(opts.impact_force_threshold > 0.0 && opts.impact_force_threshold.is_finite()) {
        return bad("impact force threshold", opts.impact_force_threshold);
    }
    if let Some(dt) = opts.output_step {
        if !(dt > 0.0 && dt.is_finite()) {
            return bad("output step", dt);
        }
    }
    if !(opts.output_from >= 0.0 && opts.output_from <= opts.t_end) {
        return Err(OptionsError(format!(
            "first output time = {}: must lie in [0, duration = {}]",
            opts.output_from, opts.t_end
        )));
    }
    Ok(())
}

/// The most values a time history may hold (2 GB of f64): a longer history
/// is refused up front rather than exhausting memory.
pub const MAX_HISTORY_VALUES: f64 = 2.5e8;

/// The stability limit `h·|λ|` of DOP853 on the negative real axis (its
/// stiffness threshold).
const EXPLICIT_STABILITY: f64 = 6.1;

/// The largest state a simulation moves exactly between rigid impacts
/// ([`Stepper::exact_where_linear`]): a step costs d² products there and
/// each term of its dense output's series d², against DOP853's twelve
/// evaluations of O(d). Measured on rigid R2 over 1000 periods: 7–12 %
/// faster up to 4 bodies, 15 % slower at 8 (docs/decisions.md D42).
const EXACT_MAX_DIM: usize = 8;

/// DOPRI5's stability limit on the negative real axis (its stiffness
/// threshold).
const DOPRI5_STABILITY: f64 = 3.25;

/// Every this many steps a run checks its progress.
const PROGRESS_CHECK: u64 = 100_000;

/// A run whose pace projects more than this many times the step limit ends
/// with [`IntegrationError::NoProgress`] (a generous factor: an early hard
/// phase, such as a first impact, may be slower than the rest).
const CRAWL_FACTOR: f64 = 100.0;

/// Free flight counts as stiff for the automatic method when stability
/// would limit an explicit method to more than this many steps per
/// forcing period (or per simulated interval without periodic forcing).
const STIFF_FREE_FLIGHT_STEPS: f64 = 1e4;

/// The method to run: DOP853 on a model whose free flight is so stiff that
/// the step limit would be reached is refused with the body and property
/// that make it stiff; `Auto` on such a model runs RODAS throughout.
fn effective_method(model: &Model, opts: &SimulationOptions) -> Result<Method, OptionsError> {
    let fast = model.free_flight_rate();
    let limit = if opts.method == Method::Dopri5 {
        DOPRI5_STABILITY
    } else {
        EXPLICIT_STABILITY
    };
    let steps_per = |t: f64| t * fast.rate / limit;
    let reference = model
        .forcing_frequency()
        .map_or(opts.t_end, |w| 2.0 * std::f64::consts::PI / w)
        .min(opts.t_end);
    match opts.method {
        // Not stiff: the run is long (--periods 1e12 was called stiff,
        // with rodas as the advice).
        Method::Dop853 | Method::Dopri5
            if steps_per(opts.t_end) > opts.max_steps as f64
                && steps_per(reference) <= STIFF_FREE_FLIGHT_STEPS =>
        {
            Err(OptionsError(format!(
                "duration = {:e} s: about {:.1e} steps, more than the limit of {}; simulate a shorter time (the model is not stiff: {:.0} steps a forcing period)",
                opts.t_end,
                steps_per(opts.t_end),
                opts.max_steps,
                steps_per(reference)
            )))
        }
        Method::Dop853 | Method::Dopri5 if steps_per(opts.t_end) > opts.max_steps as f64 => {
            let b = &model.bodies()[fast.body];
            let cause = if fast.damping {
                format!("its damping/mass = {:.3e} 1/s", fast.rate)
            } else {
                format!("sqrt(stiffness/mass) = {:.3e} rad/s", fast.rate)
            };
            Err(OptionsError(format!(
                "the model is stiff: body {} has {cause}, which limits an explicit step to {:.1e} s, \
                 {:.1e} steps for the {} s simulated (limit {}); use the implicit method rodas (or auto)",
                b.name,
                limit / fast.rate,
                steps_per(opts.t_end),
                opts.t_end,
                opts.max_steps
            )))
        }
        Method::Auto if steps_per(reference) > STIFF_FREE_FLIGHT_STEPS => Ok(Method::Rodas),
        m => Ok(m),
    }
}

/// The most output samples a streamed history may have (a CSV of 10⁹ rows
/// is tens of GB): more is refused up front.
pub const MAX_SAMPLES: f64 = 1e9;

/// Simulates `model` from its initial state over `[0, opts.t_end]`, keeping
/// the sampled time history in [`Simulation::times`] and
/// [`Simulation::states`] (refused up front beyond [`MAX_HISTORY_VALUES`]
/// values; [`simulate_streaming`] has no such limit).
pub fn simulate(model: &Model, opts: &SimulationOptions) -> Result<Simulation, OptionsError> {
    check_options(opts)?;
    if opts.accelerations || opts.storey_forces {
        return Err(OptionsError(
            "accelerations, storey_forces: a kept history holds u and v only; stream the run for them"
                .into(),
        ));
    }
    if let Some(dt) = opts.output_step {
        let values =
            ((opts.t_end - opts.output_from) / dt + 1.0) * (2 * model.bodies().len() + 1) as f64;
        if values > MAX_HISTORY_VALUES {
            return Err(OptionsError(format!(
                "output step = {dt} s over {} s: the history would hold {values:.3e} values, more than {MAX_HISTORY_VALUES:e}; take a larger output step or a shorter duration",
                opts.t_end
            )));
        }
    }
    let (mut times, mut states) = (Vec::new(), Vec::new());
    let mut sim = simulate_streaming(model, opts, |t, state| {
        times.push(t);
        states.extend_from_slice(state);
        true
    })?;
    (sim.times, sim.states) = (times, states);
    Ok(sim)
}

/// Impacts in order of start time, then contact.
fn by_start(impacts: &mut [ImpactRecord]) {
    impacts.sort_by(|a, b| {
        a.start_time
            .total_cmp(&b.start_time)
            .then(a.contact.cmp(&b.contact))
    });
}

/// The failure `source` at the interleaved state `y`, with the contact
/// engaged deepest past its impact threshold `s_on` (a rigid impact's
/// failure: its contact).
fn failure(model: &Model, source: IntegrationError, y: &[f64], s_on: &[f64]) -> SimulationFailure {
    let n = model.bodies().len();
    let u: Vec<f64> = (0..n).map(|i| y[2 * i]).collect();
    let deepest = match source {
        IntegrationError::RigidImpact { contact, .. } => {
            Some((contact, model.approach(contact, &u)))
        }
        _ => (0..model.contacts().len())
            .map(|k| (k, model.approach(k, &u)))
            .max_by(|a, b| (a.1 - s_on[a.0]).total_cmp(&(b.1 - s_on[b.0]))),
    };
    SimulationFailure {
        source,
        contact: deepest.map(|(k, _)| model.contact_name(k)),
        approach: deepest.map_or(f64::NAN, |d| d.1),
        cluster: Vec::new(),
    }
}

/// What [`local_flow`] returns: the final interleaved state, the tangent
/// columns (each an interleaved state vector, one after the other), the
/// tape of the run's linearisation if asked for, and the integrator's work.
pub(crate) struct LocalFlow {
    pub y: Vec<f64>,
    pub columns: Vec<f64>,
    pub tape: Option<local::LocalTape>,
    pub stats: Stats,
}

/// A record's sample times inside `(0, t_end)`: the steps end there.
fn breakpoints(model: &Model, t_end: f64) -> Vec<f64> {
    match model.base() {
        BaseExcitation::Record(r) => r
            .times()
            .iter()
            .copied()
            .filter(|&t| t > 0.0 && t < t_end)
            .collect(),
        _ => Vec::new(),
    }
}

/// The local integrator's flow with tangent columns: from the interleaved
/// state `y0` at 0 to `opts.t_end`, `k` tangent vectors (`columns`: each an
/// interleaved state vector, one after the other) carried by the
/// variational equations in the active set and by the exact homogeneous
/// motion elsewhere, and with `tape` the record of the run's linearisation
/// for products `Φ v` and a forcing parameter's column without integrating
/// again (docs/theory.md §10). Returns the flow, or where the run failed.
pub(crate) fn local_flow(
    model: &Model,
    opts: &SimulationOptions,
    y0: &[f64],
    (columns, k): (&[f64], usize),
    tape: bool,
) -> Result<Result<LocalFlow, IntegrationError>, OptionsError> {
    check_options(opts)?;
    let method = effective_method(model, opts)?;
    let tangents = local::Tangents {
        values: columns,
        columns: k,
    };
    let run = local::run(
        model,
        opts,
        method,
        (y0, Some(tangents)),
        breakpoints(model, opts.t_end),
        tape,
        &mut |_, _| true,
    )?;
    Ok(match run.error {
        Some(e) => Err(e),
        None => Ok(LocalFlow {
            y: run.y,
            columns: run.tangents.unwrap_or_default(),
            tape: run.tape,
            stats: run.stats,
        }),
    })
}

/// [`simulate_streaming`] by the local integrator.
fn simulate_local(
    model: &Model,
    opts: &SimulationOptions,
    method: Method,
    y0: &[f64],
    breakpoints: Vec<f64>,
    sink: &mut dyn FnMut(f64, &[f64]) -> bool,
) -> Result<Simulation, OptionsError> {
    let run = local::run(model, opts, method, (y0, None), breakpoints, false, sink)?;
    let n = model.bodies().len();
    let mut impacts = run.impacts;
    by_start(&mut impacts);
    let error = run.error.or(run
        .sink_stopped
        .map(|t| IntegrationError::Interrupted { t }));
    let s_on: Vec<f64> = model
        .contacts()
        .iter()
        .map(|c| c.law.onset_approach(opts.impact_force_threshold))
        .collect();
    let error = error
        .map(|source| match run.crawling {
            // The contact whose checks crawl, not the deepest one.
            Some(k) => {
                let u: Vec<f64> = (0..n).map(|i| run.y[2 * i]).collect();
                SimulationFailure {
                    source,
                    contact: Some(model.contact_name(k)),
                    approach: model.approach(k, &u),
                    cluster: Vec::new(),
                }
            }
            None => failure(model, source, &run.y, &s_on),
        })
        .map(|mut f| {
            let names = run.failed_set.iter();
            f.cluster = names.map(|&i| model.bodies()[i].name.clone()).collect();
            f
        });
    Ok(Simulation {
        times: Vec::new(),
        states: Vec::new(),
        final_time: run.t,
        final_displacement: (0..n).map(|i| run.y[2 * i]).collect(),
        final_velocity: (0..n).map(|i| run.y[2 * i + 1]).collect(),
        impacts,
        stats: run.stats,
        contact_evaluations: run.contact_evaluations,
        hysteretic_energy: model
            .storeys()
            .iter()
            .enumerate()
            .map(|(k, _)| run.storeys.dissipated_by(k, &run.y))
            .collect(),
        energy: run
            .energy
            .map(|[input_work, damping_dissipation, contact_dissipation]| {
                // The start from rest on every storey's first branch, the
                // end on the run's (the Bouc–Wen states after the state).
                let mut sys = ChainDynamics::new(model, false);
                let mut start = y0[..2 * n].to_vec();
                start.resize(run.y.len(), 0.0);
                let initial = sys.mechanical_energy(&start);
                *sys.storeys_mut() = run.storeys.clone();
                EnergyBalance {
                    initial,
                    mechanical: sys.mechanical_energy(&run.y),
                    input_work,
                    damping_dissipation,
                    contact_dissipation,
                    hysteretic_dissipation: run.storeys.dissipated(&run.y),
                }
            }),
        error,
        extrema: run.extrema,
        local: Some(run.local),
        soft_episodes: run.episodes,
    })
}

mod estimate;
mod events;
mod exact;
mod extrema;
mod gauges;
mod global;
mod integrator;
pub mod local;
mod switches;

pub use estimate::{estimate_work, WorkEstimate, LONG_RUN};
use events::{contact_at, contact_end, StepScan, Tracker};
pub use extrema::Extrema;
use extrema::ExtremaScan;
pub use gauges::{Gauge, GaugeReading};
pub use global::simulate_streaming;
pub use integrator::{Integrator, AUTO_LOCAL_GROUPS};
pub(crate) use switches::{flow_through_events, flow_through_events_with, ImpactJump};
pub use switches::{EpisodeReason, SoftEpisode};

#[cfg(test)]
pub(crate) mod tests;
