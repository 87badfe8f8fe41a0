//! Scalar numerics shared by the physics modules: cancellation-free special
//! functions and safeguarded root finders that report non-convergence.

/// Error of a scalar root finder.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RootError {
    /// The function values at the bracket ends do not have opposite signs.
    #[error("root not bracketed: f({lo}) = {f_lo}, f({hi}) = {f_hi}")]
    NotBracketed {
        /// Lower end of the bracket.
        lo: f64,
        /// Upper end of the bracket.
        hi: f64,
        /// Function value at `lo`.
        f_lo: f64,
        /// Function value at `hi`.
        f_hi: f64,
    },
    /// The function returned a non-finite value.
    #[error("function is not finite at x = {x}")]
    NonFinite {
        /// Where the function was evaluated.
        x: f64,
    },
    /// The iteration limit was reached before the tolerance.
    #[error("no convergence after {iterations} iterations (bracket [{lo}, {hi}])")]
    NoConvergence {
        /// Iterations performed.
        iterations: usize,
        /// Final bracket, lower end.
        lo: f64,
        /// Final bracket, upper end.
        hi: f64,
    },
}

/// The larger of two values, a NaN in `b` passed over as by `f64::max`:
/// a plain comparison, which costs less than the NaN-aware form on the
/// exact run's hot paths.
#[inline(always)]
pub(crate) fn larger(a: f64, b: f64) -> f64 {
    if b > a {
        b
    } else {
        a
    }
}

/// `(-1)^j / (j + 2)!` for j = 0..=18: the Taylor coefficients of
/// `(e^{-p} - 1 + p) / p²`.
const EXP_SERIES: [f64; 19] = {
    let mut c = [0.0; 19];
    let mut fact = 2.0; // (j + 2)!
    let mut j = 0;
    while j < 19 {
        c[j] = if j % 2 == 0 { 1.0 / fact } else { -1.0 / fact };
        fact *= (j + 3) as f64;
        j += 1;
    }
    c
};

/// `1 / (2k + 3)` for k = 0..=10: the coefficients of `atanh(s)/s` beyond
/// its first term, in powers of `s²`.
const ATANH_SERIES: [f64; 11] = {
    let mut c = [0.0; 11];
    let mut k = 0;
    while k < 11 {
        c[k] = 1.0 / (2 * k + 3) as f64;
        k += 1;
    }
    c
};

/// Horner's scheme for `Σ c_j x^j`.
#[inline]
fn horner(c: &[f64], x: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, &cj| acc * x + cj)
}

/// `e^{-p} - 1 + p`, accurate to a few ulps for every `p >= 0`.
///
/// For small `p` the direct formula cancels (the value is ~p²/2); for
/// `|p| < 1` the Taylor series `p² Σ_{j≥0} (-p)^j / (j + 2)!` is summed by
/// Horner's scheme to the degree (at most 18) at which the next term is
/// below 1e-18 of the value.
pub fn exp_neg_minus_one_plus(p: f64) -> f64 {
    let a = p.abs();
    if a < 1.0 {
        // Terms needed for the first omitted one, 2|p|^j/(j + 2)!, to stay
        // below 1e-18: 5 for |p| < 1e-3, 9 below 0.05, 13 below 0.3.
        let terms = if a < 1e-3 {
            5
        } else if a < 0.05 {
            9
        } else if a < 0.3 {
            13
        } else {
            EXP_SERIES.len()
        };
        p * p * horner(&EXP_SERIES[..terms], p)
    } else {
        (-p).exp_m1() + p
    }
}

/// `u - ln(1 + u)` for `u > -1`, accurate to a few ulps (the direct formula
/// cancels for small `u`, where the value is ~u²/2).
///
/// For `|u| < 0.25`, with `s = u/(2 + u)` (so `ln(1 + u) = 2 atanh(s)` and
/// `u - 2s = u s`): `u - ln(1 + u) = u s - 2 s³ Σ_{k≥0} s^{2k}/(2k + 3)`; the
/// two terms differ by a factor of about 6/u, so nothing cancels, and
/// `s² < 0.021` makes eleven terms enough for full precision.
pub fn x_minus_log1p(u: f64) -> f64 {
    if u.abs() < 0.25 {
        let s = u / (2.0 + u);
        let s2 = s * s;
        u * s - 2.0 * s * s2 * horner(&ATANH_SERIES, s2)
    } else {
        u - u.ln_1p()
    }
}

/// `ln(u - ln(1 + u))` for `u > 0`, finite down to the least subnormal:
/// below 1e-100, where `u - ln(1 + u) ≈ u²/2` underflows (a maximum
/// penetration of -inf at U = 5e-324 m/s), `2 ln u - ln 2 + ln(1 - 2u/3)`
/// (the next term, `u²/2`, is below 1e-200).
pub fn ln_x_minus_log1p(u: f64) -> f64 {
    if u < 1e-100 {
        2.0 * u.ln() - std::f64::consts::LN_2 + (-2.0 * u / 3.0).ln_1p()
    } else {
        x_minus_log1p(u).ln()
    }
}

/// Newton's method safeguarded by bisection on a bracket `[lo, hi]` with
/// `f(lo)` and `f(hi)` of opposite signs. `f_df` returns `(f(x), f'(x))`.
///
/// Converges when the step is below `xtol * max(|x|, tiny)` or `f(x) == 0`.
/// Reports non-convergence after `max_iter` iterations instead of returning a
/// poor value.
pub fn newton_bracketed<F>(
    f_df: F,
    lo: f64,
    hi: f64,
    xtol: f64,
    max_iter: usize,
) -> Result<f64, RootError>
where
    F: FnMut(f64) -> (f64, f64),
{
    safeguarded_newton(f_df, lo, hi, 0.5 * (lo + hi), xtol, max_iter)
}

/// [`newton_bracketed`] starting from the guess `x0` instead of the
/// bracket's midpoint. From a good guess plain Newton steps are tried first:
/// while they stay strictly inside the bracket and converge (within 8
/// steps), their limit is returned without evaluating `f` at the bracket's
/// ends (for a function with one root in the bracket, the one the
/// safeguarded iteration finds, by the same steps). Otherwise the
/// safeguarded iteration runs from `x0` (clamped into the bracket).
pub fn newton_bracketed_from<F>(
    mut f_df: F,
    lo: f64,
    hi: f64,
    x0: f64,
    xtol: f64,
    max_iter: usize,
) -> Result<f64, RootError>
where
    F: FnMut(f64) -> (f64, f64),
{
    let inside = |x: f64| x > lo.min(hi) && x < lo.max(hi);
    let mut x = x0;
    for _ in 0..8 {
        if !inside(x) {
            break;
        }
        let (fx, dfx) = f_df(x);
        if !(fx.is_finite() && dfx.is_finite()) || dfx == 0.0 {
            break;
        }
        if fx == 0.0 {
            return Ok(x);
        }
        let next = x - fx / dfx;
        if !inside(next) {
            break;
        }
        if (next - x).abs() <= xtol * next.abs().max(f64::MIN_POSITIVE) {
            return Ok(next);
        }
        x = next;
    }
    safeguarded_newton(f_df, lo, hi, x0, xtol, max_iter)
}

/// The safeguarded iteration of [`newton_bracketed`] from `x0`.
fn safeguarded_newton<F>(
    mut f_df: F,
    mut lo: f64,
    mut hi: f64,
    x0: f64,
    xtol: f64,
    max_iter: usize,
) -> Result<f64, RootError>
where
    F: FnMut(f64) -> (f64, f64),
{
    let (f_lo, _) = f_df(lo);
    let (f_hi, _) = f_df(hi);
    if !f_lo.is_finite() {
        return Err(RootError::NonFinite { x: lo });
    }
    if !f_hi.is_finite() {
        return Err(RootError::NonFinite { x: hi });
    }
    if f_lo == 0.0 {
        return Ok(lo);
    }
    if f_hi == 0.0 {
        return Ok(hi);
    }
    if f_lo.signum() == f_hi.signum() {
        return Err(RootError::NotBracketed { lo, hi, f_lo, f_hi });
    }
    let lo_negative = f_lo < 0.0;
    let mut x = if x0 > lo.min(hi) && x0 < lo.max(hi) {
        x0
    } else {
        0.5 * (lo + hi)
    };
    for _ in 0..max_iter {
        let (fx, dfx) = f_df(x);
        if !fx.is_finite() {
            return Err(RootError::NonFinite { x });
        }
        if fx == 0.0 {
            return Ok(x);
        }
        if (fx < 0.0) == lo_negative {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - fx / dfx;
        let next = if dfx.is_finite() && dfx != 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        let step = (next - x).abs();
        x = next;
        if step <= xtol * x.abs().max(f64::MIN_POSITIVE) || lo == hi {
            return Ok(x);
        }
    }
    Err(RootError::NoConvergence {
        iterations: max_iter,
        lo,
        hi,
    })
}

/// Golden-section search for the maximum of `f` on `[a, b]` (exact for a
/// unimodal `f`, a local maximum otherwise), to a bracket of 8 ulps or 60
/// iterations: where the maximum's place matters, a corner's (a
/// pushover's cap), which [`maximum`] finds only to √ε. Returns `(f(t*),
/// t*)`.
pub fn golden_max<F>(mut f: F, a: f64, b: f64) -> (f64, f64)
where
    F: FnMut(f64) -> f64,
{
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut a, mut b) = (a, b);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..60 {
        if fc > fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
        if b - a <= 8.0 * f64::EPSILON * b.abs().max(1.0) {
            break;
        }
    }
    let t = 0.5 * (a + b);
    (f(t), t)
}

/// The maximum of `f` on `[a, b]` by Brent's search (parabolas through
/// the three best points, golden sections where a parabola would not
/// shrink the bracket): exact for a unimodal `f`, a local maximum
/// otherwise. Stops where the bracket is within 2·tol of the best point,
/// tol = √ε (b − a) + 4ε|t|: near a maximum `f` changes by the square of
/// the distance, so its value there is the maximum's to rounding (a
/// golden-section search to 8 ulps of t took 60 evaluations where this
/// takes about 12). Returns `(f(t*), t*)`, the best point evaluated.
pub fn maximum<F>(mut f: F, a: f64, b: f64) -> (f64, f64)
where
    F: FnMut(f64) -> f64,
{
    // (Brent 1973, ch. 5, on −f.)
    const C: f64 = 0.381_966_011_250_105_1;
    let (mut a, mut b) = (a.min(b), a.max(b));
    let width = f64::EPSILON.sqrt() * (b - a);
    let mut x = a + C * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = -f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        let tol = width + 4.0 * f64::EPSILON * x.abs();
        if (x - m).abs() <= 2.0 * tol - 0.5 * (b - a) {
            break;
        }
        let mut parabola = false;
        if e.abs() > tol {
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            } else {
                q = -q;
            }
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < 2.0 * tol || b - u < 2.0 * tol {
                    d = if x < m { tol } else { -tol };
                }
                parabola = true;
            }
        }
        if !parabola {
            e = if x < m { b - x } else { a - x };
            d = C * e;
        }
        let u = if d.abs() >= tol {
            x + d
        } else {
            x + tol.copysign(d)
        };
        let fu = -f(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (-fx, x)
}

/// Brent's method (inverse quadratic interpolation, secant and bisection) for
/// a root of `f` in `[a, b]` given `fa = f(a)` and `fb = f(b)` of opposite
/// signs. Stops when the bracket is below `xtol` (absolute).
pub fn brent<F>(
    mut f: F,
    mut a: f64,
    mut b: f64,
    mut fa: f64,
    mut fb: f64,
    xtol: f64,
    max_iter: usize,
) -> Result<f64, RootError>
where
    F: FnMut(f64) -> f64,
{
    if fa == 0.0 {
        return Ok(a);
    }
    if fb == 0.0 {
        return Ok(b);
    }
    if fa.signum() == fb.signum() || !fa.is_finite() || !fb.is_finite() {
        return Err(RootError::NotBracketed {
            lo: a,
            hi: b,
            f_lo: fa,
            f_hi: fb,
        });
    }
    let mut c = a;
    let mut fc = fa;
    let mut d = b - a;
    let mut e = d;
    for _ in 0..max_iter {
        if fb.signum() == fc.signum() {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol = 2.0 * f64::EPSILON * b.abs() + 0.5 * xtol;
        let m = 0.5 * (c - b);
        if m.abs() <= tol || fb == 0.0 {
            return Ok(b);
        }
        if e.abs() >= tol && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * m * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * m * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * m * q - (tol * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = m;
                e = m;
            }
        } else {
            d = m;
            e = m;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol { d } else { tol.copysign(m) };
        fb = f(b);
        if !fb.is_finite() {
            return Err(RootError::NonFinite { x: b });
        }
    }
    Err(RootError::NoConvergence {
        iterations: max_iter,
        lo: b.min(c),
        hi: b.max(c),
    })
}

/// Uniform numbers in [0, 1) from a seed, the same on every machine (a
/// 64-bit linear congruential generator, its top 53 bits): the tests'
/// random cases.
#[cfg(test)]
pub(crate) fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The maximum of smooth peaks is their value to rounding in about a
    /// dozen evaluations, on any scale of t (a peak 1e-4 s wide at t =
    /// 1000 s, as an impact's force late in a run); a monotone function's
    /// search ends within a part in 1e7 of the bracket's upper end.
    #[test]
    fn a_maximum_is_found_to_rounding_in_few_evaluations() {
        for (t0, w) in [(0.0, 1.0), (1000.0, 1e-4), (-3.0, 2.0)] {
            for at in [0.3, 0.5, 0.93] {
                let top = t0 + at * w;
                // (An asymmetric peak: exponential sides, as a contact's force.)
                let f = |t: f64| {
                    let z = (t - top) / w;
                    7.0 * (-(z * z) * (1.0 + 0.8 * z)).exp()
                };
                let mut n = 0;
                let (v, t) = maximum(
                    |t| {
                        n += 1;
                        f(t)
                    },
                    t0,
                    t0 + w,
                );
                assert!(
                    (v - 7.0).abs() <= 4.0 * f64::EPSILON * 7.0,
                    "{t0} {at}: {v}"
                );
                assert!((t - top).abs() <= 1e-7 * w, "{t0} {at}: at {t}");
                assert!(n <= 25, "{t0} {at}: {n} evaluations");
            }
        }
        let (v, t) = maximum(|t: f64| t.ln(), 1.0, 2.0);
        assert!(
            2.0 - t <= 1e-7 && (v - 2f64.ln()).abs() <= 1e-7,
            "{v} at {t}"
        );
    }

    #[test]
    fn exp_neg_minus_one_plus_matches_series_and_direct() {
        // Small p: leading terms p²/2 - p³/6 + p⁴/24.
        let p = 1e-4_f64;
        let series = p * p / 2.0 - p.powi(3) / 6.0 + p.powi(4) / 24.0 - p.powi(5) / 120.0;
        assert!((exp_neg_minus_one_plus(p) - series).abs() <= 1e-15 * series);
        // Either side of the switch agrees with the direct formula (no cancellation there).
        for p in [0.999_999_f64, 1.0, 3.0] {
            let direct = (-p).exp() - 1.0 + p;
            assert!((exp_neg_minus_one_plus(p) - direct).abs() <= 4e-16 * direct);
        }
    }

    #[test]
    fn ln_x_minus_log1p_is_finite_to_the_least_subnormal() {
        // Across the switch at 1e-100 the two forms agree, and at the
        // least subnormal the value is 2 ln u - ln 2.
        let (below, above) = (ln_x_minus_log1p(0.999e-100), ln_x_minus_log1p(1.001e-100));
        let step = 2.0 * (1.001f64 / 0.999).ln();
        assert!((above - below - step).abs() < 1e-12, "{below} {above}");
        let u = 5e-324;
        let exact = 2.0 * f64::ln(u) - std::f64::consts::LN_2;
        assert_eq!(ln_x_minus_log1p(u), exact);
        assert_eq!(ln_x_minus_log1p(0.3), x_minus_log1p(0.3).ln());
    }

    #[test]
    fn x_minus_log1p_small_and_large() {
        let u = -1e-5_f64;
        let series = u * u / 2.0 - u.powi(3) / 3.0 + u.powi(4) / 4.0;
        assert!((x_minus_log1p(u) - series).abs() <= 1e-15 * series);
        for u in [0.2499_f64, 0.25, 0.9, -0.5] {
            let direct = u - (1.0 + u).ln();
            assert!((x_minus_log1p(u) - direct).abs() <= 1e-14 * direct);
        }
    }

    /// The Horner forms against the plain term-by-term series, summed to
    /// 1e-20 of the value (an independent evaluation): a few ulps over the
    /// whole range where the series are used.
    #[test]
    fn horner_forms_match_term_by_term_series() {
        let series = |first: f64, next: &dyn Fn(f64, f64) -> f64| {
            let (mut term, mut sum, mut k) = (first, 0.0_f64, 2.0_f64);
            while term.abs() > 1e-20 * sum.abs() || sum == 0.0 {
                sum += term;
                term = next(term, k);
                k += 1.0;
            }
            sum
        };
        let mut worst: f64 = 0.0;
        for i in 1..2000 {
            let u = -0.2499 + 0.4998 * i as f64 / 2000.0;
            if u == 0.0 {
                continue;
            }
            // Σ_{k≥2} (-1)^k u^k / k: term_k = -term_{k-1} u (k-1)/k.
            let want = series(u * u / 2.0, &|t, k| -t * u * k / (k + 1.0));
            worst = worst.max((x_minus_log1p(u) - want).abs() / want);
            let p = i as f64 / 2000.0;
            let want = series(p * p / 2.0, &|t, k| -t * p / (k + 1.0));
            worst = worst.max((exp_neg_minus_one_plus(p) - want).abs() / want);
        }
        assert!(
            worst <= 4.0 * f64::EPSILON,
            "worst relative difference {worst:e}"
        );
    }

    #[test]
    fn newton_and_brent_find_cube_root_of_two() {
        let exact = 2f64.cbrt();
        let x = newton_bracketed(|x| (x * x * x - 2.0, 3.0 * x * x), 0.0, 2.0, 1e-15, 100).unwrap();
        assert!((x - exact).abs() < 1e-15);
        let y = brent(|x| x * x * x - 2.0, 0.0, 2.0, -2.0, 6.0, 1e-15, 100).unwrap();
        assert!((y - exact).abs() < 1e-14);
    }

    #[test]
    fn root_finders_report_failures() {
        assert!(matches!(
            newton_bracketed(|x| (x * x + 1.0, 2.0 * x), -1.0, 1.0, 1e-12, 50),
            Err(RootError::NotBracketed { .. })
        ));
        assert!(matches!(
            newton_bracketed(|x| (x - 0.3, 1.0), 0.0, 1.0, 1e-300, 1),
            Err(RootError::NoConvergence { .. })
        ));
    }
}
