//! Where the rigid idealisation breaks (docs/theory.md §12): a rigid
//! contact's impact whose rebound returns within the impact's estimated
//! duration (a resting contact: the seed's e(V) → 1 − (2/3)V as V → 0
//! never accumulates, it only slows), one that follows a neighbour's
//! impact on a shared body within that impact's duration (chains, the
//! cradle), one beside a neighbour's soft episode, or one slower than the
//! absolute tolerance, is taken by the contact's own law, integrated, in
//! a soft episode that ends once the bodies separate.

use super::{apply_jump, Event, Switches};
use crate::dynamics::ChainDynamics;
use crate::impact::rigid::RigidImpact;
use crate::impact::ImpactError;
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
    /// Contact `other`, sharing a body, would reach its law `within` s
    /// (from its approach, rate and acceleration), inside this impact's
    /// estimated duration: a chain about to form.
    Ahead {
        /// The neighbour's contact index.
        other: usize,
        /// When it would reach its law (s from now).
        within: f64,
        /// This impact's estimated duration (s).
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
    /// An impact at `t` overlapping contact j's last impact, begun at
    /// `last.0` with the estimated duration `last.1`, if it does.
    pub(in crate::simulate) fn overlap(j: usize, t: f64, last: (f64, f64)) -> Option<Self> {
        let (tj, duration) = last;
        (t - tj < duration).then_some(Self::Overlap {
            other: j,
            after: t - tj,
            duration,
        })
    }

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
            Self::Ahead { other, within, duration } => format!(
                "contact {}, on a shared body, would reach its law within {within:.3e} s, inside this impact's estimated duration {duration:.3e} s",
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

/// Per contact, where a rigid contact's impact is judged: where its law's
/// force reaches `threshold` (the exponential law acts before the touch,
/// so a soft episode must start there to take the whole impact: begun at
/// the touch it would miss the approach's part and start with the force
/// a, the energy a/α out of nothing), 0 for laws with compact support (at
/// the touch) and for soft contacts.
pub(in crate::simulate) fn judging_gaps(chain: &ChainDynamics, threshold: f64) -> Vec<f64> {
    (0..chain.contacts())
        .map(|k| match chain.rigid_law(k) {
            Some(_) => chain.contact_law(k).onset_approach(threshold).min(0.0),
            None => 0.0,
        })
        .collect()
}

/// Why an impact above the floor, of estimated `duration` and `rebound`
/// velocity ([`judging`](crate::impact::rigid::RigidLaw::judging)), found while its bodies press
/// together at `pressing` (s̈ in m/s², positive toward each other), is
/// taken by its law: the neighbours' reason (`neighbour`, of that
/// duration); a rebound that would return within it. None: a rigid
/// impact.
pub(in crate::simulate) fn judged(
    (duration, rebound): (f64, f64),
    pressing: f64,
    neighbour: impl FnOnce(f64) -> Option<EpisodeReason>,
) -> Option<EpisodeReason> {
    if let Some(reason) = neighbour(duration) {
        return Some(reason);
    }
    if pressing > 0.0 {
        let back = 2.0 * rebound / pressing;
        if back < duration {
            return Some(EpisodeReason::Resting {
                rebound,
                back,
                duration,
            });
        }
    }
    None
}

/// When a neighbour at approach `s` (m), rate `sd` and acceleration
/// `sdd` reaches its judging gap `pre`, if within `duration`: the first
/// root of s + ṡ τ + ½ s̈ τ² = pre (0 if there already and closing). One
/// past it and opening is the overlap's to judge (its last impact).
pub(in crate::simulate) fn reaches_within(
    (s, sd, sdd): (f64, f64, f64),
    pre: f64,
    duration: f64,
) -> Option<f64> {
    let d = pre - s;
    if d <= 0.0 {
        return (sd > 0.0).then_some(0.0);
    }
    let disc = sd * sd + 2.0 * sdd * d;
    if disc < 0.0 {
        return None;
    }
    let den = sd + disc.sqrt();
    let tau = 2.0 * d / den;
    (den > 0.0 && tau <= duration).then_some(tau)
}

impl Switches {
    /// Whether rigid contact k's impact, judged at `(t, y)` (`dydt` the
    /// derivative there), is taken by its law, and why: an approach at or
    /// below `floor` (the absolute tolerance), else [`judged`] (the
    /// neighbours' reasons: a contact sharing a body in a soft episode, or
    /// whose impact began within its estimated duration). None: rigid,
    /// or not approaching.
    pub(in crate::simulate) fn judge(
        &self,
        chain: &ChainDynamics,
        k: usize,
        (t, y, dydt): (f64, &[f64], &[f64]),
        floor: f64,
    ) -> Result<Option<EpisodeReason>, IntegrationError> {
        let u = chain.approach(k, y).1;
        let Some(law) = chain.rigid_law(k).filter(|_| u > 0.0) else {
            return Ok(None);
        };
        if u <= floor {
            return Ok(Some(EpisodeReason::Slow { velocity: u }));
        }
        let judging = law.judging(u).map_err(|e| failed(t, k, e))?;
        Ok(self.judged_at(chain, k, (t, y, dydt), judging))
    }

    /// [`judged`] for contact k at `(t, y)` (`dydt` the derivative
    /// there), of the impact's estimated `(duration, rebound)`.
    fn judged_at(
        &self,
        chain: &ChainDynamics,
        k: usize,
        (t, y, dydt): (f64, &[f64], &[f64]),
        judging: (f64, f64),
    ) -> Option<EpisodeReason> {
        let bodies = |j: usize| {
            let [_, vl, _, vr] = chain.contact_indices(j);
            [vl.map(|i| i / 2), vr.map(|i| i / 2)]
        };
        let mine = bodies(k);
        let sdd = |j: usize| {
            let [_, vl, _, vr] = chain.contact_indices(j);
            vl.map_or(0.0, |i| dydt[i]) - vr.map_or(0.0, |i| dydt[i])
        };
        let neighbour = |duration: f64| {
            (0..chain.contacts())
                .filter(|&j| j != k && bodies(j).iter().flatten().any(|b| mine.contains(&Some(*b))))
                .find_map(|j| {
                    if chain.in_soft_episode(j) {
                        return Some(EpisodeReason::Cluster { other: j });
                    }
                    if let Some(overlap) = EpisodeReason::overlap(j, t, self.last_impact[j]) {
                        return Some(overlap);
                    }
                    chain.rigid_law(j)?;
                    let (s, sd) = chain.approach(j, y);
                    let within = reaches_within((s, sd, sdd(j)), self.pre[j], duration)?;
                    Some(EpisodeReason::Ahead {
                        other: j,
                        within,
                        duration,
                    })
                })
        };
        judged(judging, sdd(k), neighbour)
    }

    /// Rigid contact k's impact at `(t, y)` (`dydt` the derivative just
    /// before it): the velocities' jump applied to `y`, or a soft episode
    /// where the rigid idealisation breaks ([`Switches::judge`], again at
    /// the touch: a neighbour may have struck since the approach). The
    /// impact at the touch's velocity serves the judging and the jump.
    pub(in crate::simulate) fn rigid_or_soft(
        &mut self,
        chain: &ChainDynamics,
        k: usize,
        (t, y, dydt): (f64, &mut [f64], &[f64]),
        floor: f64,
    ) -> Result<Jump, IntegrationError> {
        let u = chain.approach(k, y).1;
        let Some(law) = chain.rigid_law(k).filter(|_| u > 0.0) else {
            return Ok(Jump::Touch);
        };
        if u <= floor {
            return Ok(Jump::Soft(EpisodeReason::Slow { velocity: u }));
        }
        let r = if self.peak_forces {
            law.impact(u)
        } else {
            law.jump(u)
        };
        let r = r.map_err(|e| failed(t, k, e))?;
        let judging = (r.duration, r.rebound_velocity);
        if let Some(reason) = self.judged_at(chain, k, (t, y, dydt), judging) {
            return Ok(Jump::Soft(reason));
        }
        apply_jump(chain, k, y, &r);
        self.last_impact[k] = (t, r.duration);
        Ok(Jump::Rigid(r))
    }

    /// Rigid contact k's impact at `(t, y)`, taken by its law for
    /// `reason`: its estimated duration kept for its neighbours' overlap
    /// test, as a jump's is (a second impact on a body within it is soft
    /// whether the first was a jump or an episode). Nothing is kept for
    /// a slow impact or one joining a neighbour's episode: no impact
    /// estimated.
    pub(in crate::simulate) fn soft_impact(
        &mut self,
        chain: &ChainDynamics,
        k: usize,
        (t, y): (f64, &[f64]),
        reason: &EpisodeReason,
    ) -> Result<(), IntegrationError> {
        let (Some(law), false) = (
            chain.rigid_law(k),
            matches!(
                reason,
                EpisodeReason::Slow { .. } | EpisodeReason::Cluster { .. }
            ),
        ) else {
            return Ok(());
        };
        let u = chain.approach(k, y).1;
        let r = law.impact(u).map_err(|e| failed(t, k, e))?;
        self.last_impact[k] = (t, r.duration);
        Ok(())
    }

    /// Suspends (`on`) or resumes contact k's impact and approach events:
    /// in a soft episode its law is integrated, no jump. (A resumed
    /// approach is armed again once the contact is open.)
    pub(in crate::simulate) fn suspend(&mut self, k: usize, on: bool) {
        self.episode[k] = on;
        for (i, e) in self.events.iter().enumerate() {
            match *e {
                Event::Impact(j) if j == k => self.armed[i] = !on,
                Event::Approach(j) if j == k && on => self.armed[i] = false,
                _ => {}
            }
        }
    }
}

/// An impact law's failure at contact k's impact at t.
fn failed(t: f64, k: usize, e: ImpactError) -> IntegrationError {
    IntegrationError::RigidImpact {
        t,
        contact: k,
        reason: e.to_string(),
    }
}
