//! The linear algebra the library writes itself, in one place: the band
//! LU of the implicit integrator ([`band`]), GMRES and the Arnoldi matrix
//! of matrix-free shooting and continuation (`krylov`), the EISPACK
//! eigenvalue iteration where nalgebra's Schur iteration stalls
//! ([`eigen`]) and the null vector of branch switching. Dense
//! factorisations, SVD and Schur come from nalgebra (docs/decisions.md
//! says why each of these is written here).
//!
//! Files: `band.rs`, `krylov.rs`, `eigen.rs`, and the null vector in
//! `mod.rs`.

pub mod band;
pub mod eigen;
pub(crate) mod krylov;

use nalgebra::DMatrix;

pub use band::{BandMatrix, Singular};
pub(crate) use krylov::{arnoldi_matrix, gmres};

/// Unit right null vector of a square matrix: the right singular vector of
/// its smallest singular value (None if the SVD fails).
pub fn null_vector(m: DMatrix<f64>) -> Option<Vec<f64>> {
    let d = m.ncols();
    let svd = m.svd(false, true);
    let v_t = svd.v_t?;
    let imin = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    Some((0..d).map(|j| v_t[(imin, j)]).collect())
}
