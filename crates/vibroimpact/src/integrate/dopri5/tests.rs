//! Tests of DOPRI5 beyond the conformance suite (orders, NaN, limits):
//! the tableau's order conditions, the dense output's end points and
//! order, and the stiffness test.
use super::*;
use crate::integrate::tests::systems::{dot, rooted_trees, tol, tree_data, Harmonic};
use crate::integrate::IntegratorOptions;

/// All order conditions (Butcher's rooted trees): the 5th-order solution
/// meets the 17 of orders 1–5, the embedded 4th-order solution `b − E` the
/// 8 of orders 1–4 and not all of order 5 (which is what makes `E` an
/// error estimate); every row sums to its node.
#[test]
fn tableau_meets_the_order_conditions() {
    for (s, row) in A.iter().enumerate() {
        assert_eq!(row.len(), s);
        let sum: f64 = row.iter().sum();
        assert!((sum - C[s]).abs() < 1e-14, "row {s}: {sum} vs {}", C[s]);
    }
    let b: Vec<f64> = B.iter().copied().chain([0.0]).collect();
    let b4: Vec<f64> = b.iter().zip(&E).map(|(b, e)| b - e).collect();
    let trees = rooted_trees(5);
    assert_eq!(trees.len(), 17);
    let mut worst5 = 0.0f64;
    for ((order, _), (gamma, phi)) in trees.iter().zip(&tree_data(&trees, &A)) {
        let r = dot(&b, phi) - 1.0 / gamma;
        assert!(r.abs() < 1e-14, "b: order {order}, residual {r:e}");
        let r4 = dot(&b4, phi) - 1.0 / gamma;
        if *order <= 4 {
            assert!(r4.abs() < 1e-14, "b - E: order {order}, residual {r4:e}");
        } else {
            worst5 = worst5.max(r4.abs());
        }
    }
    assert!(worst5 > 1e-4, "the embedded solution is of order 4 only");
}

/// The dense output passes through both ends of every step exactly (to
/// rounding) and matches the exact solution to the 4th-order accuracy of
/// the continuous extension at loose tolerance.
#[test]
fn dense_output_joins_the_steps() {
    let mut s = Dopri5::new(2, tol(1e-6)).unwrap();
    let mut sys = Harmonic::plain();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    let mut worst = 0.0f64;
    let mut out = [0.0; 2];
    while s.t() < 20.0 {
        let (t0, y0) = (s.t(), s.y().to_vec());
        s.step(&mut sys, 20.0).unwrap();
        s.dense_output(&mut sys, t0, &mut out);
        assert!((out[0] - y0[0]).abs() < 1e-15 && (out[1] - y0[1]).abs() < 1e-15);
        s.dense_output(&mut sys, s.t(), &mut out);
        assert!((out[0] - s.y()[0]).abs() < 1e-15 && (out[1] - s.y()[1]).abs() < 1e-15);
        for q in [0.25, 0.5, 0.75] {
            let t = t0 + q * (s.t() - t0);
            s.dense_output(&mut sys, t, &mut out);
            worst = worst.max((out[0] - t.cos()).abs().max((out[1] + t.sin()).abs()));
        }
    }
    // No evaluation for the dense output: 6 per step plus the reset's two.
    let st = s.stats();
    assert_eq!(st.rhs_evaluations, 6 * (st.steps + st.rejected_steps) + 2);
    // Measured 8.2e-6 (the global error at t = 20 is 6.6e-6).
    assert!(worst < 3e-5, "dense error {worst:e}");
}

/// y' = −λ (y − cos t).
struct StiffLinear(f64);
impl OdeSystem for StiffLinear {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = -self.0 * (y[0] - t.cos());
    }
}

/// Steps `sys` to `t_end`; the step at which stiffness was first reported.
fn first_detection<S: OdeSystem>(
    sys: &mut S,
    y0: &[f64],
    t_end: f64,
    o: IntegratorOptions,
) -> Option<u64> {
    let mut s = Dopri5::new(sys.dim(), o).unwrap();
    s.reset(sys, 0.0, y0).unwrap();
    while s.t() < t_end {
        s.step(sys, t_end).unwrap();
        if s.stiffness_detected() {
            return Some(s.stats().steps);
        }
    }
    None
}

#[test]
fn stiffness_test_fires_on_stiff_problems_only() {
    // Stability limits DOPRI5's step to h·λ ≈ 3.3: detected after a few
    // dozen steps (measured: steps 33 and 49).
    for tl in [1e-3, 1e-6] {
        let first = first_detection(&mut StiffLinear(1e4), &[0.0], 1.0, tol(tl));
        assert!(first.is_some_and(|f| f < 300), "tol {tl:e}: {first:?}");
    }
    // Off: never reported.
    let off = IntegratorOptions {
        stiffness_check: false,
        ..tol(1e-6)
    };
    assert_eq!(
        first_detection(&mut StiffLinear(1e4), &[0.0], 1.0, off),
        None
    );
    // Non-stiff: never.
    for tl in [1e-3, 1e-6, 1e-9] {
        assert_eq!(
            first_detection(&mut Harmonic::plain(), &[1.0, 0.0], 100.0, tol(tl)),
            None
        );
    }
}
