//! Banded linear algebra for the implicit integrator: a square band matrix in
//! LAPACK band storage with an in-place LU factorisation with partial
//! pivoting (the algorithm of LAPACK's `dgbtf2` / `dgbtrs`).
//!
//! Storage: an `n × n` matrix with `kl` sub-diagonals and `ku`
//! super-diagonals is kept column by column in `n` columns of
//! `ldab = 2·kl + ku + 1` entries; entry `(i, j)` (0-based) lives at row
//! `kl + ku + i − j` of column `j`. The first `kl` rows of each column are
//! room for the fill-in of the row interchanges: after factorisation `U` has
//! `kl + ku` super-diagonals. Factorisation costs `O(n·kl·(kl + ku))`
//! operations, a solve `O(n·(2·kl + ku))`.

use std::fmt;

/// The matrix handed to [`BandMatrix::factor`] is singular: the pivot of
/// column `column` (0-based) is zero (or not finite) after elimination of the
/// previous columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Singular {
    /// First column whose pivot vanished.
    pub column: usize,
}

impl fmt::Display for Singular {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "singular matrix: zero or non-finite pivot in column {}",
            self.column
        )
    }
}

impl std::error::Error for Singular {}

/// A square band matrix with lower/upper bandwidths `(kl, ku)`, in LAPACK
/// band storage with room for the LU fill-in, and its in-place LU
/// factorisation with partial pivoting.
///
/// Life cycle: fill the matrix ([`zero`](Self::zero), [`set`](Self::set),
/// [`add`](Self::add)), call [`factor`](Self::factor) (the storage then holds
/// the LU factors, the matrix itself is lost), then [`solve`](Self::solve) as
/// often as needed. Any modification ([`zero`](Self::zero),
/// [`set`](Self::set), [`add`](Self::add), [`assign_shifted`](Self::assign_shifted))
/// marks the matrix as not factored again. No method allocates except the
/// constructors.
#[derive(Clone, Debug)]
pub struct BandMatrix {
    n: usize,
    kl: usize,
    ku: usize,
    /// Rows per stored column, `2·kl + ku + 1`.
    ldab: usize,
    /// Column-major band storage, `n · ldab` entries.
    ab: Vec<f64>,
    /// Row interchanges of the factorisation: row `j` was swapped with row
    /// `ipiv[j]` at step `j`.
    ipiv: Vec<usize>,
    /// Whether `ab` holds LU factors (set by a successful `factor`).
    factored: bool,
}

impl BandMatrix {
    /// A zero `n × n` matrix with `kl` sub- and `ku` super-diagonals.
    /// Bandwidths larger than `n − 1` are reduced to `n − 1` (the matrix is
    /// then dense in that direction). `n = 0` gives an empty matrix.
    pub fn new(n: usize, kl: usize, ku: usize) -> Self {
        let max_bw = n.saturating_sub(1);
        let (kl, ku) = (kl.min(max_bw), ku.min(max_bw));
        let ldab = 2 * kl + ku + 1;
        Self {
            n,
            kl,
            ku,
            ldab,
            ab: vec![0.0; n * ldab],
            ipiv: vec![0; n],
            factored: false,
        }
    }

    /// A zero dense `n × n` matrix (`kl = ku = n − 1`).
    pub fn dense(n: usize) -> Self {
        Self::new(n, n, n)
    }

    /// Dimension `n`.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Lower and upper bandwidths `(kl, ku)` (after the reduction described
    /// at [`new`](Self::new)).
    pub fn bandwidths(&self) -> (usize, usize) {
        (self.kl, self.ku)
    }

    /// Whether `(i, j)` lies inside the band (and the matrix).
    pub fn in_band(&self, i: usize, j: usize) -> bool {
        i < self.n && j < self.n && i <= j + self.kl && j <= i + self.ku
    }

    /// Whether the storage currently holds LU factors (after a successful
    /// [`factor`](Self::factor) and no modification since).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Storage index of `(i, j)`; valid for `j − (kl + ku) <= i <= j + kl`.
    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        j * self.ldab + self.kl + self.ku + i - j
    }

    /// Sets every entry (including the fill-in room) to zero.
    pub fn zero(&mut self) {
        self.ab.fill(0.0);
        self.factored = false;
    }

    /// Entry `(i, j)`: the stored value inside the band, `0.0` outside it.
    /// After [`factor`](Self::factor) the storage holds the LU factors, so
    /// this no longer returns entries of the original matrix.
    ///
    /// # Panics
    /// If `i` or `j` is not below `n`.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        assert!(
            i < self.n && j < self.n,
            "BandMatrix::get({i}, {j}) out of range"
        );
        if self.in_band(i, j) {
            self.ab[self.idx(i, j)]
        } else {
            0.0
        }
    }

    /// Sets entry `(i, j)` to `v`. `(i, j)` must lie inside the band
    /// (checked by a debug assertion; in release builds an entry outside the
    /// band corrupts other entries or panics).
    pub fn set(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(
            self.in_band(i, j),
            "BandMatrix::set({i}, {j}) outside the band"
        );
        let k = self.idx(i, j);
        self.ab[k] = v;
        self.factored = false;
    }

    /// Adds `v` to entry `(i, j)`, which must lie inside the band (debug
    /// assertion, as for [`set`](Self::set)).
    pub fn add(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(
            self.in_band(i, j),
            "BandMatrix::add({i}, {j}) outside the band"
        );
        let k = self.idx(i, j);
        self.ab[k] += v;
        self.factored = false;
    }

    /// `self ← scale · a + shift · I`, for `a` of the same dimension and
    /// bandwidths (the fill-in room is set to zero). This builds iteration
    /// matrices such as `I/(hγ) − J` without allocating.
    ///
    /// # Panics
    /// If the shapes differ or `a` holds LU factors.
    pub fn assign_shifted(&mut self, a: &BandMatrix, scale: f64, shift: f64) {
        assert!(
            self.n == a.n && self.kl == a.kl && self.ku == a.ku,
            "assign_shifted: shapes differ"
        );
        assert!(!a.factored, "assign_shifted: source holds LU factors");
        for (dst, src) in self
            .ab
            .chunks_exact_mut(self.ldab)
            .zip(a.ab.chunks_exact(a.ldab))
        {
            dst[..self.kl].fill(0.0);
            for (d, &s) in dst[self.kl..].iter_mut().zip(&src[self.kl..]) {
                *d = scale * s;
            }
        }
        for j in 0..self.n {
            let k = self.idx(j, j);
            self.ab[k] += shift;
        }
        self.factored = false;
    }

    /// `out = A · x`.
    ///
    /// # Panics
    /// If the lengths differ from `n` or the matrix holds LU factors.
    pub fn mul_vec(&self, x: &[f64], out: &mut [f64]) {
        self.mul_columns(x, out, 1);
    }

    /// `out = A · X` for the `k` columns of `x` (column-major, `n` rows
    /// each) into the `k` columns of `out`: every band entry is read once
    /// for all columns (the variational equations' Φ and parameter
    /// columns, one product per stage).
    ///
    /// # Panics
    /// If the lengths differ from `n · k` or the matrix holds LU factors.
    pub fn mul_columns(&self, x: &[f64], out: &mut [f64], k: usize) {
        assert!(!self.factored, "mul_columns on a factored matrix");
        let n = self.n;
        assert!(
            x.len() == n * k && out.len() == n * k,
            "mul_columns: wrong lengths"
        );
        out.fill(0.0);
        for j in 0..n {
            let lo = j.saturating_sub(self.ku);
            let hi = (j + self.kl).min(n - 1);
            let base = self.idx(lo, j);
            let band = &self.ab[base..=base + hi - lo];
            for c in 0..k {
                let xj = x[c * n + j];
                if xj == 0.0 {
                    continue;
                }
                let o = &mut out[c * n + lo..=c * n + hi];
                for (o, &a) in o.iter_mut().zip(band) {
                    *o += a * xj;
                }
            }
        }
    }

    /// In-place LU factorisation with partial pivoting, `P·A = L·U` (LAPACK
    /// `dgbtf2`). On success the storage holds `L` (unit lower, `kl`
    /// sub-diagonals, multipliers) and `U` (`kl + ku` super-diagonals) and
    /// [`solve`](Self::solve) may be called. Fails with [`Singular`] at the
    /// first zero or non-finite pivot; the storage is then partially
    /// overwritten and must be refilled before reuse.
    pub fn factor(&mut self) -> Result<(), Singular> {
        let n = self.n;
        let (kl, ku) = (self.kl, self.ku);
        let ldab = self.ldab;
        self.factored = false;
        // Clear the fill-in room (it may hold factors of an earlier use).
        for col in self.ab.chunks_exact_mut(ldab) {
            col[..kl].fill(0.0);
        }
        // Last column touched by the row interchanges so far.
        let mut ju = 0;
        for j in 0..n {
            let km = kl.min(n - 1 - j);
            // Pivot search in rows j..=j+km of column j (contiguous storage).
            let d = self.idx(j, j);
            let mut p = 0;
            let mut pmax = self.ab[d].abs();
            for r in 1..=km {
                let v = self.ab[d + r].abs();
                if v > pmax {
                    pmax = v;
                    p = r;
                }
            }
            if pmax == 0.0 || !pmax.is_finite() {
                return Err(Singular { column: j });
            }
            self.ipiv[j] = j + p;
            ju = ju.max((j + ku + p).min(n - 1));
            if p != 0 {
                for c in j..=ju {
                    let (a, b) = (self.idx(j + p, c), self.idx(j, c));
                    self.ab.swap(a, b);
                }
            }
            let inv = 1.0 / self.ab[d];
            for v in &mut self.ab[d + 1..=d + km] {
                *v *= inv;
            }
            if km == 0 {
                continue;
            }
            // Columns c > j start after the multipliers of column j, at
            // storage index (j + 1)·ldab.
            let (left, right) = self.ab.split_at_mut((j + 1) * ldab);
            let mult = &left[d + 1..=d + km];
            for c in j + 1..=ju {
                // Row r of column c sits at (c − j − 1)·ldab + kl + ku + r − c
                // in `right`; c <= ju <= j + kl + ku keeps r = j in range.
                let top = (c - j - 1) * ldab + kl + ku + j - c;
                let t = right[top];
                if t == 0.0 {
                    continue;
                }
                for (x, &m) in right[top + 1..=top + km].iter_mut().zip(mult) {
                    *x -= m * t;
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Solves `A·x = rhs` in place (`rhs` becomes `x`) with the factors of
    /// the last successful [`factor`](Self::factor) (LAPACK `dgbtrs`).
    ///
    /// # Panics
    /// If the matrix is not factored or `rhs.len() != n`.
    pub fn solve(&self, rhs: &mut [f64]) {
        assert!(self.factored, "solve: the matrix is not factored");
        assert_eq!(rhs.len(), self.n, "solve: wrong right-hand side length");
        let n = self.n;
        let kl = self.kl;
        // Forward: apply the interchanges and L column by column.
        if kl > 0 {
            for j in 0..n.saturating_sub(1) {
                let p = self.ipiv[j];
                if p != j {
                    rhs.swap(j, p);
                }
                let km = kl.min(n - 1 - j);
                let t = rhs[j];
                if t != 0.0 {
                    let d = self.idx(j, j);
                    for (x, &m) in rhs[j + 1..=j + km].iter_mut().zip(&self.ab[d + 1..=d + km]) {
                        *x -= m * t;
                    }
                }
            }
        }
        // Backward: U has kl + ku super-diagonals.
        let kv = kl + self.ku;
        for j in (0..n).rev() {
            let d = self.idx(j, j);
            rhs[j] /= self.ab[d];
            let t = rhs[j];
            if t != 0.0 {
                let lo = j.saturating_sub(kv);
                let base = self.idx(lo, j);
                for (x, &u) in rhs[lo..j].iter_mut().zip(&self.ab[base..d]) {
                    *x -= u * t;
                }
            }
        }
    }

    /// Solves `A·X = B` for several right-hand sides stored one after the
    /// other in `rhs` (`rhs.len()` a multiple of `n`), in place.
    ///
    /// # Panics
    /// As [`solve`](Self::solve), or if `rhs.len()` is not a multiple of `n`.
    pub fn solve_many(&self, rhs: &mut [f64]) {
        assert!(self.n > 0, "solve_many: empty matrix");
        assert_eq!(
            rhs.len() % self.n,
            0,
            "solve_many: length {} is not a multiple of n = {}",
            rhs.len(),
            self.n
        );
        for b in rhs.chunks_exact_mut(self.n) {
            self.solve(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// xorshift64* pseudo-random numbers in [-1, 1).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
            (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        }
    }

    /// Random band matrix (entries in [-1, 1), no diagonal dominance) and
    /// its dense copy (row-major).
    fn random_band(n: usize, kl: usize, ku: usize, rng: &mut Rng) -> (BandMatrix, Vec<f64>) {
        let mut a = BandMatrix::new(n, kl, ku);
        let mut d = vec![0.0; n * n];
        for i in 0..n {
            for j in 0..n {
                if a.in_band(i, j) {
                    let v = rng.next();
                    a.set(i, j, v);
                    d[i * n + j] = v;
                }
            }
        }
        (a, d)
    }

    /// Dense Gaussian elimination with partial pivoting (reference).
    fn dense_solve(n: usize, mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
        for k in 0..n {
            let p = (k..n)
                .max_by(|&x, &y| a[x * n + k].abs().total_cmp(&a[y * n + k].abs()))
                .unwrap();
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
            b.swap(k, p);
            for i in k + 1..n {
                let m = a[i * n + k] / a[k * n + k];
                for j in k..n {
                    a[i * n + j] -= m * a[k * n + j];
                }
                b[i] -= m * b[k];
            }
        }
        for k in (0..n).rev() {
            let s: f64 = (k + 1..n).map(|j| a[k * n + j] * b[j]).sum();
            b[k] = (b[k] - s) / a[k * n + k];
        }
        b
    }

    fn max_abs(v: &[f64]) -> f64 {
        v.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    #[test]
    fn storage_get_set_add_and_mul_vec() {
        let mut a = BandMatrix::new(5, 1, 2);
        assert_eq!(a.n(), 5);
        assert_eq!(a.bandwidths(), (1, 2));
        assert!(a.in_band(3, 2) && a.in_band(2, 4) && !a.in_band(4, 2) && !a.in_band(0, 3));
        a.set(3, 2, 1.5);
        a.add(3, 2, 0.25);
        a.set(0, 2, -2.0);
        assert_eq!(a.get(3, 2), 1.75);
        assert_eq!(a.get(0, 2), -2.0);
        assert_eq!(a.get(4, 0), 0.0, "outside the band reads as zero");
        let mut out = [0.0; 5];
        a.mul_vec(&[1.0, 2.0, 3.0, 4.0, 5.0], &mut out);
        assert_eq!(out, [-6.0, 0.0, 0.0, 5.25, 0.0]);
        a.zero();
        assert_eq!(a.get(3, 2), 0.0);
        // Oversized bandwidths are clamped; dense(n) has n-1 both ways.
        assert_eq!(BandMatrix::new(3, 7, 1).bandwidths(), (2, 1));
        assert_eq!(BandMatrix::dense(4).bandwidths(), (3, 3));
        assert_eq!(BandMatrix::dense(0).n(), 0);
    }

    /// Three columns at once equal the dense product, column by column,
    /// for every band shape (entries read once for all columns).
    #[test]
    fn mul_columns_is_the_dense_product() {
        let mut rng = Rng(7);
        for (n, kl, ku) in [(1, 0, 0), (4, 3, 3), (7, 1, 2), (9, 0, 4), (6, 5, 0)] {
            let (a, d) = random_band(n, kl, ku, &mut rng);
            let x: Vec<f64> = (0..3 * n).map(|_| rng.next()).collect();
            let mut out = vec![f64::NAN; 3 * n];
            a.mul_columns(&x, &mut out, 3);
            for c in 0..3 {
                for i in 0..n {
                    let want: f64 = (0..n).map(|j| d[i * n + j] * x[c * n + j]).sum();
                    assert!((out[c * n + i] - want).abs() <= 1e-14, "{n} {kl} {ku}");
                }
            }
        }
    }

    /// ‖A‖∞ of a row-major dense matrix.
    fn norm_inf(n: usize, a: &[f64]) -> f64 {
        a.chunks_exact(n)
            .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    #[test]
    fn random_banded_and_dense_against_reference() {
        // Random entries in [-1, 1) (no diagonal dominance: pivoting happens).
        // Backward error η = ‖A x − b‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞): measured worst
        // 8.1e-17. Difference to a dense Gaussian elimination relative to
        // κ∞(A)·ε·‖x‖∞ (κ from the computed inverse, itself a test of
        // `solve_many`): measured worst 0.073.
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let shapes = [
            (1, 0, 0),
            (7, 0, 0),
            (10, 1, 1),
            (12, 2, 1),
            (12, 0, 3),
            (15, 3, 0),
            (20, 4, 2),
            (9, 8, 8),
            (25, 24, 24),
            (30, 5, 7),
        ];
        let (mut worst_eta, mut worst_fwd) = (0.0f64, 0.0f64);
        for &(n, kl, ku) in &shapes {
            for _ in 0..5 {
                let (mut a, dense) = random_band(n, kl, ku, &mut rng);
                let b: Vec<f64> = (0..n).map(|_| rng.next()).collect();
                let orig = a.clone();
                a.factor().unwrap();
                assert!(a.is_factored());
                let mut x = b.clone();
                a.solve(&mut x);
                let mut ax = vec![0.0; n];
                orig.mul_vec(&x, &mut ax);
                let res: Vec<f64> = ax.iter().zip(&b).map(|(p, q)| p - q).collect();
                let norm_a = norm_inf(n, &dense);
                let eta = max_abs(&res) / (norm_a * max_abs(&x) + max_abs(&b));
                assert!(eta < 1e-14, "({n},{kl},{ku}): backward error {eta:e}");
                worst_eta = worst_eta.max(eta);
                // κ∞ from the inverse (columns of the identity).
                let mut inv = vec![0.0; n * n];
                for k in 0..n {
                    inv[k * n + k] = 1.0;
                }
                a.solve_many(&mut inv);
                // `inv` holds the columns of A⁻¹; ‖A⁻¹‖∞ is the largest
                // row sum, i.e. the largest sum over a fixed index.
                let norm_inv = (0..n)
                    .map(|r| (0..n).map(|c| inv[c * n + r].abs()).sum::<f64>())
                    .fold(0.0, f64::max);
                let kappa = norm_a * norm_inv;
                let xr = dense_solve(n, dense, b);
                let diff: Vec<f64> = x.iter().zip(&xr).map(|(p, q)| p - q).collect();
                let fwd = max_abs(&diff) / (kappa * f64::EPSILON * max_abs(&x));
                assert!(
                    fwd < 10.0,
                    "({n},{kl},{ku}): forward difference {fwd} κε‖x‖ (κ = {kappa:e})"
                );
                worst_fwd = worst_fwd.max(fwd);
            }
        }
        assert!(worst_eta > 0.0 && worst_fwd > 0.0, "the checks ran");
    }

    #[test]
    fn pivoting_is_needed_and_done() {
        // Zero diagonal: without row interchanges the first pivot is 0.
        //   [0 1 0 0]
        //   [1 0 2 0]
        //   [0 3 0 1]
        //   [0 0 1 1]      (kl = ku = 1)
        let mut a = BandMatrix::new(4, 1, 1);
        for &(i, j, v) in &[
            (0, 1, 1.0),
            (1, 0, 1.0),
            (1, 2, 2.0),
            (2, 1, 3.0),
            (2, 3, 1.0),
            (3, 2, 1.0),
            (3, 3, 1.0),
        ] {
            a.set(i, j, v);
        }
        let orig = a.clone();
        let x_true = [1.0, -2.0, 0.5, 3.0];
        let mut b = [0.0; 4];
        orig.mul_vec(&x_true, &mut b);
        a.factor().unwrap();
        let mut x = b;
        a.solve(&mut x);
        for (p, q) in x.iter().zip(&x_true) {
            assert!((p - q).abs() < 1e-15, "{x:?}");
        }
        // Tiny pivot: partial pivoting keeps the solve accurate.
        let mut t = BandMatrix::dense(2);
        t.set(0, 0, 1e-20);
        t.set(0, 1, 1.0);
        t.set(1, 0, 1.0);
        t.set(1, 1, 1.0);
        t.factor().unwrap();
        let mut y = [1.0, 2.0];
        t.solve(&mut y);
        assert!(
            (y[0] - 1.0).abs() < 1e-15 && (y[1] - 1.0).abs() < 1e-15,
            "{y:?}"
        );
    }

    #[test]
    fn several_right_hand_sides() {
        let mut rng = Rng(42);
        let (mut a, _) = random_band(8, 2, 3, &mut rng);
        let orig = a.clone();
        let b: Vec<f64> = (0..24).map(|_| rng.next()).collect();
        a.factor().unwrap();
        let mut x = b.clone();
        a.solve_many(&mut x);
        for (xc, bc) in x.chunks_exact(8).zip(b.chunks_exact(8)) {
            let mut single = bc.to_vec();
            a.solve(&mut single);
            assert_eq!(single, xc);
            let mut ax = [0.0; 8];
            orig.mul_vec(xc, &mut ax);
            for (p, q) in ax.iter().zip(bc) {
                assert!((p - q).abs() < 1e-13);
            }
        }
    }

    #[test]
    fn singular_matrices_are_detected() {
        // Dense rank-1 matrix: the second pivot is exactly 4 - 2·2 = 0.
        let mut a = BandMatrix::dense(2);
        a.set(0, 0, 1.0);
        a.set(0, 1, 2.0);
        a.set(1, 0, 2.0);
        a.set(1, 1, 4.0);
        assert_eq!(a.factor(), Err(Singular { column: 1 }));
        assert!(!a.is_factored());
        // Banded with a zero column.
        let mut b = BandMatrix::new(5, 1, 1);
        for i in 0..5 {
            if i != 2 {
                b.set(i, i, 1.0);
            }
        }
        b.set(1, 0, 0.5);
        let e = b.factor().unwrap_err();
        assert_eq!(e.column, 2);
        assert!(e.to_string().contains("column 2"));
        // Non-finite entries are reported as singular too.
        let mut c = BandMatrix::new(3, 1, 1);
        c.set(0, 0, f64::NAN);
        c.set(1, 1, 1.0);
        c.set(2, 2, 1.0);
        assert_eq!(c.factor(), Err(Singular { column: 0 }));
        // Refilled after a failure, the matrix factors again.
        c.zero();
        for i in 0..3 {
            c.set(i, i, 2.0);
        }
        c.factor().unwrap();
        let mut r = [2.0, 4.0, 6.0];
        c.solve(&mut r);
        assert_eq!(r, [1.0, 2.0, 3.0]);
    }

    #[test]
    fn assign_shifted_builds_iteration_matrix() {
        let mut rng = Rng(7);
        let (j, _) = random_band(6, 1, 2, &mut rng);
        let mut e = BandMatrix::new(6, 1, 2);
        e.assign_shifted(&j, -1.0, 10.0);
        for r in 0..6 {
            for c in 0..6 {
                let expect = -j.get(r, c) + if r == c { 10.0 } else { 0.0 };
                assert_eq!(e.get(r, c), expect);
            }
        }
        // Reuse after a factorisation: the fill-in room is cleared again.
        e.factor().unwrap();
        e.assign_shifted(&j, 2.0, 0.0);
        assert!(!e.is_factored());
        for r in 0..6 {
            for c in 0..6 {
                assert_eq!(e.get(r, c), 2.0 * j.get(r, c));
            }
        }
    }
}
