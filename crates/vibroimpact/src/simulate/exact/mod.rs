//! The exact run of a model that is linear between its storeys' switches
//! (docs/theory.md §13): no contacts, storeys elastic, bilinear or IMK
//! (with their P-Δ), under a record's first-order hold or no base motion,
//! no harmonic forces, no energy audit. Between the record's samples and
//! the switches its motion is the Taylor series of [`series`]; every
//! switch is found on that motion (a storey's switch function stays
//! positive over a piece where its values at the ends exceed its rate's
//! bound times the piece, the bound from the series' coefficients; else
//! the piece is halved) and located by Brent to 4 ulp of the time; the
//! samples, the extrema and the gauges are read on the series. The local
//! integrator runs such a model this way (a building alone under a
//! record: no contacts to be local about).
//!
//! Files: `mod.rs` (the run), `series.rs` (one interval's series),
//! `tests.rs` (against closed forms and the global integrator).

mod series;
#[cfg(test)]
mod tests;

use series::{Built, Series};

use super::gauges::GaugeScan;
use super::*;
use crate::dynamics::{PiecewiseForm, StoreyTerms};
use crate::numeric::brent;

/// Halvings of a piece before a storey's switch function, positive at
/// both ends and not excluded by its bound, is taken not to reach zero
/// inside (a tangency: a yield or reversal that grazes).
const MAX_HALVINGS: usize = 10;

/// Whether `model` runs exactly under `opts` (see the module
/// documentation).
#[inline(never)]
pub(super) fn qualifies(model: &Model, opts: &SimulationOptions) -> bool {
    // (The model's own terms first, as the form would find them: a row
    // with contacts never builds its dynamics here. Every local run asks:
    // for the struck row of 1000 bodies that had been a third of its run.)
    !opts.energy
        && model.contacts().is_empty()
        && model.forces().is_empty()
        && model.gravity() == 0.0
        && matches!(
            model.base(),
            BaseExcitation::None | BaseExcitation::Record(_)
        )
        && ChainDynamics::new(model, false).piecewise_form(&mut PiecewiseForm::default())
}

/// What the run reads as it goes: the samples' row, the extrema and the
/// gauges.
struct Reader {
    /// One sample in body order [u.., v..] (then a.. and the storeys'
    /// forces, as asked).
    row: Vec<f64>,
    /// A state.
    y: Vec<f64>,
    window: Option<(f64, f64)>,
    bodies: bool,
    found: Extrema,
    gauges: Vec<GaugeScan>,
    reads: Vec<Read>,
    /// Each gauge's time, value and rate where the last piece ended (NaN
    /// time: none): a separation's rate is continuous, so the next piece
    /// starts from them.
    ends: Vec<(f64, (f64, f64))>,
}

/// Runs `model` from `y0` as [`simulate_streaming`] does, exactly (the
/// model [`qualifies`]). (Never inlined: the global run's loop beside it
/// took 20 % longer on R2 N = 3 in the benchmark's build where it was.)
#[inline(never)]
pub(super) fn run(
    model: &Model,
    opts: &SimulationOptions,
    y0: &[f64],
    sink: &mut impl FnMut(f64, &[f64]) -> bool,
) -> Simulation {
    let mut sys = ChainDynamics::new(model, false);
    let n = model.bodies().len();
    let dim = 2 * n;
    let mut form = PiecewiseForm::default();
    sys.piecewise_form(&mut form);
    let breaks = breakpoints(model, opts.t_end);
    let base = model.base();
    let mut series = Series::new(dim);
    let extra = if opts.accelerations { n } else { 0 }
        + if opts.storey_forces {
            model.storeys().len()
        } else {
            0
        };
    let mut reader = Reader {
        row: vec![0.0; dim + extra],
        y: vec![0.0; dim],
        window: opts.extrema_window,
        bodies: opts.extrema_of_bodies,
        found: Extrema {
            max_displacement: vec![0.0; n],
            max_velocity: vec![0.0; n],
            impact_margin: Vec::new(),
            gauges: Vec::new(),
        },
        gauges: opts.gauges.iter().copied().map(GaugeScan::new).collect(),
        reads: opts.gauges.iter().copied().map(Read::of).collect(),
        ends: vec![(f64::NAN, (0.0, 0.0)); opts.gauges.len()],
    };
    if let Some((from, to)) = reader.window {
        if from <= 0.0 && 0.0 <= to {
            for i in 0..n {
                reader.found.max_displacement[i] = y0[2 * i].abs();
                reader.found.max_velocity[i] = y0[2 * i + 1].abs();
            }
        }
    }
    let (mut t, mut y) = (0.0, y0.to_vec());
    let mut next_sample = 0usize;
    let mut error = None;
    if opts.output_step.is_some() && opts.output_from == 0.0 {
        next_sample = 1;
        if !reader.sample(opts, &mut sys, 0.0, &y, None, sink) {
            error = Some(IntegrationError::Interrupted { t: 0.0 });
        }
    }
    let (mut pieces, mut products) = (0u64, 0u64);
    let mut next_break = 0;
    let mut cap = f64::INFINITY;
    // What each storey's switch parts are known to be at the last piece's end.
    let mut carried = vec![Known::Nothing; model.storeys().len()];
    let mut slopes = vec![(0.0, 0.0, false); model.storeys().len()];
    slopes_of(sys.storeys(), &mut slopes);
    while error.is_none() && t < opts.t_end {
        if let Some(stop) = &opts.interrupt {
            if let Err(e) = stop.check(t) {
                error = Some(e);
                break;
            }
        }
        pieces += 1;
        if let Some(e) = crawling(opts, pieces, t) {
            error = Some(e);
            break;
        }
        while next_break < breaks.len() && breaks[next_break] <= t {
            next_break += 1;
        }
        let end = breaks.get(next_break).copied().unwrap_or(opts.t_end);
        let h = (end - t).min(cap);
        let t1 = if h == end - t { end } else { t + h };
        // (The record's line inside the interval: zero before its first
        // sample, where it jumps.)
        let (am, slope) = base.line_at(t + 0.5 * h);
        let a0 = am - slope * 0.5 * h;
        match series.build(&form, &y, (a0, slope), h) {
            Built::Done => {
                products += series_terms(&series);
                // (Longer where the terms fell fast: a long interval of
                // no forcing, where the last was halved. Kept to about 14
                // terms, ω h below 1/2 as within the record: a piece's
                // extrema and gauges are sought where their rates change
                // sign at its ends.)
                if series.terms() < 15 {
                    cap *= 2.0;
                }
            }
            Built::TooLong => {
                cap = 0.5 * h;
                if cap <= 4.0 * f64::EPSILON * t.abs().max(1e-300) {
                    error = Some(underflow(t, h, &y));
                }
                continue;
            }
            Built::NonFinite => {
                error = Some(underflow(t, h, &y));
                break;
            }
        }
        let switch = first_switch(
            sys.storeys(),
            &series,
            h,
            (&mut reader.y, &mut carried, &slopes),
        );
        let (tau, t_next) = match switch {
            Some((tau, _)) => (tau, t + tau),
            None => (h, t1),
        };
        reader.piece(&series, (t, t_next, tau), (a0, slope));
        let stopped = reader.samples(opts, &mut sys, &series, (t, t_next), &mut next_sample, sink);
        series.state(tau, &mut y);
        if y.iter().any(|x| !x.is_finite()) {
            error = Some(underflow(t, h, &y));
            break;
        }
        t = t_next;
        if let Some(ts) = stopped {
            error = Some(IntegrationError::Interrupted { t: ts });
            break;
        }
        if let Some((_, k)) = switch {
            sys.storeys_mut().switch(k, &y);
            sys.piecewise_form(&mut form);
            // (The other storeys' bounds over the piece hold where it
            // ended; their values at its planned end do not.)
            for c in carried.iter_mut() {
                if let Known::Exact(_) = c {
                    *c = Known::Nothing;
                }
            }
            carried[k] = Known::Nothing;
            slopes_of(sys.storeys(), &mut slopes);
        }
    }
    let error = error.map(|source| failure(model, source, &y, &[]));
    let mut found = reader.found;
    found.gauges = reader.gauges.iter().map(GaugeScan::reading).collect();
    Simulation {
        times: Vec::new(),
        states: Vec::new(),
        final_time: t,
        final_displacement: (0..n).map(|i| y[2 * i]).collect(),
        final_velocity: (0..n).map(|i| y[2 * i + 1]).collect(),
        impacts: Vec::new(),
        stats: Stats {
            rhs_evaluations: products,
            steps: pieces,
            ..Stats::default()
        },
        contact_evaluations: 0,
        hysteretic_energy: (0..model.storeys().len())
            .map(|k| sys.storeys().dissipated_by(k, &y))
            .collect(),
        energy: None,
        error,
        extrema: opts.extrema_window.map(|_| found),
        local: None,
        soft_episodes: Vec::new(),
    }
}

/// The products with `A` a series took (a right-hand side's worth each:
/// its terms past the first two, which are the state).
fn series_terms(series: &Series) -> u64 {
    series.terms() as u64 - 2
}

/// A state that is not finite, or an interval that cannot be shortened.
fn underflow(t: f64, h: f64, y: &[f64]) -> IntegrationError {
    IntegrationError::StepSizeUnderflow {
        t,
        h,
        y: y.to_vec(),
        reason: crate::integrate::RejectReason::NonFinite,
    }
}

/// The run's end where it crawls: its pieces at this pace would exceed
/// the step limit by [`CRAWL_FACTOR`], or exceed it.
fn crawling(opts: &SimulationOptions, pieces: u64, t: f64) -> Option<IntegrationError> {
    if pieces > opts.max_steps {
        return Some(IntegrationError::TooManySteps { t, steps: pieces });
    }
    if pieces % PROGRESS_CHECK == 0 {
        let projected = pieces as f64 * opts.t_end / t;
        if projected > CRAWL_FACTOR * opts.max_steps as f64 {
            return Some(IntegrationError::NoProgress {
                t,
                steps: pieces,
                projected,
                limit: opts.max_steps,
            });
        }
    }
    None
}

/// The first switch of a storey inside `(0, h]` on the series, and the
/// storey: where its switch function, positive at 0, reaches zero.
/// `y`: scratch for a state (only the storey's bodies are read);
/// `carried`: what each storey's switch parts are known to be at 0 (from
/// the last piece's end), set to what is known at `h`; `slopes`: each
/// storey's [`StoreyTerms::switch_rate_bounds_for`] at unit speed and
/// acceleration (they scale with them; they change where it switches).
fn first_switch(
    storeys: &StoreyTerms,
    series: &Series,
    h: f64,
    (y, carried, slopes): (&mut [f64], &mut [Known], &[Slopes]),
) -> Option<(f64, usize)> {
    let mut first: Option<(f64, usize)> = None;
    for k in storeys.switching() {
        let (below, above) = storeys.ends(k);
        let mut parts = |tau: f64| {
            series.two_states(above, below, tau, y);
            let (d, r) = storeys.switch_parts(k, y);
            let rate = y[2 * above + 1] - below.map_or(0.0, |j| y[2 * j + 1]);
            (d, r, rate)
        };
        let start = match std::mem::replace(&mut carried[k], Known::Nothing) {
            Known::Nothing => Known::Exact(parts(0.0)),
            known => known,
        };
        let b = first.map_or(h, |f| f.0);
        let (speed, acceleration) = series.rate_bounds(2 * above, below.map(|j| 2 * j));
        let (lines, turn, least_at_ends) = slopes[k];
        debug_assert!({
            let (d, t) = storeys.switch_rate_bounds_for(k, speed, acceleration);
            let near = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(y.abs());
            // (Not finite: the state's check reports it.)
            !(d.is_finite() && t.is_finite())
                || near(d, lines * speed) && near(t, turn * acceleration)
        });
        let bounds = Rates {
            lines,
            speed,
            least_at_ends,
            turn: turn * acceleration,
            acceleration,
        };
        // Moving one way on one side of zero drift, and further from its
        // switches than its parts can move over the piece, a storey clears
        // on what it carries, its parts at the end not read: it carries
        // their lower bounds on. (Its drift terms, each of slope at most
        // `lines` in the drift, move at most `lines` times the drift's
        // move, which is monotone there: tighter than the piece's speed
        // bound times its length.)
        let (g, r) = start.lower();
        let drift = |tau: f64| series.value_rate(2 * above, below.map(|j| 2 * j), tau);
        let ((da, ra), (db, rb)) = (drift(0.0), drift(b));
        let one_way = ra.abs().max(rb.abs()) > acceleration * b && da * db > 0.0;
        let moved = lines * (db - da).abs();
        if one_way && g > moved && r > bounds.turn * b {
            // (Bounds over all of `[0, b]`, where the piece ends.)
            carried[k] = Known::Above(g - moved, r - bounds.turn * b);
            continue;
        }
        let p0 = match start {
            Known::Exact(p) => p,
            _ => parts(0.0),
        };
        if p0.0.min(p0.1) <= 0.0 {
            continue;
        }
        let p1 = parts(b);
        if b == h {
            carried[k] = Known::Exact(p1);
        }
        if p1.0.min(p1.1) > 0.0 && clear(bounds, (0.0, p0), (b, p1)) {
            continue;
        }
        if let Some(tau) = root(&mut parts, bounds, (0.0, p0), (b, p1), 0) {
            if first.is_none_or(|f| tau < f.0) {
                first = Some((tau, k));
            }
        }
    }
    first
}

/// What is known of a storey's switch parts at a piece's start.
#[derive(Clone, Copy, Debug)]
enum Known {
    /// Nothing: they are read.
    Nothing,
    /// Their values (the last piece's end).
    Exact(Parts),
    /// Lower bounds on the two parts, carried over pieces the drift moved
    /// one way over without crossing zero (the drift terms continuous
    /// there: docs/theory.md §13).
    Above(f64, f64),
}

impl Known {
    /// Lower bounds on the two parts (−∞ where nothing is known).
    fn lower(self) -> (f64, f64) {
        match self {
            Known::Nothing => (f64::NEG_INFINITY, f64::NEG_INFINITY),
            Known::Exact((g, r, _)) | Known::Above(g, r) => (g, r),
        }
    }
}

/// Each storey's [`StoreyTerms::switch_rate_bounds_for`] at unit speed
/// and acceleration (the bounds are the speed and the acceleration times
/// these), and whether its drift terms are least at the ends of an
/// interval the drift moves over one way
/// ([`StoreyTerms::drift_terms_least_at_ends`]), into `slopes`.
fn slopes_of(storeys: &StoreyTerms, slopes: &mut [Slopes]) {
    for (k, s) in slopes.iter_mut().enumerate() {
        let (lines, turn) = storeys.switch_rate_bounds_for(k, 1.0, 1.0);
        *s = (lines, turn, storeys.drift_terms_least_at_ends(k));
    }
}

/// A storey's switch parts (the drift terms, the reversal's) and its
/// drift rate at a point.
type Parts = (f64, f64, f64);

/// A storey's rate bounds at unit speed and acceleration, and whether its
/// drift terms are least at the ends of a move one way ([`slopes_of`]).
type Slopes = (f64, f64, bool);

/// Whether both parts, positive at `a` and `b`, stay positive between
/// by their `bounds` (see [`root`]).
#[inline]
fn clear(bounds: Rates, (a, pa): (f64, Parts), (b, pb): (f64, Parts)) -> bool {
    let w = b - a;
    let turns = pa.2.abs().max(pb.2.abs()) <= bounds.acceleration * w;
    // (Between the ends the drift's rate is at most the mean of theirs
    // plus half the interval at the acceleration bound, each end's rate
    // growing no faster toward the other: tighter than the piece's speed
    // bound on a halved interval and near a reversal, where 1,270 of the
    // IMK frame's 1,280 halvings were; 741 are left.)
    let speed = bounds
        .speed
        .min(0.5 * (pa.2.abs() + pb.2.abs() + bounds.acceleration * w));
    let slope = bounds.lines * speed;
    let drift = match turns {
        false => bounds.least_at_ends || pa.0 + pb.0 > slope * w,
        true => pa.0 > slope * w && pb.0 > slope * w,
    };
    drift && pa.1 + pb.1 > bounds.turn * w
}

/// Bounds over a piece on how a storey's switch parts change: the drift
/// terms' slope in the drift and the drift's speed, whether they are
/// least at the ends of an interval the drift moves over one way, the
/// reversal's rate, and the drift's acceleration.
#[derive(Clone, Copy, Debug)]
struct Rates {
    /// The drift terms' rate bound at unit drift speed (their steepest
    /// slope in the drift), and the drift's speed bound over the piece.
    lines: f64,
    speed: f64,
    least_at_ends: bool,
    turn: f64,
    acceleration: f64,
}

/// The first zero of `min(parts)` in `(a, b]` (positive at `a`): none
/// where both parts stay positive by their `bounds`; else where it is not
/// positive at `b`, located by Brent; else in the halves, first to last.
/// The drift terms stay positive where the ends' values exceed their
/// rate's bound times the piece; or, where the drift rate keeps its sign
/// and each term is least at an end of an interval the drift moves over
/// one way (a line, a concave minimum of lines, a monotone function:
/// [`StoreyTerms::drift_terms_least_at_ends`]), wherever both ends are
/// positive. The drift terms of an IMK storey off its backbone
/// jump where the drift rate changes sign (they measure to the bound
/// ahead): where the rate may vanish inside, each end must clear the rate
/// bound on its own.
fn root(
    parts: &mut impl FnMut(f64) -> Parts,
    bounds: Rates,
    (a, pa): (f64, Parts),
    (b, pb): (f64, Parts),
    halvings: usize,
) -> Option<f64> {
    let g = |p: Parts| p.0.min(p.1);
    if g(pb) <= 0.0 {
        let xtol = 4.0 * f64::EPSILON * b.abs().max(1e-300);
        let found = brent(|t| g(parts(t)), a, b, g(pa), g(pb), xtol, 200);
        return Some(found.unwrap_or(b));
    }
    if halvings == MAX_HALVINGS || clear(bounds, (a, pa), (b, pb)) {
        return None;
    }
    let m = 0.5 * (a + b);
    let pm = parts(m);
    root(parts, bounds, (a, pa), (m, pm), halvings + 1)
        .or_else(|| root(parts, bounds, (m, pm), (b, pb), halvings + 1))
}

/// The largest |x| over `[a, b]` of a component `at(t)` (value, rate,
/// second derivative): at the ends, and inside where its rate changes
/// sign (Brent on the rate).
fn largest(at: impl Fn(f64) -> (f64, f64, f64), (a, b): (f64, f64)) -> f64 {
    let (ea, eb) = (at(a), at(b));
    let mut x = ea.0.abs().max(eb.0.abs());
    if ea.1 * eb.1 < 0.0 {
        let xtol = 1e-15 * b.abs().max(1e-300);
        if let Ok(t) = brent(|t| at(t).1, a, b, ea.1, eb.1, xtol, 200) {
            x = x.max(at(t).0.abs());
        }
    }
    x
}

/// How the run reads a gauge on the series: `sign (u_p − u_q)` (a
/// separation; q None: the ground) or body p's absolute acceleration.
#[derive(Clone, Copy, Debug)]
enum Read {
    Separation {
        p: usize,
        q: Option<usize>,
        sign: f64,
    },
    Acceleration {
        p: usize,
    },
}

impl Read {
    /// How `gauge` is read.
    fn of(gauge: Gauge) -> Self {
        match gauge {
            Gauge::Separation {
                left: Some(l),
                right,
                ..
            } => Read::Separation {
                p: l,
                q: right,
                sign: 1.0,
            },
            Gauge::Separation {
                left: None, right, ..
            } => Read::Separation {
                p: right.unwrap_or(0),
                q: None,
                sign: -1.0,
            },
            Gauge::AbsoluteAcceleration { body } => Read::Acceleration { p: body },
        }
    }

    /// The gauge and its rate at τ on the series, whose base acceleration
    /// is `a0 + s τ` (inlined always: at a piece's ends, the usual reading,
    /// it is a few of the end's sums).
    #[inline(always)]
    fn at(self, series: &Series, tau: f64, (a0, s): (f64, f64)) -> (f64, f64) {
        match self {
            Read::Separation { p, q, sign } => {
                let (x, r) = series.value_rate(2 * p, q.map(|j| 2 * j), tau);
                (sign * x, sign * r)
            }
            Read::Acceleration { p } => {
                let (_, a, jerk) = series.component(2 * p + 1, tau);
                (a + a0 + s * tau, jerk + s)
            }
        }
    }
}

impl Reader {
    /// The extrema and gauges over the piece `(ta, tb)` of the series
    /// (from `ta`; `tb` at its τ = `tau`), whose base acceleration is `a0 +
    /// s (t − ta)`.
    fn piece(&mut self, series: &Series, (ta, tb, tau): (f64, f64, f64), (a0, s): (f64, f64)) {
        let Some((from, to)) = self.window else {
            return;
        };
        let (a, b) = (ta.max(from), tb.min(to));
        if a > b {
            return;
        }
        if self.bodies {
            for i in 0..self.found.max_displacement.len() {
                let max_u = largest(|t| series.component(2 * i, t - ta), (a, b));
                let max_v = largest(|t| series.component(2 * i + 1, t - ta), (a, b));
                let f = &mut self.found;
                f.max_displacement[i] = f.max_displacement[i].max(max_u);
                f.max_velocity[i] = f.max_velocity[i].max(max_v);
            }
        }
        // (The piece's end read at its own τ: tb − ta may differ from it
        // in the last bit, and at the series' end that is its sums.)
        let end_tau = if b == tb { tau } else { b - ta };
        let gauges = self.gauges.iter_mut().zip(&self.reads);
        for ((gauge, &read), end) in gauges.zip(self.ends.iter_mut()) {
            let at = |t: f64| read.at(series, t - ta, (a0, s));
            let stop = read.at(series, end_tau, (a0, s));
            match (read, *end) {
                // (A separation goes on from the last piece's end, noted
                // there.)
                (Read::Separation { .. }, (t, x)) if t == a => {
                    gauge.scan_on((a, b), (x, stop), at);
                }
                _ => gauge.scan_ends((a, b), (at(a), stop), at),
            }
            *end = (b, stop);
        }
    }

    /// The output samples in `(ta, tb]` of the series (from `ta`), the
    /// next one's index kept in `next`; the time of the sample at which
    /// the sink asked to stop, if it did.
    fn samples(
        &mut self,
        opts: &SimulationOptions,
        sys: &mut ChainDynamics,
        series: &Series,
        (ta, tb): (f64, f64),
        next: &mut usize,
        sink: &mut impl FnMut(f64, &[f64]) -> bool,
    ) -> Option<f64> {
        let dt = opts.output_step?;
        loop {
            let ts = opts.output_from + *next as f64 * dt;
            if ts > tb || ts > opts.t_end {
                return None;
            }
            *next += 1;
            if ts < ta {
                continue;
            }
            let mut y = std::mem::take(&mut self.y);
            series.state(ts - ta, &mut y);
            let go_on = self.sample(opts, sys, ts, &y, Some((series, ts - ta)), sink);
            self.y = y;
            if !go_on {
                return Some(ts);
            }
        }
    }

    /// Hands the state `y` at `t` to the sink (with the accelerations
    /// relative to the ground from the series at τ, or the right-hand
    /// side without one, and the storeys' forces, as asked); false if it
    /// asks to stop.
    fn sample(
        &mut self,
        opts: &SimulationOptions,
        sys: &mut ChainDynamics,
        t: f64,
        y: &[f64],
        at: Option<(&Series, f64)>,
        sink: &mut impl FnMut(f64, &[f64]) -> bool,
    ) -> bool {
        let n = y.len() / 2;
        for i in 0..n {
            self.row[i] = y[2 * i];
            self.row[n + i] = y[2 * i + 1];
        }
        let mut k = 2 * n;
        if opts.accelerations {
            let mut rates = Vec::new();
            if at.is_none() {
                rates = vec![0.0; y.len()];
                crate::integrate::OdeSystem::rhs(sys, t, y, &mut rates);
            }
            for i in 0..n {
                self.row[k + i] = match at {
                    Some((s, tau)) => s.acceleration(i, tau),
                    None => rates[2 * i + 1],
                };
            }
            k += n;
        }
        if opts.storey_forces {
            for (j, f) in self.row[k..].iter_mut().enumerate() {
                *f = sys.storeys().force(j, y);
            }
        }
        sink(t, &self.row)
    }
}
