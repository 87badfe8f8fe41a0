//! The branch switches of bilinear storeys on a run's steps (docs/theory.md
//! §11): within a step a bilinear storey's force is linear in its drift;
//! where its switch function (yield, unloading) vanishes inside a step, the
//! step is taken again up to that time, and the branch switches there.

use super::ChainDynamics;
use crate::integrate::{IntegrationError, Stepper};
use crate::numeric::brent;

/// What a step's check found.
pub(super) enum Verdict {
    /// No switch in the step.
    Clear,
    /// A switch inside the step: the stepper is back at the step's start,
    /// and the next steps end at the switch ([`Switches::bound`]).
    Retake,
    /// The step ended at storey k's switch.
    Switch(usize),
}

/// The switches of a run's bilinear storeys.
pub(super) struct Switches {
    storeys: Vec<usize>,
    t_prev: f64,
    y_prev: Vec<f64>,
    buf: Vec<f64>,
    /// The next switch's time and storey, once located.
    pending: Option<(f64, usize)>,
}

impl Switches {
    /// None for a model without bilinear storeys.
    pub(super) fn new(sys: &ChainDynamics, dim: usize) -> Option<Self> {
        let storeys: Vec<usize> = sys.storeys().bilinear().collect();
        (!storeys.is_empty()).then(|| Self {
            storeys,
            t_prev: 0.0,
            y_prev: vec![0.0; dim],
            buf: vec![0.0; dim],
            pending: None,
        })
    }

    /// Keeps the state a step starts from; the step's `bound`, shortened to
    /// a located switch.
    pub(super) fn before_step(&mut self, st: &Stepper, bound: f64) -> f64 {
        self.t_prev = st.t();
        self.y_prev.copy_from_slice(st.y());
        self.pending.map_or(bound, |(t, _)| bound.min(t))
    }

    /// Checks the step just taken for switches (at its end and at three
    /// points inside on the dense output, located by Brent).
    pub(super) fn after_step(
        &mut self,
        st: &mut Stepper,
        sys: &mut ChainDynamics,
    ) -> Result<Verdict, IntegrationError> {
        let (t0, t1) = (self.t_prev, st.t());
        if let Some((t, k)) = self.pending {
            if t1 >= t {
                self.pending = None;
                return Ok(Verdict::Switch(k));
            }
        }
        let mut first: Option<(f64, usize)> = None;
        for &k in &self.storeys {
            let g0 = sys.storeys().switch_value(k, &self.y_prev);
            if g0 <= 0.0 {
                continue;
            }
            let g_end = sys.storeys().switch_value(k, st.y());
            let mut g = |t: f64, buf: &mut Vec<f64>| {
                st.dense_output(sys, t, buf);
                sys.storeys().switch_value(k, buf)
            };
            let (mut ta, mut ga) = (t0, g0);
            for j in 1..=4 {
                let tb = if j == 4 {
                    t1
                } else {
                    t0 + (t1 - t0) * j as f64 / 4.0
                };
                let gb = if j == 4 { g_end } else { g(tb, &mut self.buf) };
                if gb <= 0.0 {
                    let mut buf = std::mem::take(&mut self.buf);
                    let xtol = 4.0 * f64::EPSILON * tb.abs().max(1e-300);
                    let root = brent(|t| g(t, &mut buf), ta, tb, ga, gb, xtol, 200);
                    self.buf = buf;
                    let t = root.unwrap_or(tb);
                    if first.is_none_or(|(tf, _)| t < tf) {
                        first = Some((t, k));
                    }
                    break;
                }
                (ta, ga) = (tb, gb);
            }
        }
        match first {
            None => Ok(Verdict::Clear),
            Some((t, k)) if t >= t1 => Ok(Verdict::Switch(k)),
            Some(found) => {
                self.pending = Some(found);
                st.reset(sys, t0, &self.y_prev)?;
                Ok(Verdict::Retake)
            }
        }
    }
}

#[cfg(test)]
#[path = "simulate_switches_tests.rs"]
mod tests;
