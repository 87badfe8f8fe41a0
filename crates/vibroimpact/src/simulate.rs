//! Time histories of a [`Model`] with an impact log.
//!
//! ## Impacts
//! An impact of contact k starts when its approach coordinate s rises
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
//! not missed. The peak force is located by golden-section search on the
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

use crate::dynamics::ChainDynamics;
use crate::integrate::events::EventLocator;
use crate::integrate::{IntegrationError, IntegratorOptions, Interrupt, Method, Stats, Stepper};
use crate::model::{BaseExcitation, Model};
use crate::numeric::golden_max;

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
    /// Integration method: DOP853 (default), RODAS (implicit, for bodies
    /// pressed together for long times), or automatic switching on a
    /// stiffness test.
    pub method: Method,
    /// Locate the exact extrema of every |u_i| and |v_i| over this time
    /// window (see [`Extrema`]).
    pub extrema_window: Option<(f64, f64)>,
    /// Stop request checked at every step (see [`Interrupt`]): the
    /// simulation then ends early with [`IntegrationError::Interrupted`] as
    /// its error, keeping what was computed.
    pub interrupt: Option<Interrupt>,
}

impl Default for SimulationOptions {
    fn default() -> Self {
        Self {
            t_end: 1.0,
            rtol: 1e-8,
            atol: 1e-12,
            output_step: None,
            impact_force_threshold: 1e-3,
            energy: false,
            max_steps: 50_000_000,
            start: None,
            method: Method::Dop853,
            extrema_window: None,
            interrupt: None,
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
}

impl ImpactRecord {
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
}

impl EnergyBalance {
    /// `E(t) + D_c + D_k - W - E(0)`: zero up to the integration error.
    pub fn residual(&self) -> f64 {
        self.mechanical + self.damping_dissipation + self.contact_dissipation
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
    /// The integration failure that stopped the simulation early, if any.
    pub error: Option<SimulationFailure>,
    /// Exact extrema over the requested window (up to `final_time`).
    pub extrema: Option<Extrema>,
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

/// Largest |u_i| and |v_i| of every body over a time window, located on the
/// integrator's dense output rather than sampled: an interior maximum of
/// |u_i| lies where v_i changes sign within a step (Brent on the dense
/// v_i), one of |v_i| where the acceleration changes sign (golden section
/// on the dense v_i); otherwise the maximum is at a step end. Contact pulses
/// shorter than any output interval (the deepest penetration, the fastest
/// approach) are therefore caught to the integration tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Extrema {
    /// max |u_i| (m), body order.
    pub max_displacement: Vec<f64>,
    /// max |v_i| (m/s), body order.
    pub max_velocity: Vec<f64>,
}

/// Dense-output values of two components at time t.
fn dense_pair(
    st: &mut Stepper,
    sys: &mut ChainDynamics,
    (i, j): (usize, usize),
    t: f64,
) -> (f64, f64) {
    (st.dense_component(sys, i, t), st.dense_component(sys, j, t))
}

/// Running state of the extrema search: the window start and the previous
/// step end (interleaved state and its derivative).
struct ExtremaScan {
    from: f64,
    to: f64,
    t: f64,
    y: Vec<f64>,
    dydt: Vec<f64>,
    found: Extrema,
}

impl ExtremaScan {
    fn new((from, to): (f64, f64), bodies: usize, st: &Stepper) -> Self {
        let mut scan = Self {
            from,
            to,
            t: st.t(),
            y: st.y().to_vec(),
            dydt: st.dydt().to_vec(),
            found: Extrema {
                max_displacement: vec![0.0; bodies],
                max_velocity: vec![0.0; bodies],
            },
        };
        if from <= scan.t && scan.t <= to {
            for i in 0..bodies {
                scan.found.max_displacement[i] = scan.y[2 * i].abs();
                scan.found.max_velocity[i] = scan.y[2 * i + 1].abs();
            }
        }
        scan
    }

    /// Processes the accepted step from the previous end to `st.t()`.
    fn step(&mut self, st: &mut Stepper, sys: &mut ChainDynamics) {
        let t1 = st.t();
        let (a, b) = (self.t.max(self.from), t1.min(self.to));
        if a <= b {
            for i in 0..self.found.max_displacement.len() {
                let (iu, iv) = (2 * i, 2 * i + 1);
                let (ua, va) = if a == self.t {
                    (self.y[iu], self.y[iv])
                } else {
                    dense_pair(st, sys, (iu, iv), a)
                };
                let (ub, vb) = if b == t1 {
                    (st.y()[iu], st.y()[iv])
                } else {
                    dense_pair(st, sys, (iu, iv), b)
                };
                let mut max_u = ua.abs().max(ub.abs());
                let mut max_v = va.abs().max(vb.abs());
                if va * vb < 0.0 {
                    let v = |t| st.dense_component(sys, iv, t);
                    if let Ok(t) = EventLocator::FINE.locate(v, (a, va), (b, vb)) {
                        max_u = max_u.max(st.dense_component(sys, iu, t).abs());
                    }
                }
                if self.dydt[iv] * st.dydt()[iv] < 0.0 {
                    let speed = |t| st.dense_component(sys, iv, t).abs();
                    max_v = max_v.max(golden_max(speed, a, b).0);
                }
                let f = &mut self.found;
                f.max_displacement[i] = f.max_displacement[i].max(max_u);
                f.max_velocity[i] = f.max_velocity[i].max(max_v);
            }
        }
        self.t = t1;
        self.y.copy_from_slice(st.y());
        self.dydt.copy_from_slice(st.dydt());
    }
}

/// Why and where a simulation stopped early.
#[derive(Clone, Debug, thiserror::Error)]
#[error("{source}{}", contact_text(.contact, .approach))]
pub struct SimulationFailure {
    /// The integrator's error (time, step size, state and reason).
    #[source]
    pub source: IntegrationError,
    /// The contact engaged deepest at the failure (relative to its impact
    /// threshold), by name.
    pub contact: Option<String>,
    /// Its approach coordinate s (m).
    pub approach: f64,
}

fn contact_text(contact: &Option<String>, approach: &f64) -> String {
    match contact {
        Some(c) => format!("; deepest contact {c} at s = {approach:e} m"),
        None => String::new(),
    }
}

/// Per-contact event state.
#[derive(Clone, Copy, Debug)]
struct Tracker {
    s_on: f64,
    /// How far past s_on a step may end when entering (2/α; 0 for compact support).
    entry_margin: f64,
    active: Option<usize>,
}

/// Scans one step for events and samples.
struct StepScan<'a> {
    model: &'a Model,
    trackers: Vec<Tracker>,
    impacts: Vec<ImpactRecord>,
    /// (s, ṡ, dF/dt) of every contact at the start of the step.
    previous: Vec<(f64, f64, f64)>,
}

/// (s, ṡ, dF/dt) of contact k at a step end, from the state and its derivative.
fn contact_end(sys: &ChainDynamics, k: usize, y: &[f64], dydt: &[f64]) -> (f64, f64, f64) {
    let (s, sd) = sys.approach(k, y);
    let idx = sys.contact_indices(k);
    let sdd = idx[1].map_or(0.0, |i| dydt[i]) - idx[3].map_or(0.0, |i| dydt[i]);
    (s, sd, sys.contact_force_rate(k, s, sd, sdd))
}

/// Dense-output evaluation of contact k's (s, ṡ) at time t.
fn contact_at(st: &mut Stepper, sys: &mut ChainDynamics, k: usize, t: f64) -> (f64, f64) {
    let mut v = [0.0; 4];
    for (j, i) in sys.contact_indices(k).iter().enumerate() {
        if let Some(i) = *i {
            v[j] = st.dense_component(sys, i, t);
        }
    }
    (v[0] - v[2] - sys.clearance(k), v[1] - v[3])
}

impl StepScan<'_> {
    fn locate(
        st: &mut Stepper,
        sys: &mut ChainDynamics,
        k: usize,
        s_on: f64,
        (ta, ga): (f64, f64),
        (tb, gb): (f64, f64),
    ) -> f64 {
        EventLocator::FINE
            .locate(|t| contact_at(st, sys, k, t).0 - s_on, (ta, ga), (tb, gb))
            .unwrap_or(0.5 * (ta + tb))
    }

    /// Largest force of contact k on [ta, tb]. `interior`: the force rate
    /// says the maximum may lie inside (rising at ta or unknown, falling at tb
    /// or unknown), then a golden-section search on the dense output finds it.
    fn peak(
        st: &mut Stepper,
        sys: &mut ChainDynamics,
        k: usize,
        ta: f64,
        tb: f64,
        interior: bool,
    ) -> (f64, f64) {
        let mut force = |t: f64| {
            let (s, sd) = contact_at(st, sys, k, t);
            sys.contact_force(k, s, sd)
        };
        let (fa, fb) = (force(ta), force(tb));
        let tm = 0.5 * (ta + tb);
        let fm = if interior {
            force(tm)
        } else {
            f64::NEG_INFINITY
        };
        let mut best = if fa >= fb { (fa, ta) } else { (fb, tb) };
        if interior {
            for cand in [golden_max(&mut force, ta, tb), (fm, tm)] {
                if cand.0 > best.0 {
                    best = cand;
                }
            }
        }
        best
    }

    fn start(&mut self, st: &mut Stepper, sys: &mut ChainDynamics, k: usize, t: f64) {
        let (_, sd) = contact_at(st, sys, k, t);
        if sys.contact_law(k).needs_impact_velocity() {
            sys.set_onset_velocity(k, sd);
        }
        self.trackers[k].active = Some(self.impacts.len());
        self.impacts.push(ImpactRecord {
            contact: k,
            start_time: t,
            end_time: f64::NAN,
            impact_velocity: sd,
            rebound_velocity: f64::NAN,
            peak_force: f64::NEG_INFINITY,
            peak_time: t,
        });
    }

    /// Updates the running peak of contact k's impact over [ta, tb] given
    /// the force rates at the ends (None where unknown).
    #[allow(clippy::too_many_arguments)]
    fn update_peak(
        &mut self,
        st: &mut Stepper,
        sys: &mut ChainDynamics,
        k: usize,
        ta: f64,
        tb: f64,
        rate_a: Option<f64>,
        rate_b: Option<f64>,
    ) {
        if let Some(i) = self.trackers[k].active {
            let interior = rate_a.is_none_or(|r| r > 0.0) && rate_b.is_none_or(|r| r < 0.0);
            let (f, t) = Self::peak(st, sys, k, ta, tb, interior);
            if f > self.impacts[i].peak_force {
                self.impacts[i].peak_force = f;
                self.impacts[i].peak_time = t;
            }
        }
    }

    fn finish(&mut self, st: &mut Stepper, sys: &mut ChainDynamics, k: usize, t: f64) {
        if let Some(i) = self.trackers[k].active.take() {
            let (_, sd) = contact_at(st, sys, k, t);
            self.impacts[i].end_time = t;
            self.impacts[i].rebound_velocity = -sd;
        }
    }

    /// Impact-aware step control: the largest next step that does not run
    /// more than `2/α` past the threshold of a contact approaching it
    /// (linear prediction from the step's end), or None. Steps that would
    /// otherwise jump deep into a contact are rejected by the error test,
    /// which costs a whole step each time; never caps below 5 % of `h_next`.
    fn entry_limit(&self, h_next: f64) -> Option<f64> {
        let mut limit = f64::INFINITY;
        for (k, tr) in self.trackers.iter().enumerate() {
            let (s, sd, _) = self.previous[k];
            if tr.active.is_some() || sd <= 0.0 || s >= tr.s_on {
                continue;
            }
            let reach = tr.s_on + tr.entry_margin - s;
            if reach < sd * h_next {
                limit = limit.min(reach / sd);
            }
        }
        (limit < h_next).then(|| limit.max(0.05 * h_next))
    }

    /// Processes the events of the accepted step [t0, t1].
    fn scan(&mut self, st: &mut Stepper, sys: &mut ChainDynamics) {
        let (t0, t1) = (st.t_prev(), st.t());
        for k in 0..self.model.contacts().len() {
            let (s0, sd0, r0) = self.previous[k];
            let (s1, sd1, r1) = contact_end(sys, k, st.y(), st.dydt());
            self.previous[k] = (s1, sd1, r1);
            let s_on = self.trackers[k].s_on;
            let (g0, g1) = (s0 - s_on, s1 - s_on);
            let active = self.trackers[k].active.is_some();
            if !active && g1 > 0.0 && g0 <= 0.0 {
                let ts = Self::locate(st, sys, k, s_on, (t0, g0), (t1, g1));
                self.start(st, sys, k, ts);
                self.update_peak(st, sys, k, ts, t1, None, Some(r1));
            } else if active && g1 <= 0.0 {
                let te = Self::locate(st, sys, k, s_on, (t0, g0), (t1, g1));
                self.update_peak(st, sys, k, t0, te, Some(r0), None);
                self.finish(st, sys, k, te);
            } else if active {
                self.update_peak(st, sys, k, t0, t1, Some(r0), Some(r1));
            } else if g0 <= 0.0 && sd0 > 0.0 && sd1 < 0.0 {
                // Approach turned to separation inside the step: was s_on
                // exceeded in between?
                let tm = EventLocator::FINE
                    .locate(|t| contact_at(st, sys, k, t).1, (t0, sd0), (t1, sd1))
                    .unwrap_or(0.5 * (t0 + t1));
                let gm = contact_at(st, sys, k, tm).0 - s_on;
                if gm > 0.0 {
                    let ts = Self::locate(st, sys, k, s_on, (t0, g0), (tm, gm));
                    let te = Self::locate(st, sys, k, s_on, (tm, gm), (t1, g1));
                    self.start(st, sys, k, ts);
                    self.update_peak(st, sys, k, ts, te, None, None);
                    self.finish(st, sys, k, te);
                }
            }
        }
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
    if !(opts.rtol > 0.0 && opts.rtol.is_finite()) {
        return bad("rtol", opts.rtol);
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
    Ok(())
}

/// The most values a time history may hold (2 GB of f64): a longer history
/// is refused up front rather than exhausting memory.
pub const MAX_HISTORY_VALUES: f64 = 2.5e8;

/// The most output samples a streamed history may have (a CSV of 10⁹ rows
/// is tens of GB): more is refused up front.
pub const MAX_SAMPLES: f64 = 1e9;

/// Simulates `model` from its initial state over `[0, opts.t_end]`, keeping
/// the sampled time history in [`Simulation::times`] and
/// [`Simulation::states`] (refused up front beyond [`MAX_HISTORY_VALUES`]
/// values; [`simulate_streaming`] has no such limit).
pub fn simulate(model: &Model, opts: &SimulationOptions) -> Result<Simulation, OptionsError> {
    check_options(opts)?;
    if let Some(dt) = opts.output_step {
        let values = (opts.t_end / dt + 1.0) * (2 * model.bodies().len() + 1) as f64;
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

/// Simulates `model` as [`simulate`] does, handing every output sample to
/// `sink(t, [u.., v..])` instead of keeping it (the returned history is
/// empty), so that a history of any length is written as it is computed in
/// bounded memory. `sink` returns false to stop the simulation (e.g. when
/// the disk is full); the result then ends there with
/// [`IntegrationError::Interrupted`]. At most [`MAX_SAMPLES`] samples.
pub fn simulate_streaming(
    model: &Model,
    opts: &SimulationOptions,
    mut sink: impl FnMut(f64, &[f64]) -> bool,
) -> Result<Simulation, OptionsError> {
    check_options(opts)?;
    if let Some(dt) = opts.output_step {
        let samples = opts.t_end / dt + 1.0;
        if samples > MAX_SAMPLES {
            return Err(OptionsError(format!(
                "output step = {dt} s over {} s: {samples:.3e} samples, more than {MAX_SAMPLES:e}; take a larger output step or a shorter duration",
                opts.t_end
            )));
        }
    }
    let mut sys = ChainDynamics::new(model, opts.energy);
    let mut y0 = sys.initial_state(model);
    if let Some(start) = &opts.start {
        let n = model.bodies().len();
        if start.len() != 2 * n || start.iter().any(|x| !x.is_finite()) {
            return Err(OptionsError(format!(
                "start state: needs {} finite values, got {}",
                2 * n,
                start.len()
            )));
        }
        for i in 0..n {
            y0[2 * i] = start[i];
            y0[2 * i + 1] = start[n + i];
        }
    }
    let n2 = sys.state_dim();
    let int_opts = IntegratorOptions {
        rtol: opts.rtol,
        atol: opts.atol,
        max_steps: opts.max_steps,
        error_components: opts.energy.then_some(n2),
        interrupt: opts.interrupt.clone(),
        ..IntegratorOptions::default()
    };
    let mut st =
        Stepper::new(opts.method, y0.len(), int_opts).map_err(|e| OptionsError(e.to_string()))?;
    let breakpoints: Vec<f64> = match model.base() {
        BaseExcitation::Record(r) => r
            .times()
            .iter()
            .copied()
            .filter(|&t| t > 0.0 && t < opts.t_end)
            .collect(),
        _ => Vec::new(),
    };
    let mut next_break = 0;
    let mut scan = StepScan {
        model,
        trackers: (0..model.contacts().len())
            .map(|k| Tracker {
                s_on: model.contacts()[k]
                    .law
                    .onset_approach(opts.impact_force_threshold),
                entry_margin: model.contacts()[k].law.entry_margin(),
                active: None,
            })
            .collect(),
        impacts: Vec::new(),
        previous: Vec::new(),
    };
    let mut buf = vec![0.0; y0.len()];
    // One sample in body order [u.., v..].
    let mut sample = vec![0.0; n2];
    let mut record = |t: f64, y: &[f64]| {
        for i in 0..n2 / 2 {
            sample[i] = y[2 * i];
            sample[n2 / 2 + i] = y[2 * i + 1];
        }
        sink(t, &sample)
    };
    let mut next_sample = 0usize;
    let mut sink_stopped = None;
    if opts.output_step.is_some() {
        if !record(0.0, &y0) {
            sink_stopped = Some(0.0);
        }
        next_sample = 1;
    }
    let e0 = sys.mechanical_energy(&y0);
    let mut error: Option<IntegrationError> = st.reset(&mut sys, 0.0, &y0).err();
    scan.previous = (0..model.contacts().len())
        .map(|k| contact_end(&sys, k, st.y(), st.dydt()))
        .collect();
    // Contacts already engaged at the start (s_on < s <= 0) begin an impact
    // at t = 0.
    if error.is_none() {
        for k in 0..model.contacts().len() {
            if scan.previous[k].0 > scan.trackers[k].s_on {
                scan.start(&mut st, &mut sys, k, 0.0);
            }
        }
    }
    let mut extrema = match (opts.extrema_window, &error) {
        (Some(window), None) => Some(ExtremaScan::new(window, n2 / 2, &st)),
        _ => None,
    };
    while error.is_none() && sink_stopped.is_none() && st.t() < opts.t_end {
        while next_break < breakpoints.len() && breakpoints[next_break] <= st.t() {
            next_break += 1;
        }
        let bound = breakpoints.get(next_break).copied().unwrap_or(opts.t_end);
        if let Err(e) = st.step(&mut sys, bound) {
            error = Some(e);
            break;
        }
        scan.scan(&mut st, &mut sys);
        if let Some(x) = extrema.as_mut() {
            x.step(&mut st, &mut sys);
        }
        if let Some(h) = scan.entry_limit(st.h_next()) {
            st.limit_next_step(h);
        }
        // Automatic method: free flight is never stiff; leave RODAS as soon
        // as every contact is open again (the restart costs two evaluations).
        if opts.method == Method::Auto
            && st.active() == Method::Rodas
            && scan.trackers.iter().all(|t| t.active.is_none())
        {
            let (t, y) = (st.t(), st.y().to_vec());
            if let Err(e) = st.reset(&mut sys, t, &y) {
                error = Some(e);
                break;
            }
        }
        if let Some(dt) = opts.output_step {
            loop {
                let ts = next_sample as f64 * dt;
                if ts > st.t() || ts > opts.t_end {
                    break;
                }
                st.dense_output(&mut sys, ts, &mut buf);
                next_sample += 1;
                if !record(ts, &buf) {
                    sink_stopped = Some(ts);
                    break;
                }
            }
        }
    }
    if let (None, Some(t)) = (&error, sink_stopped) {
        error = Some(IntegrationError::Interrupted { t });
    }
    let y = st.y().to_vec();
    let mut impacts = scan.impacts;
    impacts.sort_by(|a, b| {
        a.start_time
            .total_cmp(&b.start_time)
            .then(a.contact.cmp(&b.contact))
    });
    let energy = opts.energy.then(|| EnergyBalance {
        initial: e0,
        mechanical: sys.mechanical_energy(&y),
        input_work: y[n2],
        damping_dissipation: y[n2 + 1],
        contact_dissipation: y[n2 + 2],
    });
    let error = error.map(|source| {
        let state = match &source {
            IntegrationError::StepSizeUnderflow { y, .. } => y.clone(),
            _ => st.y().to_vec(),
        };
        let deepest = (0..model.contacts().len())
            .map(|k| (k, sys.approach(k, &state).0))
            .max_by(|a, b| {
                (a.1 - scan.trackers[a.0].s_on).total_cmp(&(b.1 - scan.trackers[b.0].s_on))
            });
        SimulationFailure {
            source,
            contact: deepest.map(|(k, _)| model.contact_name(k)),
            approach: deepest.map_or(f64::NAN, |d| d.1),
        }
    });
    Ok(Simulation {
        times: Vec::new(),
        states: Vec::new(),
        final_time: st.t(),
        final_displacement: (0..n2 / 2).map(|i| y[2 * i]).collect(),
        final_velocity: (0..n2 / 2).map(|i| y[2 * i + 1]).collect(),
        impacts,
        stats: st.stats(),
        contact_evaluations: sys.contact_evaluations(),
        energy,
        error,
        extrema: extrema.map(|x| x.found),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactLaw, ForceForm};
    use crate::impact::closed_form::ExponentialImpact;
    use crate::impact::TwoBodies;
    use crate::model::{Body, Contact, ContactPair};

    use crate::reference::NATURAL_FREQUENCY as W0;

    use crate::reference::{r3_response as linear_exact, seed_law as law};

    fn r2(n: usize, clearance: f64, omega: f64) -> Model {
        crate::reference::r2(n, clearance, omega).unwrap()
    }

    /// R3: clearances so large nothing touches; displacement equals the exact
    /// steady state plus transient to 1e-9 relative.
    /// A history that would exhaust memory is refused before anything runs.
    #[test]
    fn oversized_history_is_refused() {
        let model = Model::row(
            3,
            0.227,
            12.46,
            0.0437,
            1e-3,
            ContactLaw::hertz(1e9, 1.5).unwrap(),
            (true, true),
            BaseExcitation::None,
        )
        .unwrap();
        let opts = SimulationOptions {
            t_end: 1.0,
            output_step: Some(1e-9),
            ..SimulationOptions::default()
        };
        let e = simulate(&model, &opts).unwrap_err().to_string();
        assert!(e.starts_with("output step = 0.000000001 s over 1 s"), "{e}");
    }

    #[test]
    fn r3_linear_limit_matches_exact_solution() {
        let omega = 0.95 * W0;
        let model = r2(3, 1e3, omega);
        let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
        let opts = SimulationOptions {
            t_end,
            rtol: 1e-12,
            atol: 1e-15,
            output_step: Some(t_end / 50.0),
            ..Default::default()
        };
        let sim = simulate(&model, &opts).unwrap();
        assert!(sim.error.is_none() && sim.impacts.is_empty());
        let scale = sim.states.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut worst: f64 = 0.0;
        for (j, &t) in sim.times.iter().enumerate() {
            let (u, v) = linear_exact(t, omega);
            for i in 0..3 {
                worst = worst.max((sim.states[j * 6 + i] - u).abs());
                worst = worst.max((sim.states[j * 6 + 3 + i] - v).abs() / W0);
            }
        }
        assert!(
            worst < 1e-9 * scale,
            "worst error {worst:e} vs scale {scale:e}"
        );
        assert_eq!(sim.contact_evaluations, 0, "no contact comes near");
    }

    /// Two free bodies reproduce the two-body impact relations (seed eqs.
    /// 10, 16) in the impact log.
    #[test]
    fn two_free_bodies_reproduce_impact_relations() {
        for (m1, m2, u) in [(0.227, 0.227, 0.3), (0.1, 0.4, 1.5)] {
            let bodies = vec![
                Body {
                    name: "a".into(),
                    mass: m1,
                    stiffness: 0.0,
                    damping: 0.0,
                },
                Body {
                    name: "b".into(),
                    mass: m2,
                    stiffness: 0.0,
                    damping: 0.0,
                },
            ];
            let contacts = vec![Contact {
                pair: ContactPair::Bodies { left: 0, right: 1 },
                clearance: 1e-3,
                law: law(),
            }];
            let model = Model::new(
                bodies,
                vec![],
                contacts,
                BaseExcitation::None,
                vec![],
                vec![],
                vec![u, 0.0],
            )
            .unwrap();
            let opts = SimulationOptions {
                t_end: 3e-3 / u + 0.01,
                rtol: 1e-12,
                atol: 1e-16,
                ..Default::default()
            };
            let sim = simulate(&model, &opts).unwrap();
            assert_eq!(sim.impacts.len(), 1);
            let imp = &sim.impacts[0];
            let model_cf = ExponentialImpact::new(&law(), TwoBodies::new(m1, m2).unwrap()).unwrap();
            let cf = model_cf.impact(u).unwrap();
            // The law acts (weakly) before s_on: the velocity there is a
            // little below U; eq. (10) holds with the velocity at s_on.
            assert!(
                imp.impact_velocity < u && (imp.impact_velocity / u - 1.0).abs() < 1e-5,
                "{imp:?}"
            );
            let e_cf = model_cf.impact(imp.impact_velocity).unwrap().restitution;
            assert!(
                (imp.restitution() - e_cf).abs() < 1e-9,
                "e {} vs {e_cf}",
                imp.restitution()
            );
            assert!(
                (imp.peak_force / cf.peak_force - 1.0).abs() < 1e-8,
                "F {} vs {}",
                imp.peak_force,
                cf.peak_force
            );
            // Momentum is conserved exactly by the pairwise force.
            let p = m1 * sim.final_velocity[0] + m2 * sim.final_velocity[1];
            assert!((p - m1 * u).abs() < 1e-12);
        }
    }

    /// R2 (N = 3, 0.95 ω0, 5 periods) agrees with independent integrators:
    /// SciPy `solve_ivp` DOP853 and SUNDIALS CVODE (Adams) at rtol 1e-13,
    /// atol 1e-16 (bench/peers, results-2026-11-22.json; they agree with each
    /// other to 6e-9), to 1e-6 at our rtol 1e-10 and to 1e-7 at rtol 1e-13.
    #[test]
    fn r2_agrees_with_scipy_and_sundials() {
        let scipy: [f64; 6] = [
            0.00026822438569644924,
            5.387370645080881e-05,
            0.0006982749704558822,
            -0.00995929240162609,
            -0.0035041867100254133,
            0.005716496838870423,
        ];
        let cvode: [f64; 6] = [
            0.00026822439317180995,
            5.387370300603941e-05,
            0.0006982749714192805,
            -0.009959292462598081,
            -0.003504186737318731,
            0.005716496834239027,
        ];
        let omega = 0.95 * W0;
        let model = r2(3, 1e-3, omega);
        let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
        for (rtol, tol) in [(1e-10, 1e-6), (1e-13, 1e-7)] {
            let sim = simulate(
                &model,
                &SimulationOptions {
                    t_end,
                    rtol,
                    atol: rtol * 1e-3,
                    ..Default::default()
                },
            )
            .unwrap();
            let y: Vec<f64> = sim.final_state();
            for reference in [scipy, cvode] {
                let scale = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let err = y
                    .iter()
                    .zip(reference)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / scale;
                assert!(err < tol, "rtol {rtol}: error {err:e} against a peer");
            }
        }
    }

    /// RODAS (implicit) and automatic switching give the same R2 history as
    /// DOP853.
    #[test]
    fn implicit_and_auto_methods_agree() {
        let omega = 0.95 * W0;
        let model = r2(3, 1e-3, omega);
        let t_end = 2.0 * 2.0 * std::f64::consts::PI / omega;
        let run = |method| {
            let sim = simulate(
                &model,
                &SimulationOptions {
                    t_end,
                    rtol: 1e-9,
                    atol: 1e-12,
                    method,
                    ..Default::default()
                },
            )
            .unwrap();
            assert!(sim.error.is_none());
            sim
        };
        let reference = run(Method::Dop853);
        for method in [Method::Rodas, Method::Auto] {
            let sim = run(method);
            for (a, b) in sim
                .final_displacement
                .iter()
                .zip(&reference.final_displacement)
            {
                assert!((a - b).abs() < 1e-6 * 1e-3, "{method:?}: {a} vs {b}");
            }
            assert_eq!(sim.impacts.len(), reference.impacts.len(), "{method:?}");
        }
    }

    /// A body pressed against a wall for a long time (constant base
    /// acceleration of 100 m/s² toward it, a strongly damped contact,
    /// a/b = 0.01 m/s): the contact is a stiff spring-dashpot (α F = 1.3e7
    /// N/m and F/(a/b) = 1e4 N s/m on 1 kg, eigenvalues -1.5e3 and -8.5e3
    /// 1/s). RODAS reaches the static equilibrium `a e^{α s} = m a_base` in a
    /// small fraction of DOP853's steps, and automatic switching finds it.
    #[test]
    fn pressed_body_implicit_method_is_efficient() {
        let law =
            ContactLaw::exponential_from_ratio(0.01, 1.3e5, 1.0, ForceForm::Published).unwrap();
        let bodies = vec![Body {
            name: "b".into(),
            mass: 1.0,
            stiffness: 0.0,
            damping: 0.0,
        }];
        let contacts = vec![Contact {
            pair: ContactPair::RightWall { body: 0 },
            clearance: 1e-4,
            law,
        }];
        let base = BaseExcitation::Record(
            crate::model::Accelerogram::new(vec![0.0, 20.0], vec![-100.0, -100.0], 1.0).unwrap(),
        );
        let model = Model::new(bodies, vec![], contacts, base, vec![], vec![1e-4], vec![]).unwrap();
        let run = |method| {
            let sim = simulate(
                &model,
                &SimulationOptions {
                    t_end: 10.0,
                    rtol: 1e-8,
                    atol: 1e-12,
                    method,
                    ..Default::default()
                },
            )
            .unwrap();
            assert!(sim.error.is_none(), "{method:?}: {:?}", sim.error);
            sim
        };
        let s_eq = 1e-4 + (100.0f64).ln() / 1.3e5;
        let (dop, ros, auto) = (run(Method::Dop853), run(Method::Rodas), run(Method::Auto));
        for sim in [&dop, &ros, &auto] {
            assert_eq!(
                sim.impacts.len(),
                1,
                "one impact, engaged from the start: {:?}",
                &sim.impacts[..2.min(sim.impacts.len())]
            );
            assert_eq!(sim.impacts[0].start_time, 0.0);
            assert!(
                (sim.final_displacement[0] - s_eq).abs() < 1e-9,
                "{} vs {s_eq}",
                sim.final_displacement[0]
            );
        }
        assert!(
            ros.stats.steps * 20 < dop.stats.steps,
            "RODAS {} vs DOP853 {} steps",
            ros.stats.steps,
            dop.stats.steps
        );
        assert!(
            auto.stats.steps * 5 < dop.stats.steps,
            "auto {} vs DOP853 {} steps",
            auto.stats.steps,
            dop.stats.steps
        );
    }

    /// An integration that cannot finish keeps what it computed and says
    /// where it stopped.
    #[test]
    fn failure_keeps_partial_results() {
        let omega = 0.95 * W0;
        let model = r2(3, 1e-3, omega);
        let opts = SimulationOptions {
            t_end: 5.0,
            max_steps: 300,
            output_step: Some(0.01),
            ..Default::default()
        };
        let sim = simulate(&model, &opts).unwrap();
        let err = sim.error.as_ref().expect("must stop early");
        assert!(sim.final_time > 0.0 && sim.final_time < 5.0);
        assert!(!sim.times.is_empty() && *sim.times.last().unwrap() <= sim.final_time);
        assert!(err.contact.is_some());
        assert!(err.to_string().contains("deepest contact"), "{err}");
    }

    /// Energy balance: W = ΔE + D_c + D_k to the integrator's tolerance, in
    /// the seed's row with many impacts.
    #[test]
    fn energy_balance_with_impacts() {
        let omega = 0.95 * W0;
        let model = r2(3, 1e-3, omega);
        let t_end = 3.0 * 2.0 * std::f64::consts::PI / omega;
        for rtol in [1e-8, 1e-11] {
            let opts = SimulationOptions {
                t_end,
                rtol,
                atol: rtol * 1e-4,
                energy: true,
                ..Default::default()
            };
            let sim = simulate(&model, &opts).unwrap();
            assert!(sim.impacts.len() > 5, "{} impacts", sim.impacts.len());
            let e = sim.energy.unwrap();
            let scale = e.input_work.abs().max(e.contact_dissipation);
            assert!(e.contact_dissipation > 0.0 && e.damping_dissipation > 0.0);
            assert!(
                e.residual().abs() < 100.0 * rtol * scale,
                "rtol {rtol}: residual {:e} of {scale:e}",
                e.residual()
            );
        }
    }

    /// Impact log bookkeeping in the seed's row: ordered, every impact ends
    /// after it starts with its peak inside. (Restitution is not bounded by
    /// 1 here: springs and excitation act during a 10 ms contact, and slow
    /// impacts can leave faster than they came.)
    #[test]
    fn impact_log_is_consistent() {
        let omega = 0.95 * W0;
        let model = r2(3, 1e-3, omega);
        let t_end = 5.0 * 2.0 * std::f64::consts::PI / omega;
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end,
                rtol: 1e-9,
                atol: 1e-13,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(sim.error.is_none());
        for w in sim.impacts.windows(2) {
            assert!(w[0].start_time <= w[1].start_time);
        }
        for imp in sim.impacts.iter().filter(|i| i.complete()) {
            assert!(
                imp.end_time > imp.start_time
                    && imp.peak_time >= imp.start_time
                    && imp.peak_time <= imp.end_time
            );
            assert!(
                imp.impact_velocity > 0.0 && imp.rebound_velocity > 0.0 && imp.peak_force > 0.0,
                "{imp:?}"
            );
        }
    }
}
