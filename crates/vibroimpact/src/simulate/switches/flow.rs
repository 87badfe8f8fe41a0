//! A bare flow through a run's events: a state, with whatever rides along
//! (the columns of a variational system), integrated over an interval by
//! DOP853 (or moved exactly, where every contact is rigid: [`Method::Exact`]),
//! every event located and applied where it happens, and a hook at
//! each rigid impact that updates what rides along (docs/theory.md §12:
//! the saltation of the period map's columns).

use super::{apply_event, EpisodeReason, Event, Jump, Switches, Verdict};
use crate::dynamics::Chain;
use crate::impact::rigid::RigidImpact;
use crate::integrate::{IntegrationError, IntegratorOptions, Linear, LinearForm, Method, Stepper};

/// What a rigid impact hands the hook: the contact, the time, the
/// extended state just before the jump, and the state just after it (the
/// velocities jumped; the rest, to be updated by the hook, as before).
pub(crate) struct ImpactJump<'a> {
    /// The model's contact index.
    pub(crate) contact: usize,
    /// The impact's time.
    pub(crate) t: f64,
    /// The extended state just before.
    pub(crate) before: &'a [f64],
    /// The extended state just after.
    pub(crate) after: &'a mut [f64],
    /// The impact.
    pub(crate) impact: &'a RigidImpact,
}

/// Integrates `sys` from `(0, z0)` to `t_end` with `opts` (at most
/// `opts.max_steps` steps, retaken ones and events included), applying its
/// events (rigid impacts, storeys' switches, onsets) where they happen;
/// `at_impact` updates the rest of the state at each rigid impact. Returns
/// the state at `t_end`, the steps taken and the rigid impacts applied.
pub(crate) fn flow_through_events<S: Chain>(
    sys: &mut S,
    z0: &[f64],
    t_end: f64,
    opts: &IntegratorOptions,
    at_impact: impl FnMut(&mut S, ImpactJump) -> Result<(), IntegrationError>,
) -> Result<(Vec<f64>, u64, usize), IntegrationError> {
    let form = sys.linear_form().and_then(LinearForm::solve);
    flow_through_events_with(sys, form, z0, t_end, opts, at_impact)
}

/// [`flow_through_events`] with the system's linear form solved already
/// (None: it has none), as a caller that solved a larger one has it
/// ([`Linear::leading`]).
pub(crate) fn flow_through_events_with<S: Chain>(
    sys: &mut S,
    form: Option<Linear>,
    z0: &[f64],
    t_end: f64,
    opts: &IntegratorOptions,
    mut at_impact: impl FnMut(&mut S, ImpactJump) -> Result<(), IntegrationError>,
) -> Result<(Vec<f64>, u64, usize), IntegrationError> {
    let dim = sys.dim();
    // A chain whose every contact is rigid moves exactly between impacts
    // (its linear form), in steps the exact series takes to rounding;
    // another by DOP853.
    let exact = form
        .filter(|form| form.dim() == dim)
        .and_then(|form| Stepper::exact(form, dim, opts));
    let mut st = match exact {
        Some(st) => st,
        None => Stepper::new(Method::Dop853, dim, opts.clone())?,
    };
    st.reset(sys, 0.0, z0)?;
    let contacts = sys.chain().contacts();
    // (Rigid impacts judged where a simulation judges them, at the default
    // impact force threshold.)
    let threshold = crate::simulate::SimulationOptions::default().impact_force_threshold;
    let pre = super::episodes::judging_gaps(sys.chain(), threshold);
    let mut switches = Switches::new(sys.chain(), dim, vec![0.0; contacts], pre)
        .map(Switches::without_peak_forces);
    let (mut steps, mut impacts) = (0_u64, 0_usize);
    while st.t() < t_end {
        steps += 1;
        if steps > opts.max_steps {
            return Err(IntegrationError::TooManySteps { t: st.t(), steps });
        }
        let Some(sw) = switches.as_mut() else {
            st.step(sys, t_end)?;
            continue;
        };
        let event = match sw.before_step(&st, t_end) {
            Err(event) => event,
            Ok(bound) => {
                st.step(sys, bound)?;
                match sw.after_step(&mut st, sys)? {
                    Verdict::Switch(event) => event,
                    Verdict::Retake | Verdict::Clear => continue,
                }
            }
        };
        if let Event::Approach(k) = event {
            let (t, y, dydt) = (st.t(), st.y(), st.dydt());
            if let Some(reason) = sw.judge(sys.chain(), k, (t, y, dydt), opts.atol)? {
                return Err(episode_refused(t, k, &reason));
            }
            continue;
        }
        let Event::Impact(k) = event else {
            apply_event(&mut st, sys, event)?;
            continue;
        };
        let (t, before, dydt) = (st.t(), st.y().to_vec(), st.dydt().to_vec());
        let mut after = before.clone();
        match sw.rigid_or_soft(sys.chain(), k, (t, &mut after, &dydt), opts.atol)? {
            Jump::Touch => {}
            Jump::Rigid(impact) => {
                impacts += 1;
                at_impact(
                    sys,
                    ImpactJump {
                        contact: k,
                        t,
                        before: &before,
                        after: &mut after,
                        impact: &impact,
                    },
                )?;
            }
            // A soft episode has no saltation: the map is the rigid one
            // throughout, or none.
            Jump::Soft(reason) => return Err(episode_refused(t, k, &reason)),
        }
        st.reset(sys, t, &after)?;
    }
    Ok((st.y().to_vec(), steps, impacts))
}

/// A period map meets a soft episode of contact k at `t`: it has no
/// saltation, so the map is the rigid one throughout, or none.
fn episode_refused(t: f64, k: usize, reason: &EpisodeReason) -> IntegrationError {
    IntegrationError::RigidImpact {
        t,
        contact: k,
        reason: format!("{}: the rigid idealisation breaks there (a simulation takes it by the contact's law); the period map needs rigid impacts throughout: keep this contact soft (impacts = \"soft\")", reason.describe_by(|j| j)),
    }
}
