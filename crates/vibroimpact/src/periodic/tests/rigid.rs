//! Periodic orbits through rigid impacts (docs/theory.md §12): the
//! saltation's monodromy against differences of the period map, the
//! impact oscillator's closed-form orbit by shooting, and the multipliers'
//! product against the saltation's determinant.

use super::*;
use crate::contact::{ContactLaw, ForceForm};
use crate::impact::closed_form::{restitution, restitution_derivative};
use crate::model::Impacts;
use crate::simulate::tests::rigid::{oscillator, shaw_holmes};
use crate::simulate::{simulate, SimulationOptions};

const ZETA_O: f64 = 0.05;
const GAP: f64 = 0.6;
const OMEGA: f64 = 1.5;
/// The seed's a/b (m/s) of the exponential wall.
const A_OVER_B: f64 = 2.5;

fn tight() -> ShootingOptions {
    ShootingOptions {
        rtol: 1e-13,
        tol: 1e-11,
        displacement_scale: 1.0,
        ..Default::default()
    }
}

/// The impact oscillator (unit mass, ω = 1, ζ = 0.05, wall at 0.6 m,
/// force sin(1.5 t + φ)) with rigid impacts: Newton's `e`, or the
/// exponential law's e(U) of seed eq. (10) at a/b = 2.5 m/s.
fn rigid_oscillator(e: Option<f64>, phase: f64, x: (f64, f64)) -> Model {
    let model = oscillator(ZETA_O, GAP, (1.0, OMEGA, phase), x);
    let model = match e {
        Some(_) => model,
        None => model.with_contact_law(
            ContactLaw::exponential(A_OVER_B, 1.0, 1e3, ForceForm::Published).unwrap(),
        ),
    };
    model
        .with_all_impacts(Impacts::Rigid { restitution: e })
        .unwrap()
}

/// The orbit shot from a simulated guess, its impact velocity, and the
/// period.
fn settled_orbit(model: &Model) -> (PeriodicSolution, f64) {
    let period = forcing_period(model).unwrap();
    let sim = simulate(
        model,
        &SimulationOptions {
            t_end: 60.0 * period,
            rtol: 1e-12,
            atol: 1e-12,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(sim.error.is_none(), "{:?}", sim.error);
    let guess = [sim.final_displacement[0], sim.final_velocity[0]];
    let sol = shoot(model, &guess, &tight()).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    let u = sim.impacts.last().unwrap().impact_velocity;
    (sol, u)
}

/// The rigid monodromy (saltation through the impacts, with de/dU of the
/// seed's e(V)) equals central differences of the rigid period map to
/// 1e-7 of its norm, on the settled one-impact orbit and off it.
#[test]
fn rigid_monodromy_equals_differences_of_the_period_map() {
    for e in [None, Some(0.8)] {
        let model = rigid_oscillator(e, 0.0, (0.0, 0.0));
        let (sol, _) = settled_orbit(&model);
        let opts = tight();
        for x in [sol.initial_state.clone(), vec![0.1, 0.9]] {
            let map = period_map(&model, &x, &opts).unwrap();
            let h = 1e-6;
            let mut worst: f64 = 0.0;
            for c in 0..2 {
                let image = |s: f64| {
                    let mut xs = x.clone();
                    xs[c] += s * h;
                    map_image(&model, &xs, &opts, MAX_STEPS).unwrap().0
                };
                let (plus, minus) = (image(1.0), image(-1.0));
                for r in 0..2 {
                    let fd = (plus[r] - minus[r]) / (2.0 * h);
                    worst = worst.max((fd - map.monodromy[(r, c)]).abs());
                }
            }
            let norm = map.monodromy.amax();
            eprintln!(
                "e {e:?} at {x:?}: Φ {} vs differences {worst:.2e}",
                map.monodromy
            );
            assert!(worst < 1e-7 * norm, "{worst:e} of {norm}");
        }
    }
}

/// The parameter's column through the impacts: the forcing frequency
/// (the map's time moves), the wall's clearance (the event moves: ∂h/∂p)
/// and Newton's e (the jump changes: ∂g/∂p) against central differences of
/// the period map, to 1e-6 (the column is itself a difference in p).
#[test]
fn rigid_parameter_columns_equal_differences() {
    let x = [0.1, 0.9];
    let opts = tight();
    type Family = fn(f64) -> Model;
    let families: [(&str, Family, f64); 3] = [
        (
            "frequency",
            |p| oscillator(ZETA_O, GAP, (1.0, p, 0.0), (0.0, 0.0)),
            OMEGA,
        ),
        (
            "clearance",
            |p| oscillator(ZETA_O, p, (1.0, OMEGA, 0.0), (0.0, 0.0)),
            GAP,
        ),
        (
            "restitution",
            |_| oscillator(ZETA_O, GAP, (1.0, OMEGA, 0.0), (0.0, 0.0)),
            0.8,
        ),
    ];
    for (name, family, p) in families {
        let at = |q: f64| {
            let e = if name == "restitution" { q } else { 0.8 };
            family(q)
                .with_all_impacts(Impacts::Rigid {
                    restitution: Some(e),
                })
                .unwrap()
        };
        let dp = 1e-8 * p;
        let derivs =
            period_map_with(&at(p), &x, &opts, Some((&at(p + dp), dp)), true, MAX_STEPS).unwrap();
        let column = derivs.dp_column.unwrap();
        let h = 1e-5 * p;
        let (plus, minus) = (
            map_image(&at(p + h), &x, &opts, MAX_STEPS).unwrap().0,
            map_image(&at(p - h), &x, &opts, MAX_STEPS).unwrap().0,
        );
        for r in 0..2 {
            let fd = (plus[r] - minus[r]) / (2.0 * h);
            eprintln!("{name}: column {} vs differences {fd}", column[r]);
            assert!(
                (column[r] - fd).abs() < 1e-6 * fd.abs().max(1.0),
                "{name} row {r}: {} vs {fd}",
                column[r]
            );
        }
    }
}

/// Shaw & Holmes's period-1 orbit (ζ 0.05, Ω 1.5, g 0.6, e 0.8) by
/// shooting, on a section half a period after the impact: the fixed point
/// equals the closed-form orbit there to 1e-10, one impact a period, and
/// the multipliers' product is det S · e^{−2ζT} = e² e^{−2ζT} (det S = e²
/// for a constant e) to 1e-10.
#[test]
fn shaw_holmes_orbit_by_shooting() {
    let e = 0.8;
    let (phi, v) = shaw_holmes(ZETA_O, GAP, (1.0, OMEGA), e, (1.7, 2.3));
    let period = 2.0 * std::f64::consts::PI / OMEGA;
    // Half a period on from the impact, by the closed-form orbit's run.
    let start = rigid_oscillator(Some(e), phi, (GAP, -e * v));
    let half = simulate(
        &start,
        &SimulationOptions {
            t_end: 0.5 * period,
            rtol: 1e-13,
            atol: 1e-14,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(half.impacts.is_empty());
    let x_half = [half.final_displacement[0], half.final_velocity[0]];
    let model = rigid_oscillator(Some(e), phi + std::f64::consts::PI, (0.0, 0.0));
    let guess = [x_half[0] + 0.02, x_half[1] - 0.03];
    let sol = shoot(&model, &guess, &tight()).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    for i in 0..2 {
        assert!(
            (sol.initial_state[i] - x_half[i]).abs() < 1e-10,
            "{:?} vs {x_half:?}",
            sol.initial_state
        );
    }
    let product = sol
        .multipliers
        .iter()
        .fold(Complex::new(1.0, 0.0), |a, m| a * m);
    let det = e * e * (-2.0 * ZETA_O * period).exp();
    assert!(
        (product.re / det - 1.0).abs() < 1e-10 && product.im.abs() < 1e-12,
        "{product} vs {det}"
    );
    assert!(sol.stable(), "{:?}", sol.multipliers);
    let orbit = orbit_summary(&model, &sol.initial_state, period, 100, 1e-12).unwrap();
    assert_eq!(orbit.impacts_per_period(), 1);
}

/// With the seed's e(U) the saltation's determinant is e (e + U de/dU):
/// the multipliers' product on the settled orbit is that times e^{−2ζT},
/// to 1e-9, with e and de/dU from the closed form of seed eq. (10) at the
/// orbit's impact velocity. Without the de/dU term it would be e².
#[test]
fn multipliers_carry_the_slope_of_the_seeds_restitution() {
    let model = rigid_oscillator(None, 0.0, (0.0, 0.0));
    let (sol, u) = settled_orbit(&model);
    let vv = u / A_OVER_B;
    let e = restitution(vv).unwrap();
    let slope = restitution_derivative(vv, e) / A_OVER_B;
    let period = sol.period;
    let det = e * (e + u * slope) * (-2.0 * ZETA_O * period).exp();
    let product = sol
        .multipliers
        .iter()
        .fold(Complex::new(1.0, 0.0), |a, m| a * m);
    eprintln!(
        "U {u}: e {e}, U de/dU {}, product {product} vs {det}",
        u * slope
    );
    assert!((product.re / det - 1.0).abs() < 1e-9, "{product} vs {det}");
    assert!(((e * e) / det - 1.0).abs() > 1e-3);
}
