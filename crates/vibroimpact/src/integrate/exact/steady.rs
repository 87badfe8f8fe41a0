//! The steady state of a harmonic under the form's matrix: the complex
//! amplitude X of `(iΩ − A) X = c − i s`, solved on the stack for a
//! chain's small blocks.

use nalgebra::{Complex, DMatrix, DVector};

use super::Harmonic;

/// A harmonic's steady state `(Ω, Re X, Im X)`: `Re X cos Ωt − Im X sin Ωt`.
pub(super) type Steady = (f64, Vec<f64>, Vec<f64>);

/// The complex amplitude X of `(iΩ − A) X = c − i s`: `(Ω, Re X, Im X)`,
/// None where the matrix is singular to working accuracy.
pub(super) fn steady_state(a: &DMatrix<f64>, norm: f64, h: &Harmonic) -> Option<Steady> {
    let d = a.nrows();
    let w = h.omega;
    if h.cos.iter().chain(&h.sin).all(|&x| x == 0.0) {
        return Some((w, vec![0.0; d], vec![0.0; d]));
    }
    let m = |i: usize, j: usize| Complex::new(-a[(i, j)], if i == j { w } else { 0.0 });
    let b: Vec<Complex<f64>> = (0..d).map(|i| Complex::new(h.cos[i], -h.sin[i])).collect();
    let x = if d <= SMALL {
        // (A chain's d ≤ 8: on the stack, no allocation; a map solves
        // these at every evaluation.)
        let mut lu = [Complex::new(0.0, 0.0); SMALL * SMALL];
        for (ij, e) in lu[..d * d].iter_mut().enumerate() {
            *e = m(ij / d, ij % d);
        }
        let mut x = [Complex::new(0.0, 0.0); SMALL];
        x[..d].copy_from_slice(&b);
        solve_small(&mut lu[..d * d], &mut x[..d])?;
        x[..d].to_vec()
    } else {
        let x = DMatrix::from_fn(d, d, m)
            .lu()
            .solve(&DVector::from_column_slice(&b))?;
        x.as_slice().to_vec()
    };
    // A singular pivot may still solve, to a response far beyond any
    // physical one: the residual and the size tell.
    let bmax = b.iter().fold(0.0f64, |s, z| s.max(z.norm()));
    let xmax = x.iter().fold(0.0f64, |s, z| s.max(z.norm()));
    let residual = (0..d)
        .map(|i| (0..d).map(|j| m(i, j) * x[j]).sum::<Complex<f64>>() - b[i])
        .fold(0.0f64, |s, z| s.max(z.norm()));
    let ok = x.iter().all(|z| z.re.is_finite() && z.im.is_finite())
        && xmax * (norm + w) * 1e-12 <= bmax
        && residual <= 1e-10 * bmax;
    ok.then(|| {
        (
            w,
            x.iter().map(|z| z.re).collect(),
            x.iter().map(|z| z.im).collect(),
        )
    })
}

/// Largest d whose steady states are solved on the stack.
const SMALL: usize = 8;

/// Solves `M x = b` in place (`m` d × d by rows, overwritten by its
/// factors; `x` holds b) by Gaussian elimination with partial pivoting,
/// as LAPACK's `gesv`; None at a zero pivot.
fn solve_small(m: &mut [Complex<f64>], x: &mut [Complex<f64>]) -> Option<()> {
    let d = x.len();
    for k in 0..d {
        let p = (k..d).max_by(|&i, &j| m[i * d + k].norm().total_cmp(&m[j * d + k].norm()))?;
        if m[p * d + k].norm() == 0.0 {
            return None;
        }
        if p != k {
            for j in 0..d {
                m.swap(k * d + j, p * d + j);
            }
            x.swap(k, p);
        }
        let pivot = m[k * d + k];
        for i in k + 1..d {
            let f = m[i * d + k] / pivot;
            for j in k + 1..d {
                let u = m[k * d + j];
                m[i * d + j] -= f * u;
            }
            let xk = x[k];
            x[i] -= f * xk;
        }
    }
    for k in (0..d).rev() {
        let s: Complex<f64> = (k + 1..d).map(|j| m[k * d + j] * x[j]).sum();
        x[k] = (x[k] - s) / m[k * d + k];
    }
    Some(())
}
