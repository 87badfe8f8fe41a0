//! Matrix-free continuation for long rows (docs/theory.md §5): the bordered
//! systems of the corrector and the tangent solved by GMRES on products
//! `Ĵ_x v` (replayed on the steps of the point's integration), and the
//! dominant Floquet multipliers by Arnoldi, so that nothing of size d² is
//! ever formed: memory O(d · (Krylov dimension + recorded stages)).

use crate::model::family::Family;
use nalgebra::Complex;

use super::problem::{unit_along, Linear, Problem};
use crate::linalg::{arnoldi_matrix, gmres};
use crate::periodic::{floquet_multipliers, MapTangent};

/// Largest GMRES basis of a bordered solve.
const MAX_GMRES: usize = 400;

/// The extended system's matrix-free operators at one point: what the
/// products need and nothing of the model family, so that the tangent and
/// the multipliers of a point can be computed at the same time on two
/// threads.
pub(super) struct Operators<'a> {
    tangent: &'a MapTangent,
    /// Ĝ_p, scaled.
    g_p: &'a [f64],
    /// The residual's scale (and, times `unit`, the unknowns').
    scale: &'a [f64],
    unit: f64,
    /// Relative accuracy of a product (GMRES and Arnoldi breakdowns).
    noise: f64,
}

impl Operators<'_> {
    /// `Ĵ_x v` in scaled variables: `(DG v - v)` with DG acting on
    /// unscaled vectors (the unknowns' scale on `v`, the residual's on the
    /// product).
    fn jacobian_product(&self, v: &[f64]) -> Vec<f64> {
        self.tangent.shifted_scaled(v, self.scale, self.unit)
    }

    /// Solves the bordered system `[Ĵ_x Ĝ_p; tᵀ] u = rhs` ((d+1)-vectors,
    /// scaled) by GMRES to the relative residual `rel_tol`.
    pub(super) fn bordered_solve(&self, t: &[f64], rhs: &[f64], rel_tol: f64) -> Option<Vec<f64>> {
        let d = self.g_p.len();
        let mut apply = |u: &[f64]| -> Result<Vec<f64>, ()> {
            let mut out = self.jacobian_product(&u[..d]);
            out.iter_mut()
                .zip(self.g_p)
                .for_each(|(o, g)| *o += g * u[d]);
            out.push(t.iter().zip(u).map(|(a, b)| a * b).sum());
            Ok(out)
        };
        let (u, _, _) = gmres(&mut apply, rhs, (d + 1).min(MAX_GMRES), rel_tol, self.noise).ok()?;
        u.iter().all(|v| v.is_finite()).then_some(u)
    }

    /// The unit tangent, oriented along `previous`: `[Ĵ_x Ĝ_p; previousᵀ]
    /// t = e_{d+1}` to 1e-8.
    pub(super) fn tangent(&self, previous: &[f64]) -> Option<Vec<f64>> {
        let mut e = vec![0.0; self.g_p.len() + 1];
        e[self.g_p.len()] = 1.0;
        Some(unit_along(
            self.bordered_solve(previous, &e, 1e-8)?,
            previous,
        ))
    }

    /// The dominant eigenvalues of the shooting map's Jacobian (Φ, or DG of
    /// the half map): Ritz values of an Arnoldi iteration of `m` vectors
    /// from a generic start, largest modulus first. The operator is
    /// `S⁻¹ Φ S − I` with `S` the residual's scales, similar to `Φ − I`:
    /// not `Ĵ_x`, whose unknowns carry the factor `unit` as well and whose
    /// eigenvalues are `unit (λ − 1)` (a row of 64 bodies reported a
    /// multiplier 97 for a stable orbit's 0.85 with it).
    pub(super) fn dominant_map_eigenvalues(&self, m: usize) -> Option<Vec<Complex<f64>>> {
        let d = self.g_p.len();
        let mut apply = |v: &[f64]| -> Result<Vec<f64>, ()> {
            Ok(self.tangent.shifted_scaled(v, self.scale, 1.0))
        };
        let ritz = arnoldi_matrix(&mut apply, d, m, self.noise).ok()?;
        floquet_multipliers(&ritz).ok()
    }
}

impl<F: Family> Problem<F> {
    /// The matrix-free operators at the point of `linear` (None for a dense
    /// linearisation).
    pub(super) fn operators<'a>(&'a self, linear: &'a Linear) -> Option<Operators<'a>> {
        let Linear::Krylov { tangent, g_p } = linear else {
            return None;
        };
        Some(Operators {
            tangent,
            g_p,
            scale: &self.scale,
            unit: self.state_unit,
            noise: 1e3 * self.opts.shooting.rtol,
        })
    }
}
