//! The events that change a run's right-hand side inside a step, located
//! on the step's dense output: the branch switches of bilinear storeys
//! (docs/theory.md §11: within a step a bilinear storey's force is linear
//! in its drift; its switch function is yield or unloading), and the onset
//! of a contact whose law needs its impact velocity (Lankarani–Nikravesh:
//! the step that crosses the onset must not be taken with the previous
//! impact's velocity), and a rigid contact's impact (docs/theory.md §12:
//! the approach reaches zero; the velocities jump there). Where one
//! happens inside a step, the step is taken again up to that time, and the
//! event is applied there.
//!
//! Files: `mod.rs` (the switches), `episodes.rs` (a rigid contact's soft
//! episodes), `flow.rs` (a bare flow through the events, for the period
//! maps), `tests.rs` (exact piecewise motion of bilinear storeys).

use super::ChainDynamics;
use crate::dynamics::Chain;
use crate::impact::rigid::RigidImpact;
use crate::integrate::{IntegrationError, OdeSystem, Stepper};
use crate::numeric::brent;

mod episodes;
mod flow;
pub(super) use episodes::{judged, judging_gaps, reaches_within, Jump};

pub use episodes::{EpisodeReason, SoftEpisode};
pub(crate) use flow::{flow_through_events, flow_through_events_with, ImpactJump};

/// An event that changes the right-hand side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Event {
    /// Bilinear storey k's branch switch.
    Storey(usize),
    /// Contact k reaches its onset approach: its impact velocity is set
    /// there.
    Onset(usize),
    /// Rigid contact k's approach reaches zero: an impact, the bodies'
    /// velocities jump.
    Impact(usize),
    /// Rigid contact k's approach reaches where its law's force stops
    /// being negligible, before the touch (the exponential law): its
    /// impact is judged there, rigid or a soft episode from there
    /// (`episodes.rs`).
    Approach(usize),
}

/// Where an approach is located, as a fraction of its step: it is where
/// an impact is judged, not an event of the motion (nothing changes
/// there), so 1e-9 of a step (R2: 5e-11 s, the gap within 5e-12 m of
/// the judging gap, 1e-6 of the seed's law's length 1/α) against rounding
/// for an impact. (R2 N = 2's rigid branch: 258 approaches, 2.5 of their
/// 5.8 evaluations each saved.)
const APPROACH_XTOL: f64 = 1e-9;

/// What a step's check found.
pub(super) enum Verdict {
    /// No event in the step.
    Clear,
    /// An event inside the step: the stepper is back at the step's start,
    /// and the next steps end at the event ([`Switches::before_step`]).
    Retake,
    /// The step ended at this event.
    Switch(Event),
}

/// The events of a run: its bilinear storeys and the onsets of its
/// contacts whose laws need the impact velocity.
pub(super) struct Switches {
    events: Vec<Event>,
    /// Per event, whether it can fire: an onset fires once per impact
    /// (disarmed when applied, armed again once its contact is open at a
    /// step's end).
    armed: Vec<bool>,
    /// Per contact, its onset approach s_on.
    s_on: Vec<f64>,
    /// Per contact, where a rigid contact's impact is judged
    /// ([`episodes::judging_gaps`]).
    pre: Vec<f64>,
    t_prev: f64,
    y_prev: Vec<f64>,
    /// The derivative at the step's start.
    f_prev: Vec<f64>,
    /// Per event, its value at the step's start and end, and whether the
    /// step's inside is looked at (kept between steps: no allocation).
    ends: Vec<(f64, f64)>,
    look: Vec<bool>,
    /// Per event, whether a rigid contact starts the step touching and
    /// separating (just after its impact): its function is 0 there to
    /// rounding, so its next root is sought after its approach turns.
    opened: Vec<bool>,
    /// Per storey event, the bound on its drift terms' rate over the
    /// last step ([`crate::dynamics::storeys::StoreyTerms::switch_rate_bounds`]).
    drift_rate: Vec<f64>,
    /// The storeys' two switch parts at the last step's end (NaN where
    /// not computed), the state there and the branches' stamp: the next
    /// step's start, while both hold.
    carried: Vec<(f64, f64)>,
    carried_y: Vec<f64>,
    carried_stamp: Option<u64>,
    /// The chain's state on the dense output (a root's search).
    buf: Vec<f64>,
    /// The chain's states at the three inside points of the last step.
    inside: [Vec<f64>; 3],
    /// The next event's time, once located.
    pending: Option<(f64, Event)>,
    /// Per contact, its last rigid impact's time and estimated duration
    /// (soft episodes, `episodes.rs`).
    last_impact: Vec<(f64, f64)>,
    /// Per contact, whether it is in a soft episode.
    episode: Vec<bool>,
    /// Whether a rigid impact's peak force is solved (a run's impact log;
    /// a period map's flow reads none: [`Switches::without_peak_forces`]).
    peak_forces: bool,
}

impl Switches {
    /// None for a model without such events; `s_on` per contact, and
    /// `pre`, where a rigid contact's impact is judged
    /// ([`episodes::judging_gaps`]).
    pub(super) fn new(
        sys: &ChainDynamics,
        dim: usize,
        s_on: Vec<f64>,
        pre: Vec<f64>,
    ) -> Option<Self> {
        let onsets = (0..s_on.len())
            .filter(|&k| sys.rigid_law(k).is_none() && sys.contact_law(k).needs_impact_velocity())
            .map(Event::Onset);
        let impacts = (0..s_on.len())
            .filter(|&k| sys.rigid_law(k).is_some())
            .map(Event::Impact);
        let approaches = (0..s_on.len())
            .filter(|&k| sys.rigid_law(k).is_some() && pre[k] < 0.0)
            .map(Event::Approach);
        // (The events read the chain's own state alone: the dense output
        // inside a step is taken of it, not of the columns a variational
        // system carries after it.)
        let own = OdeSystem::dim(sys).min(dim);
        let events: Vec<Event> = sys
            .storeys()
            .switching()
            .map(Event::Storey)
            .chain(onsets)
            .chain(impacts)
            .chain(approaches)
            .collect();
        (!events.is_empty()).then(|| Self {
            armed: vec![true; events.len()],
            ends: vec![(0.0, 0.0); events.len()],
            look: vec![false; events.len()],
            opened: vec![false; events.len()],
            drift_rate: vec![0.0; events.len()],
            carried: vec![(f64::NAN, f64::NAN); events.len()],
            carried_y: vec![0.0; dim],
            carried_stamp: None,
            events,
            s_on,
            pre,
            t_prev: 0.0,
            y_prev: vec![0.0; dim],
            f_prev: vec![0.0; dim],
            buf: vec![0.0; own],
            inside: [vec![0.0; own], vec![0.0; own], vec![0.0; own]],
            pending: None,
            last_impact: vec![(f64::NEG_INFINITY, 0.0); sys.contacts()],
            episode: vec![false; sys.contacts()],
            peak_forces: true,
        })
    }

    /// The rigid impacts' peak forces left unsolved (NaN): a flow whose
    /// impacts go to no log (the period maps': the seed's law's peak is a
    /// root of its own at each impact).
    pub(super) fn without_peak_forces(mut self) -> Self {
        self.peak_forces = false;
        self
    }

    /// Keeps the state a step starts from; the step's `bound`, shortened to
    /// a located event; or the event itself where it is located at the
    /// step's start (rounding: apply it there, no step).
    pub(super) fn before_step(&mut self, st: &Stepper, bound: f64) -> Result<f64, Event> {
        self.t_prev = st.t();
        self.y_prev.copy_from_slice(st.y());
        self.f_prev.copy_from_slice(st.dydt());
        match self.pending {
            Some((t, e)) if t <= st.t() => {
                self.pending = None;
                self.disarm(e);
                Err(e)
            }
            Some((t, _)) => Ok(bound.min(t)),
            None => Ok(bound),
        }
    }

    /// Arms again every onset whose contact is open at the end of a step
    /// that is kept (not one about to be taken again).
    fn rearm(&mut self, sys: &ChainDynamics, y: &[f64]) {
        for i in 0..self.events.len() {
            // (A rigid contact's impact is suspended in a soft episode,
            // and so is its approach.)
            match self.events[i] {
                Event::Impact(_) => continue,
                Event::Approach(k) if self.episode[k] => continue,
                _ => {}
            }
            if !self.armed[i] && self.value(sys, self.events[i], y) > 0.0 {
                self.armed[i] = true;
            }
        }
    }

    /// Marks `e` applied: an onset or an approach waits for its contact
    /// to open again.
    fn disarm(&mut self, e: Event) {
        let once = matches!(e, Event::Onset(_) | Event::Approach(_));
        if let (true, Some(i)) = (once, self.events.iter().position(|x| *x == e)) {
            self.armed[i] = false;
        }
    }

    /// The event's function in the state `y`: positive before it, zero at
    /// it (a contact's: s_on − s, positive while the contact is open; a
    /// rigid one's −s).
    fn value(&self, sys: &ChainDynamics, e: Event, y: &[f64]) -> f64 {
        match e {
            Event::Storey(k) => sys.storeys().switch_value(k, y),
            Event::Onset(k) => self.s_on[k] - sys.approach(k, y).0,
            Event::Impact(k) => -sys.approach(k, y).0,
            Event::Approach(k) => self.pre[k] - sys.approach(k, y).0,
        }
    }

    /// Checks the step just taken for events (at its end and at three
    /// points inside on the dense output, located by Brent).
    pub(super) fn after_step<S: Chain>(
        &mut self,
        st: &mut Stepper,
        sys: &mut S,
    ) -> Result<Verdict, IntegrationError> {
        let (t0, t1) = (self.t_prev, st.t());
        if let Some((t, e)) = self.pending {
            if t1 >= t {
                self.pending = None;
                self.disarm(e);
                return Ok(Verdict::Switch(e));
            }
        }
        // Live events: armed, and positive at the step's start. Each is
        // looked at inside the step (three points on the dense output)
        // only if it is not positive at the end, or if one of its parts
        // could reach zero inside by twice the bound on its rate
        // ([`StoreyTerms::switch_rate_bounds`]); a contact's onset always.
        let h = t1 - t0;
        let mut any = false;
        let mut at_start = None;
        let stamp = sys.chain().storeys().stamp();
        let carried = self.carried_stamp == Some(stamp) && self.carried_y == self.y_prev;
        self.carried_stamp = Some(stamp);
        self.carried_y.copy_from_slice(st.y());
        for i in 0..self.events.len() {
            self.look[i] = false;
            if !self.armed[i] {
                continue;
            }
            let e = self.events[i];
            let Event::Storey(k) = e else {
                let mut g0 = self.value(sys.chain(), e, &self.y_prev);
                self.opened[i] = false;
                if let Event::Impact(k) = e {
                    // Touching at the step's start (s = 0 to rounding):
                    // separating (or at rest), open from there on (after an
                    // impact applied there); approaching, an impact there.
                    if g0 <= 0.0 {
                        if sys.chain().approach(k, &self.y_prev).1 > 0.0 {
                            at_start = at_start.or(Some(e));
                        }
                        self.opened[i] = true;
                        g0 = f64::MIN_POSITIVE;
                    }
                }
                self.ends[i] = (g0, self.value(sys.chain(), e, st.y()));
                self.look[i] = g0 > 0.0;
                any |= self.look[i];
                continue;
            };
            let storeys = sys.chain().storeys();
            let (d0, r0) = match self.carried[i] {
                parts if carried && !parts.0.is_nan() => parts,
                _ => storeys.switch_parts(k, &self.y_prev),
            };
            let g0 = d0.min(r0);
            if g0 <= 0.0 {
                self.carried[i] = (f64::NAN, f64::NAN);
                continue;
            }
            let (d1, r1) = storeys.switch_parts(k, st.y());
            self.carried[i] = (d1, r1);
            let (ld, lr) =
                storeys.switch_rate_bounds(k, (&self.y_prev, &self.f_prev), (st.y(), st.dydt()), h);
            self.ends[i] = (g0, d1.min(r1));
            self.drift_rate[i] = ld;
            self.look[i] =
                d1.min(r1) <= 0.0 || d0.min(d1) <= 2.0 * ld * h || r0.min(r1) <= 2.0 * lr * h;
            any |= self.look[i];
        }
        if let Some(e) = at_start {
            self.pending = Some((t0, e));
            st.reset(sys, t0, &self.y_prev)?;
            return Ok(Verdict::Retake);
        }
        if !any {
            self.rearm(sys.chain(), st.y());
            return Ok(Verdict::Clear);
        }
        // The three inside points' states, taken once for all the events
        // looked at (a dense output may cost stages of its own).
        let times: [f64; 4] =
            [1.0, 2.0, 3.0, 4.0].map(|j| if j == 4.0 { t1 } else { t0 + h * j / 4.0 });
        for (k, t) in times[..3].iter().enumerate() {
            st.dense_output(sys, *t, &mut self.inside[k]);
        }
        let mut first: Option<(f64, Event)> = None;
        for i in 0..self.events.len() {
            if !self.look[i] {
                continue;
            }
            let e = self.events[i];
            let (mut ta, mut ga) = (t0, self.ends[i].0);
            for (j, &tb) in times.iter().enumerate() {
                let gb = match j {
                    3 => self.ends[i].1,
                    _ => self.value(sys.chain(), e, &self.inside[j]),
                };
                // Positive at both ends, a storey's switch can still dip
                // below zero between them (unless twice its rate bound
                // forbids: ga + gb > 2 bound (tb − ta)): a yield that
                // grazes, where the drift turns. Its drift terms are
                // concave in the drift (a bilinear storey's, and an IMK
                // storey's but at the corner where its backbone meets the
                // residual), so least at the drift's extremes: the dip is
                // tested where the drift rate vanishes (Brent), and the
                // root sought before it.
                let before = if j == 0 {
                    &self.y_prev
                } else {
                    &self.inside[j - 1]
                };
                let after = if j == 3 { st.y() } else { &self.inside[j] };
                let rb_impact = match e {
                    Event::Impact(k) => sys.chain().approach(k, after).1,
                    _ => 0.0,
                };
                let (tb_root, gb_root) = match e {
                    Event::Storey(k)
                        if gb > 0.0 && ga + gb <= 2.0 * self.drift_rate[i] * (tb - ta) =>
                    {
                        let rate = |c: &ChainDynamics, y: &[f64]| c.storeys().drift(k, y).1;
                        let (ra, rb) = (rate(sys.chain(), before), rate(sys.chain(), after));
                        if ra * rb < 0.0 {
                            self.dip(st, sys, e, rate, (ta, tb), (ra, rb))
                        } else {
                            (tb, gb)
                        }
                    }
                    // A rigid contact open at both points can still touch
                    // between them where its approach turns (ṡ from + to
                    // −): tested there, grazing included.
                    Event::Impact(k) if gb > 0.0 => {
                        let rate = |c: &ChainDynamics, y: &[f64]| c.approach(k, y).1;
                        let (ra, rb) = (rate(sys.chain(), before), rate(sys.chain(), after));
                        if ra > 0.0 && rb < 0.0 {
                            self.dip(st, sys, e, rate, (ta, tb), (ra, rb))
                        } else {
                            (tb, gb)
                        }
                    }
                    _ => (tb, gb),
                };
                // Just after its impact a rigid contact is at s = 0 to
                // rounding: its root is the return, after the approach
                // turns back (ṡ from − to +), where the separation is
                // largest; none while it still separates. A separation
                // lost in rounding is a resting contact.
                let (ta_root, ga_root) = match e {
                    Event::Impact(k) if gb_root <= 0.0 && self.opened[i] && ta == t0 => {
                        let rate = |c: &ChainDynamics, y: &[f64]| c.approach(k, y).1;
                        let (ra, rb) = (rate(sys.chain(), &self.y_prev), rb_impact);
                        if rb <= 0.0 {
                            (ta, ga) = (tb, f64::MIN_POSITIVE);
                            continue;
                        }
                        let (tm, gm) = self.dip(st, sys, e, rate, (t0, tb), (ra, rb));
                        if gm <= 0.0 {
                            return Err(IntegrationError::RigidImpact {
                                t: t0,
                                contact: k,
                                reason: format!(
                                    "it separates by no more than rounding (rebound {:e} m/s): a resting contact, beyond rigid impacts; keep this contact soft (impacts = \"soft\")",
                                    -ra
                                ),
                            });
                        }
                        (tm, gm)
                    }
                    _ => (ta, ga),
                };
                if gb_root <= 0.0 {
                    let mut xtol = 4.0 * f64::EPSILON * tb_root.abs().max(1e-300);
                    if let Event::Approach(_) = e {
                        xtol = xtol.max(APPROACH_XTOL * h);
                    }
                    let mut buf = std::mem::take(&mut self.buf);
                    let root = brent(
                        |t| {
                            st.dense_output(sys, t, &mut buf);
                            self.value(sys.chain(), e, &buf)
                        },
                        ta_root,
                        tb_root,
                        ga_root,
                        gb_root,
                        xtol,
                        200,
                    );
                    self.buf = buf;
                    let t = root.unwrap_or(tb_root);
                    if first.is_none_or(|(tf, _)| t < tf) {
                        first = Some((t, e));
                    }
                    break;
                }
                (ta, ga) = (tb, gb);
            }
        }
        match first {
            None => {
                self.rearm(sys.chain(), st.y());
                Ok(Verdict::Clear)
            }
            Some((t, e)) if t >= t1 => {
                self.disarm(e);
                Ok(Verdict::Switch(e))
            }
            // The exact flow's step ends at the event itself (its dense
            // output is the flow): not taken again up to it.
            Some((t, e)) if st.end_step_at(sys, t) => {
                self.disarm(e);
                Ok(Verdict::Switch(e))
            }
            Some(found) => {
                self.pending = Some(found);
                st.reset(sys, t0, &self.y_prev)?;
                Ok(Verdict::Retake)
            }
        }
    }

    /// Where `rate` (the rate of what the event's function is concave in)
    /// vanishes inside `(ta, tb)` (its values `ra`, `rb` at the ends of
    /// opposite signs), on the step's dense output by Brent, and the
    /// event's function there.
    fn dip<S: Chain>(
        &mut self,
        st: &mut Stepper,
        sys: &mut S,
        e: Event,
        rate: impl Fn(&ChainDynamics, &[f64]) -> f64,
        (ta, tb): (f64, f64),
        (ra, rb): (f64, f64),
    ) -> (f64, f64) {
        let xtol = 4.0 * f64::EPSILON * tb.abs().max(1e-300);
        let buf = &mut self.buf;
        let turn = brent(
            |t| {
                st.dense_output(sys, t, buf);
                rate(sys.chain(), buf)
            },
            ta,
            tb,
            ra,
            rb,
            xtol,
            200,
        )
        .unwrap_or(0.5 * (ta + tb));
        st.dense_output(sys, turn, &mut self.buf);
        (turn, self.value(sys.chain(), e, &self.buf))
    }
}

/// Applies `event` at the stepper's point (a storey's branch switch, a
/// contact's impact velocity, or a rigid impact's velocity jump) and
/// restarts the stepper there (the right-hand side or the state changed).
/// Returns the rigid impact applied, with its contact.
pub(super) fn apply_event<S: Chain>(
    st: &mut Stepper,
    sys: &mut S,
    event: Event,
) -> Result<Option<(usize, RigidImpact)>, IntegrationError> {
    let (t, mut y) = (st.t(), st.y().to_vec());
    let floor = st.options().atol;
    let chain = sys.chain_mut();
    let mut impact = None;
    match event {
        Event::Storey(k) => chain.storeys_mut().switch(k, &y),
        Event::Onset(k) => {
            let (_, sd) = chain.approach(k, &y);
            chain.set_onset_velocity(k, sd);
        }
        Event::Impact(k) => impact = rigid_jump(chain, k, (t, &mut y), (floor, true))?,
        // (Judged by the caller: nothing changes.)
        Event::Approach(_) => {}
    }
    st.reset(sys, t, &y)?;
    Ok(impact)
}

/// Rigid contact k's impact at `(t, y)` (docs/theory.md §12): the bodies'
/// velocities jump by ∓P/m, P = μ (1 + e) U, and the energy audit's
/// contact dissipation takes the energy lost. None where the approach
/// reaches zero without approaching (U <= 0: a touch, no impulse). An
/// approach velocity at or below `floor` (the absolute tolerance) stops
/// the run: impacts that accumulate into a resting contact, which the
/// rigid map cannot follow. Without `peak`, its peak force is not solved
/// ([`RigidLaw::jump`](crate::impact::rigid::RigidLaw::jump)).
fn rigid_jump(
    chain: &ChainDynamics,
    k: usize,
    (t, y): (f64, &mut [f64]),
    (floor, peak): (f64, bool),
) -> Result<Option<(usize, RigidImpact)>, IntegrationError> {
    let (_, u) = chain.approach(k, y);
    if u <= 0.0 {
        return Ok(None);
    }
    let stop = |reason: String| IntegrationError::RigidImpact {
        t,
        contact: k,
        reason,
    };
    if u <= floor {
        return Err(stop(format!(
            "approach velocity {u:e} m/s, at or below the absolute tolerance {floor:e}: impacts that accumulate into a resting contact (or a touch that slow) are beyond rigid impacts; keep this contact soft (impacts = \"soft\"), or tighten atol"
        )));
    }
    let Some(law) = chain.rigid_law(k) else {
        return Ok(None);
    };
    let r = if peak { law.impact(u) } else { law.jump(u) };
    let r = r.map_err(|e| stop(e.to_string()))?;
    apply_jump(chain, k, y, &r);
    Ok(Some((k, r)))
}

/// Contact k's impact `r` applied to `y`: the bodies' velocities jump by
/// ∓P/m, and the energy audit's contact dissipation takes the energy
/// lost.
fn apply_jump(chain: &ChainDynamics, k: usize, y: &mut [f64], r: &RigidImpact) {
    let [_, vl, _, vr] = chain.contact_indices(k);
    if let Some(i) = vl {
        y[i] -= r.impulse / chain.mass(i / 2);
    }
    if let Some(i) = vr {
        y[i] += r.impulse / chain.mass(i / 2);
    }
    if chain.audits_energy() {
        y[chain.audit_index() + 2] += r.energy_lost;
    }
}

#[cfg(test)]
mod tests;
