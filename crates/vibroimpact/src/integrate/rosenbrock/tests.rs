//! Tests of RODAS: order conditions, convergence and dense-output order,
//! stiff problems, Jacobians and robustness.
use super::*;
use crate::integrate::tests::systems::{fixed, observed_order, tol, Decay, Harmonic};
use crate::integrate::Dop853;

// ---------------------------------------------------------------------
// Test systems.
// ---------------------------------------------------------------------

/// Nonlinear, non-autonomous, diagonal Jacobian: y1' = -2 t y1²,
/// y2' = y2 cos t; from (1, 1): (1/(1+t²), exp(sin t)).
struct Nonlinear {
    analytic: bool,
}
impl OdeSystem for Nonlinear {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = -2.0 * t * y[0] * y[0];
        d[1] = y[1] * t.cos();
    }
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        Some((0, 0))
    }
    fn jacobian(&mut self, t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        if self.analytic {
            jac.set(0, 0, -4.0 * t * y[0]);
            jac.set(1, 1, t.cos());
        }
        self.analytic
    }
}
fn nonlinear_exact(t: f64) -> [f64; 2] {
    [1.0 / (1.0 + t * t), t.sin().exp()]
}

/// Van der Pol oscillator y1' = y2, y2' = μ (1 − y1²) y2 − y1.
struct VanDerPol {
    mu: f64,
    analytic: bool,
}
impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = self.mu * (1.0 - y[0] * y[0]) * y[1] - y[0];
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        if self.analytic {
            jac.set(0, 1, 1.0);
            jac.set(1, 0, -2.0 * self.mu * y[0] * y[1] - 1.0);
            jac.set(1, 1, self.mu * (1.0 - y[0] * y[0]));
        }
        self.analytic
    }
}

/// Stiff linear, non-autonomous: y' = −λ (y − cos t).
struct StiffLinear {
    lambda: f64,
}
impl OdeSystem for StiffLinear {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = -self.lambda * (y[0] - t.cos());
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
        jac.set(0, 0, -self.lambda);
        true
    }
}
/// Exact solution of [`StiffLinear`] from y(0) = y0.
fn stiff_linear_exact(lambda: f64, y0: f64, t: f64) -> f64 {
    let a = lambda * lambda / (1.0 + lambda * lambda);
    let b = lambda / (1.0 + lambda * lambda);
    a * t.cos() + b * t.sin() + (y0 - a) * (-lambda * t).exp()
}

/// Nonlinear chain with a banded Jacobian (kl = 2, ku = 1):
/// f_i = −y_i³ + ½ sin(y_{i−1}) y_{i−2} + exp(y_{i+1}/10) + cos t
/// (terms with indices outside 0..n dropped).
struct Chain {
    n: usize,
    banded: bool,
    analytic: bool,
}
impl OdeSystem for Chain {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
        let n = self.n;
        for i in 0..n {
            let mut v = -y[i].powi(3) + t.cos();
            if i >= 2 {
                v += 0.5 * y[i - 1].sin() * y[i - 2];
            }
            if i + 1 < n {
                v += (0.1 * y[i + 1]).exp();
            }
            d[i] = v;
        }
    }
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        self.banded.then_some((2, 1))
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], jac: &mut BandMatrix) -> bool {
        if !self.analytic {
            return false;
        }
        let n = self.n;
        for i in 0..n {
            jac.set(i, i, -3.0 * y[i] * y[i]);
            if i >= 2 {
                jac.set(i, i - 1, 0.5 * y[i - 1].cos() * y[i - 2]);
                jac.set(i, i - 2, 0.5 * y[i - 1].sin());
            }
            if i + 1 < n {
                jac.set(i, i + 1, 0.1 * (0.1 * y[i + 1]).exp());
            }
        }
        true
    }
}

/// Heat equation u_t = u_xx on (0, 1), u = 0 at both ends, central
/// differences on `n` interior points (tridiagonal, stiff: eigenvalues
/// down to ≈ −4(n+1)²).
struct Heat {
    n: usize,
    analytic: bool,
}
impl Heat {
    fn inv_dx2(&self) -> f64 {
        ((self.n + 1) * (self.n + 1)) as f64
    }
    /// Exact solution from the first discrete eigenmode sin(π x_i).
    fn exact(&self, t: f64, out: &mut [f64]) {
        let dx = 1.0 / (self.n + 1) as f64;
        let lambda = -4.0 * self.inv_dx2() * (0.5 * std::f64::consts::PI * dx).sin().powi(2);
        for (i, o) in out.iter_mut().enumerate() {
            *o = (lambda * t).exp() * (std::f64::consts::PI * (i + 1) as f64 * dx).sin();
        }
    }
}
impl OdeSystem for Heat {
    fn dim(&self) -> usize {
        self.n
    }
    fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
        let n = self.n;
        let c = self.inv_dx2();
        for i in 0..n {
            let l = if i > 0 { y[i - 1] } else { 0.0 };
            let r = if i + 1 < n { y[i + 1] } else { 0.0 };
            d[i] = c * (l - 2.0 * y[i] + r);
        }
    }
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        Some((1, 1))
    }
    fn jacobian(&mut self, _t: f64, _y: &[f64], jac: &mut BandMatrix) -> bool {
        if self.analytic {
            let c = self.inv_dx2();
            for i in 0..self.n {
                jac.set(i, i, -2.0 * c);
                if i > 0 {
                    jac.set(i, i - 1, c);
                    jac.set(i - 1, i, c);
                }
            }
        }
        self.analytic
    }
}

/// Options for fixed steps `h`: every step accepted (huge tolerances),
/// never grown (`h_max = h`).
/// Integrates with RODAS from (t0, y0) to t_end; final state and stats.
fn run<S: OdeSystem>(
    sys: &mut S,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: IntegratorOptions,
) -> (Vec<f64>, Stats) {
    let mut s = Rodas::new(sys.dim(), opts).unwrap();
    s.reset(sys, t0, y0).unwrap();
    while s.t() < t_end {
        s.step(sys, t_end).unwrap();
    }
    assert_eq!(s.t(), t_end);
    (s.y().to_vec(), s.stats())
}

// ---------------------------------------------------------------------
// 1. Tableau.
// ---------------------------------------------------------------------

#[test]
// Small dense matrix algebra reads best with explicit indices.
#[allow(clippy::needless_range_loop)]
fn tableau_order_conditions() {
    // Back to Hairer–Wanner's standard form: Γ⁻¹ = diag(1/γ) − (c_ij),
    // α = (a_ij)·Γ, b = m·Γ with m = (a_51 … a_54, 1, 1) (stiffly
    // accurate: y_new is the argument of stage 6 plus U_6), embedded
    // m̂ = (a_51 … a_54, 1, 0).
    const S: usize = N_STAGES;
    let mut a = [[0.0; S]; S];
    let mut gi = [[0.0; S]; S];
    for i in 0..S {
        gi[i][i] = 1.0 / GAMMA;
        for j in 0..i {
            gi[i][j] = -CC[i - 1][j];
            if i < 5 {
                a[i][j] = A[i - 1][j];
            } else if j < 4 {
                a[i][j] = A[3][j];
            }
        }
    }
    a[5][4] = 1.0;
    // Γ = (Γ⁻¹)⁻¹ by forward substitution, column by column.
    let mut g = [[0.0; S]; S];
    for j in 0..S {
        for i in 0..S {
            let e = if i == j { 1.0 } else { 0.0 };
            let s: f64 = (0..i).map(|k| gi[i][k] * g[k][j]).sum();
            g[i][j] = (e - s) / gi[i][i];
        }
    }
    let mul = |x: &[[f64; S]; S], y: &[[f64; S]; S]| {
        let mut r = [[0.0; S]; S];
        for i in 0..S {
            for j in 0..S {
                r[i][j] = (0..S).map(|k| x[i][k] * y[k][j]).sum();
            }
        }
        r
    };
    let alpha = mul(&a, &g);
    let mut beta = alpha;
    for i in 0..S {
        for j in 0..i {
            beta[i][j] += g[i][j];
        }
    }
    let c: Vec<f64> = (0..S).map(|i| alpha[i].iter().sum()).collect();
    let bp: Vec<f64> = (0..S).map(|i| beta[i][..i].iter().sum()).collect();
    // Nodes and d_i = Σ_j γ_ij against the tabulated ones.
    let nodes = [0.0, NODES[0], NODES[1], NODES[2], NODES[3], 1.0];
    let d = [D[0], D[1], D[2], D[3], 0.0, 0.0];
    for i in 0..S {
        assert!((c[i] - nodes[i]).abs() < 1e-14, "c_{i}: {}", c[i]);
        let gs: f64 = g[i][..=i].iter().sum();
        assert!((gs - d[i]).abs() < 1e-14, "d_{i}: {gs}");
    }
    let gam = GAMMA;
    let residuals = |m: [f64; S]| {
        let b: Vec<f64> = (0..S)
            .map(|j| (0..S).map(|k| m[k] * g[k][j]).sum())
            .collect();
        let s1 = |f: &dyn Fn(usize) -> f64| (0..S).map(|i| b[i] * f(i)).sum::<f64>();
        let bb = |i: usize, v: &[f64]| (0..S).map(|j| beta[i][j] * v[j]).sum::<f64>();
        let c2: Vec<f64> = c.iter().map(|x| x * x).collect();
        let bbp: Vec<f64> = (0..S).map(|j| bb(j, &bp)).collect();
        let abp: Vec<f64> = (0..S)
            .map(|i| (0..S).map(|j| alpha[i][j] * bp[j]).sum())
            .collect();
        [
            s1(&|_| 1.0) - 1.0,
            s1(&|i| bp[i]) - (0.5 - gam),
            s1(&|i| c[i] * c[i]) - 1.0 / 3.0,
            s1(&|i| bbp[i]) - (1.0 / 6.0 - gam + gam * gam),
            s1(&|i| c[i].powi(3)) - 0.25,
            s1(&|i| c[i] * abp[i]) - (1.0 / 8.0 - gam / 3.0),
            s1(&|i| bb(i, &c2)) - (1.0 / 12.0 - gam / 3.0),
            s1(&|i| bb(i, &bbp)) - (1.0 / 24.0 - gam / 2.0 + 1.5 * gam * gam - gam.powi(3)),
        ]
    };
    let m = [A[3][0], A[3][1], A[3][2], A[3][3], 1.0, 1.0];
    let mut m_hat = m;
    m_hat[5] = 0.0;
    let r = residuals(m);
    let r_hat = residuals(m_hat);
    // Order 4 (all 8 conditions), measured |residual| <= 2.3e-16.
    for (k, x) in r.iter().enumerate() {
        assert!(x.abs() < 1e-13, "solution, condition {k}: {x:e}");
    }
    // Embedded: order 3 (first 4 conditions) and not 4 (measured
    // residuals 0.10, 0.034, −0.0039, −0.0048 for the order-4 ones).
    for (k, x) in r_hat.iter().enumerate().take(4) {
        assert!(x.abs() < 1e-13, "embedded, condition {k}: {x:e}");
    }
    assert!(r_hat[4].abs() > 1e-2);
}

// ---------------------------------------------------------------------
// 2. Convergence order with fixed steps.
// ---------------------------------------------------------------------

#[test]
fn convergence_order_is_4() {
    let hs = [0.5, 0.25, 0.125, 0.0625];
    for analytic in [true, false] {
        let errs: Vec<f64> = hs
            .iter()
            .map(|&h| {
                let (y, st) = run(&mut Harmonic { analytic }, 0.0, &[1.0, 0.0], 10.0, fixed(h));
                assert_eq!(st.rejected_steps, 0);
                assert_eq!(st.steps, (10.0 / h).round() as u64);
                (y[0] - 10f64.cos()).hypot(y[1] + 10f64.sin())
            })
            .collect();
        // Measured (analytic and FD Jacobian alike): 4.56e-4, 2.84e-5,
        // 1.77e-6, 1.11e-7, orders 4.00, 4.00, 4.00.
        for w in errs.windows(2) {
            let p = observed_order(w[0], w[1]);
            assert!((3.5..=4.5).contains(&p), "order {p} from {errs:?}");
        }
        // Non-autonomous (exercises the h·d_i·f_t terms): worst error
        // along [0, 5].
        let errs: Vec<f64> = [0.1, 0.05, 0.025, 0.0125]
            .iter()
            .map(|&h| {
                let mut sys = Nonlinear { analytic };
                let mut s = Rodas::new(2, fixed(h)).unwrap();
                s.reset(&mut sys, 0.0, &[1.0, 1.0]).unwrap();
                let mut worst = 0.0f64;
                while s.t() < 5.0 {
                    s.step(&mut sys, 5.0).unwrap();
                    let ex = nonlinear_exact(s.t());
                    worst = worst.max((s.y()[0] - ex[0]).abs().max((s.y()[1] - ex[1]).abs()));
                }
                worst
            })
            .collect();
        // Measured: 1.52e-6, 7.32e-8, 3.95e-9, 2.29e-10, orders 4.37,
        // 4.21, 4.11 (approaching 4 from above).
        for w in errs.windows(2) {
            let p = observed_order(w[0], w[1]);
            assert!((3.5..=4.5).contains(&p), "order {p} from {errs:?}");
        }
    }
}

// ---------------------------------------------------------------------
// 3. Dense output.
// ---------------------------------------------------------------------

#[test]
fn dense_output_is_3rd_order() {
    // Fixed steps on the harmonic oscillator; at 1/4, 1/2, 3/4 of every
    // step compare with the exact solution through (t_prev, y_prev):
    // local interpolation error O(h^4) for a 3rd-order extension.
    let run_dense = |h: f64| {
        let mut sys = Harmonic { analytic: true };
        let mut s = Rodas::new(2, fixed(h)).unwrap();
        s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
        let mut worst = 0.0f64;
        let mut out = [0.0; 2];
        let mut prev = [1.0, 0.0];
        while s.t() < 10.0 {
            s.step(&mut sys, 10.0).unwrap();
            for q in [0.25, 0.5, 0.75] {
                let tq = s.t_prev() + q * (s.t() - s.t_prev());
                s.dense_output(&mut sys, tq, &mut out);
                assert_eq!(s.dense_component(&mut sys, 1, tq), out[1]);
                let dt = tq - s.t_prev();
                let loc = [
                    prev[0] * dt.cos() + prev[1] * dt.sin(),
                    prev[1] * dt.cos() - prev[0] * dt.sin(),
                ];
                worst = worst.max((out[0] - loc[0]).abs().max((out[1] - loc[1]).abs()));
            }
            prev = [s.y()[0], s.y()[1]];
        }
        worst
    };
    // Measured: 3.39e-5, 2.21e-6, 1.39e-7, 8.74e-9 (orders 3.94, 3.99,
    // 4.00).
    let errs: Vec<f64> = [0.4, 0.2, 0.1, 0.05]
        .iter()
        .map(|&h| run_dense(h))
        .collect();
    for w in errs.windows(2) {
        let p = observed_order(w[0], w[1]);
        assert!((3.5..=4.5).contains(&p), "dense order {p} from {errs:?}");
    }
}

#[test]
fn dense_output_adaptive_accuracy_and_end_points() {
    // Nonlinear problem at rtol = atol = 1e-8: dense output at 7 interior
    // points per step against the exact solution.
    let mut sys = Nonlinear { analytic: true };
    let mut s = Rodas::new(2, tol(1e-8)).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 1.0]).unwrap();
    let mut out = [0.0; 2];
    s.dense_output(&mut sys, 0.0, &mut out);
    assert_eq!(out, [1.0, 1.0], "before the first step: current state");
    let (mut worst_dense, mut worst_end) = (0.0f64, 0.0f64);
    while s.t() < 10.0 {
        let y_prev = s.y().to_vec();
        s.step(&mut sys, 10.0).unwrap();
        s.dense_output(&mut sys, s.t_prev(), &mut out);
        assert_eq!(out.as_slice(), y_prev.as_slice());
        s.dense_output(&mut sys, s.t(), &mut out);
        assert_eq!(out, s.y());
        let ex = nonlinear_exact(s.t());
        worst_end = worst_end.max((s.y()[0] - ex[0]).abs().max((s.y()[1] - ex[1]).abs()));
        for j in 1..8 {
            let tt = s.t_prev() + (s.t() - s.t_prev()) * f64::from(j) / 8.0;
            s.dense_output(&mut sys, tt, &mut out);
            let ex = nonlinear_exact(tt);
            worst_dense = worst_dense.max((out[0] - ex[0]).abs().max((out[1] - ex[1]).abs()));
        }
    }
    // Measured: worst step-end error 4.2e-9, worst dense error 4.8e-8
    // (3rd-order interpolant), 372 steps.
    assert!(worst_end < 2e-8, "{worst_end:e}");
    assert!(worst_dense < 2e-7, "{worst_dense:e}");
}

// ---------------------------------------------------------------------
// 4. Stiff problems.
// ---------------------------------------------------------------------

#[test]
fn van_der_pol_stiff_against_dop853_reference() {
    // μ = 1000 over [0, 3000] from (2, 0): relaxation oscillations with
    // period ≈ 1614, fast jumps near t ≈ 807, 1614, 2421; t = 3000 lies
    // on a slow branch. Reference: DOP853 at rtol = atol = 1e-12.
    let t_end = 3000.0;
    let mut reference = VanDerPol {
        mu: 1000.0,
        analytic: false,
    };
    let mut d = Dop853::new(2, tol(1e-12)).unwrap();
    d.reset(&mut reference, 0.0, &[2.0, 0.0]).unwrap();
    while d.t() < t_end {
        d.step(&mut reference, t_end).unwrap();
    }
    let y_ref = d.y().to_vec();
    let dop_steps = d.stats().steps;
    // Measured: 879 241 DOP853 steps, the stiffness test has fired.
    assert!(d.stiffness_detected());
    assert!(dop_steps > 500_000, "{dop_steps}");
    // Measured (tol: rel. errors y1, y2; steps):
    // 1e-5: 6.6e-5, 1.7e-4, 516;  1e-7: 6.3e-7, 1.6e-6, 1605;
    // 1e-9: 5.8e-9, 1.5e-8, 5636;  1e-7 with FD Jacobian: the same
    // errors to 2 digits, 1605 steps.
    let mut last = f64::INFINITY;
    let mut steps_1e7 = 0;
    for (tl, analytic) in [(1e-5, true), (1e-7, true), (1e-9, true), (1e-7, false)] {
        let (y, st) = run(
            &mut VanDerPol {
                mu: 1000.0,
                analytic,
            },
            0.0,
            &[2.0, 0.0],
            t_end,
            tol(tl),
        );
        let e1 = ((y[0] - y_ref[0]) / y_ref[0]).abs();
        let e2 = ((y[1] - y_ref[1]) / y_ref[1]).abs();
        assert!(
            e1 < 30.0 * tl && e2 < 50.0 * tl,
            "tol {tl:e}: {e1:e}, {e2:e}"
        );
        assert!(st.steps * 100 < dop_steps, "tol {tl:e}: {st:?}");
        assert_eq!(st.jacobian_evaluations, st.steps);
        assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
        if analytic {
            assert!(e1 < 0.1 * last, "error must decrease with tol");
            last = e1;
            if tl == 1e-7 {
                steps_1e7 = st.steps;
            }
        } else {
            // Same steps with finite differences (2 more f per step).
            assert_eq!(st.steps, steps_1e7);
        }
    }
}

#[test]
fn stiff_linear_in_few_steps() {
    // y' = −1e6 (y − cos t), y(0) = 0 (initial layer of width 1e-6),
    // over [0, 10] at rtol = atol = 1e-6.
    let lambda = 1e6;
    let t_end = 10.0;
    let ex = stiff_linear_exact(lambda, 0.0, t_end);
    let (y, st) = run(&mut StiffLinear { lambda }, 0.0, &[0.0], t_end, tol(1e-6));
    let mut d = Dop853::new(1, tol(1e-6)).unwrap();
    let mut sys = StiffLinear { lambda };
    d.reset(&mut sys, 0.0, &[0.0]).unwrap();
    while d.t() < t_end {
        d.step(&mut sys, t_end).unwrap();
    }
    let sd = d.stats();
    // Measured: RODAS 46 steps (4 rejected), error 3.0e-7; DOP853
    // 1 564 058 steps, error 1.9e-8.
    assert!(
        (y[0] - ex).abs() < 1e-6,
        "RODAS error {:e}",
        (y[0] - ex).abs()
    );
    assert!(st.steps < 100, "{st:?}");
    assert!(st.steps * 10_000 < sd.steps, "{st:?} vs {sd:?}");
}

#[test]
fn l_stable_and_stiffly_accurate() {
    // Single steps far outside any explicit stability region on
    // y' = −1e12 (y − cos t) from y = 1: an L-stable, stiffly accurate
    // method (R(∞) = 0) lands on the slow solution.
    let lambda = 1e12;
    for h in [1e-3, 1.0] {
        let (y, st) = run(&mut StiffLinear { lambda }, 0.0, &[1.0], h, fixed(h));
        assert_eq!(st.steps, 1);
        let err = (y[0] - stiff_linear_exact(lambda, 1.0, h)).abs();
        // Measured: 0 (h = 1e-3) and 2.4e-15 (h = 1).
        assert!(err < 1e-10, "h = {h}: {y:?}, error {err:e}");
    }
}

// ---------------------------------------------------------------------
// 5. Jacobians.
// ---------------------------------------------------------------------

/// Jacobian evaluated by `evaluate_jacobian` at (t, y) and the number of
/// evaluations of f it cost.
fn jacobian_of<S: OdeSystem>(sys: &mut S, t: f64, y: &[f64]) -> (BandMatrix, u64) {
    let mut s = Rodas::new(sys.dim(), tol(1e-8)).unwrap();
    s.reset(sys, t, y).unwrap();
    let before = s.stats().rhs_evaluations;
    s.method.evaluate_jacobian(sys, &s.at, &mut s.stats);
    assert_eq!(s.stats().jacobian_evaluations, 1);
    (s.method.jac.clone(), s.stats().rhs_evaluations - before)
}

#[test]
fn banded_fd_jacobian_equals_analytic() {
    let n = 12;
    let y: Vec<f64> = (0..n).map(|i| 0.5 + 0.3 * (i as f64).sin()).collect();
    let (ja, evals_a) = jacobian_of(
        &mut Chain {
            n,
            banded: true,
            analytic: true,
        },
        0.4,
        &y,
    );
    let (jf, evals_f) = jacobian_of(
        &mut Chain {
            n,
            banded: true,
            analytic: false,
        },
        0.4,
        &y,
    );
    let (jd, evals_d) = jacobian_of(
        &mut Chain {
            n,
            banded: false,
            analytic: false,
        },
        0.4,
        &y,
    );
    assert_eq!(ja.bandwidths(), (2, 1));
    assert_eq!(jd.bandwidths(), (n - 1, n - 1));
    // Analytic: only ∂f/∂t costs an evaluation; banded FD: kl + ku + 1
    // = 4 grouped evaluations (instead of n = 12) plus ∂f/∂t.
    assert_eq!(evals_a, 1);
    assert_eq!(evals_f, 4 + 1);
    assert_eq!(evals_d, n as u64 + 1);
    let mut worst = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let a = ja.get(i, j);
            let scale = a.abs().max(1.0);
            worst = worst.max((jf.get(i, j) - a).abs() / scale);
            worst = worst.max((jd.get(i, j) - a).abs() / scale);
            if !ja.in_band(i, j) {
                assert_eq!(jd.get(i, j), 0.0, "({i}, {j}) outside the band");
            }
        }
    }
    // Measured: 6.2e-8 (forward differences, δ ≈ 1.5e-8·sqrt|y|).
    assert!(worst < 1e-6, "worst relative deviation {worst:e}");
}

#[test]
fn banded_stiff_heat_equation() {
    // n = 50: eigenvalues from −9.9 to −1.04e4. Exact solution: the
    // first discrete mode, decaying as exp(−9.87 t). RODAS with the
    // analytic and the banded FD Jacobian (3 grouped evaluations).
    let n = 50;
    let heat = Heat { n, analytic: true };
    let mut y0 = vec![0.0; n];
    heat.exact(0.0, &mut y0);
    let mut ex = vec![0.0; n];
    heat.exact(0.5, &mut ex);
    let mut results = Vec::new();
    for analytic in [true, false] {
        let mut sys = Heat { n, analytic };
        let opts = tol(1e-8);
        let mut s = Rodas::with_bandwidth(n, opts, Some((1, 1))).unwrap();
        s.reset(&mut sys, 0.0, &y0).unwrap();
        while s.t() < 0.5 {
            s.step(&mut sys, 0.5).unwrap();
        }
        let err = s
            .y()
            .iter()
            .zip(&ex)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let st = s.stats();
        // Measured: error 1.3e-9, 74 steps (no rejection), both variants.
        assert!(err < 5e-8, "analytic {analytic}: error {err:e}");
        assert!(st.steps < 150, "{st:?}");
        let per_jac = if analytic { 1 } else { 3 + 1 };
        assert_eq!(
            st.rhs_evaluations,
            1 + 1 + per_jac * st.jacobian_evaluations + 5 * st.lu_decompositions + st.steps,
            "{st:?}"
        );
        results.push((s.y().to_vec(), st));
    }
    let diff = results[0]
        .0
        .iter()
        .zip(&results[1].0)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    // Measured: 3.8e-12.
    assert!(diff < 1e-10, "analytic vs FD {diff:e}");
    // An explicit method is limited by stability: DOP853 takes 809 steps
    // (measured).
    let mut d = Dop853::new(n, tol(1e-8)).unwrap();
    let mut sys = Heat { n, analytic: true };
    d.reset(&mut sys, 0.0, &y0).unwrap();
    while d.t() < 0.5 {
        d.step(&mut sys, 0.5).unwrap();
    }
    assert!(d.stats().steps > 5 * results[0].1.steps, "{:?}", d.stats());
}

// ---------------------------------------------------------------------
// 6. NaN safety and admissibility.
// ---------------------------------------------------------------------

#[test]
fn singular_iteration_matrix_is_rejected() {
    // y' = y with h·γ = 1: I/(hγ) − J = 0 is singular; the attempt is
    // rejected (reason NonFinite, h halved) and the integration goes on.
    struct Growth;
    impl OdeSystem for Growth {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&mut self, _t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = y[0];
        }
    }
    let opts = IntegratorOptions {
        h_init: Some(4.0),
        ..tol(1e-8)
    };
    let mut s = Rodas::new(1, opts).unwrap();
    s.reset(&mut Growth, 0.0, &[1.0]).unwrap();
    s.step(&mut Growth, 1.0).unwrap();
    let st = s.stats();
    assert!(st.rejected_steps > 0);
    // The singular attempt counts as a factorisation.
    assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
    while s.t() < 1.0 {
        s.step(&mut Growth, 1.0).unwrap();
    }
    assert!((s.y()[0] - 1f64.exp()).abs() < 1e-7);
}

// ---------------------------------------------------------------------
// 7. Statistics, options, misuse.
// ---------------------------------------------------------------------

#[test]
fn stats_count_every_evaluation() {
    // Per step: ∂f/∂t (1) + FD Jacobian (2 groups for the dense 2×2
    // harmonic oscillator) + f at the new point (1); per attempt: 5
    // stages; reset: 1 (+1 for HINIT).
    let mut sys = Harmonic { analytic: false };
    let mut s = Rodas::new(2, tol(1e-8)).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    assert_eq!(s.stats().rhs_evaluations, 2, "f(t0, y0) + HINIT");
    let opts = IntegratorOptions {
        h_init: Some(3.0),
        ..tol(1e-8)
    };
    let mut s = Rodas::new(2, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    let mut out = [0.0; 2];
    while s.t() < 10.0 {
        s.step(&mut sys, 10.0).unwrap();
        s.dense_output(&mut sys, 0.5 * (s.t() + s.t_prev()), &mut out);
    }
    let st = s.stats();
    assert!(st.rejected_steps > 0, "h_init = 3 must be rejected");
    assert_eq!(st.jacobian_evaluations, st.steps);
    assert_eq!(st.lu_decompositions, st.steps + st.rejected_steps);
    assert_eq!(
        st.rhs_evaluations,
        1 + (1 + 2 + 1) * st.steps + 5 * st.lu_decompositions,
        "{st:?}"
    );
    // Analytic Jacobian: no FD evaluations.
    let mut sys = Harmonic { analytic: true };
    let mut s = Rodas::new(2, tol(1e-8)).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    s.reset_stats();
    s.step(&mut sys, 10.0).unwrap();
    let st = s.stats();
    assert_eq!(st.rhs_evaluations, 2 + 5 * st.lu_decompositions);
    // Stats survive reset(), not reset_stats().
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    assert_eq!(s.stats().steps, 1);
    s.reset_stats();
    assert_eq!(s.stats(), Stats::default());
    assert_eq!(s.options().rtol, 1e-8);
}

#[test]
fn bounds_error_components_and_too_many_steps() {
    let opts = IntegratorOptions {
        h_max: 0.3,
        ..tol(1e-6)
    };
    let mut sys = Harmonic { analytic: true };
    let mut s = Rodas::new(2, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    s.step(&mut sys, 1e-3).unwrap();
    assert_eq!(s.t(), 1e-3);
    let mut t_old = s.t();
    while s.t() < 5.0 {
        s.step(&mut sys, 5.0).unwrap();
        assert!(s.t() - t_old <= 0.3 * (1.0 + 1e-12));
        t_old = s.t();
    }
    assert_eq!(s.t(), 5.0);
    assert_eq!(s.dydt(), [s.y()[1], -s.y()[0]]);
    assert!(matches!(
        s.step(&mut sys, 5.0),
        Err(IntegrationError::InvalidOptions(_))
    ));
    s.step(&mut sys, f64::INFINITY).unwrap();
    assert!(s.t() > 5.0);
    // max_steps.
    let opts = IntegratorOptions {
        max_steps: 3,
        h_init: Some(0.1),
        h_max: 0.1,
        ..tol(1e-6)
    };
    let mut s = Rodas::new(2, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    let err = loop {
        if let Err(e) = s.step(&mut sys, 1.0) {
            break e;
        }
    };
    assert!(matches!(
        err,
        IntegrationError::TooManySteps { steps: 3, .. }
    ));
    // error_components: a fast oscillating appended equation does not
    // influence the steps.
    struct WithOscillation;
    impl OdeSystem for WithOscillation {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
            d[0] = -y[0];
            d[1] = (30.0 * t).cos();
        }
    }
    let opts = IntegratorOptions {
        error_components: Some(1),
        ..tol(1e-8)
    };
    let (y2, st2) = run(&mut WithOscillation, 0.0, &[1.0, 1.0], 2.0, opts);
    let (y1, st1) = run(&mut Decay::new(), 0.0, &[1.0], 2.0, tol(1e-8));
    assert_eq!(y1[0], y2[0]);
    assert_eq!(st1.steps, st2.steps);
    let (_, st_all) = run(&mut WithOscillation, 0.0, &[1.0, 1.0], 2.0, tol(1e-8));
    assert!(st_all.steps > 2 * st2.steps, "{st_all:?} vs {st2:?}");
}

#[test]
fn matrices_are_shaped_at_reset_only_when_needed() {
    // with_bandwidth preallocates; reset with the same shape keeps the
    // allocation, another shape replaces it.
    let mut s = Rodas::with_bandwidth(50, tol(1e-6), Some((1, 1))).unwrap();
    let shape = s.method.jac.bandwidths();
    let mut heat = Heat {
        n: 50,
        analytic: true,
    };
    let y0 = vec![0.1; 50];
    s.reset(&mut heat, 0.0, &y0).unwrap();
    assert_eq!(s.method.jac.bandwidths(), shape);
    let mut chain = Chain {
        n: 50,
        banded: false,
        analytic: true,
    };
    s.reset(&mut chain, 0.0, &y0).unwrap();
    assert_eq!(s.method.jac.bandwidths(), (49, 49));
    let mut fresh = Rodas::new(50, tol(1e-6)).unwrap();
    assert_eq!(fresh.method.jac.n(), 0);
    fresh.reset(&mut heat, 0.0, &y0).unwrap();
    assert_eq!(fresh.method.jac.bandwidths(), (1, 1));
    assert_eq!(fresh.method.lu.bandwidths(), (1, 1));
}
