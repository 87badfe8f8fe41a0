//! Checks of the Lyapunov exponents against independent computations: the
//! exact linear limit, the Floquet multipliers of a stable orbit, and
//! Liouville's formula (the sum of the spectrum is the mean divergence of
//! the vector field).

use super::*;
use crate::integrate::integrate_to;
use crate::model::reference::{r2, r3, DAMPING_RATIO as ZETA, NATURAL_FREQUENCY as W0};
use crate::model::{Accelerogram, BaseExcitation};
use crate::periodic::{shoot, ShootingOptions};

/// R3 (nothing touches): every exponent is −ζω0, the real part of the
/// oscillators' eigenvalues. The sum is exact (Liouville: the trace of
/// the linear system, −2ζω0 per body); each exponent of a complex pair
/// converges like ζ/t (measured 5e-5 over 200 periods) and lies within
/// its own convergence estimate.
#[test]
fn linear_limit_exponents() {
    let model = r3(2, 0.9 * W0).unwrap();
    let ly = lyapunov_spectrum(
        &model,
        &[1e-3, 0.0, 0.0, 2e-3],
        0.0,
        &LyapunovOptions::default(),
    )
    .unwrap();
    let exact = -ZETA * W0;
    let sum: f64 = ly.exponents.iter().sum();
    assert!(
        (sum - 4.0 * exact).abs() < 1e-8 * exact.abs(),
        "{sum} vs {}",
        4.0 * exact
    );
    for (l, u) in ly.exponents.iter().zip(&ly.uncertainty) {
        assert!((l - exact).abs() < 1e-4, "{l} vs {exact}");
        assert!((l - exact).abs() <= *u, "{l} vs {exact}: estimate {u:e}");
    }
}

/// On the stable orbit of R2 N = 2 at 1.05 ω0 (two complex pairs, moduli
/// 0.9146 and 0.8953), found by shooting, the exponents are ln|μ|/T: the
/// sum of each pair (the growth of the pair's plane, which the QR
/// iteration separates geometrically, by 0.979 a period here) to 1e-6;
/// each exponent of a pair converges like 1/t only (measured 1.2e-3 after
/// 400 periods) and lies within its convergence estimate (2.7e-3).
#[test]
fn stable_orbit_exponents_are_the_floquet_exponents() {
    let model = r2(2, 1e-3, 1.05 * W0).unwrap();
    let sol = shoot(&model, &[0.0; 4], &ShootingOptions::default()).unwrap();
    assert!(sol.converged && sol.stable());
    let floquet: Vec<f64> = sol
        .multipliers
        .iter()
        .map(|m| m.norm().ln() / sol.period)
        .collect();
    assert!(floquet[1] - floquet[2] > 0.01, "{floquet:?}");
    let opts = LyapunovOptions {
        transient: 1000,
        periods: 400,
        ..LyapunovOptions::default()
    };
    let ly = lyapunov_spectrum(&model, &sol.initial_state, 0.0, &opts).unwrap();
    for pair in [0..2, 2..4] {
        let lyap: f64 = ly.exponents[pair.clone()].iter().sum();
        let exact: f64 = floquet[pair.clone()].iter().sum();
        assert!((lyap - exact).abs() < 1e-6, "{pair:?}: {lyap} vs {exact}");
    }
    for ((l, f), u) in ly.exponents.iter().zip(&floquet).zip(&ly.uncertainty) {
        assert!(
            (l - f).abs() <= *u && *u < 5e-3,
            "{l} vs {f}: estimate {u:e}"
        );
    }
    // The two largest alone are the first two of the full spectrum: the
    // same first columns, orthonormalised the same way (on other steps:
    // the columns enter the step control).
    let two = LyapunovOptions {
        count: Some(2),
        ..opts
    };
    let top = lyapunov_spectrum(&model, &sol.initial_state, 0.0, &two).unwrap();
    for (a, b) in top.exponents.iter().zip(&ly.exponents) {
        assert!((a - b).abs() < 1e-8, "{a} vs {b}");
    }
}

/// The state of a row with one more component, the integral of the
/// divergence of the vector field: the bodies' dampers and the contacts'
/// velocity dependence (∂F/∂ṡ by a central difference of the contact
/// force, not from the analytic Jacobian).
struct WithDivergence {
    sys: ChainDynamics,
    /// (state indices of the left and right velocities, 1/m of each).
    contacts: Vec<([Option<usize>; 2], [f64; 2])>,
    body_damping: f64,
}

impl WithDivergence {
    fn new(model: &Model) -> Self {
        let sys = ChainDynamics::new(model, false);
        let inv_mass: Vec<f64> = model.bodies().iter().map(|b| 1.0 / b.mass).collect();
        let contacts = (0..model.contacts().len())
            .map(|k| {
                let [_, vl, _, vr] = sys.contact_indices(k);
                let m = |v: Option<usize>| v.map_or(0.0, |i| inv_mass[i / 2]);
                ([vl, vr], [m(vl), m(vr)])
            })
            .collect();
        let body_damping = model.bodies().iter().map(|b| b.damping / b.mass).sum();
        Self {
            sys,
            contacts,
            body_damping,
        }
    }

    fn divergence(&self, y: &[f64]) -> f64 {
        let mut div = -self.body_damping;
        for (k, (_, inv_m)) in self.contacts.iter().enumerate() {
            let (s, sdot) = self.sys.approach(k, y);
            let h = 1e-6 * sdot.abs().max(1e-3);
            let df = (self.sys.contact_force(k, s, sdot + h)
                - self.sys.contact_force(k, s, sdot - h))
                / (2.0 * h);
            div -= df * (inv_m[0] + inv_m[1]);
        }
        div
    }
}

impl OdeSystem for WithDivergence {
    fn dim(&self) -> usize {
        self.sys.dim() + 1
    }

    fn rhs(&mut self, t: f64, y: &[f64], dydt: &mut [f64]) {
        let d = self.sys.dim();
        self.sys.rhs(t, &y[..d], &mut dydt[..d]);
        dydt[d] = self.divergence(&y[..d]);
    }
}

/// The sum of the full spectrum over a window is the mean divergence of
/// the vector field over it (Liouville), for impacting motion of R2 N = 2
/// at 1.05 ω0 from a displaced start to its stable orbit (the contact
/// damping dominates the divergence during impacts): to 1e-6 relative
/// (measured 1e-7).
#[test]
fn spectrum_sum_is_the_mean_divergence() {
    let model = r2(2, 1e-3, 1.05 * W0).unwrap();
    let x0 = [0.5e-3, -0.5e-3, 0.02, 0.0];
    let opts = LyapunovOptions {
        transient: 0,
        periods: 60,
        ..LyapunovOptions::default()
    };
    let ly = lyapunov_spectrum(&model, &x0, 0.0, &opts).unwrap();
    let mut sys = WithDivergence::new(&model);
    let mut y0 = to_interleaved(&x0);
    y0.push(0.0);
    // The contact damping is a spike of ~1 ms at every impact: the
    // quadrature needs a tight tolerance (at 1e-9 it is off by 3e-3, at
    // 1e-10 by 7e-7, at 1e-12 by 1e-10 relative).
    let int = IntegratorOptions {
        rtol: 1e-12,
        atol: 1e-15,
        ..IntegratorOptions::default()
    };
    let (y, _) = integrate_to(&mut sys, 0.0, &y0, ly.averaging_time, &int).unwrap();
    let mean = y[4] / ly.averaging_time;
    let sum: f64 = ly.exponents.iter().sum();
    assert!((sum - mean).abs() < 1e-6 * mean.abs(), "{sum} vs {mean}");
    // The contacts matter: the bodies' dampers alone give −4ζω0.
    assert!((mean + 4.0 * ZETA * W0).abs() > 0.05 * mean.abs(), "{mean}");
}

/// Bad input is refused with the reason.
#[test]
fn bad_input_is_refused() {
    let model = r2(2, 1e-3, W0).unwrap();
    let run = |x: &[f64], opts: LyapunovOptions| {
        lyapunov_spectrum(&model, x, 0.0, &opts)
            .unwrap_err()
            .to_string()
    };
    let x = [0.0; 4];
    assert!(run(&x[..3], LyapunovOptions::default()).contains("needs 4 values"));
    assert!(run(&[f64::NAN, 0.0, 0.0, 0.0], LyapunovOptions::default()).contains("finite"));
    for count in [0, 5] {
        let opts = LyapunovOptions {
            count: Some(count),
            ..LyapunovOptions::default()
        };
        assert!(run(&x, opts).contains(&format!("count = {count}")));
    }
    let opts = LyapunovOptions {
        periods: 1,
        ..LyapunovOptions::default()
    };
    assert!(run(&x, opts).contains("periods = 1"));
    let recorded = model.clone().with_base(BaseExcitation::Record(
        Accelerogram::new(vec![0.0, 1.0], vec![0.0, 1.0], 1.0).unwrap(),
    ));
    let err = lyapunov_spectrum(&recorded, &x, 0.0, &LyapunovOptions::default()).unwrap_err();
    assert!(err.to_string().contains("periodic forcing"), "{err}");
}

/// The stated uncertainty is the scatter of repeated runs: on the chaotic
/// attractor of R2 N = 2 at 0.8409 ω0, sixteen consecutive windows of 200
/// periods each give largest exponents whose standard deviation is the
/// mean stated standard error to within a factor 2 (measured 0.034
/// against 0.049, ratio 0.70; twelve windows of 400 periods 0.95, of 100
/// periods 1.32; the former estimate, the running average's settling,
/// stated about half the scatter).
#[test]
fn the_uncertainty_is_the_scatter_of_repeated_runs() {
    let model = r2(2, 1e-3, 0.8409 * W0).unwrap();
    let settle = LyapunovOptions {
        count: Some(1),
        transient: 200,
        periods: 2,
        ..LyapunovOptions::default()
    };
    let mut x = lyapunov_spectrum(&model, &[1e-4, 0.0, 0.0, 0.0], 0.0, &settle)
        .unwrap()
        .final_state;
    let window = LyapunovOptions {
        count: Some(1),
        transient: 0,
        periods: 200,
        ..LyapunovOptions::default()
    };
    let (mut largest, mut stated) = (Vec::new(), Vec::new());
    for _ in 0..16 {
        let ly = lyapunov_spectrum(&model, &x, 0.0, &window).unwrap();
        x = ly.final_state;
        largest.push(ly.exponents[0]);
        stated.push(ly.uncertainty[0]);
    }
    let n = largest.len() as f64;
    let mean = largest.iter().sum::<f64>() / n;
    assert!(mean > 0.3, "not chaotic: {largest:?}");
    let sd = (largest.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let se = stated.iter().sum::<f64>() / n;
    assert!(
        (0.5..=2.0).contains(&(sd / se)),
        "scatter {sd} against stated {se}"
    );
}

/// The local integrator's exponents (tangents carried by the exact
/// transition matrices of the free motion, integrated only in the active
/// set) against the independent values: R3's −ζω0 (the sum exact to
/// rounding: measured 3e-16 relative, the global integrator's 2e-10), the
/// Floquet exponents of R2 N = 2's stable orbit at 1.05 ω0 (pair sums to
/// 1e-6, every exponent the global integrator's to 1e-8), and on the
/// chaotic attractor at 0.8409 ω0 the global integrator's largest exponent
/// and its sum, the means of four runs each (measured over 1000 periods:
/// 0.675 and 0.640, three standard errors 0.056; sums to 1e-2).
#[test]
fn local_exponents_match_independent_values() {
    use crate::simulate::Integrator;
    let local = |opts: LyapunovOptions| LyapunovOptions {
        integrator: Integrator::Local,
        ..opts
    };
    let r3_model = r3(2, 0.9 * W0).unwrap();
    let ly = lyapunov_spectrum(
        &r3_model,
        &[1e-3, 0.0, 0.0, 2e-3],
        0.0,
        &local(LyapunovOptions::default()),
    )
    .unwrap();
    let exact = -ZETA * W0;
    let sum: f64 = ly.exponents.iter().sum();
    assert!((sum - 4.0 * exact).abs() < 1e-12 * exact.abs(), "{sum}");
    for (l, u) in ly.exponents.iter().zip(&ly.uncertainty) {
        assert!((l - exact).abs() <= *u, "{l} vs {exact}: estimate {u:e}");
    }

    let model = r2(2, 1e-3, 1.05 * W0).unwrap();
    let sol = shoot(&model, &[0.0; 4], &ShootingOptions::default()).unwrap();
    let floquet: Vec<f64> = sol
        .multipliers
        .iter()
        .map(|m| m.norm().ln() / sol.period)
        .collect();
    let opts = LyapunovOptions {
        transient: 1000,
        periods: 400,
        ..LyapunovOptions::default()
    };
    let (g, l) = (
        lyapunov_spectrum(&model, &sol.initial_state, 0.0, &opts).unwrap(),
        lyapunov_spectrum(&model, &sol.initial_state, 0.0, &local(opts.clone())).unwrap(),
    );
    for pair in [0..2, 2..4] {
        let lyap: f64 = l.exponents[pair.clone()].iter().sum();
        let exact: f64 = floquet[pair.clone()].iter().sum();
        assert!((lyap - exact).abs() < 1e-6, "{pair:?}: {lyap} vs {exact}");
    }
    for (a, b) in g.exponents.iter().zip(&l.exponents) {
        assert!((a - b).abs() < 1e-8, "{a} vs {b}");
    }

    let chaotic = r2(2, 1e-3, 0.8409 * W0).unwrap();
    let opts = LyapunovOptions {
        transient: 200,
        periods: 1000,
        ..LyapunovOptions::default()
    };
    // Four starts 1e-12 apart per integrator: on the attractor each run's
    // estimate is one draw (a change of rounding alone moved the local
    // run's from 0.665 to 0.595, 3.5 stated errors), so the two
    // integrators' means are compared, within three standard errors of
    // their difference from the runs' own scatter.
    let runs = |opts: &LyapunovOptions| -> Vec<LyapunovSpectrum> {
        (0..4)
            .map(|j| {
                let x0 = [1e-4 * (1.0 + 1e-12 * j as f64), 0.0, 0.0, 0.0];
                lyapunov_spectrum(&chaotic, &x0, 0.0, opts).unwrap()
            })
            .collect()
    };
    let (g, l) = (runs(&opts), runs(&local(opts.clone())));
    let stats = |runs: &[LyapunovSpectrum], f: &dyn Fn(&LyapunovSpectrum) -> f64| {
        let v: Vec<f64> = runs.iter().map(f).collect();
        let mean = v.iter().sum::<f64>() / 4.0;
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 3.0;
        (mean, var)
    };
    let first = |s: &LyapunovSpectrum| s.exponents[0];
    let ((mg, vg), (ml, vl)) = (stats(&g, &first), stats(&l, &first));
    let se = ((vg + vl) / 4.0).sqrt();
    assert!(
        (mg - ml).abs() < 3.0 * se && ml > 0.3,
        "{mg} ± {se} vs {ml}: {g:?} {l:?}"
    );
    // The sums are time averages of the phase-space contraction (the
    // contacts' damping along trajectories that part after a few
    // periods): estimates with a scatter of their own (measured: 4e-3
    // apart over 1000 periods).
    let sum = |s: &LyapunovSpectrum| s.exponents.iter().sum::<f64>();
    let ((sg, _), (sl, _)) = (stats(&g, &sum), stats(&l, &sum));
    assert!((sg - sl).abs() < 1e-2 * sg.abs(), "{sg} vs {sl}");
}

/// A law that needs the impact's onset velocity (Lankarani–Nikravesh) is
/// refused by either integrator's exponents, by contact.
#[test]
fn exponents_refuse_onset_velocity_laws() {
    use crate::contact::{ContactLaw, ForceForm};
    use crate::simulate::Integrator;
    let law = ContactLaw::lankarani_nikravesh(1e7, 1.5, 0.8, 1e-3, ForceForm::Published).unwrap();
    let model = r2(2, 1e-3, 0.9 * W0).unwrap().with_contact_law(law);
    for integrator in [Integrator::Global, Integrator::Local] {
        let opts = LyapunovOptions {
            integrator,
            ..LyapunovOptions::default()
        };
        let e = lyapunov_spectrum(&model, &[0.0; 4], 0.0, &opts).unwrap_err();
        assert!(e.to_string().contains("onset velocity"), "{e}");
        assert!(e.to_string().contains(&model.contact_name(0)), "{e}");
    }
}

/// Through rigid impacts the tangent vectors take each impact's saltation
/// (docs/theory.md §12): on the impact oscillator's stable one-impact
/// orbit with the seed's e(U), the spectrum's sum is ln |det Φ| / T of
/// its monodromy to 1e-9 (det Φ = e (e + U de/dU) e^{−2ζT}), and each
/// exponent is ln |μ| / T of its complex pair of multipliers to 1e-3.
#[test]
fn rigid_impacts_exponents_equal_the_orbits_multipliers() {
    use crate::contact::{ContactLaw, ForceForm};
    use crate::model::Impacts;
    use crate::simulate::tests::rigid::oscillator;
    let law = ContactLaw::exponential(2.5, 1.0, 1e3, ForceForm::Published).unwrap();
    let model = oscillator(0.05, 0.6, (1.0, 1.5, 0.0), (0.0, 0.0))
        .with_contact_law(law)
        .with_all_impacts(Impacts::Rigid { restitution: None })
        .unwrap();
    let shooting = ShootingOptions {
        rtol: 1e-12,
        tol: 1e-10,
        displacement_scale: 0.1,
        ..Default::default()
    };
    let sol = shoot(&model, &[-0.5, 1.0], &shooting).unwrap();
    assert!(sol.converged && sol.stable(), "{:?}", sol.multipliers);
    let ly = lyapunov_spectrum(
        &model,
        &sol.initial_state,
        0.0,
        &LyapunovOptions {
            transient: 0,
            periods: 100,
            rtol: 1e-11,
            ..Default::default()
        },
    )
    .unwrap();
    let t = sol.period;
    let sum: f64 = ly.exponents.iter().sum();
    let det: f64 = sol.multipliers.iter().map(|m| m.norm().ln()).sum::<f64>() / t;
    eprintln!(
        "exponents {:?} vs multipliers {:?}",
        ly.exponents, sol.multipliers
    );
    assert!((sum / det - 1.0).abs() < 1e-9, "{sum} vs {det}");
    for (l, m) in ly.exponents.iter().zip(&sol.multipliers) {
        assert!(
            (l - m.norm().ln() / t).abs() < 1e-3 * det.abs(),
            "{l} vs {m}"
        );
    }
}
