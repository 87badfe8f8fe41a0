//! The continuation problem in scaled variables: the extended system
//! `Ĝ(z) = 0` with its Jacobian, the pseudo-arclength corrector, the
//! tangent, and a converged point evaluated in full (orbit summary,
//! multipliers, test values).

use nalgebra::{DMatrix, DVector};

use super::events::TestValues;
use super::{model_at, BranchPoint, ContinuationError, ContinuationOptions};
use crate::integrate::{integrate_to, IntegratorOptions};
use crate::model::Model;
use crate::newton::{damped_newton, NewtonOptions, NewtonStop, NewtonSystem};
use crate::periodic::{
    forcing_period, map_multipliers, map_time, mirror, orbit_summary, period_map, ShootingOptions,
};

/// A converged point of the extended system with its linearisation.
#[derive(Clone, Debug)]
pub(super) struct Solved {
    pub(super) z: Vec<f64>,
    pub(super) jac: DMatrix<f64>,
    pub(super) monodromy: DMatrix<f64>,
}

/// The continuation problem in scaled variables: the family of models, the
/// options and the scales.
pub(super) struct Problem<F> {
    family: F,
    pub(super) opts: ContinuationOptions,
    pub(super) scale: Vec<f64>,
    p_scale: f64,
    pub(super) d: usize,
}

impl<F: FnMut(f64) -> Result<Model, String>> Problem<F> {
    /// Scales: the displacement scale for u, × Ω of `model` for v, the
    /// option `parameter_scale` (default |p0|) for p.
    pub(super) fn new(family: F, opts: ContinuationOptions, model: &Model, p0: f64) -> Self {
        let d = 2 * model.bodies().len();
        let w = model.forcing_frequency().unwrap_or(1.0);
        let u = opts.shooting.displacement_scale;
        let p_scale = opts.parameter_scale.unwrap_or(p0.abs());
        Self {
            family,
            opts,
            scale: (0..d).map(|i| if i < d / 2 { u } else { u * w }).collect(),
            p_scale,
            d,
        }
    }

    pub(super) fn model(&mut self, p: f64) -> Result<Model, ContinuationError> {
        model_at(&mut self.family, p)
    }

    pub(super) fn unscale(&self, z: &[f64]) -> (Vec<f64>, f64) {
        let x = z[..self.d]
            .iter()
            .zip(&self.scale)
            .map(|(a, s)| a * s)
            .collect();
        (x, z[self.d] * self.p_scale)
    }

    pub(super) fn scale_state(&self, x: &[f64], p: f64) -> Vec<f64> {
        let mut z: Vec<f64> = x.iter().zip(&self.scale).map(|(a, s)| a / s).collect();
        z.push(p / self.p_scale);
        z
    }

    /// Ĝ(z) and its Jacobian [Ĵ_x, Ĝ_p] (d × (d+1)), and Φ.
    pub(super) fn residual(&mut self, z: &[f64]) -> Option<(Vec<f64>, DMatrix<f64>, DMatrix<f64>)> {
        let (x, p) = self.unscale(z);
        let d = self.d;
        let model = self.model(p).ok()?;
        let map = period_map(&model, &x, &self.opts.shooting).ok()?;
        let g: Vec<f64> = (0..d)
            .map(|i| (map.image[i] - x[i]) / self.scale[i])
            .collect();
        let dp = 1e-6 * self.p_scale.max(p.abs());
        let model_p = self.model(p + dp).ok()?;
        let image_p = period_image(&model_p, &x, &self.opts.shooting)?;
        let mut jac = DMatrix::zeros(d, d + 1);
        for r in 0..d {
            for c in 0..d {
                let id = if r == c { 1.0 } else { 0.0 };
                jac[(r, c)] = (map.monodromy[(r, c)] - id) * self.scale[c] / self.scale[r];
            }
            jac[(r, d)] = (image_p[r] - map.image[r]) / dp * self.p_scale / self.scale[r];
        }
        Some((g, jac, map.monodromy))
    }

    /// Newton on [Ĝ(z) = 0, t·(z - z_pred) = 0] from `pred` (the shared
    /// damped Newton, no line search, steps damped to
    /// `step.corrector_max_step`, stagnation at the period map's noise
    /// floor accepted). Returns the solution and the evaluations used.
    pub(super) fn correct(&mut self, pred: &[f64], t: &[f64]) -> Option<(Solved, usize)> {
        let opts = NewtonOptions {
            tol: self.opts.shooting.tol,
            max_iterations: self.opts.max_corrector.saturating_sub(1),
            max_step: self.opts.step.corrector_max_step,
            line_search: false,
            // The correction is negligible although the residual is a
            // little above tol.
            stall: Some((1e-2, 100.0)),
        };
        let mut corrector = Corrector {
            problem: self,
            pred,
            t,
        };
        let out = damped_newton(&mut corrector, pred, &opts).ok()?;
        let (_, jac, monodromy, _) = out.point;
        out.stop.eq(&NewtonStop::Converged).then_some((
            Solved {
                z: out.x,
                jac,
                monodromy,
            },
            out.evaluations,
        ))
    }

    /// Unit tangent at a solution, oriented along `previous`.
    pub(super) fn tangent(&self, jac: &DMatrix<f64>, previous: &[f64]) -> Option<Vec<f64>> {
        let d = self.d;
        let mut a = DMatrix::zeros(d + 1, d + 1);
        a.view_mut((0, 0), (d, d + 1)).copy_from(jac);
        for c in 0..=d {
            a[(d, c)] = previous[c];
        }
        let mut e = DVector::zeros(d + 1);
        e[d] = 1.0;
        let t = a.lu().solve(&e)?;
        let norm = t.norm();
        let mut t: Vec<f64> = t.iter().map(|v| v / norm).collect();
        if t.iter().zip(previous).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
            t.iter_mut().for_each(|v| *v = -*v);
        }
        Some(t)
    }
}

/// `P(x)` without the variational equations (for ∂G/∂p).
pub(super) fn period_image(model: &Model, x: &[f64], opts: &ShootingOptions) -> Option<Vec<f64>> {
    let n = model.bodies().len();
    let t = map_time(model, opts).ok()?;
    let mut sys = crate::dynamics::ChainDynamics::new(model, false);
    let y0 = crate::dynamics::to_interleaved(x);
    let int_opts = IntegratorOptions {
        rtol: opts.rtol,
        atol: opts.rtol * opts.displacement_scale,
        max_steps: 200_000,
        interrupt: opts.interrupt.clone(),
        ..IntegratorOptions::default()
    };
    let (y, _) = integrate_to(&mut sys, 0.0, &y0, t, &int_opts).ok()?;
    let image = crate::dynamics::from_interleaved(&y, n);
    Some(if opts.symmetric {
        mirror(&image)
    } else {
        image
    })
}

/// A point in full detail (for test functions and output).
#[derive(Clone)]
pub(super) struct Evaluated {
    pub(super) solved: Solved,
    pub(super) tangent: Vec<f64>,
    pub(super) point: BranchPoint,
    pub(super) tests: TestValues,
}

impl Evaluated {
    /// The predictor `z + s t` at arclength `s` along the point's tangent.
    pub(super) fn predict(&self, s: f64) -> Vec<f64> {
        self.solved
            .z
            .iter()
            .zip(&self.tangent)
            .map(|(z, t)| z + s * t)
            .collect()
    }
}

impl<F: FnMut(f64) -> Result<Model, String>> Problem<F> {
    /// The point `solved` in full detail: tangent (oriented along
    /// `previous_tangent`), orbit summary, multipliers and test values.
    pub(super) fn evaluate(
        &mut self,
        solved: Solved,
        previous_tangent: &[f64],
    ) -> Option<Evaluated> {
        self.evaluate_with(solved, previous_tangent, true)
    }

    /// [`evaluate`](Self::evaluate), without the orbit summary (one more
    /// integration of the period with its extrema and impacts) when
    /// `with_orbit` is false: then the amplitudes are empty and the impacts
    /// per period 0, which the tests of folds, branch points, period
    /// doublings and Neimark–Sacker points do not read.
    pub(super) fn evaluate_with(
        &mut self,
        solved: Solved,
        previous_tangent: &[f64],
        with_orbit: bool,
    ) -> Option<Evaluated> {
        let tangent = self.tangent(&solved.jac, previous_tangent)?;
        let (x, p) = self.unscale(&solved.z);
        let symmetric = self.opts.shooting.symmetric;
        let multipliers = map_multipliers(&solved.monodromy, symmetric).ok()?;
        let tests = TestValues::at(
            &solved.jac,
            &tangent,
            &solved.monodromy,
            &multipliers,
            0,
            symmetric,
        );
        let point = BranchPoint {
            parameter: p,
            state: x,
            stable: multipliers.first().is_none_or(|m| m.norm() < 1.0),
            multipliers,
            max_displacement: Vec::new(),
            max_velocity: Vec::new(),
            impacts_per_period: 0,
            label: None,
        };
        let e = Evaluated {
            solved,
            tangent,
            point,
            tests,
        };
        if with_orbit {
            self.add_orbit(e)
        } else {
            Some(e)
        }
    }

    /// Completes a point evaluated without its orbit summary: the
    /// amplitudes over the period and the impacts per period.
    pub(super) fn add_orbit(&mut self, mut e: Evaluated) -> Option<Evaluated> {
        let p = e.point.parameter;
        let model = self.model(p).ok()?;
        let period =
            forcing_period(&model).ok()? * f64::from(self.opts.shooting.subharmonic.max(1));
        let orbit = orbit_summary(
            &model,
            &e.point.state,
            period,
            self.opts.orbit_samples,
            self.opts.shooting.rtol,
        )
        .ok()?;
        let impacts = orbit.impacts_per_period();
        e.tests.impacts = impacts;
        e.point.impacts_per_period = impacts;
        e.point.max_displacement = orbit.max_displacement;
        e.point.max_velocity = orbit.max_velocity;
        Some(e)
    }

    /// The solution at parameter `bound`, between the solutions `a` and
    /// `b` that bracket it: predicted by linear interpolation and corrected
    /// with the parameter held.
    pub(super) fn end_point(
        &mut self,
        a: &Evaluated,
        b: &Evaluated,
        bound: f64,
    ) -> Option<Evaluated> {
        let (pa, pb) = (a.point.parameter, b.point.parameter);
        let theta = (bound - pa) / (pb - pa);
        let mut pred: Vec<f64> = a
            .solved
            .z
            .iter()
            .zip(&b.solved.z)
            .map(|(za, zb)| za + theta * (zb - za))
            .collect();
        pred[self.d] = bound / self.p_scale;
        let mut held = vec![0.0; self.d + 1];
        held[self.d] = 1.0;
        let (solved, _) = self.correct(&pred, &held)?;
        self.evaluate(solved, &a.tangent)
    }
}

/// The pseudo-arclength corrector as a Newton system: unknowns z (scaled),
/// residual `[Ĝ(z); t·(z − z_pred)]`, direction from the LU factors of
/// `[Ĵ; tᵀ]`.
struct Corrector<'p, 'a, F> {
    problem: &'p mut Problem<F>,
    pred: &'a [f64],
    t: &'a [f64],
}

impl<F: FnMut(f64) -> Result<Model, String>> NewtonSystem for Corrector<'_, '_, F> {
    /// Ĝ(z), its Jacobian, Φ and the constraint residual.
    type Point = (Vec<f64>, DMatrix<f64>, DMatrix<f64>, f64);
    /// Any failure (model, integration) ends the correction.
    type Error = ();

    fn evaluate(&mut self, z: &[f64]) -> Result<Self::Point, ()> {
        let (g, jac, monodromy) = self.problem.residual(z).ok_or(())?;
        let c = (0..z.len())
            .map(|i| self.t[i] * (z[i] - self.pred[i]))
            .sum::<f64>();
        Ok((g, jac, monodromy, c))
    }

    fn residual_norm(&self, (g, _, _, c): &Self::Point) -> f64 {
        g.iter().fold(c.abs(), |m, v| m.max(v.abs()))
    }

    fn direction(
        &mut self,
        _z: &[f64],
        (g, jac, _, c): &Self::Point,
    ) -> Result<Option<Vec<f64>>, ()> {
        let d = self.problem.d;
        let mut a = DMatrix::zeros(d + 1, d + 1);
        a.view_mut((0, 0), (d, d + 1)).copy_from(jac);
        for (col, &tc) in self.t.iter().enumerate() {
            a[(d, col)] = tc;
        }
        let mut rhs = DVector::zeros(d + 1);
        for (r, gr) in g.iter().enumerate() {
            rhs[r] = -gr;
        }
        rhs[d] = -c;
        Ok(a.lu().solve(&rhs).map(|delta| delta.as_slice().to_vec()))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        delta.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }
}
