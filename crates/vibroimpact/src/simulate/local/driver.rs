//! The local integrator's event loop (docs/theory.md §10): the set's
//! steps with roll-back, the history sampled from exact and integrated
//! motion, and the run from start to end.

use super::pace::{checks_crawl, counted};
use super::*;

/// How a step of the active set ended.
pub(super) enum Stepped {
    /// Taken back: an activation inside it; the set goes on to that time.
    RolledBack,
    /// Taken back for an event of the set inside it (a branch switch, an
    /// onset), or an event applied where the step was to start: counted
    /// as a step (events alone cannot run forever).
    Retaken,
    /// Kept, with the activation reached at its end if any.
    Kept(Crossing),
}

/// What [`run`] returns to [`simulate_streaming`]: the result, the state
/// at its final time (interleaved) and the work.
pub(in crate::simulate) struct LocalRun {
    pub t: f64,
    pub y: Vec<f64>,
    pub impacts: Vec<ImpactRecord>,
    pub stats: Stats,
    pub contact_evaluations: u64,
    pub local: LocalStats,
    pub error: Option<IntegrationError>,
    /// With [`IntegrationError::ChecksCrawl`]: the contact checked most
    /// since the previous progress check (model index).
    pub crawling: Option<usize>,
    /// The exact extrema over the options' window, if asked for.
    pub extrema: Option<Extrema>,
    /// The tangent columns at the final time, if carried (as given).
    pub tangents: Option<Vec<f64>>,
    /// The tape of the run's linearisation, if asked for.
    pub tape: Option<LocalTape>,
    /// The energy audit's sums (excitation work, damper and contact
    /// dissipation), if asked for.
    pub energy: Option<[f64; 3]>,
    /// The storeys' memory at the final time (`y` carries their Bouc–Wen
    /// states after the interleaved state).
    pub storeys: StoreyTerms,
    pub sink_stopped: Option<f64>,
    /// The bodies of the set whose step failed or passed a limit (model
    /// indices), if one did.
    pub failed_set: Vec<usize>,
    /// The rigid contacts' soft episodes.
    pub episodes: Vec<SoftEpisode>,
}

/// Tangent columns carried by a run: `columns` vectors of the interleaved
/// state, one after the other.
#[derive(Clone, Copy, Debug)]
pub(in crate::simulate) struct Tangents<'w> {
    pub values: &'w [f64],
    pub columns: usize,
}

impl Run<'_> {
    /// The tangent columns at `t` (the sets' last steps end there): the
    /// sets' rows from their states, the others by their groups' exact
    /// homogeneous motion.
    pub(super) fn tangents_at(&mut self, t: f64) -> Vec<f64> {
        let n2 = 2 * self.model.bodies().len();
        let mut w = vec![0.0; self.columns * n2];
        for g in 0..self.tangents.len() {
            if self.in_set[g] {
                continue;
            }
            self.tangents_to(g, t);
            let bodies = self.free.groups()[g].bodies();
            let m2 = 2 * bodies.len();
            for c in 0..self.columns {
                let rows = &self.tangents[g].1[c * m2..(c + 1) * m2];
                put_rows(bodies, rows, &mut w[c * n2..(c + 1) * n2]);
            }
        }
        for set in self.set.iter().chain(&self.sets) {
            let b2 = 2 * set.bodies.len();
            let z = set.st.y();
            for c in 0..self.columns {
                let rows = &z[b2 * (1 + c)..b2 * (2 + c)];
                put_rows(&set.bodies, rows, &mut w[c * n2..(c + 1) * n2]);
            }
        }
        w
    }

    /// Moves group `g`'s tangent columns to `t` by its exact homogeneous
    /// motion.
    pub(super) fn tangents_to(&mut self, g: usize, t: f64) {
        let (t0, w) = &mut self.tangents[g];
        if t > *t0 && self.columns > 0 {
            let m2 = w.len() / self.columns;
            for col in w.chunks_mut(m2) {
                self.free.propagate_homogeneous(g, t - *t0, col);
            }
            *t0 = t;
        }
    }

    /// Writes the whole interleaved state at `t` into `out`: the sets'
    /// bodies from their dense output (their last steps hold `t`), the others
    /// from their exact motion; then the Bouc–Wen states, if `out` has
    /// room for them.
    pub(super) fn state_at(&mut self, t: f64, out: &mut [f64]) {
        // Under a record the reference states move up to the sample
        // (everything before it has been sampled and checked): else every
        // sample would propagate the record from the last check. That
        // changes the trajectory by rounding; under harmonic forcing a
        // propagation costs the same over any interval, and sampling does
        // not touch the trajectory at all. (The extrema are scanned before
        // a reference moves.)
        let rebase = matches!(self.model.base(), BaseExcitation::Record(_));
        if rebase && (self.extrema.is_some() || self.energy.is_some()) {
            for g in 0..self.exact.len() {
                if !self.in_set[g] {
                    self.before_move(g, t);
                }
            }
        }
        let Run {
            free,
            exact,
            in_set,
            ..
        } = &mut *self;
        for (g, (t0, x)) in exact.iter_mut().enumerate() {
            if in_set[g] {
                continue;
            }
            debug_assert!(t >= *t0, "exact motion never runs backward");
            let moved;
            let x: &[f64] = if free.stays_at_rest(g, x) {
                x
            } else if rebase {
                free.propagate(g, *t0, t, x);
                *t0 = t;
                x
            } else {
                let mut y = Rows::from_slice(x);
                free.propagate(g, *t0, t, &mut y);
                moved = y;
                &moved
            };
            put_rows(free.groups()[g].bodies(), x, out);
        }
        let n2 = 2 * self.model.bodies().len();
        let hysteretic = out.len() > n2;
        if hysteretic {
            out[n2..].copy_from_slice(&self.hysteretic);
        }
        for set in self.set.iter_mut().chain(&mut self.sets) {
            let mut y = vec![0.0; set.st.y().len()];
            set.st.dense_output(&mut set.sys, t, &mut y);
            put_rows(&set.bodies, &y, out);
            let places =
                storeys::hysteretic_places(set.sys.chain().storeys(), &self.storeys, &set.storeys);
            for (i, w) in places.filter(|_| hysteretic) {
                out[w..w + 2].copy_from_slice(&y[i..i + 2]);
            }
        }
    }

    /// One step of a set, with its events: a boundary contact or a due
    /// check that becomes active inside the step sends the set back to the
    /// step's start and on to that time (`pending`); otherwise the step is
    /// kept open (its impacts are logged when it closes, [`Run::close`]).
    /// Returns the activation reached at the step's end, if any.
    pub(super) fn step_set(
        &mut self,
        set: &mut ActiveSet,
        pending: &mut Crossing,
    ) -> Result<Stepped, IntegrationError> {
        let t = set.st.t();
        let next_break = self
            .breakpoints
            .get(self.breakpoints.partition_point(|&b| b <= t))
            .copied()
            .unwrap_or(f64::INFINITY);
        let mut bound = self
            .opts
            .t_end
            .min(next_break)
            .min(pending.map_or(f64::INFINITY, |p| p.0));
        if let Some(sw) = set.switches.as_mut() {
            match sw.before_step(&set.st, bound) {
                Ok(b) => bound = b,
                Err(event) => {
                    apply_event(&mut set.st, &mut set.sys, event)?;
                    return Ok(Stepped::Retaken);
                }
            }
        }
        set.saved.0 = t;
        set.saved.1.clear();
        set.saved.1.extend_from_slice(set.st.y());
        if self.tape.is_some() {
            set.sys.system_mut().clear();
        }
        set.st.step(&mut set.sys, bound)?;
        let t1 = set.st.t();
        let h = set.st.h_last();
        let recorded = match self.tape {
            Some(_) => Some(set.sys.system().accepted_step(t, h, t1)?),
            None => None,
        };
        let mut first = self.boundary_crossing(set);
        // (With clusters the checks are due in the run's loop, in time
        // order with the sets.)
        if !self.clustered {
            if let Some(due) = self.due_checks(first.map_or(t1, |f| f.0)) {
                first = Some(due);
            }
        }
        if let Some((ts, k)) = first.filter(|f| f.0 < t1) {
            // Back to the step's start; on to the activation.
            if let Some(p) = pending.take() {
                if p.0 > ts {
                    self.generation[p.1] += 1;
                    self.queue
                        .push(Reverse((Time(p.0), p.1, self.generation[p.1])));
                }
            }
            let (t0, y0) = (set.saved.0, set.saved.1.clone());
            self.absorb(set);
            set.st.reset(&mut set.sys, t0, &y0)?;
            if ts <= t0 {
                // Active where the step began: joined there.
                return Ok(Stepped::Kept(Some((t0, k))));
            }
            *pending = Some((ts, k));
            set.st.limit_next_step(ts - t0);
            return Ok(Stepped::RolledBack);
        }
        // The set's own events: one inside the step takes it again up to
        // there (a due check found at its end is queued again).
        if let Some(sw) = set.switches.as_mut() {
            match sw.after_step(&mut set.st, &mut set.sys)? {
                Verdict::Retake => {
                    if let Some((tf, k)) = first {
                        self.generation[k] += 1;
                        self.queue.push(Reverse((Time(tf), k, self.generation[k])));
                    }
                    return Ok(Stepped::Retaken);
                }
                Verdict::Switch(e) => set.event = Some(e),
                Verdict::Clear => {}
            }
        }
        if let (Some(tape), Some(first)) = (self.tape.as_mut(), recorded) {
            tape.step(t, h, set.sys.system(), first);
        }
        if let Some(p) = *pending {
            if p.0 <= t1 {
                *pending = None;
                // Another activation at the same time is checked again
                // there, once p's groups have joined.
                if let Some(f) = first.filter(|f| f.1 != p.1) {
                    self.generation[f.1] += 1;
                    self.queue
                        .push(Reverse((Time(f.0), f.1, self.generation[f.1])));
                }
                return Ok(Stepped::Kept(Some(p)));
            }
        }
        Ok(Stepped::Kept(first))
    }
}

/// Simulates `model` over `[0, opts.t_end]` by the local integrator,
/// handing samples to `record` as [`simulate_streaming`] does.
pub(in crate::simulate) fn run(
    model: &Model,
    opts: &SimulationOptions,
    method: Method,
    (y0, tangents): (&[f64], Option<Tangents<'_>>),
    breakpoints: Vec<f64>,
    tape: bool,
    record: &mut dyn FnMut(f64, &[f64]) -> bool,
) -> Result<LocalRun, OptionsError> {
    check_request(model, opts, method, tape, tangents)?;
    let mut run = Run::new(model, opts, method, (y0, tangents), breakpoints, tape)?;
    let n = model.bodies().len();
    let mut out = LocalRun {
        t: 0.0,
        y: y0.to_vec(),
        impacts: Vec::new(),
        stats: Stats::default(),
        contact_evaluations: 0,
        local: LocalStats::default(),
        error: None,
        crawling: None,
        extrema: None,
        tangents: None,
        tape: None,
        energy: None,
        storeys: StoreyTerms::default(),
        sink_stopped: None,
        failed_set: Vec::new(),
        episodes: Vec::new(),
    };
    // The whole state, and the storeys' Bouc–Wen states after it.
    let mut sample = vec![0.0; 2 * n + run.hysteretic.len()];
    let mut next_sample = 0usize;
    // Emits the samples up to `t` (inclusive) from the current motion.
    let mut whole = opts
        .accelerations
        .then(|| (ChainDynamics::new(model, false), vec![0.0; sample.len()]));
    let mut emit = |run: &mut Run, t: f64, stopped: &mut Option<f64>| {
        let Some(dt) = opts.output_step else { return };
        while stopped.is_none() {
            let ts = opts.output_from + next_sample as f64 * dt;
            if ts > t || ts > opts.t_end {
                break;
            }
            run.state_at(ts, &mut sample);
            // (The sample reads the storeys' memory for its accelerations
            // and storey forces alone.)
            if opts.accelerations || opts.storey_forces {
                run.sync_storeys(true);
            }
            let body = body_sample(run, ts, &sample, whole.as_mut());
            next_sample += 1;
            if !record(ts, &body) {
                *stopped = Some(ts);
            }
        }
    };
    out.error = run.first_set().err();
    let mut t = 0.0;
    let mut steps: u64 = 0;
    let mut next_guard = PROGRESS_CHECK;
    let initial_checks = run.local.contact_checks;
    let mut checks_before = run.checks_per_contact.clone();
    while out.error.is_none() && out.sink_stopped.is_none() {
        // The earliest set (its open step first), unless a check of two
        // exactly moving groups is due before it (or there is no set). (One
        // set's steps take the checks due inside them.)
        let mut earliest = run.earliest();
        let due = run.next_check().map(|c| c.0);
        if run.clustered && due.is_some_and(|tq| earliest.is_some_and(|e| tq < e.0)) {
            earliest = None;
        }
        if let Some((te, open, which)) = earliest {
            t = te;
            // Its open step's scans come before its samples.
            if open {
                run.make_current(which);
                run.scan_open();
            }
            emit(&mut run, t, &mut out.sink_stopped);
            if !open && t >= opts.t_end {
                break;
            }
        } else if due.is_none() && t >= opts.t_end {
            break;
        }
        if let Some(stop) = &opts.interrupt {
            if let Err(e) = stop.check(t) {
                out.error = Some(e);
                break;
            }
        }
        // Checks that crawl (bounds so loose that every check looks only a
        // hair ahead) end the run with the reason, as steps that crawl do.
        // (The first check of every contact at t = 0 is not pace.)
        let checks = run.local.contact_checks - initial_checks;
        if checks >= next_guard && t > 0.0 {
            next_guard = checks + PROGRESS_CHECK;
            if let Some((e, k)) = checks_crawl(&run, opts, (t, checks), &checks_before) {
                (out.error, out.crawling) = (Some(e), k);
                break;
            }
            checks_before.clone_from(&run.checks_per_contact);
        }
        let Some((_, open, which)) = earliest else {
            let next = due.map_or(opts.t_end, |c| c.min(opts.t_end));
            emit(&mut run, next, &mut out.sink_stopped);
            t = next;
            if next >= opts.t_end {
                break;
            }
            // (Every set then waits at its time, its open step taken back
            // to the check if it joins there.)
            run.park_current();
            if let Some(at) = run.due_checks(next) {
                if let Err(e) = run.join(at.1, at.0) {
                    out.error = Some(e);
                }
            }
            continue;
        };
        run.make_current(if open { None } else { which });
        if open {
            if let Err(e) = run.close(t) {
                out.error = Some(e);
            }
            continue;
        }
        let Some(mut set) = run.set.take() else {
            continue;
        };
        let mut pending = set.pending;
        run.defer = true;
        let stepped = run.step_set(&mut set, &mut pending);
        run.defer = false;
        set.pending = pending;
        t = set.st.t();
        match stepped {
            Err(e) => out.error = Some(e),
            Ok(Stepped::RolledBack) => {}
            Ok(Stepped::Retaken) => {
                steps += 1;
                out.error = counted(&set, (method, opts), (t, steps));
            }
            Ok(Stepped::Kept(reached)) => {
                steps += 1;
                out.error = counted(&set, (method, opts), (t, steps));
                set.open = Some(reached);
                set.scanned = false;
            }
        }
        if out.error.is_some() {
            out.failed_set.clone_from(&set.bodies);
        }
        run.set = Some(set);
    }
    Ok(run.finish(out, t))
}

/// A streamed sample in body order from the whole state `y` at `t`
/// (interleaved, the Bouc–Wen states after it): [u.., v..], the
/// accelerations of the whole model `whole` (its dynamics and a buffer)
/// after them if asked (a Lankarani–Nikravesh contact's onset velocity is
/// not tracked there), then the storeys' forces if asked.
fn body_sample(
    run: &Run,
    t: f64,
    y: &[f64],
    whole: Option<&mut (ChainDynamics, Vec<f64>)>,
) -> Vec<f64> {
    let n = run.model.bodies().len();
    let mut body: Vec<f64> = (0..n)
        .map(|i| y[2 * i])
        .chain((0..n).map(|i| y[2 * i + 1]))
        .collect();
    if let Some((sys, rates)) = whole {
        sys.storeys_mut().clone_from(&run.storeys);
        crate::integrate::OdeSystem::rhs(sys, t, y, rates);
        body.extend((0..n).map(|i| rates[2 * i + 1]));
    }
    if run.opts.storey_forces {
        let at = body.len();
        body.resize(at + run.model.storeys().len(), 0.0);
        run.storey_forces(y, &mut body[at..]);
    }
    body
}

/// The requests the local integrator refuses: the energy audit with
/// tangents or a tape, a tape with a law that needs the onset velocity or
/// with a method other than DOP853, tangents or a tape with hysteretic
/// storeys.
fn check_request(
    model: &Model,
    opts: &SimulationOptions,
    method: Method,
    tape: bool,
    tangents: Option<Tangents<'_>>,
) -> Result<(), OptionsError> {
    let columns = tape || tangents.is_some_and(|w| w.columns > 0);
    if let Some(k) = (0..model.contacts().len()).find(|&k| model.impacts(k).is_rigid()) {
        if columns {
            return Err(OptionsError(format!(
                "contact {}: the local integrator carries no tangent columns through rigid impacts (their period maps run on the global flow)",
                model.contact_name(k)
            )));
        }
    }
    if model.gravity() != 0.0 {
        return Err(OptionsError(
            "gravity along the row: such models run on the global integrator (integrator = global, or auto)".into(),
        ));
    }
    if opts.energy && (tape || tangents.is_some_and(|w| w.columns > 0)) {
        return Err(OptionsError(
            "the energy audit carries no tangent columns or tape".into(),
        ));
    }
    // (Period maps refuse such laws before a tape is asked for; the tape
    // would miss the onset velocity's dependence on the state.)
    if tape
        && model
            .contacts()
            .iter()
            .any(|c| c.law.needs_impact_velocity())
    {
        return Err(OptionsError(
            "a tangent tape cannot follow a law that needs the impact's onset velocity".into(),
        ));
    }
    if !model.storeys().is_empty() && (tape || tangents.is_some_and(|w| w.columns > 0)) {
        return Err(OptionsError(
            "tangent columns cannot follow hysteretic storeys (their branch switches and Bouc–Wen states are not in the variational equations)".into(),
        ));
    }
    if tape && method != Method::Dop853 {
        return Err(OptionsError(format!(
            "a tangent tape replays DOP853's stages; the method here is {method:?}"
        )));
    }
    Ok(())
}

impl<'a> Run<'a> {
    /// The run's state at t = 0: the groups' exact motions from `y0` (and
    /// their tangent columns), no set yet, every contact unscheduled.
    fn new(
        model: &'a Model,
        opts: &'a SimulationOptions,
        method: Method,
        (y0, tangents): (&[f64], Option<Tangents<'_>>),
        breakpoints: Vec<f64>,
        tape: bool,
    ) -> Result<Self, OptionsError> {
        let free = FreeMotion::new(model).map_err(|e| OptionsError(e.to_string()))?;
        let n = model.bodies().len();
        let ng = free.groups().len();
        let nc = model.contacts().len();
        let mut sides = Vec::with_capacity(2 * nc);
        for (k, c) in model.contacts().iter().enumerate() {
            for g in side_groups(&free, c).into_iter().flatten() {
                sides.push((g, k));
            }
        }
        let group_contacts = Lists::new(ng, sides.iter().copied());
        let group_storeys = Lists::new(
            ng,
            (model.storeys().iter().enumerate())
                .filter(|&(s, _)| Self::checked_storey(model, s))
                .map(|(s, st)| (free.place(st.above).0, s)),
        );
        let ns = model.storeys().len();
        let storeys = StoreyTerms::new(model.storeys(), 2 * n, model.initial_displacement());
        let exact = free
            .groups()
            .iter()
            .map(|g| (0.0, rows_of(g.bodies(), y0)))
            .collect();
        let columns = tangents.map_or(0, |w| w.columns);
        // (None carried: none per group.)
        let tangent_refs = tangents.map_or(Vec::new(), |tw| {
            let rows = |g: &free_motion::Group| -> Vec<f64> {
                (0..columns)
                    .flat_map(|c| rows_of(g.bodies(), &tw.values[c * 2 * n..(c + 1) * 2 * n]))
                    .collect()
            };
            free.groups().iter().map(|g| (0.0, rows(g))).collect()
        });
        let like: Vec<bool> = (0..nc).map(|k| like_previous(model, k)).collect();
        let activation = Activation::all(model, opts, &like);
        let (rigid, pre) = rigid_parts(model, opts, &like)?;
        let mut run = Self {
            model,
            opts,
            method,
            free,
            exact,
            in_set: vec![false; ng],
            joined: vec![0.0; ng],
            defer: false,
            deferred: Vec::new(),
            slot: vec![None; n],
            activation,
            group_contacts,
            group_storeys,
            generation: vec![0; nc + ns],
            queue: BinaryHeap::new(),
            set: None,
            sets: Vec::new(),
            merging: Vec::new(),
            clustered: clustered(model, opts, tape, columns),
            impacts: Vec::new(),
            onset: vec![(None, 0.0); nc],
            stats: Stats::default(),
            contact_evaluations: 0,
            local: LocalStats {
                body_evaluations: vec![0; n],
                ..LocalStats::default()
            },
            checks_per_contact: vec![0; nc + ns],
            hysteretic: vec![0.0; storeys.states()],
            storeys,
            extrema: None,
            columns,
            tangents: tangent_refs,
            breakpoints,
            tape: tape.then(TapeRecord::default),
            alike: Vec::new(),
            energy: None,
            rigid,
            last_impact: vec![(f64::NEG_INFINITY, 0.0); nc],
            pre,
            armed: vec![false; nc],
            episodes: Vec::new(),
        };
        // Every group with storeys on linear branches moves about its rest
        // state (one with a Bouc–Wen storey joins the set at once).
        for g in 0..ng {
            let storeys = &run.group_storeys[g];
            let linear = storeys
                .iter()
                .all(|&s| run.storeys.linear_branch(s).is_some());
            if !storeys.is_empty() && linear {
                run.settle_rest(g)
                    .map_err(|e| OptionsError(e.to_string()))?;
            }
        }
        if opts.energy {
            run.energy = Some(LocalEnergy::new(model, &run.free));
        }
        run.alike = model
            .contacts()
            .iter()
            .map(|c| alike::alike(&run.free, c))
            .collect();
        if let Some(window) = opts.extrema_window {
            // (A rigid contact's margin is its approach itself, as in the
            // global run.)
            let s_on = (model.contacts().iter().enumerate())
                .map(|(k, c)| match run.is_rigid(k) {
                    true => 0.0,
                    false => c.law.onset_approach(opts.impact_force_threshold),
                })
                .collect();
            run.extrema = Some(LocalExtrema::new(
                window,
                model,
                &run.free,
                (s_on, &opts.gauges, opts.extrema_of_bodies),
            ));
        }
        Ok(run)
    }

    /// The first set at t = 0: the contacts active there, and the storeys
    /// near yield or integrated throughout; every other check scheduled
    /// (none for a contact open at rest for good).
    fn first_set(&mut self) -> Result<(), IntegrationError> {
        let model = self.model;
        let nc = model.contacts().len();
        let checked = (0..model.storeys().len())
            .filter(|&s| Run::checked_storey(model, s))
            .map(|s| nc + s);
        let still: Vec<bool> = (self.exact.iter().enumerate())
            .map(|(g, (_, x))| self.free.stays_at_rest(g, x))
            .collect();
        for k in (0..nc).chain(checked) {
            if self.open_at_rest(k, |g| still[g]) {
                continue;
            }
            if !self.touches_set(k) && self.schedule(k, 0.0) {
                self.join(k, 0.0)?;
            }
        }
        Ok(())
    }

    /// The run's result at its end `t` (where it stopped): the state, the
    /// tangents, the exact motion's extrema and energy since each group's
    /// last reference, and the set's results.
    fn finish(self, mut out: LocalRun, t: f64) -> LocalRun {
        let mut run = self;
        let n = run.model.bodies().len();
        let opts = run.opts;
        // The state at the end (or where it stopped: the earliest set).
        let t_final = match run.earliest() {
            Some((te, ..)) => te,
            None => t.min(opts.t_end),
        };
        let mut y = vec![0.0; 2 * n + run.hysteretic.len()];
        run.state_at(t_final, &mut y);
        run.sync_storeys(true);
        if run.columns > 0 {
            out.tangents = Some(run.tangents_at(t_final));
        }
        // The exact motion since each group's last reference state: its
        // extrema and its part of the energy audit.
        for g in 0..run.exact.len() {
            if !run.in_set[g] {
                run.before_move(g, t_final);
            }
        }
        run.park_current();
        for mut set in std::mem::take(&mut run.sets) {
            // An open step at the end logs its impacts (one past where the
            // run stopped does not).
            if set.open.take().is_some() && !set.scanned && set.st.t() <= t_final {
                std::mem::swap(&mut run.impacts, &mut set.scan.impacts);
                set.scan.scan(&mut set.st, &mut set.sys);
                std::mem::swap(&mut run.impacts, &mut set.scan.impacts);
            }
            run.energy_of_set(set.st.y(), set.sys.chain().audit_index());
            run.absorb(&mut set);
            if let (Some(ex), Some(scan)) = (run.extrema.as_mut(), &set.extrema) {
                ex.merge(&set, scan);
            }
            run.contact_evaluations += set.sys.chain().contact_evaluations();
        }
        out.t = t_final;
        out.y = y;
        out.impacts = std::mem::take(&mut run.impacts);
        out.stats = run.stats;
        out.contact_evaluations = run.contact_evaluations;
        out.local = run.local;
        out.extrema = run.extrema.map(LocalExtrema::into_found);
        out.energy = run.energy.map(|e| e.sums);
        out.tape = run.tape.map(|r| r.finish(run.free, n, t_final));
        out.storeys = run.storeys;
        out.episodes = run.episodes;
        out
    }
}
