//! Matrix-free linear algebra of Newton–Krylov shooting and continuation:
//! GMRES and the Arnoldi matrix of products with a Jacobian.

use nalgebra::{DMatrix, DVector};

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// GMRES output: the solution, the Krylov basis and the Hessenberg matrix.
pub(crate) type KrylovSolve = (Vec<f64>, Vec<Vec<f64>>, DMatrix<f64>);

/// GMRES (Saad–Schultz, no restart, at most `m` iterations) for `A δ = b`
/// with the matrix-free product `apply(v) = A v`; returns δ and the Arnoldi
/// data (the Krylov basis and the Hessenberg matrix of A). It stops at a
/// relative residual `rel_tol`, or at a breakdown: a new vector below
/// `noise` times its product, i.e. the product lies in the span of the
/// basis to the accuracy of the (integrated) product.
pub(crate) fn gmres<E, A: FnMut(&[f64]) -> Result<Vec<f64>, E>>(
    apply: &mut A,
    b: &[f64],
    m: usize,
    rel_tol: f64,
    noise: f64,
) -> Result<KrylovSolve, E> {
    let d = b.len();
    let beta = dot(b, b).sqrt();
    let mut basis: Vec<Vec<f64>> =
        vec![b.iter().map(|x| x / beta.max(f64::MIN_POSITIVE)).collect()];
    let mut h = DMatrix::<f64>::zeros(m + 1, m);
    let mut k_used = 0;
    for k in 0..m {
        let mut w = apply(&basis[k])?;
        let applied = dot(&w, &w).sqrt();
        // Modified Gram–Schmidt, repeated once ("twice is enough"): after
        // heavy cancellation (|w| ~ 1e-5 |A v_k| near a breakdown) one
        // pass can leave w visibly non-orthogonal to the basis.
        for _ in 0..2 {
            for (j, q) in basis.iter().enumerate() {
                let hij = dot(&w, q);
                h[(j, k)] += hij;
                w.iter_mut().zip(q).for_each(|(a, b)| *a -= hij * b);
            }
        }
        let norm = dot(&w, &w).sqrt();
        h[(k + 1, k)] = norm;
        k_used = k + 1;
        let res = least_squares(&h, k_used, beta).1;
        // Breakdown: A v_k lies in the span of the basis to the accuracy
        // of the product (an invariant subspace, e.g. of identical
        // uncoupled bodies); a further vector would be integration noise
        // and give spurious Ritz values (N = 200 linear: a multiplier 4.6
        // on a stable orbit), so the basis stops here.
        if norm <= noise * applied || res <= rel_tol * beta {
            basis.push(w.iter().map(|x| x / norm.max(f64::MIN_POSITIVE)).collect());
            break;
        }
        basis.push(w.iter().map(|x| x / norm).collect());
    }
    let (y, _) = least_squares(&h, k_used, beta);
    let mut delta = vec![0.0; d];
    for (j, yj) in y.iter().enumerate() {
        delta
            .iter_mut()
            .zip(&basis[j])
            .for_each(|(a, q)| *a += yj * q);
    }
    let hk = h.view((0, 0), (k_used + 1, k_used)).clone_owned();
    Ok((delta, basis, hk))
}

/// The Arnoldi matrix of the map's Jacobian: `H_k + I` from `m` Arnoldi
/// vectors (fewer at a breakdown) of `A = DG − I` (`apply`, scaled
/// variables, dimension d) from a generic start vector; its eigenvalues
/// are the Ritz values of DG, the dominant ones first to converge.
pub(crate) fn arnoldi_matrix<E, A: FnMut(&[f64]) -> Result<Vec<f64>, E>>(
    apply: &mut A,
    d: usize,
    m: usize,
    noise: f64,
) -> Result<DMatrix<f64>, E> {
    let start: Vec<f64> = (0..d)
        .map(|i| 1.0 + 0.1 * ((i * 7919) % 97) as f64 / 97.0)
        .collect();
    let (_, basis, h) = gmres(apply, &start, m.min(d).max(1), 0.0, noise)?;
    let k = h.ncols().min(basis.len() - 1);
    Ok(h.view((0, 0), (k, k)).clone_owned() + DMatrix::<f64>::identity(k, k))
}

/// The least-squares solution y of `H_k y ≈ β e_1` (the first k columns of
/// the Hessenberg matrix) and its residual.
fn least_squares(h: &DMatrix<f64>, k: usize, beta: f64) -> (DVector<f64>, f64) {
    let hk = h.view((0, 0), (k + 1, k)).clone_owned();
    let mut e1 = DVector::zeros(k + 1);
    e1[0] = beta;
    let y = hk
        .clone()
        .svd(true, true)
        .solve(&e1, 1e-14)
        .unwrap_or_else(|_| DVector::zeros(k));
    let res = (&hk * &y - &e1).norm();
    (y, res)
}
