//! Tests of the exact flow: a forced oscillator against its closed form,
//! a forced pair against DOP853 (and a leading part of either's dense
//! output against the whole), the dense output between quarters, a step
//! ended at an event inside it, a leading block alone, a resonance
//! refused, a stepper that takes the exact flow where the form holds,
//! the series summed in four chains against Horner, and the steady state
//! folded into it.

use super::*;
use crate::integrate::{IntegratorOptions, Method, Stepper};
use nalgebra::Complex;

/// Bodies on springs to the ground (ω², 2ζω per body), the first two
/// joined by a spring `k12` (per unit mass), under `F cos Ω t + G sin Ω t`
/// on the first and a constant `P` on the last.
struct Forced {
    w2: Vec<f64>,
    c: Vec<f64>,
    k12: f64,
    omega: f64,
    f: f64,
    g: f64,
    p: f64,
}

/// The lightly damped oscillator of the closed-form tests: (ω, ζ, F, Ω).
const OSCILLATOR: (f64, f64, f64, f64) = (7.4, 0.02, 3.0, 6.1);

impl Forced {
    /// One body: [`OSCILLATOR`] under F cos Ω t.
    fn oscillator() -> Self {
        Self::lone(OSCILLATOR)
    }

    /// One body of (ω, ζ) under F cos Ω t.
    fn lone((w, zeta, f, omega): (f64, f64, f64, f64)) -> Self {
        Self {
            w2: vec![w * w],
            c: vec![2.0 * zeta * w],
            k12: 0.0,
            omega,
            f,
            g: 0.0,
            p: 0.0,
        }
    }

    fn matrix(&self) -> DMatrix<f64> {
        let n = self.w2.len();
        let mut a = DMatrix::zeros(2 * n, 2 * n);
        for i in 0..n {
            a[(2 * i, 2 * i + 1)] = 1.0;
            a[(2 * i + 1, 2 * i)] = -self.w2[i];
            a[(2 * i + 1, 2 * i + 1)] = -self.c[i];
        }
        if n > 1 {
            for (i, j) in [(0, 1), (1, 0)] {
                a[(2 * i + 1, 2 * i)] -= self.k12;
                a[(2 * i + 1, 2 * j)] += self.k12;
            }
        }
        a
    }
}

impl OdeSystem for Forced {
    fn dim(&self) -> usize {
        2 * self.w2.len()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let a = self.matrix();
        let n = self.w2.len();
        for i in 0..2 * n {
            dydt[i] = (0..2 * n).map(|j| a[(i, j)] * y[j]).sum();
        }
        dydt[1] += self.f * (self.omega * t).cos() + self.g * (self.omega * t).sin();
        dydt[2 * n - 1] += self.p;
    }

    fn linear_form(&self) -> Option<LinearForm> {
        let n = self.w2.len();
        let mut wave = Harmonic {
            omega: self.omega,
            cos: vec![0.0; 2 * n],
            sin: vec![0.0; 2 * n],
        };
        wave.cos[1] = self.f;
        wave.sin[1] = self.g;
        let mut steady = Harmonic {
            omega: 0.0,
            cos: vec![0.0; 2 * n],
            sin: vec![0.0; 2 * n],
        };
        steady.cos[2 * n - 1] = self.p;
        Some(LinearForm {
            a: self.matrix(),
            blocks: vec![vec![wave, steady]],
        })
    }
}

fn options(rtol: f64, h_max: f64) -> IntegratorOptions {
    IntegratorOptions {
        rtol,
        atol: rtol * 1e-3,
        h_max,
        ..IntegratorOptions::default()
    }
}

/// `(t, y)` at the end of `t_end` by `method`, and the stepper there.
fn run(sys: &mut Forced, y0: &[f64], t_end: f64, method: Method, rtol: f64) -> Stepper {
    let h = sys.linear_form().unwrap().solve().unwrap().step_limit();
    let mut st = Stepper::new(method, y0.len(), options(rtol, h)).unwrap();
    st.reset(sys, 0.0, y0).unwrap();
    while st.t() < t_end {
        st.step(sys, t_end).unwrap();
    }
    st
}

/// x'' + 2ζω x' + ω² x = F cos Ω t from (x0, v0): the closed form.
fn oscillator(
    t: f64,
    (w, zeta, f, omega): (f64, f64, f64, f64),
    (x0, v0): (f64, f64),
) -> (f64, f64) {
    let x = Complex::new(f, 0.0) / Complex::new(w * w - omega * omega, 2.0 * zeta * w * omega);
    let steady = |t: f64| {
        let e = Complex::new(0.0, omega * t).exp();
        ((x * e).re, (x * Complex::new(0.0, omega) * e).re)
    };
    let (p0, q0) = steady(0.0);
    let wd = w * (1.0 - zeta * zeta).sqrt();
    let a = x0 - p0;
    let b = (v0 - q0 + zeta * w * a) / wd;
    let decay = (-zeta * w * t).exp();
    let (s, c) = (wd * t).sin_cos();
    let xh = decay * (a * c + b * s);
    let vh = decay * (-zeta * w * (a * c + b * s) + wd * (-a * s + b * c));
    let (p, q) = steady(t);
    (p + xh, q + vh)
}

/// `y` is the closed form's `(x, v)` to 1e-12 of an amplitude of 0.1 (and
/// ω times it for the velocity).
fn assert_on(y: &[f64], (x, v): (f64, f64), w: f64) {
    let scale = 0.1;
    assert!((y[0] - x).abs() < 1e-12 * scale, "{} vs {x}", y[0]);
    assert!((y[1] - v).abs() < 1e-12 * scale * w, "{} vs {v}", y[1]);
}

/// A lightly damped oscillator under F cos Ω t, 40 periods: the state at
/// the end and the dense output inside the last step (at a quarter and
/// between quarters) equal the closed form to 1e-12 of the amplitude.
#[test]
fn a_forced_oscillator_moves_as_its_closed_form() {
    let (w, zeta, f, omega) = OSCILLATOR;
    let mut sys = Forced::oscillator();
    let y0 = [0.01, -0.2];
    let t_end = 40.0 * 2.0 * std::f64::consts::PI / omega;
    let mut st = run(&mut sys, &y0, t_end, Method::Exact, 1e-6);
    assert_eq!(st.active(), Method::Exact);
    let exact = oscillator(t_end, (w, zeta, f, omega), (y0[0], y0[1]));
    assert_on(st.y(), exact, w);
    let scale = 0.1;
    let (t0, h) = (st.t_prev(), st.h_last());
    let mut out = [0.0; 2];
    for s in [0.25, 0.5, 0.37, 0.913] {
        let t = t0 + s * h;
        st.dense_output(&mut sys, t, &mut out);
        let (x, v) = oscillator(t, (w, zeta, f, omega), (y0[0], y0[1]));
        assert!(
            (out[0] - x).abs() < 1e-12 * scale,
            "s {s}: {} vs {x}",
            out[0]
        );
        assert!(
            (out[1] - v).abs() < 1e-12 * scale * w,
            "s {s}: {} vs {v}",
            out[1]
        );
        let one = st.dense_component(&mut sys, 0, t);
        assert!(
            (one - out[0]).abs() < 1e-15 * scale,
            "s {s}: {one} vs {}",
            out[0]
        );
    }
}

/// A step ended at an event inside it (`end_step_at`, 0.37 of the last
/// step of 40 periods): the point is the closed form's there to 1e-12 of
/// the amplitude, its derivative the system's own, the dense output of
/// the first part (a former quarter included) the closed form's, and the
/// next step goes on exactly from there; DOP853 refuses (its dense output
/// interpolates), and so does a time outside the step.
#[test]
fn a_step_ends_where_an_event_lies_inside_it() {
    let (w, zeta, f, omega) = OSCILLATOR;
    let forced = (w, zeta, f, omega);
    let mut sys = Forced::oscillator();
    let y0 = [0.01, -0.2];
    let t_end = 40.0 * 2.0 * std::f64::consts::PI / omega;
    let mut st = run(&mut sys, &y0, t_end, Method::Exact, 1e-6);
    let (t0, h) = (st.t_prev(), st.h_last());
    assert!(!st.end_step_at(&mut sys, t0 - 0.1 * h));
    assert!(!st.end_step_at(&mut sys, t_end + 0.1 * h));
    let t = t0 + 0.37 * h;
    assert!(st.end_step_at(&mut sys, t));
    assert_eq!((st.t(), st.t_prev()), (t, t0));
    assert_on(st.y(), oscillator(t, forced, (y0[0], y0[1])), w);
    let mut rate = [0.0; 2];
    sys.rhs(t, st.y(), &mut rate);
    for (a, b) in st.dydt().iter().zip(&rate) {
        assert!((a - b).abs() < 1e-12 * w * w * 0.1, "{a} vs {b}");
    }
    let mut out = [0.0; 2];
    for s in [0.25, 0.5, 0.9] {
        let ts = t0 + s * (t - t0);
        st.dense_output(&mut sys, ts, &mut out);
        assert_on(&out, oscillator(ts, forced, (y0[0], y0[1])), w);
    }
    st.step(&mut sys, t_end).unwrap();
    assert_eq!(st.t(), t_end);
    assert_on(st.y(), oscillator(t_end, forced, (y0[0], y0[1])), w);
    let mut st = run(&mut sys, &y0, 1.0, Method::Dop853, 1e-10);
    let t = st.t_prev() + 0.37 * st.h_last();
    assert!(!st.end_step_at(&mut sys, t));
    assert_eq!(st.t(), 1.0);
}

/// The leading block of a two-block form ([`Linear::leading`], a
/// variational system's state) moves as the one-block form solved alone,
/// bit for bit (the same balancing, norm and steady states), over a span
/// of 1.3 s; the second block, under a harmonic of its own, is dropped.
#[test]
fn a_leading_block_moves_as_its_own_form() {
    let own = Forced::oscillator();
    let mut pair = own.linear_form().unwrap();
    let column = Harmonic {
        omega: 6.3,
        cos: vec![0.5, 0.1],
        sin: vec![-0.2, 0.7],
    };
    let alone = pair.clone().solve().unwrap();
    pair.blocks.push(vec![column]);
    let both = pair.solve().unwrap();
    let leading = both.leading(1);
    assert_eq!(leading.dim(), alone.dim());
    assert_eq!(both.dim(), 2 * alone.dim());
    let (mut a, mut b) = ([0.01, -0.2], [0.01, -0.2]);
    alone.flow((0.4, 1.7), &mut a);
    leading.flow((0.4, 1.7), &mut b);
    assert_eq!(a.map(f64::to_bits), b.map(f64::to_bits));
    assert!(a.iter().all(|x| x.is_finite()));
}

/// A span taken at once ([`Linear::flow`], the exponential squared up to
/// it): 3.2 periods of the forced oscillator, from t = 0.4 s, equal the
/// closed form to 1e-12 of the amplitude; a span of zero leaves the
/// state as it is.
#[test]
fn a_span_moves_at_once_as_the_closed_form() {
    let (w, zeta, f, omega) = OSCILLATOR;
    let sys = Forced::oscillator();
    let linear = sys.linear_form().unwrap().solve().unwrap();
    let y0 = [0.01, -0.2];
    let (t0, t1) = (0.4, 0.4 + 3.2 * 2.0 * std::f64::consts::PI / w);
    let start = oscillator(t0, (w, zeta, f, omega), (y0[0], y0[1]));
    let mut y = [start.0, start.1];
    linear.flow((t0, t1), &mut y);
    assert_on(&y, oscillator(t1, (w, zeta, f, omega), (y0[0], y0[1])), w);
    let mut same = [start.0, start.1];
    linear.flow((t0, t0), &mut same);
    assert!((same[0] - start.0).abs() < 1e-17 && (same[1] - start.1).abs() < 1e-16);
}

/// A stiff oscillator (ω = 300 rad/s, ω² = 9e4 in its velocity row):
/// the step is limited by the balanced norm, about ω, not by ‖A‖∞ ≈ ω²
/// (300 times longer), and 40 periods still equal the closed form to
/// 1e-12 of the amplitude, in about 4 steps a period.
#[test]
fn a_stiff_oscillator_steps_by_its_balanced_norm() {
    let (w, zeta, f, omega) = (300.0, 0.02, 3.0e3, 250.0);
    let mut sys = Forced::lone((w, zeta, f, omega));
    let limit = sys.linear_form().unwrap().solve().unwrap().step_limit();
    let balanced = 2.0 / (w + 2.0 * zeta * w);
    assert!(
        (0.5 * balanced..=balanced * 1.0001).contains(&limit),
        "{limit} vs {balanced}"
    );
    let y0 = [0.01, -2.0];
    let t_end = 40.0 * 2.0 * std::f64::consts::PI / w;
    let st = run(&mut sys, &y0, t_end, Method::Exact, 1e-6);
    assert_on(
        st.y(),
        oscillator(t_end, (w, zeta, f, omega), (y0[0], y0[1])),
        w,
    );
    assert!(st.stats().steps <= 8 * 40, "{} steps", st.stats().steps);
}

/// Three bodies, two of them joined, under a harmonic force and a
/// constant one: the exact flow equals DOP853 at rtol 1e-13 to 1e-10 of
/// the motion.
#[test]
fn a_forced_coupled_row_moves_as_dop853_says() {
    let mut sys = Forced {
        w2: vec![40.0, 55.0, 12.0],
        c: vec![0.3, 0.1, 0.05],
        k12: 20.0,
        omega: 5.3,
        f: 1.5,
        g: -0.7,
        p: 0.4,
    };
    let y0 = [0.01, 0.0, -0.02, 0.1, 0.0, 0.05];
    let t_end = 12.0;
    let exact = run(&mut sys, &y0, t_end, Method::Exact, 1e-6);
    let reference = run(&mut sys, &y0, t_end, Method::Dop853, 1e-13);
    let scale = y0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    for (a, b) in exact.y().iter().zip(reference.y()) {
        assert!((a - b).abs() < 1e-10 * scale, "{a} vs {b}");
    }
    // A leading part of the dense output (an event's state) is the whole
    // one's, bit for bit: at a quarter of the step, between quarters,
    // ending inside the block.
    for mut st in [exact, reference] {
        let (t0, h) = (st.t_prev(), st.h_last());
        for s in [0.25, 0.37] {
            let mut whole = [0.0; 6];
            st.dense_output(&mut sys, t0 + s * h, &mut whole);
            for m in [2, 3] {
                let mut part = vec![0.0; m];
                st.dense_output(&mut sys, t0 + s * h, &mut part);
                assert_eq!(part, whole[..m], "{:?} s {s}: {m} of 6", st.active());
            }
        }
    }
}

/// An undamped oscillator forced at its own frequency has no steady
/// state: no exact form (the integration is DOP853's); a constant force
/// on a free body neither.
#[test]
fn a_resonance_has_no_exact_form() {
    let resonant = Forced {
        w2: vec![49.0],
        c: vec![0.0],
        k12: 0.0,
        omega: 7.0,
        f: 1.0,
        g: 0.0,
        p: 0.0,
    };
    assert!(resonant.linear_form().unwrap().solve().is_none());
    let free = Forced {
        w2: vec![0.0],
        c: vec![0.0],
        k12: 0.0,
        omega: 3.0,
        f: 0.0,
        g: 0.0,
        p: -9.81,
    };
    assert!(free.linear_form().unwrap().solve().is_none());
    let off = Forced {
        omega: 6.0,
        ..resonant
    };
    assert!(off.linear_form().unwrap().solve().is_some());
}

/// [`Forced`] whose form can be withheld (as a chain's goes while a soft
/// episode runs).
struct Withheld {
    sys: Forced,
    linear: bool,
}

impl OdeSystem for Withheld {
    fn dim(&self) -> usize {
        self.sys.dim()
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        self.sys.rhs(t, y, dydt);
    }

    fn linear_form(&self) -> Option<LinearForm> {
        self.linear.then(|| self.sys.linear_form()).flatten()
    }
}

/// A stepper asked to move exactly where it can: exact while the form
/// holds, DOP853 from the reset where it goes, exact again from the reset
/// where it is back; the end state is the closed form's to 1e-9 of the
/// amplitude, and the work counters hold every engine's steps.
#[test]
fn a_stepper_moves_exactly_from_each_reset_where_the_form_holds() {
    let (w, zeta, f, omega) = OSCILLATOR;
    let mut sys = Withheld {
        sys: Forced::oscillator(),
        linear: true,
    };
    let y0 = [0.01, -0.2];
    let mut st = Stepper::new(Method::Dop853, 2, options(1e-12, f64::INFINITY))
        .unwrap()
        .exact_where_linear();
    let (mut t, mut y, mut steps) = (0.0, y0.to_vec(), 0);
    for (t_end, linear, active) in [
        (3.0, true, Method::Exact),
        (6.5, false, Method::Dop853),
        (10.0, true, Method::Exact),
    ] {
        sys.linear = linear;
        st.reset(&mut sys, t, &y).unwrap();
        assert_eq!(st.active(), active, "from t = {t}");
        while st.t() < t_end {
            st.step(&mut sys, t_end).unwrap();
            steps += 1;
        }
        (t, y) = (st.t(), st.y().to_vec());
    }
    let (x, v) = oscillator(t, (w, zeta, f, omega), (y0[0], y0[1]));
    let scale = 0.1;
    assert!((y[0] - x).abs() < 1e-9 * scale, "{} vs {x}", y[0]);
    assert!((y[1] - v).abs() < 1e-9 * scale * w, "{} vs {v}", y[1]);
    assert_eq!(st.stats().steps, steps);
}

/// The series summed in four chains equals the plain Horner sum to
/// rounding, and each component alone ([`series_at`]) is the same bits,
/// for the unrolled sizes and others, and for every term count mod 4.
#[test]
fn the_series_in_four_chains_is_horner_to_rounding() {
    let n = 10;
    // Terms of e^{x τ} in each component (x_i up to 2, τ up to 1): the
    // step's series at its largest ‖A‖ τ.
    let x: Vec<f64> = (0..n).map(|i| 2.0 - 0.37 * i as f64).collect();
    let mut terms = vec![0.0; (MAX_TERMS + 1) * n];
    for i in 0..n {
        let mut t = 1.0 + 0.1 * i as f64;
        for k in 0..=MAX_TERMS {
            terms[k * n + i] = t;
            t *= x[i] / (k + 1) as f64;
        }
    }
    for m in [1, 2, 3, 4, 6, 8, 10] {
        for count in [1, 2, 5, 26, 27, 28, 29, MAX_TERMS + 1] {
            for tau in [0.0, 0.013, 0.5, 1.0] {
                let mut out = vec![0.0; m];
                sum_series(&terms, (n, count), tau, &mut out);
                for (i, o) in out.iter().enumerate() {
                    let horner = (0..count)
                        .rev()
                        .fold(0.0, |a, k| a * tau + terms[k * n + i]);
                    let scale = (0..count).map(|k| terms[k * n + i].abs() * tau.powi(k as i32));
                    let tol = 4.0 * f64::EPSILON * scale.sum::<f64>();
                    assert!(
                        (o - horner).abs() <= tol,
                        "m {m} count {count} τ {tau} component {i}: {o} against {horner}"
                    );
                    let alone = series_at(&terms, (n, count), tau, i);
                    assert_eq!(alone.to_bits(), o.to_bits(), "m {m} count {count} τ {tau}");
                }
            }
        }
    }
    // The closed form where the series is whole: e^{2·1} to rounding.
    let mut e = [0.0];
    sum_series(&terms, (n, MAX_TERMS + 1), 1.0, &mut e);
    assert!((e[0] - 2f64.exp()).abs() <= 4.0 * f64::EPSILON * 2f64.exp());
}

/// The steady state folded into a step's series sums to the steady state
/// itself plus the deviation's series (to rounding of the sum's terms),
/// a constant force's included; a forcing far faster than the step does
/// not fold, and leaves the terms as they were.
#[test]
fn the_steady_state_folds_into_the_series() {
    let mut sys = Forced::lone((7.4, 0.02, 3.0, 11.1));
    sys.g = -1.3;
    sys.p = 0.7;
    let form = sys.linear_form().and_then(LinearForm::solve).unwrap();
    let (n, h, t0) = (2, form.step_limit(), 0.37);
    let v = [2e-3, -0.05];
    let mut terms = vec![0.0; (MAX_TERMS + 1) * n];
    let count = series_terms(&form, (&v, n), h, &mut terms).unwrap();
    let unfolded = terms.clone();
    let folded = fold_steady(&form, (t0, h), (n, n), &mut terms, count).unwrap();
    assert!(folded > count, "Ω h = {} needs more terms", 11.1 * h);
    for s in [0.0, 0.1, 0.377, 0.5, 0.93, 1.0] {
        let tau = s * h;
        let mut motion = [0.0; 2];
        sum_series(&terms, (n, folded), tau, &mut motion);
        let mut deviation = [0.0; 2];
        sum_series(&unfolded, (n, count), tau, &mut deviation);
        let mut steady = [0.0; 2];
        form.steady_into(t0 + tau, &mut steady);
        for i in 0..2 {
            let expected = steady[i] + deviation[i];
            // (The steady terms reach |X| e^{Ω τ}: a few units of rounding
            // of that.)
            let size = steady[i].abs().max(0.1) * (11.1 * tau).exp();
            assert!(
                (motion[i] - expected).abs() <= 16.0 * f64::EPSILON * size,
                "s {s}, row {i}: {} against {expected}",
                motion[i]
            );
        }
    }
    // Ω h = 400: the steady terms would need far more than MAX_TERMS.
    let fast = Forced::lone((7.4, 0.02, 3.0, 400.0 / h));
    let form = fast.linear_form().and_then(LinearForm::solve).unwrap();
    let mut terms = unfolded.clone();
    assert_eq!(fold_steady(&form, (t0, h), (n, n), &mut terms, count), None);
    assert_eq!(terms, unfolded);
}
