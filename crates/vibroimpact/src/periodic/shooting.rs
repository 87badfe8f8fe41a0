//! Shooting: damped Newton on `G(x) = P(x) - x` with the dense monodromy,
//! or matrix-free (Newton–Krylov, the dominant multipliers by Arnoldi)
//! for long rows (docs/theory.md §5).

use nalgebra::{DMatrix, DVector};

use super::{
    forcing_period, map_multipliers, map_time, period_map, period_map_with, scales, MapTangent,
    PeriodMap, PeriodicError, PeriodicSolution, ShootingOptions, MAX_STEPS, MIN_ARNOLDI,
    MULTIPLIER_RTOL, TRUST,
};
use crate::linalg::{arnoldi_matrix, gmres};
use crate::model::Model;
use crate::newton::{damped_newton, NewtonOptions, NewtonOutcome, NewtonStop, NewtonSystem};

fn scaled_norm(r: &[f64], scale: &[f64]) -> f64 {
    r.iter()
        .zip(scale)
        .map(|(x, s)| (x / s).abs())
        .fold(0.0, f64::max)
}

/// The damped Newton options of shooting: a trust region of half a
/// displacement scale per iteration (a full Newton step can land deep
/// inside a contact, where e^{αs} makes the period map astronomically
/// stiff), with a line search.
fn newton_options(opts: &ShootingOptions) -> NewtonOptions {
    NewtonOptions {
        tol: opts.tol,
        max_iterations: opts.max_iterations,
        max_step: TRUST,
        line_search: true,
        stall: None,
    }
}

/// Shooting with the dense monodromy matrix: residual `P(x) − x`,
/// direction from the LU factors of `Φ − I`.
struct DenseShooting<'a> {
    model: &'a Model,
    opts: &'a ShootingOptions,
    scale: Vec<f64>,
    /// Newton iterations so far (for error reports).
    iteration: usize,
}

/// The period map and the residual `P(x) − x` (unscaled).
pub(crate) type DensePoint = (PeriodMap, Vec<f64>);

impl NewtonSystem for DenseShooting<'_> {
    type Point = DensePoint;
    type Error = PeriodicError;

    fn evaluate(&mut self, x: &[f64]) -> Result<Self::Point, PeriodicError> {
        let map =
            period_map(self.model, x, self.opts).map_err(|source| PeriodicError::Integration {
                iteration: self.iteration,
                source,
            })?;
        let r = map.image.iter().zip(x).map(|(p, x)| p - x).collect();
        Ok((map, r))
    }

    fn residual_norm(&self, (_, r): &Self::Point) -> f64 {
        scaled_norm(r, &self.scale)
    }

    fn direction(
        &mut self,
        _x: &[f64],
        (map, r): &Self::Point,
    ) -> Result<Option<Vec<f64>>, PeriodicError> {
        self.iteration += 1;
        let d = r.len();
        let a = &map.monodromy - DMatrix::<f64>::identity(d, d);
        let rhs = DVector::from_iterator(d, r.iter().map(|v| -v));
        Ok(a.lu().solve(&rhs).map(|delta| delta.as_slice().to_vec()))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        scaled_norm(delta, &self.scale)
    }

    /// A failed integration at a large trial step is skipped (the step may
    /// reach far into a contact); at `λ <= 1e-3` it is an error.
    fn skip_failed_trial(&self, lambda: f64, _error: &PeriodicError) -> bool {
        lambda > 1e-3
    }
}

/// Matrix-free Newton–Krylov shooting: residual `P(x) − x` (scaled), the
/// direction by GMRES on the monodromy operator to a relative residual of
/// 1e-3 (inexact Newton).
struct KrylovShooting<'a> {
    model: &'a Model,
    opts: &'a ShootingOptions,
    scale: &'a [f64],
    /// Newton iterations so far (for error reports).
    iteration: usize,
    /// The last evaluated state and the products at it.
    tangent: Option<(Vec<f64>, MapTangent)>,
}

impl KrylovShooting<'_> {
    /// The scaled residual at `x` and the products there.
    fn record(&self, x: &[f64]) -> Result<(Vec<f64>, MapTangent), PeriodicError> {
        let iteration = self.iteration;
        let out = period_map_with(self.model, x, self.opts, None, false, MAX_STEPS)
            .map_err(|source| PeriodicError::Integration { iteration, source })?;
        let tangent = out.tangent.ok_or_else(|| {
            PeriodicError::Options("the period map recorded no tangent (internal error)".into())
        })?;
        let image = out.map.image;
        let residual = (0..x.len())
            .map(|i| (image[i] - x[i]) / self.scale[i])
            .collect();
        Ok((residual, tangent))
    }

    /// The products at `x`, from its evaluation (again if `x` was not the
    /// last state evaluated).
    fn tangent_at(&mut self, x: &[f64]) -> Result<&MapTangent, PeriodicError> {
        let fresh = match self.tangent.take() {
            Some((at, tangent)) if at == x => (at, tangent),
            _ => (x.to_vec(), self.record(x)?.1),
        };
        Ok(&self.tangent.insert(fresh).1)
    }
}

impl NewtonSystem for KrylovShooting<'_> {
    /// The scaled residual.
    type Point = Vec<f64>;
    type Error = PeriodicError;

    fn evaluate(&mut self, x: &[f64]) -> Result<Vec<f64>, PeriodicError> {
        let (residual, tangent) = self.record(x)?;
        self.tangent = Some((x.to_vec(), tangent));
        Ok(residual)
    }

    fn residual_norm(&self, r: &Vec<f64>) -> f64 {
        r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }

    fn direction(&mut self, x: &[f64], r: &Vec<f64>) -> Result<Option<Vec<f64>>, PeriodicError> {
        self.iteration += 1;
        let b: Vec<f64> = r.iter().map(|v| -v).collect();
        let noise = 1e3 * self.opts.rtol;
        let scale = self.scale;
        let (iteration, opts) = (self.iteration, self.opts);
        let tangent = self.tangent_at(x)?;
        let mut apply = |v: &[f64]| {
            stopped(opts, iteration)?;
            Ok(tangent.shifted_scaled(v, scale, 1.0))
        };
        let (delta, _, _) = gmres(&mut apply, &b, 60, 1e-3, noise)?;
        Ok(Some(
            delta.iter().zip(self.scale).map(|(d, s)| d * s).collect(),
        ))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        scaled_norm(delta, self.scale)
    }
}

/// The period nT and the state dimension, after the checks both
/// shootings make: a periodic forcing, a map that applies to the model, a
/// guess of its size.
fn shooting_checks(
    model: &Model,
    guess: &[f64],
    opts: &ShootingOptions,
) -> Result<(f64, usize), PeriodicError> {
    opts.check()?;
    let period = forcing_period(model)? * f64::from(opts.subharmonic.max(1));
    map_time(model, opts)?;
    let d = 2 * model.bodies().len();
    if guess.len() != d {
        return Err(PeriodicError::BadState {
            expected: d,
            got: guess.len(),
        });
    }
    Ok((period, d))
}

/// Finds a periodic solution of period nT near `guess` (body order) by
/// Newton's method on the period map.
pub fn shoot(
    model: &Model,
    guess: &[f64],
    opts: &ShootingOptions,
) -> Result<PeriodicSolution, PeriodicError> {
    let (period, out) = shoot_orbit(model, guess, opts)?;
    let (mut map, _) = out.point;
    // The monodromy of a converged orbit once more at a 100× tighter
    // tolerance (down to 1e-13): the Newton iterations need it to the
    // period map's accuracy, the reported multipliers to more (their error
    // grows along the period to ~30× the tolerance; measured on the linear
    // limit R3).
    if out.stop == NewtonStop::Converged && opts.rtol > MULTIPLIER_RTOL {
        let fine = ShootingOptions {
            rtol: (opts.rtol / 100.0).max(MULTIPLIER_RTOL),
            ..opts.clone()
        };
        if let Ok(m) = period_map(model, &out.x, &fine) {
            map = m;
        }
    }
    let multipliers = map_multipliers(&map.monodromy, opts.symmetric)?;
    let monodromy = if opts.symmetric {
        &map.monodromy * &map.monodromy
    } else {
        map.monodromy
    };
    Ok(PeriodicSolution {
        converged: out.stop == NewtonStop::Converged,
        stop: out.stop,
        period,
        initial_state: out.x,
        residual_history: out.history,
        monodromy,
        multipliers,
    })
}

/// The Newton iteration of [`shoot`] alone: the period nT and Newton's
/// outcome (the state, the map there, the stop and the residual history),
/// without the multipliers' finer monodromy. A branch's start, which
/// corrects and evaluates its point in full itself, takes this (a soft
/// R2 N = 2 start spent 1.4 ms of its 1.6 ms on that finer map).
pub(crate) fn shoot_orbit(
    model: &Model,
    guess: &[f64],
    opts: &ShootingOptions,
) -> Result<(f64, NewtonOutcome<DensePoint>), PeriodicError> {
    let (period, _) = shooting_checks(model, guess, opts)?;
    let mut sys = DenseShooting {
        model,
        opts,
        scale: scales(model, opts),
        iteration: 0,
    };
    Ok((
        period,
        damped_newton(&mut sys, guess, &newton_options(opts))?,
    ))
}

/// Newton–Krylov shooting for large systems (matrix-free: products with
/// Φ replayed on each iterate's integration, `MapTangent`): each Newton
/// step solves `(Φ - I) δ = -(P(x) - x)`
/// by GMRES to a relative residual of 1e-3 (inexact Newton). The dominant
/// Floquet multipliers come from an Arnoldi iteration of Φ at the solution
/// (`arnoldi` Krylov vectors; Ritz values, largest modulus first). The
/// returned `monodromy` is empty (0 × 0). At least
/// [`MIN_ARNOLDI`] vectors (or the whole space, if smaller) are required:
/// with fewer the dominant multiplier can be missed and an unstable orbit
/// called stable.
pub fn shoot_krylov(
    model: &Model,
    guess: &[f64],
    opts: &ShootingOptions,
    arnoldi: usize,
) -> Result<PeriodicSolution, PeriodicError> {
    let (period, d) = shooting_checks(model, guess, opts)?;
    if arnoldi < MIN_ARNOLDI.min(d) {
        return Err(PeriodicError::Options(format!(
            "arnoldi = {arnoldi}: at least {} Krylov vectors are needed for a stability verdict",
            MIN_ARNOLDI.min(d)
        )));
    }
    let scale = scales(model, opts);
    let mut sys = KrylovShooting {
        model,
        opts,
        scale: &scale,
        iteration: 0,
        tangent: None,
    };
    let out = damped_newton(&mut sys, guess, &newton_options(opts))?;
    let x = out.x;
    // Dominant multipliers: Arnoldi on Φ (Ritz values of the Hessenberg
    // matrix of Φ - I, shifted back by 1), from a generic start vector.
    let noise = 1e3 * opts.rtol;
    let iteration = sys.iteration;
    let tangent = sys.tangent_at(&x)?;
    let mut apply = |v: &[f64]| {
        stopped(opts, iteration)?;
        Ok(tangent.shifted_scaled(v, &scale, 1.0))
    };
    let ritz = arnoldi_matrix(&mut apply, d, arnoldi, noise)?;
    let multipliers = map_multipliers(&ritz, opts.symmetric)?;
    Ok(PeriodicSolution {
        converged: out.stop == NewtonStop::Converged,
        stop: out.stop,
        period,
        initial_state: x,
        residual_history: out.history,
        monodromy: DMatrix::zeros(0, 0),
        multipliers,
    })
}

/// A stop requested (`opts.interrupt`) between two products with Φ: at
/// N = 10⁶ one GMRES solve lasted 20 s past Ctrl-C.
fn stopped(opts: &ShootingOptions, iteration: usize) -> Result<(), PeriodicError> {
    match &opts.interrupt {
        Some(stop) => stop
            .check(0.0)
            .map_err(|source| PeriodicError::Integration { iteration, source }),
        None => Ok(()),
    }
}
