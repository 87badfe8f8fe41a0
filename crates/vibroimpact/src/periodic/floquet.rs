//! Floquet multipliers: the eigenvalues of the monodromy matrix (or of
//! the half map's Jacobian, squared), largest modulus first
//! (docs/theory.md §5).

use nalgebra::{Complex, DMatrix};

use super::PeriodicError;

/// Floquet multipliers from the Jacobian of the shooting map: its
/// eigenvalues, squared for the symmetric half map (largest modulus first).
pub fn map_multipliers(
    jacobian: &DMatrix<f64>,
    symmetric: bool,
) -> Result<Vec<Complex<f64>>, PeriodicError> {
    Ok(multipliers_of_map(
        floquet_multipliers(jacobian)?,
        symmetric,
    ))
}

/// The Floquet multipliers from the eigenvalues of the shooting map's
/// Jacobian: squared for the half map (Φ = DG²), largest modulus first.
pub(crate) fn multipliers_of_map(
    mut eigenvalues: Vec<Complex<f64>>,
    symmetric: bool,
) -> Vec<Complex<f64>> {
    if symmetric {
        eigenvalues.iter_mut().for_each(|m| *m = *m * *m);
        eigenvalues.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    }
    eigenvalues
}

/// Floquet multipliers (eigenvalues of the monodromy), largest modulus first.
///
/// The Francis (Schur) iteration is bounded: nalgebra's unbounded version
/// cycles forever on some spectra, e.g. the half map of a linear symmetric
/// row, whose eigenvalues come in ± pairs of equal modulus. Without
/// convergence the spectrum is shifted by a fraction of the matrix's size
/// (M + cI has eigenvalues λ + c, a pattern the iteration does not stall
/// on) and shifted back, which costs at most ~ε|c| in accuracy. Each
/// shift is first tried with 10 iterations per eigenvalue (a converging
/// iteration needs 2–3), then all again with 200: a stall would otherwise
/// burn the large budget before the shift (R2 N = 8 on the half map: 40 %
/// of the spectra stall unshifted, 3 ms each with 200 per eigenvalue,
/// against 20 µs for the shifted solve).
pub fn floquet_multipliers(monodromy: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, PeriodicError> {
    let d = monodromy.nrows();
    let size = monodromy.amax().max(f64::MIN_POSITIVE);
    let attempts = [10, 200]
        .into_iter()
        .flat_map(|per| [0.0, 0.3, -0.55].map(|shift| (shift, per * d.max(10))));
    for (shift, budget) in attempts {
        let c = shift * size;
        let m = monodromy + DMatrix::<f64>::identity(d, d) * c;
        if let Some(schur) = nalgebra::linalg::Schur::try_new(m, f64::EPSILON, budget) {
            let mut mu: Vec<Complex<f64>> =
                schur.complex_eigenvalues().iter().map(|l| l - c).collect();
            mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
            return Ok(mu);
        }
    }
    // nalgebra's iteration stalls on some spectra of clustered ± pairs:
    // the EISPACK algorithm (crate::linalg::eigen) instead.
    let mut mu =
        crate::linalg::eigen::eigenvalues(monodromy).ok_or(PeriodicError::Eigenvalues(d))?;
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    Ok(mu)
}
