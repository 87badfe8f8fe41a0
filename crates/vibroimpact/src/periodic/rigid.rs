//! The shooting map of a model with rigid impacts (docs/theory.md §12):
//! the state and Φ's columns integrated between impacts by the global
//! integrator, the velocities' jump applied at each impact and the
//! columns multiplied by its saltation matrix (including de/dU of a
//! velocity-dependent law, seed eq. (10)). Where the chain is linear
//! between impacts the state alone goes through the events and the
//! columns follow it exactly from impact to impact ([`replayed`]). Φ is
//! always dense here: the matrix-free products are products with it.

use super::map::{
    parameter_column, shooting_map, variational_map, MapDerivatives, MapTangent, Tape,
};
use super::*;
use crate::dynamics::saltation::Saltation;
use crate::impact::rigid::RigidImpact;
use crate::integrate::LinearForm;
use crate::simulate::{flow_through_events, flow_through_events_with, ImpactJump};

/// [`period_map_with`](super::period_map_with) for a model with rigid
/// impacts: the map, its dense Jacobian (also behind the tangent without
/// `dense`) and, with `shifted = (model at p + dp, dp)`, `∂P/∂p`.
pub(super) fn rigid_map(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    (shifted, dense): (Option<(&Model, f64)>, bool),
    t: f64,
    max_steps: u64,
) -> Result<MapDerivatives, IntegrationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    if d > MAX_DENSE_DIM {
        return Err(IntegrationError::InvalidOptions(format!(
            "rigid impacts: the period map of {n} bodies carries its dense {d}×{d} monodromy through the impacts' saltation; at most {} bodies",
            MAX_DENSE_DIM / 2
        )));
    }
    let dynamics = |m: &Model| ChainDynamics::new(m, false);
    let (mut var, dt_dp) = variational_map(
        (model, dynamics(model)),
        d,
        shifted.map(|(m, dp)| (m, dynamics(m), dp)),
        (opts, t),
        |c| c,
    )?;
    let z0 = var.initial_state(&to_interleaved(x));
    let int_opts = opts.integrator_options(max_steps, Some(d));
    let (z, steps) = match replayed(&mut var, &z0, t, &int_opts)? {
        Some(replayed) => replayed,
        None => {
            let (z, steps, _) = flow_through_events(&mut var, &z0, t, &int_opts, saltation)?;
            (z, steps)
        }
    };
    let image = from_interleaved(&z[..d], n);
    let phi = var.sensitivity(&z).to_vec();
    let dp_column = var.parameter_sensitivity(&z).map(|s| {
        let mut flow = vec![0.0; d];
        var.system_mut().rhs(t, &z[..d], &mut flow);
        parameter_column(s, &flow, dt_dp, opts.symmetric)
    });
    let symmetric = opts.symmetric;
    let map = shooting_map(image, &phi, d, n, symmetric);
    let tangent = (!dense).then_some(MapTangent {
        tape: Tape::Dense(phi),
        n,
        symmetric,
    });
    Ok(MapDerivatives {
        map,
        dp_column,
        steps,
        tangent,
    })
}

/// An impact of the state's run: contact, time, the state just before
/// and just after, the impact.
type Recorded = (usize, f64, Vec<f64>, Vec<f64>, RigidImpact);

/// Where the chain moves exactly between impacts (its linear form), its
/// columns need not ride through the events: the state alone is flowed
/// through them (its impacts recorded), and then the columns (Φ's and
/// the parameter's, which the state does not steer) are moved exactly
/// from impact to impact, each impact's saltation applied there with the
/// state just before and after it. The extended state at `t` and the
/// steps of both runs; None where the chain has no linear form.
fn replayed(
    var: &mut Variational<ChainDynamics>,
    z0: &[f64],
    t: f64,
    int_opts: &IntegratorOptions,
) -> Result<Option<(Vec<f64>, u64)>, IntegrationError> {
    let dim = var.dim();
    let Some(form) = (var.linear_form().and_then(LinearForm::solve)).filter(|f| f.dim() == dim)
    else {
        return Ok(None);
    };
    let d = var.state_dim();
    let mut jumps: Vec<Recorded> = Vec::new();
    // (The state's own form is the first block of the columns': not
    // solved again.)
    let own = Some(form.leading(1));
    let state = var.system_mut();
    let (y, steps, _) = flow_through_events_with(state, own, &z0[..d], t, int_opts, |_, j| {
        jumps.push((
            j.contact,
            j.t,
            j.before.to_vec(),
            j.after.to_vec(),
            *j.impact,
        ));
        Ok(())
    })?;
    let (mut z, mut t_last) = (z0.to_vec(), 0.0);
    for (contact, t_k, state_before, state_after, impact) in &jumps {
        form.flow((t_last, *t_k), &mut z);
        let mut before = z;
        before[..d].copy_from_slice(state_before);
        let mut after = before.clone();
        after[..d].copy_from_slice(state_after);
        saltation(
            var,
            ImpactJump {
                contact: *contact,
                t: *t_k,
                before: &before,
                after: &mut after,
                impact,
            },
        )?;
        (z, t_last) = (after, *t_k);
    }
    form.flow((t_last, t), &mut z);
    z[..d].copy_from_slice(&y);
    Ok(Some((z, steps)))
}

/// The shooting map's image alone through rigid impacts (interleaved),
/// and the steps taken.
pub(super) fn rigid_image(
    model: &Model,
    y0: &[f64],
    t: f64,
    int_opts: &IntegratorOptions,
) -> Result<(Vec<f64>, u64), IntegrationError> {
    let mut sys = ChainDynamics::new(model, false);
    let (y, steps, _) = flow_through_events(&mut sys, y0, t, int_opts, |_, _| Ok(()))?;
    Ok((y, steps))
}

/// The rigid impacts over `t` from the interleaved state `y0`: each one's
/// contact and approach velocity, in order (a branch's grazing test).
pub(crate) fn rigid_impacts_over(
    model: &Model,
    y0: &[f64],
    t: f64,
    int_opts: &IntegratorOptions,
) -> Result<Vec<(usize, f64)>, IntegrationError> {
    let mut sys = ChainDynamics::new(model, false);
    let mut found = Vec::new();
    flow_through_events(&mut sys, y0, t, int_opts, |_, jump| {
        found.push((jump.contact, jump.impact.impact_velocity));
        Ok(())
    })?;
    Ok(found)
}

/// The shooting map's image and its product with the interleaved column
/// `w0` through rigid impacts (both interleaved).
pub(super) fn rigid_product(
    model: &Model,
    y0: &[f64],
    w0: &[f64],
    t: f64,
    int_opts: &IntegratorOptions,
) -> Result<(Vec<f64>, Vec<f64>), IntegrationError> {
    let mut var = Variational::new(ChainDynamics::new(model, false), 1);
    let z0 = var.initial_state_with(y0, &[w0]);
    let (mut z, _, _) = flow_through_events(&mut var, &z0, t, int_opts, saltation)?;
    let w = z.split_off(y0.len());
    Ok((z, w))
}

/// The saltation of an impact applied to the carried columns of `var`
/// (docs/theory.md §12): `S w` for each column of Φ, and for a parameter's
/// column `S s + ∂g/∂p + (f⁺ − G f⁻) ∂h/∂p / U`, the jump's and the event's
/// own dependence on p by differences against the shifted system.
pub(crate) fn saltation(
    var: &mut Variational<ChainDynamics>,
    jump: ImpactJump,
) -> Result<(), IntegrationError> {
    let d = var.state_dim();
    let k = jump.contact;
    let states = (&jump.before[..d], &jump.after[..d]);
    let salt = Saltation::new(var.system_mut(), k, jump.t, states, jump.impact);
    let columns = var.columns();
    for c in 0..columns {
        salt.apply(&mut jump.after[d * (1 + c)..d * (2 + c)]);
    }
    let Some((shifted, dp)) = var.shifted() else {
        return Ok(());
    };
    let chain = var.system();
    let before = &jump.before[..d];
    let h_p = (shifted.approach(k, before).0 - chain.approach(k, before).0) / dp;
    let column = &mut jump.after[d * (1 + columns)..d * (2 + columns)];
    salt.apply_shifted(column, h_p);
    // The jump's own ∂g/∂p: the shifted law's and masses' velocity changes.
    let u = jump.impact.impact_velocity;
    let impulse_p = match shifted.rigid_law(k) {
        Some(law) => {
            law.jump(u)
                .map_err(|e| IntegrationError::RigidImpact {
                    t: jump.t,
                    contact: k,
                    reason: e.to_string(),
                })?
                .impulse
        }
        None => 0.0,
    };
    let [_, vl, _, vr] = chain.contact_indices(k);
    let p = jump.impact.impulse;
    if let Some(i) = vl {
        column[i] += (p / chain.mass(i / 2) - impulse_p / shifted.mass(i / 2)) / dp;
    }
    if let Some(i) = vr {
        column[i] += (impulse_p / shifted.mass(i / 2) - p / chain.mass(i / 2)) / dp;
    }
    Ok(())
}
