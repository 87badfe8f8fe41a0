//! Eigenvalues of a small real matrix by the Francis double-shift QR
//! iteration on its Hessenberg form (the EISPACK `hqr` algorithm, with
//! exceptional shifts every 10 iterations). A fallback for nalgebra's
//! Schur iteration, which stalls on some spectra of clustered ± pairs
//! (docs/decisions.md D16: an Arnoldi matrix of the R2 half map with
//! eigenvalues near ±0.92 failed with every shift and 10⁶ iterations).

use nalgebra::{Complex, DMatrix};

/// Iterations per eigenvalue before giving up.
const MAX_ITERATIONS: usize = 60;

/// The eigenvalues of the square matrix `m`, in no particular order; None
/// if the iteration does not converge or the matrix is not finite.
pub fn eigenvalues(m: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    let n = m.nrows();
    if n == 0 || !m.iter().all(|v| v.is_finite()) {
        return (n == 0).then(Vec::new);
    }
    let mut a = m.clone().hessenberg().h();
    for j in 0..n {
        for i in j + 2..n {
            a[(i, j)] = 0.0;
        }
    }
    let anorm: f64 = a.iter().map(|v| v.abs()).sum();
    let mut out = vec![Complex::new(0.0, 0.0); n];
    let mut t = 0.0;
    let mut nn = n as isize - 1;
    while nn >= 0 {
        let mut its = 0;
        loop {
            let u = nn as usize;
            // A negligible subdiagonal element splits the matrix.
            let mut l = u;
            while l >= 1 {
                let mut s = a[(l - 1, l - 1)].abs() + a[(l, l)].abs();
                if s == 0.0 {
                    s = anorm;
                }
                if a[(l, l - 1)].abs() + s == s {
                    a[(l, l - 1)] = 0.0;
                    break;
                }
                l -= 1;
            }
            let mut x = a[(u, u)];
            if l == u {
                out[u] = Complex::new(x + t, 0.0);
                nn -= 1;
                break;
            }
            let mut y = a[(u - 1, u - 1)];
            let mut w = a[(u, u - 1)] * a[(u - 1, u)];
            if l == u - 1 {
                let p = 0.5 * (y - x);
                let q = p * p + w;
                let z = q.abs().sqrt();
                x += t;
                if q >= 0.0 {
                    let z = p + z.copysign(p);
                    out[u - 1] = Complex::new(x + z, 0.0);
                    out[u] = Complex::new(if z != 0.0 { x - w / z } else { x + z }, 0.0);
                } else {
                    out[u - 1] = Complex::new(x + p, -z);
                    out[u] = Complex::new(x + p, z);
                }
                nn -= 2;
                break;
            }
            if its == MAX_ITERATIONS {
                return None;
            }
            if its > 0 && its % 10 == 0 {
                // Exceptional shift.
                t += x;
                for i in 0..=u {
                    a[(i, i)] -= x;
                }
                let s = a[(u, u - 1)].abs() + a[(u - 1, u - 2)].abs();
                x = 0.75 * s;
                y = x;
                w = -0.4375 * s * s;
            }
            its += 1;
            francis_step(&mut a, l, u, x, y, w);
        }
    }
    Some(out)
}

/// One double-shift QR step on the active block `l..=u` of the Hessenberg
/// matrix `a`, with the shifts from `x`, `y`, `w` (the trailing 2 × 2
/// block's trace and determinant data).
fn francis_step(a: &mut DMatrix<f64>, l: usize, u: usize, x: f64, y: f64, w: f64) {
    // Two consecutive small subdiagonal elements: start the bulge there.
    let mut m = u - 2;
    let (mut p, mut q, mut r);
    loop {
        let z = a[(m, m)];
        let rr = x - z;
        let ss = y - z;
        p = (rr * ss - w) / a[(m + 1, m)] + a[(m, m + 1)];
        q = a[(m + 1, m + 1)] - z - rr - ss;
        r = a[(m + 2, m + 1)];
        let s = p.abs() + q.abs() + r.abs();
        p /= s;
        q /= s;
        r /= s;
        if m == l {
            break;
        }
        let u1 = a[(m, m - 1)].abs() * (q.abs() + r.abs());
        let v1 = p.abs() * (a[(m - 1, m - 1)].abs() + z.abs() + a[(m + 1, m + 1)].abs());
        if u1 + v1 == v1 {
            break;
        }
        m -= 1;
    }
    for i in m + 2..=u {
        a[(i, i - 2)] = 0.0;
        if i != m + 2 {
            a[(i, i - 3)] = 0.0;
        }
    }
    let mut xk = 0.0;
    for k in m..u {
        if k != m {
            p = a[(k, k - 1)];
            q = a[(k + 1, k - 1)];
            r = if k != u - 1 { a[(k + 2, k - 1)] } else { 0.0 };
            xk = p.abs() + q.abs() + r.abs();
            if xk != 0.0 {
                p /= xk;
                q /= xk;
                r /= xk;
            }
        }
        let s = (p * p + q * q + r * r).sqrt().copysign(p);
        if s == 0.0 {
            continue;
        }
        if k == m {
            if l != m {
                a[(k, k - 1)] = -a[(k, k - 1)];
            }
        } else {
            a[(k, k - 1)] = -s * xk;
        }
        p += s;
        let (x1, y1, z1) = (p / s, q / s, r / s);
        q /= p;
        r /= p;
        for j in k..=u {
            let mut pp = a[(k, j)] + q * a[(k + 1, j)];
            if k != u - 1 {
                pp += r * a[(k + 2, j)];
                a[(k + 2, j)] -= pp * z1;
            }
            a[(k + 1, j)] -= pp * y1;
            a[(k, j)] -= pp * x1;
        }
        let last = u.min(k + 3);
        for i in l..=last {
            let mut pp = x1 * a[(i, k)] + y1 * a[(i, k + 1)];
            if k != u - 1 {
                pp += z1 * a[(i, k + 2)];
                a[(i, k + 2)] -= pp * r;
            }
            a[(i, k + 1)] -= pp * q;
            a[(i, k)] -= pp;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(mut v: Vec<Complex<f64>>) -> Vec<Complex<f64>> {
        v.sort_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)));
        v
    }

    /// Against nalgebra where its Schur iteration converges: a random-ish
    /// 7 × 7 matrix with complex and real eigenvalues, to 1e-12.
    #[test]
    fn agrees_with_schur() {
        let m = DMatrix::<f64>::from_fn(7, 7, |i, j| {
            ((i * 13 + j * 7 + 3) % 17) as f64 / 17.0 - 0.4
                + if i == j { 0.3 * i as f64 } else { 0.0 }
        });
        let ours = sorted(eigenvalues(&m).unwrap());
        let schur = nalgebra::linalg::Schur::try_new(m, f64::EPSILON, 10_000).unwrap();
        let theirs = sorted(schur.complex_eigenvalues().iter().copied().collect());
        for (a, b) in ours.iter().zip(&theirs) {
            assert!((a - b).norm() < 1e-12, "{a} vs {b}");
        }
        assert!(ours.iter().any(|l| l.im != 0.0));
    }

    /// The Arnoldi matrix of the R2 N = 2 half map on which nalgebra's
    /// Schur iteration stalls (every shift, 10⁶ iterations): eigenvalues
    /// close to ±0.92 in pairs; checked by the trace and the determinant.
    #[test]
    fn clustered_pairs() {
        let v = [
            -0.9202127493954368,
            0.056288597722496905,
            0.0,
            0.0,
            0.05627537037923787,
            0.9199977675686353,
            0.019921980646447363,
            0.0,
            0.001221297840488602,
            0.01984667396765267,
            -0.9192092964720073,
            0.05714524882631609,
            -7.53066787935212e-5,
            -0.001221297840490513,
            0.05713202148305614,
            0.9194242782988065,
        ];
        let m = DMatrix::from_column_slice(4, 4, &v);
        let l = eigenvalues(&m).unwrap();
        let trace: Complex<f64> = l.iter().sum();
        let det: Complex<f64> = l.iter().product();
        assert!((trace.re - m.trace()).abs() < 1e-13 && trace.im.abs() < 1e-13);
        assert!(
            (det.re - m.determinant()).abs() < 1e-13,
            "{det} vs {}",
            m.determinant()
        );
        assert_eq!(
            l.iter().filter(|x| (x.norm() - 0.92).abs() < 0.01).count(),
            4
        );
    }
}
