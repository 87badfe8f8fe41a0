//! A run streamed sample by sample (docs/theory.md §4): the checks of the
//! run, its start state, the global integrator's steps with impact
//! tracking, extrema, the automatic method's switch back to DOP853, the
//! early ends (stiff, crawling) and the output sampler; the local
//! integrator's run where it is chosen (§10).

use super::switches::{apply_event, judging_gaps, Event, Jump, Switches, Verdict};
use super::*;
use crate::integrate::{LinearForm, OdeSystem};

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
    check_run(model, opts)?;
    let y0 = start_state(model, opts)?;
    let int_opts = IntegratorOptions {
        rtol: opts.rtol,
        atol: opts.atol,
        max_steps: opts.max_steps,
        // Not the audit's quadratures (the storeys' states come before).
        error_components: opts
            .energy
            .then_some(ChainDynamics::state_len(model, false)),
        interrupt: opts.interrupt.clone(),
        ..IntegratorOptions::default()
    };
    let method = effective_method(model, opts)?;
    let breakpoints = breakpoints(model, opts.t_end);
    if opts.integrator.resolve_run(model, opts) == Integrator::Local {
        // (Its options checked as the global stepper's would be; the local
        // run builds its own systems and steppers.)
        int_opts
            .validate(y0.len())
            .map_err(|e| OptionsError(e.to_string()))?;
        if exact::qualifies(model, opts) {
            return Ok(exact::run(model, opts, &y0, &mut sink));
        }
        return simulate_local(model, opts, method, &y0, breakpoints, &mut sink);
    }
    let mut sys = ChainDynamics::new(model, opts.energy);
    debug_assert_eq!(sys.dim(), y0.len());
    let n2 = sys.state_dim();
    let mut st =
        Stepper::new(method, y0.len(), int_opts).map_err(|e| OptionsError(e.to_string()))?;
    // Between rigid impacts a small chain moves exactly (its linear form,
    // while no soft episode runs; docs/theory.md §12): asked for where the
    // chain has a form at the start, before any episode.
    let rigid = (0..model.contacts().len()).any(|k| model.impacts(k).is_rigid());
    if rigid && y0.len() <= EXACT_MAX_DIM && sys.linear_form().and_then(LinearForm::solve).is_some()
    {
        st = st.exact_where_linear();
    }
    let mut next_break = 0;
    let mut output = Output::new(opts, (y0.len(), n2, model.storeys().len()), &mut sink);
    let mut sink_stopped = None;
    if opts.output_step.is_some() && opts.output_from == 0.0 {
        if !output.record(0.0, &y0, &mut sys) {
            sink_stopped = Some(0.0);
        }
        output.next = 1;
    }
    let e0 = sys.mechanical_energy(&y0);
    let mut error: Option<IntegrationError> = st.reset(&mut sys, 0.0, &y0).err();
    let mut scan = start_scan(model, opts, (&mut st, &mut sys), error.is_none());
    let mut extrema = match (opts.extrema_window, &error) {
        (Some(window), None) => {
            // (A rigid contact's margin is its approach itself.)
            let s_on = scan
                .trackers
                .iter()
                .map(|tr| {
                    if tr.s_on == f64::INFINITY {
                        0.0
                    } else {
                        tr.s_on
                    }
                })
                .collect();
            Some(ExtremaScan::new(
                window,
                n2 / 2,
                (s_on, &opts.gauges, opts.extrema_of_bodies),
                &st,
                &sys,
            ))
        }
        _ => None,
    };
    let s_on: Vec<f64> = scan.trackers.iter().map(|tr| tr.s_on).collect();
    let pre = judging_gaps(&sys, opts.impact_force_threshold);
    let mut switches = Switches::new(&sys, y0.len(), s_on, pre);
    let mut episodes: Vec<SoftEpisode> = Vec::new();
    // (Every episode before `closed` has ended: the checks start there.)
    let mut closed = 0;
    let mut steps: u64 = 0;
    while error.is_none() && sink_stopped.is_none() && st.t() < opts.t_end {
        while next_break < breakpoints.len() && breakpoints[next_break] <= st.t() {
            next_break += 1;
        }
        let mut bound = breakpoints.get(next_break).copied().unwrap_or(opts.t_end);
        if let Some(sw) = switches.as_mut() {
            match sw.before_step(&st, bound) {
                Ok(b) => bound = b,
                // An event located at the step's start: applied there
                // (counted as a step: events alone cannot run forever).
                Err(event) => {
                    steps += 1;
                    let runs = (&mut scan, extrema.as_mut(), &mut episodes);
                    error = applied(event, (&mut st, &mut sys), sw, runs, opts)
                        .or_else(|| early_end(&st, method, opts, steps));
                    if error.is_some() {
                        break;
                    }
                    continue;
                }
            }
        }
        if let Err(e) = st.step(&mut sys, bound) {
            error = Some(e);
            break;
        }
        let mut switch_here = None;
        if let Some(sw) = switches.as_mut() {
            match sw.after_step(&mut st, &mut sys) {
                Err(e) => {
                    error = Some(e);
                    break;
                }
                // A step taken again counts: retakes alone cannot run
                // forever.
                Ok(Verdict::Retake) => {
                    steps += 1;
                    error = early_end(&st, method, opts, steps);
                    if error.is_some() {
                        break;
                    }
                    continue;
                }
                Ok(Verdict::Switch(k)) => switch_here = Some(k),
                Ok(Verdict::Clear) => {}
            }
        }
        scan.scan(&mut st, &mut sys);
        if let Some(x) = extrema.as_mut() {
            x.step(&mut st, &mut sys);
        }
        if let Some(sw) = switches.as_mut() {
            let open = &mut episodes[closed..];
            if let Err(e) = separated(open, (&mut st, &mut sys), sw, &mut scan) {
                error = Some(e);
                break;
            }
            while episodes.get(closed).is_some_and(|e| !e.end_time.is_nan()) {
                closed += 1;
            }
        }
        if let Some(h) = scan.entry_limit(st.h_next()) {
            st.limit_next_step(h);
        }
        steps += 1;
        error = early_end(&st, method, opts, steps);
        if error.is_some() {
            break;
        }
        // Automatic method: leave RODAS as soon as every contact is open
        // again and an explicit step of RODAS's size would be stable (the
        // restart costs two evaluations).
        if method == Method::Auto
            && st.active() == Method::Rodas
            && scan.trackers.iter().all(|t| t.active.is_none())
            && st
                .rodas_jacobian_bound()
                .is_some_and(|b| st.h_next() * b < EXPLICIT_STABILITY)
        {
            let (t, y) = (st.t(), st.y().to_vec());
            if let Err(e) = st.reset(&mut sys, t, &y) {
                error = Some(e);
                break;
            }
        }
        sink_stopped = output.samples(&mut st, &mut sys);
        // A bilinear storey's branch switches, or a contact's impact
        // velocity is set, where the step ended; the right-hand side
        // changes there, so the stepper restarts.
        if let (Some(event), Some(sw)) = (switch_here, switches.as_mut()) {
            let runs = (&mut scan, extrema.as_mut(), &mut episodes);
            error = applied(event, (&mut st, &mut sys), sw, runs, opts);
            if error.is_some() {
                break;
            }
        }
    }
    if let (None, Some(t)) = (&error, sink_stopped) {
        error = Some(IntegrationError::Interrupted { t });
    }
    let extrema = extrema.map(ExtremaScan::finish);
    let mut sim = global_result(model, opts, (st, sys), scan, e0, error, extrema);
    sim.soft_episodes = episodes;
    Ok(sim)
}

/// Applies `event` where the stepper stands ([`apply_event`]; a rigid
/// contact's impact by [`Switches::rigid_or_soft`]): the extrema scan
/// restarts there (and takes a rigid impact's velocity jump); a rigid
/// impact enters the impact log; a soft episode starts its contact's law
/// and tracker there.
fn applied(
    event: Event,
    (st, sys): (&mut Stepper, &mut ChainDynamics),
    sw: &mut Switches,
    (scan, extrema, episodes): (
        &mut StepScan,
        Option<&mut ExtremaScan>,
        &mut Vec<SoftEpisode>,
    ),
    opts: &SimulationOptions,
) -> Option<IntegrationError> {
    let (k, approach) = match event {
        Event::Impact(k) => (k, false),
        Event::Approach(k) => (k, true),
        _ => {
            if let Err(e) = apply_event(st, sys, event) {
                return Some(e);
            }
            if let Some(x) = extrema {
                x.restarted(st, false);
            }
            return None;
        }
    };
    let (t, mut y, dydt) = (st.t(), st.y().to_vec(), st.dydt().to_vec());
    let floor = st.options().atol;
    // Judged where the law's force starts (an approach): a soft episode
    // from there, or on to the touch; at the touch, the jump or an
    // episode from there.
    let jump = match approach {
        true => match sw.judge(sys, k, (t, &y, &dydt), floor) {
            Ok(Some(reason)) => Jump::Soft(reason),
            Ok(None) => return None,
            Err(e) => return Some(e),
        },
        false => match sw.rigid_or_soft(sys, k, (t, &mut y, &dydt), floor) {
            Ok(jump) => jump,
            Err(e) => return Some(e),
        },
    };
    if let Jump::Soft(reason) = &jump {
        if let Err(e) = sw.soft_impact(sys, k, (t, &y), reason) {
            return Some(e);
        }
        sys.set_soft_episode(k, true);
        sw.suspend(k, true);
    }
    if let Err(e) = st.reset(sys, t, &y) {
        return Some(e);
    }
    let jumped = matches!(jump, Jump::Rigid(_));
    match jump {
        Jump::Touch => {}
        Jump::Rigid(r) => scan.impacts.push(ImpactRecord::jump(k, t, r)),
        Jump::Soft(reason) => {
            scan.trackers[k] = Tracker::new(sys.contact_law(k), opts.impact_force_threshold);
            scan.previous[k] = contact_end(sys, k, st.y(), st.dydt());
            scan.start(st, sys, k, t);
            episodes.push(SoftEpisode {
                contact: k,
                start_time: t,
                end_time: f64::NAN,
                reason,
            });
        }
    }
    if let Some(x) = extrema {
        x.restarted(st, jumped);
    }
    None
}

/// Ends every soft episode whose bodies have separated by the stepper's
/// point (the approach below its impact threshold and opening, no impact
/// under way): the contact's impacts are jumps again from there.
fn separated(
    episodes: &mut [SoftEpisode],
    (st, sys): (&mut Stepper, &mut ChainDynamics),
    sw: &mut Switches,
    scan: &mut StepScan,
) -> Result<(), IntegrationError> {
    let mut ended = false;
    for ep in episodes.iter_mut().filter(|e| e.end_time.is_nan()) {
        let k = ep.contact;
        let tracker = scan.trackers[k];
        let (s, sd) = sys.approach(k, st.y());
        if tracker.active.is_none() && s < tracker.s_on.min(0.0) && sd < 0.0 {
            sys.set_soft_episode(k, false);
            sw.suspend(k, false);
            scan.trackers[k] = Tracker::never();
            ep.end_time = st.t();
            ended = true;
        }
    }
    if ended {
        let (t, y) = (st.t(), st.y().to_vec());
        st.reset(sys, t, &y)?;
    }
    Ok(())
}

/// The impact scan of a global run from the stepper's start: every
/// contact tracked; if `started` (the stepper is at t = 0), those already
/// engaged there (s_on < s <= 0) in an impact from t = 0.
fn start_scan(
    model: &Model,
    opts: &SimulationOptions,
    (st, sys): (&mut Stepper, &mut ChainDynamics),
    started: bool,
) -> StepScan {
    let mut scan = StepScan {
        ids: (0..model.contacts().len()).collect(),
        trackers: model
            .contacts()
            .iter()
            .enumerate()
            .map(|(k, c)| match model.impacts(k).is_rigid() {
                // Never engaged: its impacts are the switches' events.
                true => Tracker::never(),
                false => Tracker::new(&c.law, opts.impact_force_threshold),
            })
            .collect(),
        impacts: Vec::new(),
        previous: (0..model.contacts().len())
            .map(|k| contact_end(sys, k, st.y(), st.dydt()))
            .collect(),
    };
    if started {
        for k in 0..model.contacts().len() {
            if scan.previous[k].0 > scan.trackers[k].s_on {
                scan.start(st, sys, k, 0.0);
            }
        }
    }
    scan
}

/// The checks of a run beyond the options' own: the output samples within
/// [`MAX_SAMPLES`], a record's duration within the record.
pub(super) fn check_run(model: &Model, opts: &SimulationOptions) -> Result<(), OptionsError> {
    check_options(opts)?;
    if let Some(dt) = opts.output_step {
        let samples = (opts.t_end - opts.output_from) / dt + 1.0;
        if samples > MAX_SAMPLES {
            return Err(OptionsError(format!(
                "output step = {dt} s over {} s: {samples:.3e} samples, more than {MAX_SAMPLES:e}; take a larger output step or a shorter duration",
                opts.t_end
            )));
        }
    }
    for gauge in &opts.gauges {
        gauge.check(model.bodies().len()).map_err(OptionsError)?;
    }
    if let BaseExcitation::Record(r) = model.base() {
        let end = r.times().last().copied().unwrap_or(0.0);
        // A hair of slack for a duration typed from the record's own times.
        if opts.t_end > end * (1.0 + 1e-12) {
            return Err(OptionsError(format!(
                "duration = {} s: the accelerogram ends at {end} s; give a duration up to the record's end (a record is not extended with zeros)",
                opts.t_end
            )));
        }
    }
    Ok(())
}

/// The interleaved start state: the model's, or the options' `start`
/// (body order, checked).
fn start_state(model: &Model, opts: &SimulationOptions) -> Result<Vec<f64>, OptionsError> {
    let mut y0 = ChainDynamics::initial_state(model, opts.energy);
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
    Ok(y0)
}

/// Why a run ends early after `steps` steps, if it does: an explicit
/// method whose stability limits its step so far that the rest of the run
/// would exceed the step limit (a contact or body far stiffer than the
/// motion), or any method that crawls (a nonsensical parameter, e.g. a
/// contact damping of 1e300) instead of grinding to the step limit.
fn early_end(
    st: &Stepper,
    method: Method,
    opts: &SimulationOptions,
    steps: u64,
) -> Option<IntegrationError> {
    if matches!(method, Method::Dop853 | Method::Dopri5) && st.stiffness_detected() {
        let h = st.t() - st.t_prev();
        let projected = (opts.t_end - st.t()) / h;
        let limit = opts.max_steps;
        if projected > limit.saturating_sub(st.stats().steps) as f64 {
            return Some(IntegrationError::Stiff {
                t: st.t(),
                h,
                projected,
                limit,
            });
        }
    }
    if steps % PROGRESS_CHECK == 0 {
        let projected = steps as f64 * opts.t_end / st.t();
        if projected > CRAWL_FACTOR * opts.max_steps as f64 {
            return Some(IntegrationError::NoProgress {
                t: st.t(),
                steps,
                projected,
                limit: opts.max_steps,
            });
        }
    }
    None
}

/// The output samples of a run: every `output_step` from `output_from`,
/// in body order, to the sink.
struct Output<'a, S> {
    step: Option<f64>,
    from: f64,
    t_end: f64,
    /// Index of the next sample.
    next: usize,
    /// Dense output in the integrator's layout.
    buf: Vec<f64>,
    /// One sample in body order [u.., v..] (and a.. with
    /// `accelerations`).
    sample: Vec<f64>,
    /// The right-hand side at a sample, for its accelerations.
    rates: Option<Vec<f64>>,
    /// Whether samples end with the storeys' forces.
    storey_forces: bool,
    sink: &'a mut S,
}

impl<'a, S: FnMut(f64, &[f64]) -> bool> Output<'a, S> {
    /// `dims`: the integrated state's length, the mechanical state's and
    /// the number of hysteretic storeys.
    fn new(opts: &SimulationOptions, dims: (usize, usize, usize), sink: &'a mut S) -> Self {
        let extra = if opts.accelerations { dims.1 / 2 } else { 0 }
            + if opts.storey_forces { dims.2 } else { 0 };
        Self {
            step: opts.output_step,
            from: opts.output_from,
            t_end: opts.t_end,
            next: 0,
            buf: vec![0.0; dims.0],
            sample: vec![0.0; dims.1 + extra],
            rates: opts.accelerations.then(|| vec![0.0; dims.0]),
            storey_forces: opts.storey_forces,
            sink,
        }
    }

    /// Hands the interleaved state `y` at `t` to the sink (with the
    /// bodies' accelerations from `sys`, if asked); false if it asks to
    /// stop.
    fn record(&mut self, t: f64, y: &[f64], sys: &mut ChainDynamics) -> bool {
        let n = sys.state_dim() / 2;
        for i in 0..n {
            self.sample[i] = y[2 * i];
            self.sample[n + i] = y[2 * i + 1];
        }
        let mut at = 2 * n;
        if let Some(rates) = self.rates.as_mut() {
            crate::integrate::OdeSystem::rhs(sys, t, y, rates);
            for i in 0..n {
                self.sample[at + i] = rates[2 * i + 1];
            }
            at += n;
        }
        if self.storey_forces {
            for (k, f) in self.sample[at..].iter_mut().enumerate() {
                *f = sys.storeys().force(k, y);
            }
        }
        (self.sink)(t, &self.sample)
    }

    /// The samples within the last step, by dense output; the time of the
    /// sample at which the sink asked to stop, if it did.
    fn samples(&mut self, st: &mut Stepper, sys: &mut ChainDynamics) -> Option<f64> {
        let dt = self.step?;
        loop {
            let ts = self.from + self.next as f64 * dt;
            if ts > st.t() || ts > self.t_end {
                return None;
            }
            st.dense_output(sys, ts, &mut self.buf);
            self.next += 1;
            let buf = std::mem::take(&mut self.buf);
            let go_on = self.record(ts, &buf, sys);
            self.buf = buf;
            if !go_on {
                return Some(ts);
            }
        }
    }
}

/// The result of a run by the global integrator: the final state, the
/// impacts in order, the energy balance and the failure, if any, with the
/// state it happened in.
fn global_result(
    model: &Model,
    opts: &SimulationOptions,
    (st, sys): (Stepper, ChainDynamics),
    scan: StepScan,
    e0: f64,
    error: Option<IntegrationError>,
    extrema: Option<Extrema>,
) -> Simulation {
    let n2 = sys.state_dim();
    let y = st.y().to_vec();
    let mut impacts = scan.impacts;
    by_start(&mut impacts);
    let q = sys.audit_index();
    let energy = opts.energy.then(|| EnergyBalance {
        initial: e0,
        mechanical: sys.mechanical_energy(&y),
        input_work: y[q],
        damping_dissipation: y[q + 1],
        contact_dissipation: y[q + 2],
        hysteretic_dissipation: sys.storeys().dissipated(&y),
    });
    let error = error.map(|source| {
        let state = match &source {
            IntegrationError::StepSizeUnderflow { y, .. } => y.clone(),
            _ => st.y().to_vec(),
        };
        let s_on: Vec<f64> = scan.trackers.iter().map(|tr| tr.s_on).collect();
        failure(model, source, &state, &s_on)
    });
    Simulation {
        times: Vec::new(),
        states: Vec::new(),
        final_time: st.t(),
        final_displacement: (0..n2 / 2).map(|i| y[2 * i]).collect(),
        final_velocity: (0..n2 / 2).map(|i| y[2 * i + 1]).collect(),
        impacts,
        stats: st.stats(),
        contact_evaluations: sys.contact_evaluations(),
        hysteretic_energy: model
            .storeys()
            .iter()
            .enumerate()
            .map(|(k, _)| sys.storeys().dissipated_by(k, &y))
            .collect(),
        energy,
        error,
        extrema,
        local: None,
        soft_episodes: Vec::new(),
    }
}
