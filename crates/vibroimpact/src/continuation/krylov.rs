//! Matrix-free continuation for long rows (docs/theory.md §5): the bordered
//! systems of the corrector and the tangent solved by GMRES on products
//! `Ĵ_x v` (replayed on the steps of the point's integration), and the
//! dominant Floquet multipliers by Arnoldi, so that nothing of size d² is
//! ever formed: memory O(d · (Krylov dimension + recorded stages)).

use nalgebra::Complex;

use super::problem::{Linear, Problem};
use crate::model::Model;
use crate::periodic::{arnoldi_matrix, floquet_multipliers, gmres, MapTangent};

/// Largest GMRES basis of a bordered solve.
const MAX_GMRES: usize = 400;

impl<F: FnMut(f64) -> Result<Model, String>> Problem<F> {
    /// `Ĵ_x v` in scaled variables at the point of `linear`: `(DG v - v)`
    /// with DG acting on unscaled vectors (the unknowns' scale on `v`, the
    /// residual's on the product).
    fn jacobian_product(&self, tangent: &MapTangent, v: &[f64]) -> Vec<f64> {
        let unit = self.state_unit;
        let unscaled: Vec<f64> = v
            .iter()
            .zip(&self.scale)
            .map(|(a, s)| a * s * unit)
            .collect();
        let product = tangent.product(&unscaled);
        (0..v.len())
            .map(|i| product[i] / self.scale[i] - unit * v[i])
            .collect()
    }

    /// Solves the bordered system `[Ĵ_x Ĝ_p; tᵀ] u = rhs` ((d+1)-vectors,
    /// scaled) by GMRES to the relative residual `rel_tol`, matrix-free.
    pub(super) fn bordered_solve(
        &mut self,
        linear: &Linear,
        t: &[f64],
        rhs: &[f64],
        rel_tol: f64,
    ) -> Option<Vec<f64>> {
        let Linear::Krylov { tangent, g_p } = linear else {
            return None;
        };
        let d = self.d;
        let mut apply = |u: &[f64]| -> Result<Vec<f64>, ()> {
            let mut out = self.jacobian_product(tangent, &u[..d]);
            out.iter_mut().zip(g_p).for_each(|(o, g)| *o += g * u[d]);
            out.push(t.iter().zip(u).map(|(a, b)| a * b).sum());
            Ok(out)
        };
        let noise = 1e3 * self.opts.shooting.rtol;
        let (u, _, _) = gmres(&mut apply, rhs, (d + 1).min(MAX_GMRES), rel_tol, noise).ok()?;
        u.iter().all(|v| v.is_finite()).then_some(u)
    }

    /// The dominant eigenvalues of the shooting map's Jacobian (Φ, or DG of
    /// the half map) at the point of `linear`: Ritz values of an Arnoldi
    /// iteration of `opts.krylov` vectors from a generic start, largest
    /// modulus first.
    pub(super) fn dominant_map_eigenvalues(
        &mut self,
        linear: &Linear,
    ) -> Option<Vec<Complex<f64>>> {
        let Linear::Krylov { tangent, .. } = linear else {
            return None;
        };
        let d = self.d;
        let m = self.opts.krylov?;
        let mut apply =
            |v: &[f64]| -> Result<Vec<f64>, ()> { Ok(self.jacobian_product(tangent, v)) };
        let noise = 1e3 * self.opts.shooting.rtol;
        let ritz = arnoldi_matrix(&mut apply, d, m, noise).ok()?;
        floquet_multipliers(&ritz).ok()
    }
}
