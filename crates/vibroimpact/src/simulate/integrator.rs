//! Which integrator runs a simulation: the global one, the local one
//! (docs/theory.md §10), or the one of the two that pays for the model.

use super::{OptionsError, SimulationOptions};
use crate::integrate::Method;
use crate::model::{BaseExcitation, Model};

/// How a simulation advances the state.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Integrator {
    /// The local integrator where it pays, the global one elsewhere (see
    /// [`Integrator::resolve`]).
    #[default]
    Auto,
    /// Every body integrated at every step by the step driver.
    Global,
    /// Exact motion between contacts; only bodies whose contacts are
    /// active are integrated ([`super::local::LocalStats`] counts the work).
    /// A model with no contacts, linear between its storeys' switches,
    /// under a record or none, runs exactly throughout (docs/theory.md
    /// §13; no local statistics).
    Local,
}

/// Groups of bodies (joined by springs) from which [`Integrator::Auto`]
/// runs the local integrator (docs/decisions.md D24: at 16 bodies of R2
/// near resonance, where every body impacts, the local run takes 6 % more
/// time; at 0.5 ω0, 2× less; below, the global integrator is as fast or
/// faster).
pub const AUTO_LOCAL_GROUPS: usize = 16;

impl Integrator {
    /// `auto`, `global` or `local`.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Auto => "auto",
            Integrator::Global => "global",
            Integrator::Local => "local",
        }
    }

    /// The integrator that runs `model` with `opts`: as
    /// [`Integrator::resolve`], except that `auto` runs a model linear
    /// between its storeys' switches under a record exactly (through the
    /// local integrator), rigid impacts
    /// locally from [`AUTO_LOCAL_GROUPS`] groups on (no record, no
    /// gravity), and under a record `auto` is local
    /// for at least [`AUTO_LOCAL_GROUPS`] groups where that was measured
    /// to pay (docs/decisions.md D41): no exact peaks asked for (their
    /// scans of every exactly moving group cost the local run 2.2–3.3
    /// times the global one's in the pounding study), and DOP853, or
    /// DOPRI5 at rtol 1e-7 or tighter (looser, DOPRI5's steps are the
    /// record's samples and the global run is the faster).
    pub fn resolve_run(self, model: &Model, opts: &SimulationOptions) -> Integrator {
        let record = matches!(model.base(), BaseExcitation::Record(_));
        // A model linear between its storeys' switches under a record
        // runs exactly (docs/theory.md §13), which the local integrator
        // hands it: a 4-storey IMK frame under a far-field record, 5.3
        // ms against the global run's 7.4 at DOPRI5 rtol 1e-3 and 18 at
        // DOP853 rtol 1e-10 (docs/decisions.md D43).
        if self == Integrator::Auto && record && super::exact::qualifies(model, opts) {
            return Integrator::Local;
        }
        let groups = || {
            crate::simulate::local::free_motion::spring_groups(model)
                .1
                .len()
        };
        // Rigid impacts (no record, no gravity): the local run jumps
        // between exact motions, measured faster from 16 groups on (R2 at
        // 0.95 ω0 over 100 periods: 1.6× at 16 bodies, 3.5× at 64;
        // docs/decisions.md D42). (Period maps keep the global flow.)
        if self == Integrator::Auto
            && model.has_rigid_impacts()
            && !record
            && model.gravity() == 0.0
            && groups() >= AUTO_LOCAL_GROUPS
        {
            return Integrator::Local;
        }
        if self != Integrator::Auto
            || !record
            || model.has_rigid_impacts()
            || model.gravity() != 0.0
        {
            return self.resolve(model);
        }
        let groups = groups();
        let pays = match opts.method {
            Method::Dop853 => true,
            Method::Dopri5 => opts.rtol <= 1e-7,
            Method::Exact | Method::Rodas | Method::Auto => false,
        };
        if groups >= AUTO_LOCAL_GROUPS && pays && opts.extrema_window.is_none() {
            Integrator::Local
        } else {
            Integrator::Global
        }
    }

    /// The integrator that runs `model`: [`Integrator::Auto`] is local for
    /// a model of at least [`AUTO_LOCAL_GROUPS`] groups whose free motion
    /// has a bounded steady state under its forcing (no undamped group
    /// under harmonic forcing), no recorded base motion and no rigid
    /// impacts, global otherwise; the others are themselves. (A record moves every group
    /// and the global integrator steps at its samples anyway: at full
    /// scale rows of 16 and 64 yielding buildings at DOPRI5 rtol 1e-4
    /// take 1.5 and 0.8 times the global run's time locally, their
    /// pounding study with exact peaks 3.3 and 2.2 times; docs/decisions.md
    /// D40. [`Integrator::resolve_run`] knows the run's options and picks
    /// local where it pays.)
    pub fn resolve(self, model: &Model) -> Integrator {
        match self {
            // (Rigid impacts run on the global integrator: docs/theory.md
            // §12.)
            Integrator::Auto
                if matches!(model.base(), BaseExcitation::Record(_))
                    || model.has_rigid_impacts()
                    || model.gravity() != 0.0 =>
            {
                Integrator::Global
            }
            Integrator::Auto => {
                let (place, members) = crate::simulate::local::free_motion::spring_groups(model);
                // Per group: damped (by a body's or a coupling's damper).
                let mut damped = vec![false; members.len()];
                for (i, b) in model.bodies().iter().enumerate() {
                    damped[place[i].0] |= b.damping != 0.0;
                }
                for c in model.couplings() {
                    damped[place[c.a].0] |= c.damping != 0.0;
                }
                let harmonic = model.forcing_frequency().is_some();
                if members.len() >= AUTO_LOCAL_GROUPS && !(harmonic && damped.contains(&false)) {
                    Integrator::Local
                } else {
                    Integrator::Global
                }
            }
            other => other,
        }
    }
}

impl std::str::FromStr for Integrator {
    type Err = OptionsError;
    fn from_str(s: &str) -> Result<Self, OptionsError> {
        match s {
            "auto" => Ok(Integrator::Auto),
            "global" => Ok(Integrator::Global),
            "local" => Ok(Integrator::Local),
            _ => Err(OptionsError(format!(
                "integrator = {s:?}: must be auto, global or local"
            ))),
        }
    }
}
