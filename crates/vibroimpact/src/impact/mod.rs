//! Two-body impact relations (docs/theory.md §2, seed eqs. 4–18).
//!
//! ## Files
//! - `closed_form.rs` — seed eqs. 8–18 in closed form;
//! - `direct.rs` — impacts by direct integration, any law;
//! - `rigid/` — the rigid limit: an impact as a velocity jump with the
//!   pair's e(U) (docs/theory.md §12);
//! - `table.rs` — functions of one variable tabulated once (piecewise
//!   Chebyshev), for `rigid/`.
//!
//! Two bodies on a line (or a body and a wall, `m2 = ∞`) collide through a
//! contact law. Their relative motion `x = s` obeys
//! `μ ẍ = -F(x, ẋ)` with the reduced mass `μ = m1 m2 / (m1 + m2)`.
//!
//! - [`closed_form`]: Fujita's exact relations for the exponential law: the
//!   phase trajectory (eq. 8), the coefficient of restitution e(V) (eq. 10),
//!   the peak force f_max(V) (eqs. 15–17).
//! - [`direct`]: the same quantities, and contact duration and maximum
//!   penetration, by direct integration of the relative motion for any
//!   contact law.

pub mod closed_form;
pub mod direct;
pub mod rigid;
mod table;

use crate::numeric::RootError;

/// Errors of the impact relations.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImpactError {
    /// A parameter is out of its domain.
    #[error("{name} = {} is invalid: {requirement}", crate::field_error::shown(*value))]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// What it must satisfy.
        requirement: &'static str,
    },
    /// A root solver failed.
    #[error("{what}: {source}")]
    Solver {
        /// What was being solved.
        what: &'static str,
        /// The solver's error.
        source: RootError,
    },
    /// A fixed-point iteration did not reach its tolerance.
    #[error(
        "fixed-point iteration for {what} did not converge in {iterations} iterations at V = {v}"
    )]
    FixedPointNoConvergence {
        /// What was being iterated.
        what: &'static str,
        /// Dimensionless impact velocity.
        v: f64,
        /// Iterations performed.
        iterations: usize,
    },
    /// The direct integration failed.
    #[error("direct integration of the impact failed: {0}")]
    Integration(#[from] crate::integrate::IntegrationError),
    /// The law is not available for this computation.
    #[error("{0}")]
    Unsupported(String),
}

pub(crate) fn positive(name: &'static str, value: f64) -> Result<f64, ImpactError> {
    if value > 0.0 && value.is_finite() {
        Ok(value)
    } else {
        Err(ImpactError::InvalidParameter {
            name,
            value,
            requirement: "must be finite and > 0",
        })
    }
}

/// The masses of the two colliding bodies. `m2 = +∞` models a rigid wall
/// (or a body held by the frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoBodies {
    m1: f64,
    m2: f64,
}

impl TwoBodies {
    /// Two bodies of masses `m1 > 0` and `m2 > 0` (kg); `m2` may be `+∞`.
    pub fn new(m1: f64, m2: f64) -> Result<Self, ImpactError> {
        positive("mass1", m1)?;
        if m2.is_nan() || m2 <= 0.0 {
            return Err(ImpactError::InvalidParameter {
                name: "mass2",
                value: m2,
                requirement: "must be > 0 (or infinite for a wall)",
            });
        }
        Ok(Self { m1, m2 })
    }

    /// A body of mass `m1` against a rigid wall.
    pub fn against_wall(m1: f64) -> Result<Self, ImpactError> {
        Self::new(m1, f64::INFINITY)
    }

    /// Mass of body 1 (kg).
    pub fn m1(&self) -> f64 {
        self.m1
    }

    /// Mass of body 2 (kg), `+∞` for a wall.
    pub fn m2(&self) -> f64 {
        self.m2
    }

    /// Reduced mass `μ = m1 m2 / (m1 + m2)` (`m1` against a wall). The seed's
    /// equal masses give `μ = m/2` (its eq. 4). Written as the smaller mass
    /// over `1 + small/large`, so that no product overflows: `m1 m2` of
    /// 1e308 kg against 2 kg was infinite, and with it every force.
    pub fn reduced_mass(&self) -> f64 {
        let (small, large) = if self.m1 <= self.m2 {
            (self.m1, self.m2)
        } else {
            (self.m2, self.m1)
        };
        small / (1.0 + small / large)
    }

    /// Peak accelerations `F/m1`, `F/m2` of the two bodies for a force `F`
    /// (the seed's "impact acceleration"); 0 for a wall.
    pub fn accelerations(&self, force: f64) -> [f64; 2] {
        [force / self.m1, force / self.m2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduced mass never overflows: 1e308 kg against 2 kg is 2 kg to
    /// rounding (the product m1 m2 was infinite, and every force with it);
    /// equal masses give exactly half, a wall the body's own mass, and
    /// unequal ones m1 m2 / (m1 + m2) to rounding.
    #[test]
    fn the_reduced_mass_is_exact_where_the_product_overflows() {
        let mu = |a, b| TwoBodies::new(a, b).unwrap().reduced_mass();
        assert!((mu(1e308, 2.0) / 2.0 - 1.0).abs() < 1e-15);
        assert!((mu(2.0, 1e308) / 2.0 - 1.0).abs() < 1e-15);
        assert_eq!(mu(0.227, 0.227), 0.1135);
        assert_eq!(mu(0.227, f64::INFINITY), 0.227);
        let exact: f64 = 3.0 * 7.0 / 10.0;
        assert!((mu(3.0, 7.0) - exact).abs() < 1e-15 * exact);
    }
}
