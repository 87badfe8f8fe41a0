//! Storeys with a hysteretic law (docs/theory.md §11): the force across a
//! storey follows the storey's drift and its history. Such a storey's
//! elastic stiffness is its law's, not a body spring or a coupling; its
//! dampers (Rayleigh on the initial stiffness) stay linear couplings.

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
