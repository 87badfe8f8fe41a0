//! The events of an accepted step: impact onsets and ends located on the
//! dense output, peak forces, the step limit of a contact approaching its
//! threshold.

use super::*;

/// Per-contact event state.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tracker {
    pub(super) s_on: f64,
    /// How far past s_on a step may end when entering (2/α; 0 for compact support).
    pub(super) entry_margin: f64,
    pub(super) active: Option<usize>,
}

impl Tracker {
    /// A contact of this law, no impact under way.
    pub(super) fn new(law: &crate::contact::ContactLaw, impact_force_threshold: f64) -> Self {
        Self {
            s_on: law.onset_approach(impact_force_threshold),
            entry_margin: law.entry_margin(),
            active: None,
        }
    }

    /// A rigid contact's: never engaged (s_on = ∞; its impacts are
    /// events, [`crate::simulate::switches`]).
    pub(super) fn never() -> Self {
        Self {
            s_on: f64::INFINITY,
            entry_margin: 0.0,
            active: None,
        }
    }
}

/// Scans one step for events and samples.
pub(super) struct StepScan {
    /// The model's index of each contact of the integrated system (the
    /// identity for the whole model; a subset for the local integrator).
    pub(super) ids: Vec<usize>,
    pub(super) trackers: Vec<Tracker>,
    pub(super) impacts: Vec<ImpactRecord>,
    /// (s, ṡ, dF/dt) of every contact at the start of the step.
    pub(super) previous: Vec<(f64, f64, f64)>,
}

/// (s, ṡ, dF/dt) of contact k at a step end, from the state and its derivative.
pub(super) fn contact_end(
    sys: &ChainDynamics,
    k: usize,
    y: &[f64],
    dydt: &[f64],
) -> (f64, f64, f64) {
    contact_end_force(sys, k, y, dydt).0
}

/// [`contact_end`], and the force there (the number [`contact_at`] and
/// the law give at the step's end, from the same evaluation).
#[inline]
fn contact_end_force(
    sys: &ChainDynamics,
    k: usize,
    y: &[f64],
    dydt: &[f64],
) -> ((f64, f64, f64), f64) {
    let (s, sd) = sys.approach(k, y);
    let idx = sys.contact_indices(k);
    let sdd = idx[1].map_or(0.0, |i| dydt[i]) - idx[3].map_or(0.0, |i| dydt[i]);
    let (f, rate) = sys.contact_force_and_rate(k, s, sd, sdd);
    ((s, sd, rate), f)
}

/// Dense-output evaluation of contact k's (s, ṡ) at time t.
pub(super) fn contact_at<S: Chain>(st: &mut Stepper, sys: &mut S, k: usize, t: f64) -> (f64, f64) {
    let mut v = [0.0; 4];
    for (j, i) in sys.chain().contact_indices(k).iter().enumerate() {
        if let Some(i) = *i {
            v[j] = st.dense_component(sys, i, t);
        }
    }
    (v[0] - v[2] - sys.chain().clearance(k), v[1] - v[3])
}

impl StepScan {
    pub(super) fn locate<S: Chain>(
        st: &mut Stepper,
        sys: &mut S,
        k: usize,
        s_on: f64,
        (ta, ga): (f64, f64),
        (tb, gb): (f64, f64),
    ) -> f64 {
        EventLocator::FINE
            .locate(|t| contact_at(st, sys, k, t).0 - s_on, (ta, ga), (tb, gb))
            .unwrap_or(0.5 * (ta + tb))
    }

    /// Largest force of contact k on [ta, tb]; `fb`, the force at `tb`
    /// where it is known. `interior`: the force rate says the maximum may
    /// lie inside (rising at ta or unknown, falling at tb or unknown),
    /// then a search on the dense output finds it ([`maximum`]).
    pub(super) fn peak<S: Chain>(
        st: &mut Stepper,
        sys: &mut S,
        k: usize,
        ta: f64,
        (tb, fb): (f64, Option<f64>),
        interior: bool,
    ) -> (f64, f64) {
        let mut force = |t: f64| {
            let (s, sd) = contact_at(st, sys, k, t);
            sys.chain().contact_force(k, s, sd)
        };
        let fa = force(ta);
        let fb = fb.unwrap_or_else(|| force(tb));
        let tm = 0.5 * (ta + tb);
        let fm = if interior {
            force(tm)
        } else {
            f64::NEG_INFINITY
        };
        let mut best = if fa >= fb { (fa, ta) } else { (fb, tb) };
        if interior {
            for cand in [maximum(&mut force, ta, tb), (fm, tm)] {
                if cand.0 > best.0 {
                    best = cand;
                }
            }
        }
        best
    }

    /// Raises the peak of contact k's impact under way to its largest
    /// force on [ta, tb]: `rate_a`, `rate_b` the force's rate at an end
    /// that is the step's (else None), `fb` the force at `tb` if known.
    pub(super) fn update_peak<S: Chain>(
        &mut self,
        st: &mut Stepper,
        sys: &mut S,
        k: usize,
        (ta, rate_a): (f64, Option<f64>),
        (tb, rate_b, fb): (f64, Option<f64>, Option<f64>),
    ) {
        if let Some(i) = self.trackers[k].active {
            let interior = rate_a.is_none_or(|r| r > 0.0) && rate_b.is_none_or(|r| r < 0.0);
            let (f, t) = Self::peak(st, sys, k, ta, (tb, fb), interior);
            if f > self.impacts[i].peak_force {
                self.impacts[i].peak_force = f;
                self.impacts[i].peak_time = t;
            }
        }
    }

    pub(super) fn start<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S, k: usize, t: f64) {
        let (_, sd) = contact_at(st, sys, k, t);
        if sys.chain().contact_law(k).needs_impact_velocity() {
            sys.chain_mut().set_onset_velocity(k, sd);
        }
        self.trackers[k].active = Some(self.impacts.len());
        self.impacts.push(ImpactRecord {
            rigid: None,
            contact: self.ids[k],
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
    pub(super) fn finish<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S, k: usize, t: f64) {
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
    pub(super) fn entry_limit(&self, h_next: f64) -> Option<f64> {
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
    pub(super) fn scan<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S) {
        let (t0, t1) = (st.t_prev(), st.t());
        for k in 0..self.trackers.len() {
            let s_on = self.trackers[k].s_on;
            // (A rigid contact's impacts are events, logged where applied.)
            if s_on == f64::INFINITY {
                continue;
            }
            let (s0, sd0, r0) = self.previous[k];
            let ((s1, sd1, r1), f1) = contact_end_force(sys.chain(), k, st.y(), st.dydt());
            self.previous[k] = (s1, sd1, r1);
            let (g0, g1) = (s0 - s_on, s1 - s_on);
            let active = self.trackers[k].active.is_some();
            if !active && g1 > 0.0 && g0 <= 0.0 {
                let ts = Self::locate(st, sys, k, s_on, (t0, g0), (t1, g1));
                self.start(st, sys, k, ts);
                // (The onset velocity just set may change the force at t1.)
                self.update_peak(st, sys, k, (ts, None), (t1, Some(r1), None));
            } else if active && g1 <= 0.0 {
                let te = Self::locate(st, sys, k, s_on, (t0, g0), (t1, g1));
                self.update_peak(st, sys, k, (t0, Some(r0)), (te, None, None));
                self.finish(st, sys, k, te);
            } else if active {
                self.update_peak(st, sys, k, (t0, Some(r0)), (t1, Some(r1), Some(f1)));
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
                    self.update_peak(st, sys, k, (ts, None), (te, None, None));
                    self.finish(st, sys, k, te);
                }
            }
        }
    }
}
