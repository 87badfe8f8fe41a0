//! Conformance suite: the same checks for every method plugged into the
//! [`Driver`]: observed order of the solution and of the dense output,
//! dense-output accuracy under adaptive control, the exact end time, NaN
//! rejection with recovery, admissibility, the step limit and the interrupt,
//! and a restart keeping the step size.

use super::systems::{fixed, tol, Decay, Harmonic};
use crate::integrate::{
    Dop853Method, Dopri5Method, Driver, IntegrationError, IntegratorOptions, Interrupt, OdeSystem,
    RejectReason, RodasMethod, StepMethod,
};

/// Forced, damped oscillator `x'' + 0.2 x' + x = cos(1.3 t)`, from (1, 0):
/// non-autonomous (exercises RODAS's `∂f/∂t`), exact solution known.
struct Forced;

const ZETA2: f64 = 0.2;
const OMEGA: f64 = 1.3;

impl Forced {
    /// The particular (steady-state) solution and its derivative.
    fn particular(t: f64) -> [f64; 2] {
        let (k, c) = (1.0 - OMEGA * OMEGA, ZETA2 * OMEGA);
        let det = k * k + c * c;
        let (a, b) = (k / det, c / det);
        let (cs, sn) = ((OMEGA * t).cos(), (OMEGA * t).sin());
        [a * cs + b * sn, OMEGA * (b * cs - a * sn)]
    }

    /// Exact solution at `t` through `y0` at `t0`: the particular solution
    /// plus the free damped oscillation `e^{-τ/10}(C cos ω_d τ + D sin ω_d τ)`,
    /// `τ = t − t0`.
    fn exact_from(t0: f64, y0: &[f64], t: f64) -> [f64; 2] {
        let (p0, p) = (Self::particular(t0), Self::particular(t));
        let wd = (1.0 - 0.01_f64).sqrt();
        let cc = y0[0] - p0[0];
        let dd = (y0[1] - p0[1] + 0.1 * cc) / wd;
        let tau = t - t0;
        let e = (-0.1 * tau).exp();
        let (cs, sn) = ((wd * tau).cos(), (wd * tau).sin());
        [
            p[0] + e * (cc * cs + dd * sn),
            p[1] + e * (-0.1 * (cc * cs + dd * sn) + wd * (dd * cs - cc * sn)),
        ]
    }

    /// Exact solution from (1, 0) at t = 0.
    fn exact(t: f64) -> [f64; 2] {
        Self::exact_from(0.0, &[1.0, 0.0], t)
    }
}

impl OdeSystem for Forced {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, t: f64, y: &[f64], d: &mut [f64]) {
        d[0] = y[1];
        d[1] = (OMEGA * t).cos() - ZETA2 * y[1] - y[0];
    }
}

fn max_err(y: &[f64], t: f64) -> f64 {
    let e = Forced::exact(t);
    (y[0] - e[0]).abs().max((y[1] - e[1]).abs())
}

/// Global error at t = 2 with fixed steps h, and the largest local error
/// of the dense output at the step midpoints (against the exact solution
/// through each step's start).
fn fixed_step_errors<M: StepMethod>(h: f64) -> (f64, f64) {
    let mut s = Driver::<M>::new(2, fixed(h)).unwrap();
    let mut sys = Forced;
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    let mut dense = 0.0f64;
    let mut mid = [0.0; 2];
    while s.t() < 2.0 {
        s.step(&mut sys, 2.0).unwrap();
        let tm = 0.5 * (s.t_prev() + s.t());
        s.dense_output(&mut sys, tm, &mut mid);
        // Local reference: the exact solution through the step's start.
        let local = Forced::exact_from(s.t_prev(), &s.at.y_prev, tm);
        dense = dense.max((mid[0] - local[0]).abs().max((mid[1] - local[1]).abs()));
    }
    (max_err(s.y(), 2.0), dense)
}

/// Observed orders from halving the step.
fn observed_orders<M: StepMethod>(h: f64) -> (f64, f64) {
    let (g1, d1) = fixed_step_errors::<M>(h);
    let (g2, d2) = fixed_step_errors::<M>(h / 2.0);
    ((g1 / g2).log2(), (d1 / d2).log2())
}

/// Every method: solution order `p`, dense-output local order at least
/// `q + 1` for a dense output of order `q` (measured on the forced
/// oscillator).
fn check_orders<M: StepMethod>(h: f64, p: f64, q: f64) {
    let (order, dense_order) = observed_orders::<M>(h);
    assert!((order - p).abs() < 0.6, "order {order} vs {p}");
    assert!(dense_order > q + 0.5, "dense order {dense_order} vs {q}");
}

/// Adaptive runs at tolerance 1e-9: the solution and the dense output at
/// the step midpoints stay within 100× the tolerance of the exact
/// solution, and the final time is exactly the end time.
fn check_adaptive_accuracy_and_end_time<M: StepMethod>(dense_factor: f64) {
    let tolerance = 1e-9;
    let t_end = 10.0 / 3.0;
    let mut s = Driver::<M>::new(2, tol(tolerance)).unwrap();
    let mut sys = Forced;
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    let mut worst_dense = 0.0f64;
    let mut mid = [0.0; 2];
    while s.t() < t_end {
        s.step(&mut sys, t_end).unwrap();
        assert!(s.t() <= t_end, "never past the bound");
        let tm = 0.5 * (s.t_prev() + s.t());
        s.dense_output(&mut sys, tm, &mut mid);
        worst_dense = worst_dense.max(max_err(&mid, tm));
        // End points are the stored states, exactly.
        assert_eq!(s.dense_component(&mut sys, 0, s.t()), s.y()[0]);
    }
    assert_eq!(s.t(), t_end, "lands exactly on the end time");
    let err = max_err(s.y(), t_end);
    assert!(err < 100.0 * tolerance, "error {err:e}");
    assert!(
        worst_dense < dense_factor * tolerance,
        "dense error {worst_dense:e}"
    );
}

/// `restart` after a change of state (an impulse, columns made
/// orthonormal again) evaluates `f` once, keeps the proposed step, and the
/// run continues on the exact solution through the new state (within
/// 100× the tolerance).
fn check_restart<M: StepMethod>() {
    let tolerance = 1e-9;
    let mut s = Driver::<M>::new(2, tol(tolerance)).unwrap();
    let mut sys = Forced;
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    s.step(&mut sys, 10.0).unwrap();
    let (h, evaluations, t) = (s.h_next(), s.stats().rhs_evaluations, s.t());
    let kicked = [s.y()[0] + 0.25, s.y()[1] - 0.5];
    s.restart(&mut sys, &kicked).unwrap();
    assert_eq!(s.stats().rhs_evaluations, evaluations + 1);
    assert_eq!((s.t(), s.h_next(), s.y()), (t, h, &kicked[..]));
    let t_end = t + 2.0;
    while s.t() < t_end {
        s.step(&mut sys, t_end).unwrap();
    }
    let exact = Forced::exact_from(t, &kicked, t_end);
    let err = s
        .y()
        .iter()
        .zip(&exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 100.0 * tolerance, "error {err:e} after the restart");
}

/// A first step of 10 (far outside DOP853's stability region; for RODAS
/// a stage argument `y·(1 − 1.544·hγ/(1 + hγ)) < 0`) runs into the trap;
/// the attempt is rejected and retried, the solution stays finite and
/// accurate, and the accepted step does not propose a larger one.
fn check_nan_in_stages<M: StepMethod>(trap: fn(&mut Decay)) {
    let mut sys = Decay::new();
    trap(&mut sys);
    let opts = IntegratorOptions {
        h_init: Some(10.0),
        ..tol(1e-10)
    };
    let mut s = Driver::<M>::new(1, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0]).unwrap();
    s.step(&mut sys, 10.0).unwrap();
    assert!(sys.nan_returns > 0, "the trap must fire");
    assert!(s.stats().rejected_steps > 0);
    assert!(s.t() < 10.0);
    assert!(s.h_next() <= s.t() - s.t_prev());
    while s.t() < 10.0 {
        s.step(&mut sys, 10.0).unwrap();
        assert!(s.y()[0].is_finite());
    }
    let err = (s.y()[0] - (-10f64).exp()).abs();
    assert!(err < 1e-10, "final error {err:e}");
}

/// Steps until an error.
fn run_until_error<M: StepMethod>(
    s: &mut Driver<M>,
    sys: &mut Decay,
    t_end: f64,
) -> IntegrationError {
    loop {
        match s.step(sys, t_end) {
            Err(e) => return e,
            Ok(()) => assert!(s.t() < t_end, "should fail before {t_end}"),
        }
    }
}

/// `f` = NaN for t > 0.7: the integrator creeps up to 0.7 and gives up
/// with a step-size underflow there (reason and point in the message),
/// keeps its last point and can be reset.
fn check_nan_beyond_time<M: StepMethod>() {
    let mut sys = Decay::new();
    sys.nan_after = 0.7;
    let mut s = Driver::<M>::new(1, tol(1e-10)).unwrap();
    s.reset(&mut sys, 0.0, &[1.0]).unwrap();
    let err = run_until_error(&mut s, &mut sys, 2.0);
    match &err {
        IntegrationError::StepSizeUnderflow { t, h, y, reason } => {
            assert_eq!(*reason, RejectReason::NonFinite);
            assert!(*t <= 0.7 && 0.7 - t < 1e-12, "t = {t}");
            assert!(*h < 16.0 * f64::EPSILON * t);
            assert!((y[0] - (-t).exp()).abs() < 1e-9, "y = {y:?}");
            assert_eq!((*t, y.as_slice()), (s.t(), s.y()), "last accepted point");
            let msg = err.to_string();
            for part in [
                "underflow".to_string(),
                format!("t = {t:e}"),
                format!("h = {h:e}"),
                format!("{y:?}"),
                RejectReason::NonFinite.to_string(),
            ] {
                assert!(msg.contains(&part), "{msg:?} lacks {part:?}");
            }
        }
        other => panic!("unexpected error {other:?}"),
    }
    s.reset(&mut Decay::new(), 0.0, &[1.0]).unwrap();
    s.step(&mut Decay::new(), 1.0).unwrap();
    // A non-finite initial state is refused, and stepping with it.
    assert!(matches!(
        s.reset(&mut sys, 0.0, &[f64::NAN]),
        Err(IntegrationError::NonFiniteInitialState { .. })
    ));
    assert!(matches!(
        s.step(&mut sys, 1.0),
        Err(IntegrationError::InvalidOptions(_))
    ));
}

/// Inadmissible states: admissible only within 1e-3 of the exact solution,
/// a first step of 10 (far off for both methods) is rejected and the run
/// recovers; a region left by the exact solution (y >= 0.3, left at
/// t* = ln(1/0.3)) ends in an underflow at its boundary with reason
/// NotAdmissible.
fn check_admissibility<M: StepMethod>() {
    let mut sys = Decay::new();
    sys.tube = 1e-3;
    let opts = IntegratorOptions {
        h_init: Some(10.0),
        ..tol(1e-10)
    };
    let mut s = Driver::<M>::new(1, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0]).unwrap();
    while s.t() < 10.0 {
        s.step(&mut sys, 10.0).unwrap();
    }
    assert!(sys.inadmissible.get() > 0, "the test must fire");
    assert!(s.stats().rejected_steps >= sys.inadmissible.get());
    assert!((s.y()[0] - (-10f64).exp()).abs() < 1e-10);

    let mut sys = Decay::new();
    sys.admissible_min = 0.3;
    let t_star = (1.0f64 / 0.3).ln();
    let mut s = Driver::<M>::new(1, tol(1e-10)).unwrap();
    s.reset(&mut sys, 0.0, &[1.0]).unwrap();
    match run_until_error(&mut s, &mut sys, 3.0) {
        IntegrationError::StepSizeUnderflow { t, y, reason, .. } => {
            assert_eq!(reason, RejectReason::NotAdmissible);
            assert!((t - t_star).abs() < 1e-8, "t = {t}, t* = {t_star}");
            assert!(y[0] >= 0.3);
        }
        other => panic!("unexpected result {other:?}"),
    }
}

/// The step limit and the interrupt stop the integration with their
/// errors, keeping the last accepted point.
fn check_limits<M: StepMethod>() {
    let opts = IntegratorOptions {
        max_steps: 5,
        ..fixed(0.01)
    };
    let mut sys = Forced;
    let mut s = Driver::<M>::new(2, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    for _ in 0..5 {
        s.step(&mut sys, 1.0).unwrap();
    }
    let t = s.t();
    match s.step(&mut sys, 1.0) {
        Err(IntegrationError::TooManySteps { t: at, steps: 5 }) => assert_eq!(at, t),
        other => panic!("expected the step limit, got {other:?}"),
    }
    let stop = Interrupt::new();
    let opts = IntegratorOptions {
        interrupt: Some(stop.clone()),
        ..fixed(0.01)
    };
    let mut s = Driver::<M>::new(2, opts).unwrap();
    s.reset(&mut sys, 0.0, &[1.0, 0.0]).unwrap();
    s.step(&mut sys, 1.0).unwrap();
    stop.request();
    assert!(matches!(
        s.step(&mut sys, 1.0),
        Err(IntegrationError::Interrupted { t }) if t == s.t()
    ));
    assert_eq!(stop.time(), s.t());
}

/// Invalid options, dimension mismatches, non-finite initial states and
/// stepping before a successful reset are refused.
fn check_misuse<M: StepMethod>() {
    let bad = |o: IntegratorOptions| {
        matches!(
            Driver::<M>::new(2, o),
            Err(IntegrationError::InvalidOptions(_))
        )
    };
    assert!(bad(tol(0.0)));
    assert!(bad(IntegratorOptions {
        atol: -1.0,
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        rtol: f64::NAN,
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        h_init: Some(0.0),
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        h_max: 0.0,
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        h_min: 2.0,
        h_max: 1.0,
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        max_steps: 0,
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        error_components: Some(0),
        ..Default::default()
    }));
    assert!(bad(IntegratorOptions {
        error_components: Some(3),
        ..Default::default()
    }));
    assert!(matches!(
        Driver::<M>::new(0, IntegratorOptions::default()),
        Err(IntegrationError::InvalidOptions(_))
    ));

    let mut s = Driver::<M>::new(2, IntegratorOptions::default()).unwrap();
    let mut sys = Harmonic::plain();
    assert!(matches!(
        s.step(&mut sys, 1.0),
        Err(IntegrationError::InvalidOptions(_))
    ));
    assert!(matches!(
        s.reset(&mut sys, 0.0, &[1.0]),
        Err(IntegrationError::InvalidOptions(_))
    ));
    assert!(matches!(
        s.reset(&mut Decay::new(), 0.0, &[1.0]),
        Err(IntegrationError::InvalidOptions(_))
    ));
    assert!(matches!(
        s.reset(&mut sys, f64::NAN, &[1.0, 0.0]),
        Err(IntegrationError::InvalidOptions(_))
    ));
    assert!(matches!(
        s.reset(&mut sys, 2.0, &[f64::NAN, 0.0]),
        Err(IntegrationError::NonFiniteInitialState { t }) if t == 2.0
    ));
    let mut nan_sys = Decay::new();
    nan_sys.nan_above = 0.5;
    let mut s1 = Driver::<M>::new(1, IntegratorOptions::default()).unwrap();
    assert!(matches!(
        s1.reset(&mut nan_sys, 0.0, &[1.0]),
        Err(IntegrationError::NonFiniteInitialState { .. })
    ));
    assert!(matches!(
        s1.step(&mut nan_sys, 1.0),
        Err(IntegrationError::InvalidOptions(_))
    ));
}

#[test]
fn dop853_conforms() {
    // Measured at h = 0.5, 0.25: orders 7.98 and 7.96 (dense output of
    // order 7: local error h^8).
    check_orders::<Dop853Method>(0.5, 8.0, 7.0);
    check_adaptive_accuracy_and_end_time::<Dop853Method>(100.0);
    check_nan_in_stages::<Dop853Method>(|d| d.nan_above = 1.5);
    check_nan_beyond_time::<Dop853Method>();
    check_admissibility::<Dop853Method>();
    check_limits::<Dop853Method>();
    check_misuse::<Dop853Method>();
    check_restart::<Dop853Method>();
}

#[test]
fn dopri5_conforms() {
    // Measured at h = 0.1, 0.05: orders 5.03 and 4.96 (dense output of
    // order 4: local error h^5).
    check_orders::<Dopri5Method>(0.1, 5.0, 4.0);
    check_adaptive_accuracy_and_end_time::<Dopri5Method>(100.0);
    check_nan_in_stages::<Dopri5Method>(|d| d.nan_above = 1.5);
    check_nan_beyond_time::<Dopri5Method>();
    check_admissibility::<Dopri5Method>();
    check_limits::<Dopri5Method>();
    check_misuse::<Dopri5Method>();
    check_restart::<Dopri5Method>();
}

#[test]
fn rodas_conforms() {
    // Measured at h = 0.05, 0.025: orders 4.00 and 4.00 (dense output of
    // order 3: local error h^4).
    check_orders::<RodasMethod>(0.05, 4.0, 3.0);
    // The 3rd-order dense output is less accurate than the solution.
    check_adaptive_accuracy_and_end_time::<RodasMethod>(1e4);
    check_nan_in_stages::<RodasMethod>(|d| d.nan_below = 0.0);
    check_nan_beyond_time::<RodasMethod>();
    check_admissibility::<RodasMethod>();
    check_limits::<RodasMethod>();
    check_misuse::<RodasMethod>();
    check_restart::<RodasMethod>();
}
