//! Storeys with a hysteretic law (docs/theory.md §11): the force across a
//! storey follows the storey's drift and its history. Such a storey's
//! elastic stiffness is its law's, not a body spring or a coupling; its
//! dampers (Rayleigh on the initial stiffness) stay linear couplings.
//!
//! P-Δ (docs/theory.md §11): the gravity load P above a storey of height h
//! acts through its drift as a shear −(P/h)·d, a negative geometric
//! stiffness beside the law's force, on every branch.

use super::{Model, ModelError, ModelErrorKind};
use crate::model::hysteresis::StoreyLaw;

/// A storey between body `below` (or the ground) and body `above`: the
/// force F(d, z) of its law at the drift d = u_above − u_below pulls
/// `above` back (−F) and `below` along (+F).
#[derive(Clone, Debug, PartialEq)]
pub struct Storey {
    /// The body below, or None for the ground.
    pub below: Option<usize>,
    /// The body above.
    pub above: usize,
    /// The law.
    pub law: StoreyLaw,
    /// The P-Δ geometric stiffness P/h (N/m, ≥ 0; 0: none): the storey's
    /// shear is F(d, z) − (P/h)·d.
    pub p_delta: f64,
}

impl Model {
    /// The model with hysteretic `storeys` added, checked: existing,
    /// different bodies and a law that passes its checks (errors at
    /// `storey.K.KEY`).
    pub fn with_storeys(mut self, storeys: Vec<Storey>) -> Result<Self, ModelError> {
        let n = self.bodies.len();
        for (k, s) in storeys.iter().enumerate() {
            if s.above >= n || s.below.is_some_and(|b| b >= n || b == s.above) {
                return Err(ModelError::new(
                    ModelErrorKind::UnknownBody,
                    format!("storey.{}", k + 1),
                    format!("storey {}: must join two different existing bodies, or a body and the ground", k + 1),
                ));
            }
            let k0 = s.law.initial_stiffness();
            if !(s.p_delta >= 0.0 && s.p_delta.is_finite()) || s.p_delta >= k0 {
                return Err(ModelError::new(
                    ModelErrorKind::InvalidValue,
                    format!("storey.{}.p_delta", k + 1),
                    format!(
                        "storey {}: P-Δ stiffness P/h = {} N/m: must be finite, ≥ 0 and below the law's elastic stiffness {k0} N/m (else the storey is unstable at zero drift)",
                        k + 1,
                        s.p_delta
                    ),
                ));
            }
            s.law.check().map_err(|e| {
                ModelError::new(
                    ModelErrorKind::InvalidValue,
                    format!("storey.{}.{}", k + 1, e.key),
                    format!("storey {}: {e}", k + 1),
                )
            })?;
        }
        self.storeys = storeys;
        Ok(self)
    }

    /// The hysteretic storeys.
    pub fn storeys(&self) -> &[Storey] {
        &self.storeys
    }
}
