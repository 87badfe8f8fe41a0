//! Smooth functions of one variable tabulated once to near double precision:
//! piecewise Chebyshev series on equal pieces (docs/theory.md §12, the
//! rigid limit's restitution of the damped power laws).
//!
//! Each piece carries the series of degree [`DEGREE`] through the function's
//! values at its Chebyshev–Lobatto points, and the series of its
//! derivative; a value and its slope cost one Clenshaw sum each.

/// Degree of each piece's series (its nodes: `DEGREE + 1`, the two ends
/// shared with the neighbours).
pub const DEGREE: usize = 16;

/// `C` functions of one variable on `[lo, hi]`, tabulated.
#[derive(Clone, Debug, PartialEq)]
pub struct Table<const C: usize> {
    lo: f64,
    width: f64,
    /// Per piece, per function: the coefficients of the value and of its
    /// derivative in the piece's variable t ∈ [−1, 1].
    pieces: Vec<[(Vec<f64>, Vec<f64>); C]>,
}

impl<const C: usize> Table<C> {
    /// Tabulates `f` on `[lo, hi]` in `pieces` equal pieces (`f` is called
    /// `pieces · DEGREE + 1` times, at ascending points).
    pub fn new<E>(
        (lo, hi): (f64, f64),
        pieces: usize,
        mut f: impl FnMut(f64) -> Result<[f64; C], E>,
    ) -> Result<Self, E> {
        let width = (hi - lo) / pieces as f64;
        let mut out = Vec::with_capacity(pieces);
        // The value at the piece's upper end, shared with the next piece.
        let mut shared: Option<[f64; C]> = None;
        for p in 0..pieces {
            let centre = lo + (p as f64 + 0.5) * width;
            // Nodes t_j = cos(π j / N), j = N … 0: ascending in x.
            let mut values = [[0.0; C]; DEGREE + 1];
            for j in (0..=DEGREE).rev() {
                values[j] = match (j, shared) {
                    (j, Some(v)) if j == DEGREE => v,
                    _ => {
                        let t = (std::f64::consts::PI * j as f64 / DEGREE as f64).cos();
                        f(centre + 0.5 * width * t)?
                    }
                };
            }
            shared = Some(values[0]);
            out.push(std::array::from_fn(|c| {
                let v: Vec<f64> = values.iter().map(|x| x[c]).collect();
                let coefficients = chebyshev(&v);
                let slope = derivative(&coefficients, 0.5 * width);
                (coefficients, slope)
            }));
        }
        Ok(Self {
            lo,
            width,
            pieces: out,
        })
    }

    /// The table's interval.
    pub fn range(&self) -> (f64, f64) {
        (self.lo, self.lo + self.width * self.pieces.len() as f64)
    }

    /// Whether `x` lies in the table.
    pub fn contains(&self, x: f64) -> bool {
        let (lo, hi) = self.range();
        (lo..=hi).contains(&x)
    }

    /// Function `c`'s value and derivative at `x`, which the caller keeps
    /// within the table ([`Table::contains`]; outside, the nearest end's).
    pub fn at(&self, c: usize, x: f64) -> (f64, f64) {
        let (p, t) = self.piece(x);
        let (value, slope) = &self.pieces[p][c];
        (clenshaw(value, t), clenshaw(slope, t))
    }

    /// Function `c`'s value at `x` alone, as [`Table::at`] has it.
    pub fn value(&self, c: usize, x: f64) -> f64 {
        let (p, t) = self.piece(x);
        clenshaw(&self.pieces[p][c].0, t)
    }

    /// The piece `x` lies in (the nearest end's outside) and `x` on it,
    /// in [-1, 1].
    fn piece(&self, x: f64) -> (usize, f64) {
        let (lo, hi) = self.range();
        let x = x.clamp(lo, hi);
        let p = (((x - lo) / self.width) as usize).min(self.pieces.len() - 1);
        (
            p,
            2.0 * (x - lo - (p as f64 + 0.5) * self.width) / self.width,
        )
    }
}

/// Chebyshev coefficients `c_k` of the interpolant through `v_j = f(cos(π j
/// / N))`: `f(t) = Σ c_k T_k(t)`.
fn chebyshev(v: &[f64]) -> Vec<f64> {
    let n = v.len() - 1;
    (0..=n)
        .map(|k| {
            let sum: f64 = (0..=n)
                .map(|j| {
                    let w = if j == 0 || j == n { 0.5 } else { 1.0 };
                    w * v[j] * (std::f64::consts::PI * (j * k) as f64 / n as f64).cos()
                })
                .sum();
            let ck = 2.0 * sum / n as f64;
            if k == 0 || k == n {
                0.5 * ck
            } else {
                ck
            }
        })
        .collect()
}

/// Coefficients of d/dx of `Σ c_k T_k(t)` with `x = centre + half t`.
fn derivative(c: &[f64], half: f64) -> Vec<f64> {
    let n = c.len() - 1;
    let mut d = vec![0.0; n + 1];
    for k in (1..=n).rev() {
        let next = if k < n { d[k + 1] } else { 0.0 };
        d[k - 1] = next + 2.0 * k as f64 * c[k];
    }
    d[0] *= 0.5;
    d.iter_mut().for_each(|x| *x /= half);
    d
}

/// `Σ c_k T_k(t)` by Clenshaw's recurrence.
fn clenshaw(c: &[f64], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ck in c.iter().skip(1).rev() {
        (b1, b2) = (2.0 * t * b1 - b2 + ck, b1);
    }
    t * b1 - b2 + c[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth function and its derivative to near double precision, and
    /// the nodes shared by neighbouring pieces (each value asked once).
    #[test]
    fn tabulates_a_smooth_function_and_its_slope() {
        let mut calls = Vec::new();
        let table = Table::<2>::new((-3.0, 4.0), 5, |x| {
            calls.push(x);
            Ok::<_, ()>([(3.0 * x).sin(), (0.5 * x).exp()])
        })
        .unwrap();
        assert_eq!(calls.len(), 5 * DEGREE + 1);
        assert!(calls.windows(2).all(|w| w[0] < w[1]));
        let mut worst: f64 = 0.0;
        for i in 0..=700 {
            let x = -3.0 + 7.0 * i as f64 / 700.0;
            let (f, df) = table.at(0, x);
            worst = worst.max((f - (3.0 * x).sin()).abs());
            worst = worst.max((df - 3.0 * (3.0 * x).cos()).abs() / 100.0);
            let (g, dg) = table.at(1, x);
            assert_eq!(table.value(1, x).to_bits(), g.to_bits());
            let exact = (0.5 * x).exp();
            worst = worst.max((g / exact - 1.0).abs());
            worst = worst.max((dg / (0.5 * exact) - 1.0).abs() / 100.0);
        }
        assert!(worst < 1e-13, "worst {worst:e}");
        assert!(!table.contains(-3.0 - 1e-9) && !table.contains(4.0 + 1e-9));
        assert!(table.contains(-3.0) && table.contains(4.0));
    }
}
