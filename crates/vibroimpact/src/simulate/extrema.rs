//! Exact extrema over a window on the integrator's dense output
//! (docs/theory.md §10 for the local integrator's exact motion).

use super::gauges::{Gauge, GaugeReading, GaugeScan};
use super::*;

/// Largest |u_i| and |v_i| of every body over a time window, located on the
/// integrator's dense output rather than sampled: an interior maximum of
/// |u_i| lies where v_i changes sign within a step (Brent on the dense
/// v_i), one of |v_i| where the acceleration changes sign (Brent's parabolic search
/// on the dense v_i); otherwise the maximum is at a step end. Contact pulses
/// shorter than any output interval (the deepest penetration, the fastest
/// approach) are therefore caught to the integration tolerance.
#[derive(Clone, Debug, PartialEq)]
pub struct Extrema {
    /// max |u_i| (m), body order.
    pub max_displacement: Vec<f64>,
    /// max |v_i| (m/s), body order.
    pub max_velocity: Vec<f64>,
    /// Per contact, max (s − s_on): how far the approach s passed the
    /// impact threshold s_on (positive: an impact in the window; it
    /// crosses zero where an impact grazes into or out of existence).
    /// Interior maxima where ṡ changes sign are located like those of |u_i|.
    pub impact_margin: Vec<f64>,
    /// What each of the options' gauges read, in their order.
    pub gauges: Vec<GaugeReading>,
}

/// Dense-output values of two components at time t.
pub(super) fn dense_pair<S: Chain>(
    st: &mut Stepper,
    sys: &mut S,
    (i, j): (usize, usize),
    t: f64,
) -> (f64, f64) {
    (st.dense_component(sys, i, t), st.dense_component(sys, j, t))
}

/// A gauge's values and rates at the step's ends from the states and
/// rates there (`start`, `end`), where the scan covers the `whole` step: a
/// separation's from the bodies' (u, v); an acceleration's from the
/// rates, the ground's (z̈ at the ends) and the jerks. None where they are
/// to be read on the dense output.
fn gauge_ends(
    gauge: Gauge,
    whole: bool,
    (y0, f0): (&[f64], &[f64]),
    (y1, f1): (&[f64], &[f64]),
    jerk: Option<(&Jerk, (f64, f64))>,
) -> Option<((f64, f64), (f64, f64))> {
    if !whole {
        return None;
    }
    let side = |y: &[f64], i: Option<usize>| i.map_or((0.0, 0.0), |i| (y[2 * i], y[2 * i + 1]));
    match (gauge, jerk) {
        (Gauge::Separation { left, right, .. }, _) => {
            let (la, ra) = (side(y0, left), side(y0, right));
            let (lb, rb) = (side(y1, left), side(y1, right));
            Some(((la.0 - ra.0, la.1 - ra.1), (lb.0 - rb.0, lb.1 - rb.1)))
        }
        (Gauge::AbsoluteAcceleration { body }, Some((jerk, (za, zb)))) => {
            let iv = 2 * body + 1;
            let ja = jerk.at_start[body];
            ja.is_finite()
                .then(|| ((f0[iv] + za, ja), (f1[iv] + zb, jerk.at_end[body])))
        }
        _ => None,
    }
}

/// The gauge's reading on `[a, b]` within the step ending at `st.t()`, on
/// the dense output: a separation's rate is the bodies' relative velocity;
/// an acceleration is the dense velocity's slope plus the ground's, its
/// rate a difference of the acceleration within the step (where a record
/// is linear).
/// `ends`: an acceleration's values and rates at the step's ends, where
/// known exactly (else read on the dense output).
fn gauge_step_with<S: Chain>(
    gauge: &mut GaugeScan,
    st: &mut Stepper,
    sys: &mut S,
    (a, b): (f64, f64),
    ends: Option<((f64, f64), (f64, f64))>,
) {
    match gauge.gauge {
        Gauge::Separation { left, right, .. } => {
            let mut side = |i: Option<usize>, t: f64| {
                i.map_or((0.0, 0.0), |i| dense_pair(st, sys, (2 * i, 2 * i + 1), t))
            };
            let at = |t| {
                let (l, r) = (side(left, t), side(right, t));
                (l.0 - r.0, l.1 - r.1)
            };
            match ends {
                Some(ends) => gauge.scan_ends((a, b), ends, at),
                None => gauge.scan(a, b, at),
            }
        }
        Gauge::AbsoluteAcceleration { body } => {
            let (t0, t1) = (st.t_prev(), st.t());
            if t1 <= t0 {
                return;
            }
            let h = 1e-4 * (t1 - t0);
            // The slope of the velocity's polynomial (smooth past the
            // step's ends); the ground's at t itself.
            let mut acceleration = |t: f64| {
                let slope = (st.dense_component(sys, 2 * body + 1, t + h)
                    - st.dense_component(sys, 2 * body + 1, t - h))
                    / (2.0 * h);
                slope + sys.chain().base_acceleration(t)
            };
            let at = |t: f64| {
                let (lo, hi) = ((t - h).max(t0), (t + h).min(t1));
                let x = acceleration(t);
                (x, (acceleration(hi) - acceleration(lo)) / (hi - lo))
            };
            match ends {
                Some(ends) => gauge.scan_ends((a, b), ends, at),
                None => gauge.scan(a, b, at),
            }
        }
    }
}

/// Running state of the extrema search: the window start and the previous
/// step end (interleaved state and its derivative).
pub(super) struct ExtremaScan {
    pub(super) from: f64,
    pub(super) to: f64,
    pub(super) t: f64,
    pub(super) y: Vec<f64>,
    pub(super) dydt: Vec<f64>,
    /// The impact threshold s_on of every contact.
    pub(super) s_on: Vec<f64>,
    pub(super) found: Extrema,
    /// The gauges being read.
    pub(super) gauges: Vec<GaugeScan>,
    /// Whether the bodies and contacts are scanned (else the gauges alone).
    bodies: bool,
    /// With acceleration gauges: every body's absolute jerk at the last
    /// step's end, and scratch for the right-hand side that gives it.
    jerk: Option<Jerk>,
}

/// The bodies' absolute jerk at a step's end: one evaluation of the
/// right-hand side a hair back along the step's tangent.
struct Jerk {
    /// At the step's start (the step before's end).
    at_start: Vec<f64>,
    at_end: Vec<f64>,
    probe: Vec<f64>,
    rates: Vec<f64>,
}

impl Jerk {
    /// The jerk at the step's end `st.t()` into `at_end`: the acceleration
    /// f_v + z̈ there less its value at t − ε on the tangent y − ε f, over ε
    /// (ε a millionth of the step; the jerk is continuous where a record
    /// kinks, the acceleration relative to the ground is not).
    fn update<S: Chain>(&mut self, st: &Stepper, sys: &mut S) {
        std::mem::swap(&mut self.at_start, &mut self.at_end);
        let (t, y, f) = (st.t(), st.y(), st.dydt());
        let eps = 1e-6 * st.h_last();
        for ((p, y), f) in self.probe.iter_mut().zip(y).zip(f) {
            *p = y - eps * f;
        }
        crate::integrate::OdeSystem::rhs(sys, t - eps, &self.probe, &mut self.rates);
        let ground = |t| sys.chain().base_acceleration(t);
        let dz = ground(t) - ground(t - eps);
        for (i, j) in self.at_end.iter_mut().enumerate() {
            *j = (f[2 * i + 1] - self.rates[2 * i + 1] + dz) / eps;
        }
    }
}

impl ExtremaScan {
    /// The scan from the stepper's point over `(from, to)`: every body,
    /// the contacts with thresholds `s_on`, and `gauges`.
    pub(super) fn new(
        (from, to): (f64, f64),
        bodies: usize,
        (s_on, gauges, of_bodies): (Vec<f64>, &[Gauge], bool),
        st: &Stepper,
        sys: &ChainDynamics,
    ) -> Self {
        let mut scan = Self {
            from,
            to,
            t: st.t(),
            y: st.y().to_vec(),
            dydt: st.dydt().to_vec(),
            found: Extrema {
                max_displacement: vec![0.0; bodies],
                max_velocity: vec![0.0; bodies],
                impact_margin: vec![f64::NEG_INFINITY; s_on.len()],
                gauges: Vec::new(),
            },
            s_on,
            gauges: gauges.iter().copied().map(GaugeScan::new).collect(),
            bodies: of_bodies,
            jerk: gauges
                .iter()
                .any(|g| matches!(g, Gauge::AbsoluteAcceleration { .. }))
                .then(|| Jerk {
                    at_start: vec![f64::NAN; bodies],
                    at_end: vec![f64::NAN; bodies],
                    probe: vec![0.0; st.y().len()],
                    rates: vec![0.0; st.y().len()],
                }),
        };
        if from <= scan.t && scan.t <= to {
            for i in 0..bodies {
                scan.found.max_displacement[i] = scan.y[2 * i].abs();
                scan.found.max_velocity[i] = scan.y[2 * i + 1].abs();
            }
            for (k, m) in scan.found.impact_margin.iter_mut().enumerate() {
                *m = sys.approach(k, &scan.y).0 - scan.s_on[k];
            }
        }
        scan
    }

    /// The contacts' approach maxima on [a, b] within the step ending at
    /// `st.t()`: at the ends, and inside where ṡ changes sign.
    pub(super) fn contact_step<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S, a: f64, b: f64) {
        let t1 = st.t();
        for k in 0..self.s_on.len() {
            let (sa, sda) = if a == self.t {
                sys.chain().approach(k, &self.y)
            } else {
                contact_at(st, sys, k, a)
            };
            let (sb, sdb) = if b == t1 {
                sys.chain().approach(k, st.y())
            } else {
                contact_at(st, sys, k, b)
            };
            let mut max_s = sa.max(sb);
            if sda > 0.0 && sdb < 0.0 {
                let rate = |t| contact_at(st, sys, k, t).1;
                if let Ok(t) = EventLocator::FINE.locate(rate, (a, sda), (b, sdb)) {
                    max_s = max_s.max(contact_at(st, sys, k, t).0);
                }
            }
            let m = &mut self.found.impact_margin[k];
            *m = m.max(max_s - self.s_on[k]);
        }
    }

    /// The right-hand side changed where the last step ended (an event: a
    /// storey's branch, a contact's onset): the jerk there is one-sided,
    /// so the next step reads its accelerations on the dense output. Where
    /// the state `jumped` there too (a rigid impact), the next step starts
    /// from the stepper's state, and the velocities after the jump count.
    pub(super) fn restarted(&mut self, st: &Stepper, jumped: bool) {
        if let Some(jerk) = self.jerk.as_mut() {
            jerk.at_end.fill(f64::NAN);
        }
        if jumped {
            self.y.copy_from_slice(st.y());
            self.dydt.copy_from_slice(st.dydt());
            if self.from <= self.t && self.t <= self.to {
                for (i, m) in self.found.max_velocity.iter_mut().enumerate() {
                    *m = m.max(self.y[2 * i + 1].abs());
                }
            }
        }
    }

    /// What the scan found.
    pub(super) fn finish(mut self) -> Extrema {
        self.found.gauges = self.gauges.iter().map(GaugeScan::reading).collect();
        self.found
    }

    /// The bodies' |u|, |v| and the contacts' margins on `[a, b]` within
    /// the step ending at `st.t()`.
    fn bodies_step<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S, (a, b): (f64, f64)) {
        let t1 = st.t();
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
                max_v = max_v.max(maximum(speed, a, b).0);
            }
            let f = &mut self.found;
            f.max_displacement[i] = f.max_displacement[i].max(max_u);
            f.max_velocity[i] = f.max_velocity[i].max(max_v);
        }
        self.contact_step(st, sys, a, b);
    }

    /// Processes the accepted step from the previous end to `st.t()`.
    pub(super) fn step<S: Chain>(&mut self, st: &mut Stepper, sys: &mut S) {
        let t1 = st.t();
        let (a, b) = (self.t.max(self.from), t1.min(self.to));
        if a <= b && self.bodies {
            self.bodies_step(st, sys, (a, b));
        }
        if a <= b {
            // The bodies' accelerations and jerks at the step's ends, where
            // the scan's ends are the step's.
            let whole = a == self.t && b == t1 && self.t == st.t_prev();
            if let Some(jerk) = self.jerk.as_mut() {
                jerk.update(st, sys);
            }
            let ground = self.jerk.as_ref().map(|_| {
                let z = |t| sys.chain().base_acceleration(t);
                (z(a), z(b))
            });
            for gauge in self.gauges.iter_mut() {
                let ends = gauge_ends(
                    gauge.gauge,
                    whole,
                    (&self.y, &self.dydt),
                    (st.y(), st.dydt()),
                    self.jerk.as_ref().zip(ground),
                );
                gauge_step_with(gauge, st, sys, (a, b), ends);
            }
        } else if let Some(jerk) = self.jerk.as_mut() {
            jerk.update(st, sys);
        }
        self.t = t1;
        self.y.copy_from_slice(st.y());
        self.dydt.copy_from_slice(st.dydt());
    }
}
