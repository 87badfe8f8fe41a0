//! The exponential's series on a step's deviation, and the steady
//! state's own series folded into it: a step's motion as one power
//! series in the time from its start (docs/theory.md §12), summed in four
//! Horner chains.

use super::{times, Linear, MAX_TERMS};

/// The series terms `A^k v / k!` of the deviation `v` (whole blocks) into
/// `terms` (term k at `[k·n..k·n + v.len()]`), as many as reach 1e-17 of
/// the largest entry of `v` over a step `h`: how many, or None where
/// `MAX_TERMS` do not.
pub(super) fn series_terms(
    form: &Linear,
    (v, n): (&[f64], usize),
    h: f64,
    terms: &mut [f64],
) -> Option<usize> {
    let (m, d) = (v.len(), form.d);
    let (first, rest) = terms.split_at_mut(n);
    let first = &mut first[..m];
    first.copy_from_slice(v);
    // (Entries measured balanced, `S v`.)
    let balanced = |x: &[f64]| {
        x.chunks_exact(d).fold(0.0f64, |m, b| {
            b.iter()
                .zip(&form.scale)
                .fold(m, |m, (x, s)| m.max((x * s).abs()))
        })
    };
    let size = balanced(first);
    let mut count = 1;
    let mut previous: &[f64] = first;
    let mut scale = 1.0;
    for (k, term) in rest.chunks_exact_mut(n).enumerate() {
        let term = &mut term[..m];
        let inv = 1.0 / (k + 1) as f64;
        for (p, t) in previous.chunks_exact(d).zip(term.chunks_exact_mut(d)) {
            times(&form.rows, p, t);
            t.iter_mut().for_each(|x| *x *= inv);
        }
        count += 1;
        scale *= h;
        let largest = balanced(term) * scale;
        if largest <= 1e-17 * size {
            return Some(count);
        }
        previous = term;
    }
    None
}

/// `out = Σ_k τ^k terms_k` over the first `count` terms of `n`
/// components each, for the first `out.len()` components: four Horner
/// chains in τ⁴ (the terms k ≡ r mod 4), joined by Horner in τ. The
/// chains are independent, so a dense output does not wait on one
/// dependent chain of a product and a sum a term (Estrin's idea); the
/// small blocks' sizes unrolled. [`series_at`] is one component of it,
/// the same operations.
pub(super) fn sum_series(terms: &[f64], (n, count): (usize, usize), tau: f64, out: &mut [f64]) {
    match out.len() {
        2 => sum_series_of::<2>(terms, (n, count), tau, out),
        4 => sum_series_of::<4>(terms, (n, count), tau, out),
        6 => sum_series_of::<6>(terms, (n, count), tau, out),
        8 => sum_series_of::<8>(terms, (n, count), tau, out),
        _ => {
            for (i, o) in out.iter_mut().enumerate() {
                *o = series_at(terms, (n, count), tau, i);
            }
        }
    }
}

/// [`sum_series`] of M components.
fn sum_series_of<const M: usize>(
    terms: &[f64],
    (n, count): (usize, usize),
    tau: f64,
    out: &mut [f64],
) {
    let t4 = (tau * tau) * (tau * tau);
    let mut c = [[0.0f64; M]; 4];
    for k in (0..count).rev() {
        let chain = &mut c[k % 4];
        for (x, t) in chain.iter_mut().zip(&terms[k * n..k * n + M]) {
            *x = *x * t4 + t;
        }
    }
    for (i, o) in out[..M].iter_mut().enumerate() {
        *o = ((c[3][i] * tau + c[2][i]) * tau + c[1][i]) * tau + c[0][i];
    }
}

/// Component i of [`sum_series`].
pub(super) fn series_at(terms: &[f64], (n, count): (usize, usize), tau: f64, i: usize) -> f64 {
    let t4 = (tau * tau) * (tau * tau);
    let mut c = [0.0f64; 4];
    for k in (0..count).rev() {
        c[k % 4] = c[k % 4] * t4 + terms[k * n + i];
    }
    ((c[3] * tau + c[2]) * tau + c[1]) * tau + c[0]
}

/// Folds the steady states' own series about the step's start `t0` into
/// the deviation's `terms` (`count` of them, the first `m` components of
/// `n` each, whole blocks): `Re(X e^{iΩ(t0+τ)}) = Σ_k τ^k Re(X e^{iΩt0}
/// (iΩ)^k) / k!`, so that the sum is the motion itself and a dense output
/// takes no sine. The count grows to what the steady terms need over a
/// step `h` (each harmonic's `|X| (Ω h)^k / k!` below 1e-17 of the
/// deviation's or the steady state's size, balanced; the deviation's
/// terms beyond its own count are below that: zero). The new count, or
/// None and nothing changed where more than `MAX_TERMS` would be needed
/// (a forcing far faster than the step).
pub(super) fn fold_steady(
    form: &Linear,
    (t0, h): (f64, f64),
    (n, m): (usize, usize),
    terms: &mut [f64],
    count: usize,
) -> Option<usize> {
    let d = form.d;
    let blocks = &form.steady[..m / d];
    let amplitude = |xr: &[f64], xi: &[f64]| {
        (xr.iter().zip(xi).zip(&form.scale))
            .fold(0.0f64, |a, ((r, i), s)| a.max((r.abs() + i.abs()) * s))
    };
    let mut size = (terms[..m].chunks_exact(d)).fold(0.0f64, |a, b| {
        b.iter()
            .zip(&form.scale)
            .fold(a, |a, (x, s)| a.max((x * s).abs()))
    });
    for (_, xr, xi) in blocks.iter().flatten() {
        size = size.max(amplitude(xr, xi));
    }
    let mut need = count;
    for (w, xr, xi) in blocks.iter().flatten() {
        let mut bound = amplitude(xr, xi);
        let mut k = 0;
        while bound > 1e-17 * size {
            k += 1;
            if k > MAX_TERMS {
                return None;
            }
            bound *= w * h / k as f64;
        }
        need = need.max(k + 1);
    }
    for term in terms[count * n..need * n].chunks_exact_mut(n) {
        term[..m].fill(0.0);
    }
    for (b, block) in blocks.iter().enumerate() {
        for (w, xr, xi) in block {
            let (s, c) = (w * t0).sin_cos();
            for (i, (r, im)) in xr.iter().zip(xi).enumerate() {
                // Re and Im of X e^{iΩt0} (iΩ)^k / k!, k = 0, 1, …
                let (mut re, mut imag) = (r * c - im * s, r * s + im * c);
                for k in 0..need {
                    terms[k * n + b * d + i] += re;
                    let f = w / (k + 1) as f64;
                    (re, imag) = (-imag * f, re * f);
                }
            }
        }
    }
    Some(need)
}
