//! Event location on the dense output of an accepted step: the one place
//! where a sign change of an event function `g(t)` between the ends of a
//! step is detected ([`Crossing`]) and its time found ([`EventLocator`],
//! Brent's method on the dense output, so no extra integration step is
//! taken). Simulation (impact start and end, turning points, extrema),
//! sweeps (through simulation) and the two-body impact integration (peak
//! force, deepest penetration, contact boundary, separation) all use it.

use crate::numeric::{brent, RootError};

/// Which sign changes of an event function over a step count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// From positive to non-positive (`g_a > 0 ≥ g_b`), e.g. a velocity
    /// turning from approach to separation.
    Falling,
    /// From non-positive to positive (`g_a ≤ 0 < g_b`), e.g. a gap closing.
    Rising,
    /// Either of the two.
    Either,
}

impl Crossing {
    /// Whether `g` made this crossing between the values `before` and
    /// `after` at the step ends.
    pub fn happened(self, before: f64, after: f64) -> bool {
        let (a, b) = (before > 0.0, after > 0.0);
        match self {
            Self::Falling => a && !b,
            Self::Rising => !a && b,
            Self::Either => a != b,
        }
    }
}

/// Finds the time of a crossing inside a step from the dense output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventLocator {
    /// Time tolerance relative to `max(|t_b|, 1)`.
    pub rel_tol: f64,
    /// Most iterations of Brent's method.
    pub max_iter: usize,
}

impl EventLocator {
    /// Locates to the resolution of the time axis (`4ε` relative):
    /// simulation events.
    pub const FINE: Self = Self {
        rel_tol: 4.0 * f64::EPSILON,
        max_iter: 200,
    };

    /// The time in `[ta, tb]` where `g` (evaluated on the dense output)
    /// changes sign, given `ga = g(ta)` and `gb = g(tb)`. Errors if the
    /// values do not bracket a root or Brent's method does not converge.
    pub fn locate<G: FnMut(f64) -> f64>(
        &self,
        g: G,
        (ta, ga): (f64, f64),
        (tb, gb): (f64, f64),
    ) -> Result<f64, RootError> {
        let xtol = self.rel_tol * tb.abs().max(1.0);
        brent(g, ta, tb, ga, gb, xtol, self.max_iter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::tests::systems::Harmonic;
    use crate::integrate::StepMethod;
    use crate::integrate::{Dop853Method, Driver, IntegratorOptions, RodasMethod};

    #[test]
    fn crossings_are_classified_by_sign() {
        assert!(Crossing::Falling.happened(1.0, 0.0));
        assert!(Crossing::Falling.happened(1.0, -1.0));
        assert!(!Crossing::Falling.happened(0.0, -1.0));
        assert!(Crossing::Rising.happened(0.0, 1.0));
        assert!(!Crossing::Rising.happened(1.0, 2.0));
        assert!(Crossing::Either.happened(-1.0, 1.0));
        assert!(Crossing::Either.happened(1.0, -1.0));
        assert!(!Crossing::Either.happened(-1.0, 0.0));
    }

    /// The zeros of cos t (the position of the oscillator from (1, 0)) are
    /// found on the dense output to the tolerance of the integration.
    fn zeros_of_cosine<M: StepMethod>(tol: f64) -> Vec<f64> {
        let opts = IntegratorOptions {
            rtol: tol,
            atol: tol,
            ..Default::default()
        };
        let mut st = Driver::<M>::new(2, opts).unwrap();
        st.reset(&mut Harmonic::plain(), 0.0, &[1.0, 0.0]).unwrap();
        let mut found = Vec::new();
        let mut g_old = 1.0;
        while st.t() < 10.0 {
            st.step(&mut Harmonic::plain(), 10.0).unwrap();
            let g_new = st.y()[0];
            if Crossing::Either.happened(g_old, g_new) {
                let (ta, tb) = (st.t_prev(), st.t());
                let t = EventLocator::FINE
                    .locate(
                        |t| st.dense_component(&mut Harmonic::plain(), 0, t),
                        (ta, g_old),
                        (tb, g_new),
                    )
                    .unwrap();
                found.push(t);
            }
            g_old = g_new;
        }
        found
    }

    #[test]
    fn locates_zeros_on_dense_output_of_both_methods() {
        use std::f64::consts::PI;
        for (zeros, err) in [
            (zeros_of_cosine::<Dop853Method>(1e-12), 1e-11),
            (zeros_of_cosine::<RodasMethod>(1e-10), 1e-7),
        ] {
            assert_eq!(zeros.len(), 3);
            for (k, t) in zeros.iter().enumerate() {
                let exact = PI * (k as f64 + 0.5);
                assert!((t - exact).abs() < err, "{t} vs {exact}");
            }
        }
    }
}
