//! Response spectra against closed forms and an independent integration.

use super::*;
use crate::model::record::{parse_columns, Units};

/// A record of `n` steps of h with acceleration `f(t)` (m/s²).
fn record(n: usize, h: f64, f: impl Fn(f64) -> f64) -> Record {
    let text: String = (0..=n)
        .map(|k| {
            let t = k as f64 * h;
            format!("{t:e} {:e}\n", f(t))
        })
        .collect();
    parse_columns(&text, "test", Some(Units::MetersPerSecond2)).unwrap()
}

/// The exact response of a damped oscillator at rest to a constant ground
/// acceleration a from t = 0: x(t) = −a/ω² (1 − e^{−ζωt}(cos ω_d t +
/// ζω/ω_d sin ω_d t)); its peak over the samples, to 1e-12 relative.
#[test]
fn constant_acceleration_matches_the_closed_form() {
    let (h, n, a) = (0.01, 2000, 0.3);
    let r = record(n, h, |_| a);
    for (period, zeta) in [(0.1, 0.05), (1.0, 0.02), (3.0, 0.0)] {
        let s = response_spectrum(&r, 1.0, zeta, &[period]).unwrap()[0];
        let w = 2.0 * std::f64::consts::PI / period;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let exact = (1..=n)
            .map(|k| {
                let t = k as f64 * h;
                let x = -a / (w * w)
                    * (1.0
                        - (-zeta * w * t).exp()
                            * ((wd * t).cos() + zeta * w / wd * (wd * t).sin()));
                x.abs()
            })
            .fold(0.0, f64::max);
        assert!(
            (s.displacement - exact).abs() < 1e-12 * exact,
            "T = {period}: {} vs {exact}",
            s.displacement
        );
        assert!(
            (s.pseudo_acceleration - w * w * s.displacement).abs() < 1e-15 * s.pseudo_acceleration
        );
    }
}

/// A sine record sampled coarsely is a piecewise-linear input: the
/// recurrence equals an independent integration (DOP853 at rtol 1e-12 of
/// the oscillator under the linear interpolant, step by step) to 1e-9
/// relative in the peak.
#[test]
fn piecewise_linear_input_matches_an_integration() {
    use crate::integrate::{integrate_to, IntegratorOptions, OdeSystem};
    let (h, n) = (0.02, 300);
    let r = record(n, h, |t| 2.0 * (7.0 * t).sin() + 0.5 * (19.0 * t).cos());
    struct Osc<'a> {
        w: f64,
        z: f64,
        r: &'a Record,
    }
    impl OdeSystem for Osc<'_> {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
            let k = ((t / 0.02) as usize).min(self.r.times.len() - 2);
            let s = (t - self.r.times[k]) / 0.02;
            let a = self.r.acceleration[k] * (1.0 - s) + self.r.acceleration[k + 1] * s;
            dy[0] = y[1];
            dy[1] = -2.0 * self.z * self.w * y[1] - self.w * self.w * y[0] - a;
        }
    }
    for period in [0.15, 0.8] {
        let w = 2.0 * std::f64::consts::PI / period;
        let mut sys = Osc { w, z: 0.05, r: &r };
        let opts = IntegratorOptions {
            rtol: 1e-12,
            atol: 1e-15,
            ..IntegratorOptions::default()
        };
        let mut y = vec![0.0, 0.0];
        let mut peak = 0.0f64;
        for k in 0..n {
            let (next, _) =
                integrate_to(&mut sys, k as f64 * h, &y, (k + 1) as f64 * h, &opts).unwrap();
            y = next;
            peak = peak.max(y[0].abs());
        }
        let s = response_spectrum(&r, 1.0, 0.05, &[period]).unwrap()[0];
        assert!(
            (s.displacement - peak).abs() < 1e-9 * peak,
            "T = {period}: {} vs {peak}",
            s.displacement
        );
    }
}

#[test]
fn bad_input_is_refused() {
    let r = record(10, 0.01, |t| t);
    let e = response_spectrum(&r, 1.0, 1.5, &[1.0]).unwrap_err();
    assert_eq!((e.field, e.value.as_deref()), ("damping", Some("1.5")));
    assert_eq!(e.to_string(), "damping = 1.5: give a ratio in [0, 1)");
    assert_eq!(
        e.spelled("--damping", " "),
        "--damping 1.5: give a ratio in [0, 1)"
    );
    let e = response_spectrum(&r, 1.0, 0.05, &[0.0]).unwrap_err();
    assert_eq!(e.field, "periods");
    assert!(periods(1.0, 0.5, 10, true).unwrap_err().contains("periods"));
    let p = periods(0.05, 5.0, 100, true).unwrap();
    assert_eq!(p.len(), 100);
    assert!((p[99] - 5.0).abs() < 1e-12 && (p[0] - 0.05).abs() < 1e-15);
}
