//! Periodic orbits through rigid impacts (docs/theory.md §12): the
//! saltation's monodromy against differences of the period map, the
//! impact oscillator's closed-form orbit by shooting, and the multipliers'
//! product against the saltation's determinant.

use super::*;
use crate::contact::{ContactLaw, ForceForm};
use crate::impact::closed_form::{restitution, restitution_derivative};
use crate::model::Impacts;
use crate::simulate::tests::rigid::{ball_on_table, oscillator, shaw_holmes};
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

/// Gravity (m/s²), restitution and forcing of the bouncing ball.
const G: f64 = 9.81;
const E_BALL: f64 = 0.5;
const W_TABLE: f64 = 2.0 * std::f64::consts::PI;

/// A ball (1 kg, no spring) on a table moving as z = A sin ωt with
/// Γ = A ω²/g, in the table's frame: ü = −z̈ − g, the table a wall at
/// u = 0 below it, Newton's e.
fn bouncing_ball(gamma: f64) -> Model {
    let (ball, table) = ball_on_table(0.0, ContactLaw::hertz(1e9, 1.5).unwrap());
    // z̈ = −A ω² sin ωt = A ω² sin(ωt + π).
    let base = BaseExcitation::Harmonic {
        amplitude: gamma * G,
        frequency: W_TABLE,
        phase: std::f64::consts::PI,
    };
    Model::new(
        vec![ball],
        vec![],
        vec![table],
        base,
        vec![],
        vec![0.1],
        vec![],
    )
    .unwrap()
    .with_gravity(G)
    .unwrap()
    .with_all_impacts(Impacts::Rigid {
        restitution: Some(E_BALL),
    })
    .unwrap()
}

/// The ball's period-1 orbit in closed form (Holmes 1982, without his
/// small-bounce approximation): it leaves the table at phase φ with the
/// absolute velocity gT/2 and lands one period later at the same phase,
/// so the table's velocity there is A ω cos φ = gT (1 − e)/(2 (1 + e)),
/// sin φ > 0 on the stable branch. Returns the state (u, u̇) relative to
/// the table at t = 0 and the impact map's Jacobian's trace, whose
/// determinant is e²: tr = 1 + e² − (1 + e)² Γ sin φ.
fn ball_orbit(gamma: f64) -> ([f64; 2], f64) {
    let period = 2.0 * std::f64::consts::PI / W_TABLE;
    let amp = gamma * G / (W_TABLE * W_TABLE);
    let cos = std::f64::consts::PI * (1.0 - E_BALL) / ((1.0 + E_BALL) * gamma);
    let phi = cos.acos();
    let (t_star, v_up) = (phi / W_TABLE, 0.5 * G * period);
    // From the impact at t* to t = T (≡ 0), free flight above the table.
    let tau = period - t_star;
    let z = |t: f64| amp * (W_TABLE * t).sin();
    let zd = |t: f64| amp * W_TABLE * (W_TABLE * t).cos();
    let u = z(t_star) + v_up * tau - 0.5 * G * tau * tau - z(period);
    let v = v_up - G * tau - zd(period);
    let trace = 1.0 + E_BALL * E_BALL - (1.0 + E_BALL).powi(2) * gamma * phi.sin();
    ([u, v], trace)
}

/// The bouncing ball's period-1 orbit and its multipliers by shooting
/// equal the closed form to 1e-8, below the period doubling and at it
/// (Γ_PD² = (π(1 − e)/(1 + e))² + (2(1 + e²)/(1 + e)²)²: a multiplier
/// −1 to 1e-8).
#[test]
fn the_bouncing_ball_of_holmes() {
    let pi = std::f64::consts::PI;
    let ratio = (1.0 - E_BALL) / (1.0 + E_BALL);
    let gamma_pd = (pi * ratio).hypot(2.0 * (1.0 + E_BALL * E_BALL) / (1.0 + E_BALL).powi(2));
    for gamma in [1.3, gamma_pd] {
        let model = bouncing_ball(gamma);
        let (x, trace) = ball_orbit(gamma);
        let guess = [x[0] * 1.01, x[1] * 0.99];
        let sol = shoot(&model, &guess, &tight()).unwrap();
        assert!(sol.converged, "{gamma}: {:?}", sol.residual_history);
        for i in 0..2 {
            assert!(
                (sol.initial_state[i] - x[i]).abs() < 1e-8,
                "{gamma}: {:?} vs {x:?}",
                sol.initial_state
            );
        }
        let disc = Complex::new(trace * trace - 4.0 * E_BALL * E_BALL, 0.0).sqrt();
        let exact = [(trace + disc) / 2.0, (trace - disc) / 2.0];
        for m in &sol.multipliers {
            let err = exact
                .iter()
                .map(|x| (m - x).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(err < 1e-8, "{gamma}: {m} vs {exact:?}");
        }
        eprintln!("Γ {gamma}: multipliers {:?}", sol.multipliers);
    }
}

/// Continued in the table's acceleration from Γ = 1.2, the ball's
/// period-1 branch has its period doubling at the closed form's Γ_PD to
/// 1e-8 (and no other special point before Γ = 1.7); in metres, so the
/// shooting's displacement scale is 1 m.
#[test]
fn continuation_locates_the_bouncing_balls_period_doubling() {
    use crate::continuation::{continue_branch, ContinuationOptions, SpecialKind};
    use crate::model::family::of;
    let pi = std::f64::consts::PI;
    let ratio = (1.0 - E_BALL) / (1.0 + E_BALL);
    let gamma_pd = (pi * ratio).hypot(2.0 * (1.0 + E_BALL * E_BALL) / (1.0 + E_BALL).powi(2));
    let opts = ContinuationOptions {
        shooting: tight(),
        ..Default::default()
    };
    let family = of("amplitude", |a: f64| Ok(bouncing_ball(a / G)));
    let (x0, _) = ball_orbit(1.2);
    let branch = continue_branch(family, 1.2 * G, &x0, 1.7 * G, &opts, |_| true).unwrap();
    let found: Vec<(SpecialKind, f64)> = branch
        .special
        .iter()
        .map(|s| (s.kind, s.parameter / G))
        .collect();
    eprintln!(
        "{} points: {found:?} vs Γ_PD {gamma_pd}",
        branch.points.len()
    );
    assert_eq!(found.len(), 1, "{found:?}");
    assert_eq!(found[0].0, SpecialKind::PeriodDoubling);
    assert!(
        (found[0].1 - gamma_pd).abs() < 1e-8,
        "{found:?} vs {gamma_pd}"
    );
}

/// The impact oscillator's branch of impacting orbits (e = 0.8) from
/// Ω = 1.5 folds at Ω = 1.8576 and comes back to the grazing of its
/// impact, where it ends with the reason, labelled GR1: the grazing orbit
/// is the linear steady state of amplitude g, (1 − Ω²)² + (2ζΩ)² =
/// (p/g)², and the last point lies within 1e-7 of that Ω, its impact
/// velocity below 1e-3 of the orbit's (or its closest approach within
/// 1e-6 of the reach, where the impact is lost in rounding). The linear branch from Ω = 2.5,
/// which does not touch, ends there too, at its closest approach.
#[test]
fn the_impact_oscillators_branch_ends_at_its_grazing() {
    use crate::continuation::{continue_branch, ContinuationOptions, StopReason};
    use crate::model::family::of;
    let opts = ContinuationOptions {
        shooting: ShootingOptions {
            displacement_scale: 0.1,
            ..Default::default()
        },
        ..Default::default()
    };
    let family = of("frequency", |w: f64| {
        Ok(oscillator(ZETA_O, GAP, (1.0, w, 0.0), (0.0, 0.0))
            .with_all_impacts(Impacts::Rigid {
                restitution: Some(0.8),
            })
            .unwrap())
    });
    let (sol, _) = settled_orbit(&rigid_oscillator(Some(0.8), 0.0, (0.0, 0.0)));
    let branch = continue_branch(family, OMEGA, &sol.initial_state, 3.5, &opts, |_| true).unwrap();
    let StopReason::Grazing(why) = &branch.stop else {
        unreachable!("{:?}", branch.stop)
    };
    assert!(why.contains("(GR)"), "{why}");
    // Ω² = y: y² − (2 − 4ζ²) y + 1 − (p/g)² = 0.
    let b = 2.0 - 4.0 * ZETA_O * ZETA_O;
    let y = (b + (b * b + 4.0 * (1.0 / (GAP * GAP) - 1.0)).sqrt()) / 2.0;
    let grazing = y.sqrt();
    let ends_at_gr = |branch: &crate::continuation::Branch| {
        let last = branch.points.last().unwrap();
        let gr = branch.special.last().unwrap();
        assert_eq!((gr.label.as_str(), gr.parameter), ("GR1", last.parameter));
        assert_eq!(last.label.as_deref(), Some("GR1"));
        assert!(
            (last.parameter - grazing).abs() < 1e-7,
            "{} vs {grazing}",
            last.parameter
        );
        eprintln!(
            "{} points, GR1 at {} vs grazing {grazing}: {}",
            branch.points.len(),
            last.parameter,
            branch.stop
        );
    };
    ends_at_gr(&branch);
    assert!(branch
        .special
        .iter()
        .any(|s| (s.parameter - 1.85757).abs() < 1e-4));
    // From the side that does not touch: the linear steady state at
    // Ω = 2.5, continued down, grazes the wall at the same Ω_g.
    let linear = oscillator(ZETA_O, GAP, (1.0, 2.5, 0.0), (0.0, 0.0))
        .with_all_impacts(Impacts::Rigid {
            restitution: Some(0.8),
        })
        .unwrap();
    let start = shoot(&linear, &[0.0, 0.0], &tight()).unwrap();
    assert!(start.converged);
    let family = of("frequency", |w: f64| {
        Ok(oscillator(ZETA_O, GAP, (1.0, w, 0.0), (0.0, 0.0))
            .with_all_impacts(Impacts::Rigid {
                restitution: Some(0.8),
            })
            .unwrap())
    });
    let branch = continue_branch(family, 2.5, &start.initial_state, 1.2, &opts, |_| true).unwrap();
    assert!(matches!(&branch.stop, StopReason::Grazing(why) if why.contains("closest approach")));
    ends_at_gr(&branch);
}

/// The rigid limit of the seed's law on a periodic orbit: R2 N = 2 at
/// 0.95 ω0, the exponential law at α × 1, 10, 100, 1000, 3000 (a/b
/// fixed), each orbit shot from the previous one (Φ in the step control:
/// the soft multipliers to about 5e-6), tends to the rigid orbit with e(V)
/// of seed eq. (10): the state's difference falls about 7× a decade of α
/// (ln α/α: order 0.85 in 1/α observed), the multipliers' about 10×, and
/// the Richardson extrapolation of the soft multipliers in ln α/α from
/// α × 1000 and × 3000 equals the rigid multipliers to 1e-4 (measured
/// 3.9e-5; from × 100 and × 1000, 1.3e-4: not yet asymptotic). At the
/// seed's α itself the orbit's state is 6.8e-5 m off and its largest
/// multiplier is real (1.274) where the rigid pair is complex (|μ| 1.517).
#[test]
fn soft_orbits_tend_to_the_rigid_orbit() {
    use crate::model::reference::{r2, ALPHA, A_OVER_B, FORCE_SCALE, NATURAL_FREQUENCY as W0};
    let base = r2(2, 1e-3, 0.95 * W0).unwrap();
    let opts = ShootingOptions {
        rtol: 1e-12,
        tol: 1e-10,
        control_monodromy: true,
        ..Default::default()
    };
    let mut x = guess_by_simulation(&base, 200.0, 1e-10).unwrap();
    let mut soft = Vec::new();
    for f in [1.0, 10.0, 100.0, 1000.0, 3000.0] {
        let law = ContactLaw::exponential_from_ratio(
            A_OVER_B,
            ALPHA * f,
            FORCE_SCALE,
            ForceForm::Published,
        )
        .unwrap();
        let sol = shoot(&base.clone().with_contact_law(law), &x, &opts).unwrap();
        assert!(sol.converged, "α × {f}: {:?}", sol.residual_history);
        x.clone_from(&sol.initial_state);
        soft.push((ALPHA * f, sol));
    }
    let rigid = base
        .with_all_impacts(Impacts::Rigid { restitution: None })
        .unwrap();
    let r = shoot(&rigid, &x, &opts).unwrap();
    assert!(r.converged, "{:?}", r.residual_history);
    let distance = |s: &PeriodicSolution| {
        let dx = s
            .initial_state
            .iter()
            .zip(&r.initial_state)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let dm = s
            .multipliers
            .iter()
            .zip(&r.multipliers)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        (dx, dm)
    };
    let d: Vec<(f64, f64)> = soft.iter().map(|(_, s)| distance(s)).collect();
    eprintln!(
        "rigid multipliers {:?}; (state, multipliers) differences {d:?}",
        r.multipliers
    );
    assert!((6.0e-5..7.5e-5).contains(&d[0].0), "{:?}", d[0]);
    for w in d[1..4].windows(2) {
        assert!(w[0].0 / w[1].0 > 5.0 && w[0].1 / w[1].1 > 7.0, "{w:?}");
    }
    // Richardson in g(α) = ln α / α from the last two.
    let g = |a: f64| a.ln() / a;
    let [(a1, s1), (a2, s2)] = [&soft[3], &soft[4]];
    let ratio = g(*a2) / (g(*a1) - g(*a2));
    for ((m1, m2), mr) in s1
        .multipliers
        .iter()
        .zip(&s2.multipliers)
        .zip(&r.multipliers)
    {
        let extrapolated = m2 + (m2 - m1) * ratio;
        assert!((extrapolated - mr).norm() < 1e-4, "{extrapolated} vs {mr}");
    }
}

/// Nordmark's square root at grazing: past the grazing frequency Ω_g of
/// the impact oscillator (e = 0.8), the linear steady state would pass
/// the wall by δ ∝ Ω_g − Ω, and the rigid period map moves it by its
/// impact, ‖P(x) − x‖ ∝ U ∝ √δ (the discontinuity's square-root term of
/// Nordmark's map). Over Ω_g − Ω = 1e-3 … 1e-7 the measured exponent is
/// 0.5 ± 0.02; before grazing the map leaves the linear orbit in place
/// (no impact) to 1e-9.
#[test]
fn the_map_jumps_as_the_square_root_past_grazing() {
    let b = 2.0 - 4.0 * ZETA_O * ZETA_O;
    let grazing = ((b + (b * b + 4.0 * (1.0 / (GAP * GAP) - 1.0)).sqrt()) / 2.0).sqrt();
    // The linear steady state at t = 0 of x'' + 2ζx' + x = sin Ωt.
    let linear = |w: f64| {
        let amp = 1.0 / (1.0 - w * w).hypot(2.0 * ZETA_O * w);
        let lag = (2.0 * ZETA_O * w).atan2(1.0 - w * w);
        [-amp * lag.sin(), amp * w * lag.cos()]
    };
    let jump = |w: f64| {
        let model = oscillator(ZETA_O, GAP, (1.0, w, 0.0), (0.0, 0.0))
            .with_all_impacts(Impacts::Rigid {
                restitution: Some(0.8),
            })
            .unwrap();
        let x = linear(w);
        let image = map_image(&model, &x, &tight(), MAX_STEPS).unwrap().0;
        (image[0] - x[0]).abs().max((image[1] - x[1]).abs())
    };
    assert!(jump(grazing + 1e-4) < 1e-9, "{}", jump(grazing + 1e-4));
    let eps = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7];
    let d: Vec<f64> = eps.iter().map(|e| jump(grazing - e)).collect();
    let n = eps.len() as f64;
    let (lx, ly): (Vec<f64>, Vec<f64>) = eps.iter().zip(&d).map(|(e, d)| (e.ln(), d.ln())).unzip();
    let (mx, my) = (lx.iter().sum::<f64>() / n, ly.iter().sum::<f64>() / n);
    let slope = lx
        .iter()
        .zip(&ly)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum::<f64>()
        / lx.iter().map(|x| (x - mx).powi(2)).sum::<f64>();
    eprintln!("jumps {d:?}: exponent {slope}");
    assert!((slope - 0.5).abs() < 0.02, "{slope}: {d:?}");
}

/// The rigid R2 N = 2 branch from the homotopy, which runs with soft
/// impacts (the rigid map's corner at the first grazing stopped it at an
/// amplitude of 0.0055 of 0.05 m/s²): Newton on the rigid model converges
/// from the soft orbit at 0.95 ω0 to the rigid orbit that the soft orbits
/// tend to (its state within 7.5e-5 m of the soft one at the seed's α,
/// as `soft_orbits_tend_to_the_rigid_orbit` measures). Continued down in
/// frequency, the branch ends at a grazing (GR1, near 0.56 ω0), just past
/// which an impact would start within another's estimated duration (the
/// rigid idealisation breaks).
#[test]
fn a_rigid_branch_starts_from_the_soft_homotopy() {
    use crate::continuation::{
        amplitude_homotopy, continue_branch, ContinuationOptions, StopReason,
    };
    use crate::model::file::ModelDocument;
    use crate::model::parameter::ParameterizedModel;
    let text = include_str!("../../../../../examples/fujita-row-n2.toml");
    let soft_doc = ModelDocument::from_toml(text, "fujita-row-n2.toml").unwrap();
    let doc = soft_doc
        .clone()
        .with_impact_options(Some("rigid"), None)
        .unwrap();
    let opts = ContinuationOptions::default();
    let (family, target) = ParameterizedModel::in_amplitude(doc.clone()).unwrap();
    let guess = amplitude_homotopy(&family, target, &opts).unwrap();
    let rigid = doc.build().unwrap().model;
    let r = shoot(&rigid, &guess, &opts.shooting).unwrap();
    assert!(r.converged, "{:?}", r.residual_history);
    let soft = shoot(&soft_doc.build().unwrap().model, &guess, &opts.shooting).unwrap();
    let dx = r
        .initial_state
        .iter()
        .zip(&soft.initial_state)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    eprintln!(
        "rigid orbit {:?}, {dx:e} m from the soft one",
        r.multipliers
    );
    assert!((6.0e-5..7.5e-5).contains(&dx), "{dx}");
    let frequency = ParameterizedModel::new(doc, "frequency").unwrap();
    let w = rigid.forcing_frequency().unwrap();
    let branch =
        continue_branch(&frequency, w, &r.initial_state, 0.5 * w, &opts, |_| true).unwrap();
    let StopReason::Grazing(why) = &branch.stop else {
        unreachable!("{:?}", branch.stop)
    };
    let last = branch.points.last().unwrap().parameter;
    eprintln!("{} points, last at {last}: {why}", branch.points.len());
    assert_eq!(branch.special.last().unwrap().label, "GR1");
    assert!((0.55..0.6).contains(&(last / 7.41)), "{last}");
    // Just past it the rigid idealisation breaks: an impact would start
    // within another's estimated duration.
    let beyond = frequency.model_at(last - 0.02).unwrap();
    let e = crate::periodic::map_image(
        &beyond,
        &branch.points.last().unwrap().state,
        &opts.shooting,
        crate::periodic::MAX_STEPS,
    )
    .unwrap_err();
    assert!(
        e.to_string().contains("the rigid idealisation breaks"),
        "{e}"
    );
}
