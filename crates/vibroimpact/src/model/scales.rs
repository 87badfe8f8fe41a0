//! The model's own force scales against double precision. A contact law
//! that never vanishes (the exponential one) presses on a body even at
//! rest, across its clearance: where the forces that move the body (its
//! spring across the clearance, the excitation, its initial motion) are
//! far below that, they are lost in rounding when the forces are summed,
//! and a run "completes" with the body exactly at rest (issue 38: a row's
//! mass of 1e-100 kg did so in 10 steps).

use super::{ContactPair, Model, ModelError, ModelErrorKind};

/// The smallest ratio of a body's moving forces to the contact forces on
/// it at rest that keeps them: double precision carries 16 digits, this
/// leaves the moving forces 6.
pub(super) const KEPT_ABOVE: f64 = 1e-10;

/// Refuses a model in which a body's moving forces fall below
/// [`KEPT_ABOVE`] × the forces its contacts press on it at rest, naming
/// the body's mass (`body.K.mass`) and the least mass that keeps them.
pub(super) fn check_rounding(model: &Model) -> Result<(), ModelError> {
    let n = model.bodies.len();
    // Per body: the contacts' forces at rest, and the smallest clearance
    // of those that press.
    let mut at_rest = vec![0.0f64; n];
    let mut gap = vec![f64::INFINITY; n];
    for c in &model.contacts {
        if c.law.has_compact_support() {
            continue;
        }
        let f = c.law.force(-c.clearance, 0.0, 0.0).abs();
        let bodies = match c.pair {
            ContactPair::Bodies { left, right } => [Some(left), Some(right)],
            ContactPair::LeftWall { body } | ContactPair::RightWall { body } => [Some(body), None],
        };
        for b in bodies.into_iter().flatten() {
            at_rest[b] += f;
            gap[b] = gap[b].min(c.clearance);
        }
    }
    let base = model.base.peak();
    for (i, b) in model.bodies.iter().enumerate() {
        if at_rest[i] == 0.0 {
            continue;
        }
        let forced = model
            .forces
            .iter()
            .filter(|f| f.body == i)
            .fold(0.0f64, |m, f| m.max(f.amplitude.abs()));
        let (u0, v0) = (
            model.initial_displacement[i].abs(),
            model.initial_velocity[i].abs(),
        );
        let g = gap[i].max(u0);
        // The acceleration the body moves with: the base's, a force's,
        // its spring's across the clearance, its initial speed turned
        // within the clearance.
        let acceleration = base
            .max(forced / b.mass)
            .max(b.stiffness / b.mass * g)
            .max(if g > 0.0 { v0 * v0 / g } else { 0.0 });
        let moving = b.mass * acceleration;
        if moving > 0.0 && moving < KEPT_ABOVE * at_rest[i] {
            let least = KEPT_ABOVE * at_rest[i] / acceleration;
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                format!("body.{}.mass", i + 1),
                format!(
                    "body {}: mass = {:e} kg: the forces that move it ({moving:.3e} N, at {acceleration:.3e} m/s²) are below double precision against what its contacts' laws press on it at rest across their clearances ({:.3e} N), and would be lost in rounding; give a mass of at least {least:.2e} kg, or a law with compact support",
                    b.name, b.mass, at_rest[i]
                ),
            ));
        }
    }
    Ok(())
}
