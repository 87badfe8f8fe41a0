//! Where the rigid idealisation breaks (docs/theory.md §12): a rigid
//! contact's impact whose rebound returns within the impact's estimated
//! duration (a resting contact: the seed's e(V) → 1 − (2/3)V as V → 0
//! never accumulates, it only slows), one that follows a neighbour's
//! impact on a shared body within that impact's duration (chains, the
//! cradle), one beside a neighbour's soft episode, or one slower than the
//! absolute tolerance, is taken by the contact's own law, integrated, in
//! a soft episode that ends once the bodies separate.

use super::{rigid_jump, Event, Switches};
use crate::dynamics::ChainDynamics;
use crate::impact::rigid::RigidImpact;
use crate::integrate::IntegrationError;
use crate::model::Model;

/// Why a rigid contact's impact was taken by its soft law.
#[derive(Clone, Debug, PartialEq)]
pub enum EpisodeReason {
    /// The rebound returns after `back` s, within the impact's estimated
    /// duration (a contact coming to rest under a pressing force).
    Resting {
        /// The rebound's relative velocity (m/s).
        rebound: f64,
        /// Its return time under the pressing acceleration (s).
        back: f64,
        /// The impact's estimated duration (s).
        duration: f64,
    },
    /// A second impact on a body `after` s after contact `other`'s, within
    /// that impact's estimated duration.
    Overlap {
        /// The neighbour's contact index.
        other: usize,
        /// Time since its impact (s).
        after: f64,
        /// Its impact's estimated duration (s).
        duration: f64,
    },
    /// Contact `other`, sharing a body, is in a soft episode.
    Cluster {
        /// The neighbour's contact index.
        other: usize,
    },
    /// An approach velocity at or below the absolute tolerance.
    Slow {
        /// The approach velocity (m/s).
        velocity: f64,
    },
}

impl EpisodeReason {
    /// The reason in words, contacts by name.
    pub fn describe(&self, model: &Model) -> String {
        self.describe_by(|k| model.contact_name(k))
    }

    /// The reason in words, contacts named by `name` (of an index).
    pub fn describe_by<S: std::fmt::Display>(&self, name: impl Fn(usize) -> S) -> String {
        match self {
            Self::Resting { rebound, back, duration } => format!(
                "its rebound ({rebound:.3e} m/s) returns after {back:.3e} s, within the impact's estimated duration {duration:.3e} s: a resting contact"
            ),
            Self::Overlap { other, after, duration } => format!(
                "{after:.3e} s after an impact of contact {} on a shared body, within that impact's estimated duration {duration:.3e} s",
                name(*other)
            ),
            Self::Cluster { other } => format!(
                "contact {}, on a shared body, is in a soft episode",
                name(*other)
            ),
            Self::Slow { velocity } => format!(
                "approach velocity {velocity:.3e} m/s, at or below the absolute tolerance"
            ),
        }
    }
}

/// A rigid contact's soft episode.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftEpisode {
    /// The model's contact index.
    pub contact: usize,
    /// When it started (s).
    pub start_time: f64,
    /// When the bodies separated (s); NaN if still in contact at the end.
    pub end_time: f64,
    /// Why.
    pub reason: EpisodeReason,
}

/// What a rigid contact's impact becomes.
pub(in crate::simulate) enum Jump {
    /// The approach reached zero without approaching: nothing.
    Touch,
    /// The velocities jumped.
    Rigid(RigidImpact),
    /// Its law takes it: a soft episode, for this reason.
    Soft(EpisodeReason),
}

impl Switches {
    /// Rigid contact k's impact at `(t, y)` (`dydt` the derivative just
    /// before it): the velocities' jump applied to `y`, or a soft episode
    /// where the rigid idealisation breaks (the module's reasons).
    pub(in crate::simulate) fn rigid_or_soft(
        &mut self,
        chain: &ChainDynamics,
        k: usize,
        (t, y, dydt): (f64, &mut [f64], &[f64]),
        floor: f64,
    ) -> Result<Jump, IntegrationError> {
        let (_, u) = chain.approach(k, y);
        let Some(law) = chain.rigid_law(k) else {
            return Ok(Jump::Touch);
        };
        if u <= 0.0 {
            return Ok(Jump::Touch);
        }
        let bodies = |j: usize| {
            let [_, vl, _, vr] = chain.contact_indices(j);
            [vl.map(|i| i / 2), vr.map(|i| i / 2)]
        };
        let mine = bodies(k);
        for j in (0..chain.contacts()).filter(|&j| j != k) {
            if !bodies(j).iter().flatten().any(|b| mine.contains(&Some(*b))) {
                continue;
            }
            if chain.in_soft_episode(j) {
                return Ok(Jump::Soft(EpisodeReason::Cluster { other: j }));
            }
            let (tj, duration) = self.last_impact[j];
            if t - tj < duration {
                return Ok(Jump::Soft(EpisodeReason::Overlap {
                    other: j,
                    after: t - tj,
                    duration,
                }));
            }
        }
        if u <= floor {
            return Ok(Jump::Soft(EpisodeReason::Slow { velocity: u }));
        }
        let r = law.impact(u).map_err(|e| IntegrationError::RigidImpact {
            t,
            contact: k,
            reason: e.to_string(),
        })?;
        let [_, vl, _, vr] = chain.contact_indices(k);
        let pressing = vl.map_or(0.0, |i| dydt[i]) - vr.map_or(0.0, |i| dydt[i]);
        if pressing > 0.0 {
            let back = 2.0 * r.rebound_velocity / pressing;
            if back < r.duration {
                return Ok(Jump::Soft(EpisodeReason::Resting {
                    rebound: r.rebound_velocity,
                    back,
                    duration: r.duration,
                }));
            }
        }
        rigid_jump(chain, k, (t, y), floor)?;
        self.last_impact[k] = (t, r.duration);
        Ok(Jump::Rigid(r))
    }

    /// Suspends (`on`) or resumes contact k's impact event: in a soft
    /// episode its law is integrated, no jump.
    pub(in crate::simulate) fn suspend(&mut self, k: usize, on: bool) {
        if let Some(i) = self.events.iter().position(|e| *e == Event::Impact(k)) {
            self.armed[i] = !on;
        }
    }
}
