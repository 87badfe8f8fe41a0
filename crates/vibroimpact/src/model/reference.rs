//! The reference problems of `docs/theory.md` §6 as library values, so that
//! tests, benchmarks, examples and the report build them from one place:
//!
//! - **R1**, two of the seed's balls: [`seed_law`], [`seed_bodies`] and the
//!   closed-form table [`R1_TABLE`] (seed eqs. 10 and 16–17);
//! - **R2**, the seed's row of N pendulums between two walls: [`r2`];
//! - **R3**, its linear limit (clearances so large that nothing touches):
//!   [`r3`] with the exact response [`r3_steady_amplitude`] and
//!   [`r3_response`].

use crate::contact::{ContactLaw, ForceForm};
use crate::impact::TwoBodies;
use crate::model::{BaseExcitation, Model, ModelError};

/// Mass of one of the seed's pendulums, a 38.1 mm steel ball (kg).
pub const MASS: f64 = 0.227;
/// Natural frequency ω₀ of the seed's pendulum (rad/s; 1.18 Hz).
pub const NATURAL_FREQUENCY: f64 = 7.41;
/// Damping ratio ζ of the seed's pendulum.
pub const DAMPING_RATIO: f64 = 0.013;
/// The seed's identified a/b of the exponential law (m/s).
pub const A_OVER_B: f64 = 1.2;
/// The seed's identified α of the exponential law (1/m).
pub const ALPHA: f64 = 1.3e5;
/// The force scale a of the exponential law (N).
pub const FORCE_SCALE: f64 = 1.0;
/// Every gap of the row, walls included (m).
pub const CLEARANCE: f64 = 1e-3;
/// Amplitude A of the base acceleration A sin(Ω t) (m/s²).
pub const BASE_AMPLITUDE: f64 = 0.05;
/// The clearance of R3: so large that nothing touches (m).
pub const R3_CLEARANCE: f64 = 1e3;

/// One row of the closed-form reference table R1 (`docs/theory.md` §2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct R1Row {
    /// Dimensionless impact velocity V = U/(a/b).
    pub v: f64,
    /// Coefficient of restitution e(V) (seed eq. 10).
    pub e: f64,
    /// Dimensionless peak force f_max(V) (seed eqs. 16–17).
    pub f_max: f64,
}

/// The closed-form reference table R1: e and f_max to the digits printed in
/// `docs/theory.md` §2 (checked there against direct integration).
pub const R1_TABLE: [R1Row; 6] = [
    R1Row {
        v: 0.01,
        e: 0.993377454400,
        f_max: 4.96703803e-05,
    },
    R1Row {
        v: 0.1,
        e: 0.937475579950,
        f_max: 4.70080031e-03,
    },
    R1Row {
        v: 0.5,
        e: 0.748434931597,
        f_max: 9.88769556e-02,
    },
    R1Row {
        v: 1.0,
        e: 0.593624260040,
        f_max: 3.50368739e-01,
    },
    R1Row {
        v: 2.0,
        e: 0.410719686061,
        f_max: 1.24478950e+00,
    },
    R1Row {
        v: 10.0,
        e: 0.099981624753,
        f_max: 2.64635581e+01,
    },
];

/// The seed's exponential law: a/b = 1.2 m/s, α = 1.3e5 1/m, a = 1 N, in
/// the published (signed) form.
pub fn seed_law() -> ContactLaw {
    match ContactLaw::exponential_from_ratio(A_OVER_B, ALPHA, FORCE_SCALE, ForceForm::Published) {
        Ok(law) => law,
        Err(e) => unreachable!("the seed's constants are a valid law: {e}"),
    }
}

/// Two of the seed's balls (R1).
pub fn seed_bodies() -> TwoBodies {
    match TwoBodies::new(MASS, MASS) {
        Ok(b) => b,
        Err(e) => unreachable!("the seed's masses are valid: {e}"),
    }
}

/// Reference problem R2: `n` of the seed's pendulums between two walls,
/// every gap `clearance` (the seed's is [`CLEARANCE`]), the seed's law,
/// base acceleration `0.05 sin(frequency·t)` m/s², at rest at t = 0.
/// Errors for `n = 0` or a clearance or frequency the model refuses.
pub fn r2(n: usize, clearance: f64, frequency: f64) -> Result<Model, ModelError> {
    r2_forced(n, clearance, frequency, BASE_AMPLITUDE)
}

/// The struck granular chain in "sonic vacuum" (docs/theory.md §10):
/// `n` steel beads of 0.0286 kg touching without precompression, Hertz
/// contacts `7e9 s^1.5` N between neighbours, no springs, no walls, the
/// first bead moving at `striker` m/s (examples/granular-chain.toml with
/// N = 100 and 1 m/s).
pub fn struck_chain(n: usize, striker: f64) -> Result<Model, ModelError> {
    let law = crate::contact::ContactLaw::hertz(7e9, 1.5).map_err(|e| {
        ModelError::new(
            crate::model::ModelErrorKind::InvalidValue,
            "row.contact",
            e.to_string(),
        )
    })?;
    let m = Model::row(
        n,
        0.0286,
        0.0,
        0.0,
        0.0,
        law,
        (false, false),
        BaseExcitation::None,
    )?;
    let mut v = vec![0.0; n];
    if let Some(first) = v.first_mut() {
        *first = striker;
    }
    m.with_initial_state(Vec::new(), v)
}

/// R2 with N = 3 at 0.95 ω0 after 5 periods from rest, `[u.., v..]`, by
/// SciPy's DOP853 at rtol 1e-13, atol 1e-16 (bench/peers,
/// results-2026-11-22.json; SUNDIALS' CVODE agrees to 6e-9).
#[cfg(test)]
pub(crate) const R2_N3_SCIPY: [f64; 6] = [
    0.00026822438569644924,
    5.387370645080881e-05,
    0.0006982749704558822,
    -0.00995929240162609,
    -0.0035041867100254133,
    0.005716496838870423,
];

/// [`r2`] under the base acceleration `amplitude · sin(frequency·t)` m/s²
/// (branches and curves in the forcing amplitude; 0 is the rest state).
pub fn r2_forced(
    n: usize,
    clearance: f64,
    frequency: f64,
    amplitude: f64,
) -> Result<Model, ModelError> {
    let (m, w0, zeta) = (MASS, NATURAL_FREQUENCY, DAMPING_RATIO);
    let base = BaseExcitation::Harmonic {
        amplitude,
        frequency,
        phase: 0.0,
    };
    Model::row(
        n,
        m,
        m * w0 * w0,
        2.0 * zeta * m * w0,
        clearance,
        seed_law(),
        (true, true),
        base,
    )
}

/// Reference problem R3: [`r2`] with clearances of [`R3_CLEARANCE`].
pub fn r3(n: usize, frequency: f64) -> Result<Model, ModelError> {
    r2(n, R3_CLEARANCE, frequency)
}

/// R3's exact steady-state amplitude of every body at forcing frequency
/// `frequency`: `A / sqrt((ω₀² − Ω²)² + (2ζω₀Ω)²)`.
pub fn r3_steady_amplitude(frequency: f64) -> f64 {
    let (w0, zeta, w) = (NATURAL_FREQUENCY, DAMPING_RATIO, frequency);
    BASE_AMPLITUDE / ((w0 * w0 - w * w).powi(2) + (2.0 * zeta * w0 * w).powi(2)).sqrt()
}

/// R3's exact displacement and velocity of every body at time `t`, from
/// rest: `u'' + 2ζω₀ u' + ω₀² u = −A sin(Ω t)`, steady state plus the
/// decaying free oscillation.
pub fn r3_response(t: f64, frequency: f64) -> (f64, f64) {
    let (w0, zeta, w) = (NATURAL_FREQUENCY, DAMPING_RATIO, frequency);
    let d = (w0 * w0 - w * w).powi(2) + (2.0 * zeta * w0 * w).powi(2);
    let b1 = -BASE_AMPLITUDE * (w0 * w0 - w * w) / d;
    let b2 = BASE_AMPLITUDE * 2.0 * zeta * w0 * w / d;
    let wd = w0 * (1.0 - zeta * zeta).sqrt();
    let c1 = -b2;
    let c2 = (zeta * w0 * c1 - w * b1) / wd;
    let e = (-zeta * w0 * t).exp();
    let (sn, cs) = (wd * t).sin_cos();
    let u = b1 * (w * t).sin() + b2 * (w * t).cos() + e * (c1 * cs + c2 * sn);
    let v = b1 * w * (w * t).cos() - b2 * w * (w * t).sin()
        + e * (-zeta * w0 * (c1 * cs + c2 * sn) + wd * (-c1 * sn + c2 * cs));
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn r2_is_the_seed_row() {
        let m = r2(3, CLEARANCE, 0.95 * NATURAL_FREQUENCY).unwrap();
        assert_eq!(m.bodies().len(), 3);
        assert_eq!(m.contacts().len(), 4);
        let b = &m.bodies()[1];
        assert!((b.stiffness / b.mass).sqrt() - NATURAL_FREQUENCY < 1e-12);
        assert!((b.damping / (2.0 * b.mass * NATURAL_FREQUENCY) - DAMPING_RATIO).abs() < 1e-15);
        assert_eq!(m.contacts()[0].clearance, CLEARANCE);
        assert!(r2(0, CLEARANCE, 7.0).is_err());
        assert_eq!(r3(2, 7.0).unwrap().contacts()[1].clearance, R3_CLEARANCE);
    }

    /// The exact R3 response satisfies its equation and starts at rest; it
    /// tends to the steady amplitude.
    #[test]
    fn r3_response_solves_the_linear_equation() {
        let w = 0.9 * NATURAL_FREQUENCY;
        assert_eq!(r3_response(0.0, w), (0.0, 0.0));
        let (w0, z) = (NATURAL_FREQUENCY, DAMPING_RATIO);
        for t in [0.3, 2.0, 17.0] {
            // u'' by a central difference of the exact velocity.
            let dt = 1e-5;
            let a = (r3_response(t + dt, w).1 - r3_response(t - dt, w).1) / (2.0 * dt);
            let (u, v) = r3_response(t, w);
            let residual = a + 2.0 * z * w0 * v + w0 * w0 * u + BASE_AMPLITUDE * (w * t).sin();
            assert!(residual.abs() < 1e-8, "at {t}: {residual:e}");
        }
        // After the transient (e^{-ζω₀t} < 1e-12), one period's extreme.
        let t0 = 30.0 / (z * w0);
        let peak = (0..2000)
            .map(|k| {
                r3_response(t0 + k as f64 * 2.0 * std::f64::consts::PI / w / 2000.0, w)
                    .0
                    .abs()
            })
            .fold(0.0, f64::max);
        assert!((peak / r3_steady_amplitude(w) - 1.0).abs() < 1e-5);
    }
}
