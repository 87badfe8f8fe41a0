//! The continuation problem in scaled variables: the extended system
//! `Ĝ(z) = 0` with its Jacobian, the pseudo-arclength corrector, the
//! tangent, and a converged point evaluated in full (orbit summary,
//! multipliers, test values).

use crate::model::family::Family;
use std::sync::Arc;

use nalgebra::{DMatrix, DVector};

use super::events::{BranchEvent, Observed, TestValues};
use super::{BranchPoint, ContinuationError, ContinuationOptions, SpecialKind};
use crate::model::Model;
use crate::newton::{damped_newton, NewtonOptions, NewtonStop, NewtonSystem};
use crate::periodic::{
    forcing_period, map_image, map_multipliers, multipliers_of_map, orbit_summary_by,
    period_map_with, MapTangent, ShootingOptions, MAX_STEPS,
};

/// The linearisation of the extended system at a point.
#[derive(Clone, Debug)]
pub(super) enum Linear {
    /// The Jacobian [Ĵ_x, Ĝ_p] (d × (d+1)) and Φ (or DG of the half map),
    /// from the full variational equations.
    Dense {
        /// [Ĵ_x, Ĝ_p], scaled.
        jac: DMatrix<f64>,
        /// Φ, or DG of the half map (body order, unscaled).
        monodromy: DMatrix<f64>,
    },
    /// Matrix-free: products Ĵ_x v replayed on the steps of the point's
    /// integration, and the column Ĝ_p.
    Krylov {
        /// Products with Φ (or DG), unscaled.
        tangent: Arc<MapTangent>,
        /// Ĝ_p, scaled.
        g_p: Vec<f64>,
    },
}

/// A converged point of the extended system with its linearisation.
#[derive(Clone, Debug)]
pub(super) struct Solved {
    pub(super) z: Vec<f64>,
    pub(super) linear: Linear,
}

/// The continuation problem in scaled variables: the family of models, the
/// options and the scales.
///
/// The residual's rows are scaled by `scale` (the corrector's tolerance
/// is on them); the unknowns' state part by `scale · state_unit`, with
/// `state_unit = √(max(N, 2)/2)` for a row of N bodies. The arclength is
/// the Euclidean norm of the unknowns, so the state counts in it as its
/// root-mean-square over the bodies, as much for a row of 100 as for a row
/// of two: without it, a parameter step of the same size moved the
/// arclength √(N/2) times further and the steps `ds_max` allows shrank
/// with N (docs/decisions.md D20).
#[derive(Clone)]
pub(super) struct Problem<F> {
    family: F,
    pub(super) opts: ContinuationOptions,
    /// Scales of the residual's rows (the state's displacement and
    /// velocity scales).
    pub(super) scale: Vec<f64>,
    /// Factor from `scale` to the unknowns' state scale.
    pub(super) state_unit: f64,
    p_scale: f64,
    pub(super) d: usize,
    /// Integration steps of the last evaluation of the map (0: none yet).
    steps: u64,
    /// The chord's largest contraction (ratio of consecutive residual
    /// norms) in the last correction that took two chord iterates (NaN:
    /// none yet).
    chord_rate: f64,
}

impl<F: Family> Problem<F> {
    /// Scales: the displacement scale for u, × Ω of `model` for v,
    /// `p_scale` for p (the branch's, `branch::parameter_scale`).
    pub(super) fn new(family: F, opts: ContinuationOptions, model: &Model, p_scale: f64) -> Self {
        let d = 2 * model.bodies().len();
        let w = model.forcing_frequency().unwrap_or(1.0);
        let u = opts.shooting.displacement_scale;
        Self {
            family,
            opts,
            scale: (0..d).map(|i| if i < d / 2 { u } else { u * w }).collect(),
            state_unit: ((d / 2).max(2) as f64 / 2.0).sqrt(),
            p_scale,
            d,
            steps: 0,
            chord_rate: f64::NAN,
        }
    }

    /// What the last corrections learnt for the next: the map's steps
    /// and the chord's contraction.
    pub(super) fn learnt(&self) -> (u64, f64) {
        (self.steps, self.chord_rate)
    }

    /// Starts from what another copy's corrections learnt ([`Self::learnt`]).
    pub(super) fn learn(&mut self, (steps, chord_rate): (u64, f64)) {
        (self.steps, self.chord_rate) = (steps, chord_rate);
    }

    pub(super) fn model(&mut self, p: f64) -> Result<Model, ContinuationError> {
        Ok(self.family.model_at(p)?)
    }

    pub(super) fn unscale(&self, z: &[f64]) -> (Vec<f64>, f64) {
        let x = z[..self.d]
            .iter()
            .zip(&self.scale)
            .map(|(a, s)| a * s * self.state_unit)
            .collect();
        (x, z[self.d] * self.p_scale)
    }

    pub(super) fn scale_state(&self, x: &[f64], p: f64) -> Vec<f64> {
        let mut z: Vec<f64> = x
            .iter()
            .zip(&self.scale)
            .map(|(a, s)| a / (s * self.state_unit))
            .collect();
        z.push(p / self.p_scale);
        z
    }

    /// Ĝ(z) and, with `full`, its linearisation: dense, the Jacobian
    /// [Ĵ_x, Ĝ_p] (d × (d+1)) and Φ from one integration of the variational
    /// equations with the parameter column; matrix-free
    /// (`opts.krylov`), the parameter column alone. Without `full`, from
    /// the state alone.
    pub(super) fn residual(&mut self, z: &[f64], full: bool) -> Option<Residual> {
        let (x, p) = self.unscale(z);
        let d = self.d;
        let model = self.model(p).ok()?;
        let scaled = |image: &[f64], scale: &[f64]| -> Vec<f64> {
            (0..d).map(|i| (image[i] - x[i]) / scale[i]).collect()
        };
        // A corrector iterate far off the branch can lie deep inside a
        // contact, where the map is astronomically stiff (R2 N = 4 past the
        // fold at 0.538 ω0: one evaluation took 1.2 s, 1500 times the
        // usual): at most 20 times the steps of the last evaluation.
        let budget = if self.steps == 0 {
            MAX_STEPS
        } else {
            (20 * self.steps).max(2000)
        };
        if !full {
            let (image, steps) = period_image_within(&model, &x, &self.opts.shooting, budget)?;
            self.steps = steps;
            return Some(Residual {
                g: scaled(&image, &self.scale),
                linear: None,
            });
        }
        let dp = 1e-6 * self.p_scale.max(p.abs());
        let model_p = self.model(p + dp).ok()?;
        let shifted = Some((&model_p, dp));
        let dense = self.opts.krylov.is_none();
        let derivatives =
            period_map_with(&model, &x, &self.opts.shooting, shifted, dense, budget).ok()?;
        self.steps = derivatives.steps;
        let (map, dp_column) = (derivatives.map, derivatives.dp_column?);
        if let Some(tangent) = derivatives.tangent {
            let g_p = (0..d)
                .map(|r| dp_column[r] * self.p_scale / self.scale[r])
                .collect();
            return Some(Residual {
                g: scaled(&map.image, &self.scale),
                linear: Some(Linear::Krylov {
                    tangent: Arc::new(tangent),
                    g_p,
                }),
            });
        }
        let mut jac = DMatrix::zeros(d, d + 1);
        for r in 0..d {
            for c in 0..d {
                let id = if r == c { 1.0 } else { 0.0 };
                jac[(r, c)] =
                    (map.monodromy[(r, c)] - id) * self.scale[c] * self.state_unit / self.scale[r];
            }
            jac[(r, d)] = dp_column[r] * self.p_scale / self.scale[r];
        }
        Some(Residual {
            g: scaled(&map.image, &self.scale),
            linear: Some(Linear::Dense {
                jac,
                monodromy: map.monodromy,
            }),
        })
    }

    /// Newton on [Ĝ(z) = 0, t·(z - z_pred) = 0] from `pred` (the shared
    /// damped Newton, no line search, steps damped to
    /// `step.corrector_max_step`, stagnation at the period map's noise
    /// floor accepted). Returns the solution and the evaluations used.
    ///
    /// With `nearby`, the Jacobian of a solution close to `pred` (the point
    /// the predictor left), the iteration starts as a chord iteration with
    /// it: residuals of the state alone, a third of the cost of an
    /// evaluation with the variational equations (docs/decisions.md D15).
    /// The iterate the observed contraction predicts to converge (that of
    /// the last two chord iterates, or after the first one that of the
    /// last correction) is evaluated in full (so the solution comes with
    /// its own Jacobian), as is every iterate once the chord contracts
    /// poorly (ratio above 1/4): Newton from there. Returns the solution
    /// and the work of the correction in Newton iterations for the step
    /// control: a full evaluation after the first counts two, two chord
    /// iterations one (a chord iteration costs a third of a full one, and
    /// a few of them are no sign of a hard correction).
    pub(super) fn correct(
        &mut self,
        pred: &[f64],
        t: &[f64],
        nearby: Option<&Linear>,
    ) -> Option<(Solved, usize)> {
        let opts = self.corrector_options();
        let chord = match nearby {
            Some(Linear::Dense { jac, .. }) => Some(bordered(jac, t)),
            _ => None,
        };
        let mut corrector = Corrector::new(self, pred, t, chord, false);
        let out = damped_newton(&mut corrector, pred, &opts).ok()?;
        let rate = corrector
            .chord_norms
            .windows(2)
            .map(|w| w[1] / w[0])
            .fold(f64::NAN, f64::max);
        let chord = corrector.chord_norms.len();
        if rate.is_finite() {
            self.chord_rate = rate;
        }
        if out.stop != NewtonStop::Converged {
            return None;
        }
        let (residual, c) = out.point;
        let residual = match residual.linear {
            Some(_) => residual,
            // Converged at a chord iterate: its Jacobian is still needed.
            None => self.residual(&out.x, true)?,
        };
        let linear = residual.linear?;
        // One more Newton step with a dense Jacobian just computed, without
        // evaluating again: the residual tolerance bounds ‖Ĝ‖, and the
        // state error is ‖Ĵ⁻¹‖ times that, large where a multiplier is near
        // 1; the step takes it to the square of the residual.
        let z = match &linear {
            Linear::Dense { jac, .. } => {
                let rhs =
                    DVector::from_iterator(self.d + 1, residual.g.iter().map(|g| -g).chain([-c]));
                let delta = bordered(jac, t).lu().solve(&rhs)?;
                out.x.iter().zip(delta.iter()).map(|(z, d)| z + d).collect()
            }
            Linear::Krylov { .. } => out.x,
        };
        Some((
            Solved { z, linear },
            if chord == 0 {
                out.evaluations
            } else {
                let full = out.evaluations - chord;
                2 * full.saturating_sub(1) + chord.div_ceil(2)
            },
        ))
    }
}

impl<F: Family> Problem<F> {
    /// The corrector's Newton options: no line search, steps damped to
    /// `step.corrector_max_step`, stagnation at the period map's noise
    /// floor accepted.
    fn corrector_options(&self) -> NewtonOptions {
        NewtonOptions {
            tol: self.opts.shooting.tol,
            max_iterations: self.opts.max_corrector.saturating_sub(1),
            max_step: self.opts.step.corrector_max_step,
            line_search: false,
            // The correction is negligible although the residual is a
            // little above tol.
            stall: Some((1e-2, 100.0)),
        }
    }

    /// The corrector's solution from `pred` by chord iterations alone
    /// with the dense Jacobian of `nearby` (Broyden-updated): state-only
    /// maps, no variational one, so the solution comes without its own
    /// Jacobian. None where `nearby` is matrix-free or the chord does not
    /// converge.
    fn correct_chord(&mut self, pred: &[f64], t: &[f64], nearby: &Linear) -> Option<Vec<f64>> {
        let Linear::Dense { jac, .. } = nearby else {
            return None;
        };
        let opts = self.corrector_options();
        let chord = Some(bordered(jac, t));
        let mut corrector = Corrector::new(self, pred, t, chord, true);
        let out = damped_newton(&mut corrector, pred, &opts).ok()?;
        (out.stop == NewtonStop::Converged).then_some(out.x)
    }

    /// A trial point of a location whose event reads only the orbit (a
    /// grazing: the impacts per period and the impact margin), corrected
    /// by the chord alone from `a` and summarised. Its linearisation,
    /// tangent, multipliers and other test values are `a`'s stand-ins, so
    /// it is provisional: the point a location ends on is evaluated in
    /// full. R2 N = 2: a grazing whose impact splits in two is bisected in
    /// 20 trials, each of which had cost a variational map.
    fn trial_on_orbit(&mut self, pred: &[f64], a: &Evaluated) -> Option<Evaluated> {
        let z = self.correct_chord(pred, &a.tangent, &a.solved.linear)?;
        let (state, parameter) = self.unscale(&z);
        let e = Evaluated {
            solved: Solved {
                z,
                linear: a.solved.linear.clone(),
            },
            tangent: a.tangent.clone(),
            point: BranchPoint {
                parameter,
                state,
                ..a.point.clone()
            },
            tests: a.tests,
        };
        self.add_orbit(e)
    }
}

/// Unit tangent at a solution with the dense Jacobian `jac` = [Ĵ_x Ĝ_p],
/// oriented along `previous`: the solution of `[jac; previousᵀ] t =
/// e_{d+1}`, normalised.
fn dense_tangent(jac: &DMatrix<f64>, previous: &[f64]) -> Option<Vec<f64>> {
    let d = jac.nrows();
    let mut e = DVector::zeros(d + 1);
    e[d] = 1.0;
    let t = bordered(jac, previous).lu().solve(&e)?;
    Some(unit_along(t.as_slice().to_vec(), previous))
}

/// `t` normalised and oriented along `previous`.
pub(super) fn unit_along(mut t: Vec<f64>, previous: &[f64]) -> Vec<f64> {
    let norm = t.iter().map(|v| v * v).sum::<f64>().sqrt();
    let sign = if t.iter().zip(previous).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
        -1.0
    } else {
        1.0
    };
    t.iter_mut().for_each(|v| *v *= sign / norm);
    t
}

/// `P(x)` without the variational equations.
pub(super) fn period_image(model: &Model, x: &[f64], opts: &ShootingOptions) -> Option<Vec<f64>> {
    period_image_within(model, x, opts, MAX_STEPS).map(|(image, _)| image)
}

/// [`period_image`] in at most `max_steps` steps, and the steps taken.
fn period_image_within(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    max_steps: u64,
) -> Option<(Vec<f64>, u64)> {
    map_image(model, x, opts, max_steps).ok()
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

impl<F: Family> Problem<F> {
    /// The point `solved` in full detail: tangent (oriented along
    /// `previous_tangent`), multipliers and test values, and with
    /// `with_orbit` its orbit summary (one more integration of the period
    /// with its extrema and impacts; without it the amplitudes are empty
    /// and the impacts per period 0, which the tests of folds, branch
    /// points, period doublings and Neimark–Sacker points do not read).
    pub(super) fn evaluate_with(
        &mut self,
        solved: Solved,
        previous_tangent: &[f64],
        with_orbit: bool,
    ) -> Option<Evaluated> {
        let (x, p) = self.unscale(&solved.z);
        let symmetric = self.opts.shooting.symmetric;
        let (tangent, multipliers, tests) = match &solved.linear {
            Linear::Dense { jac, monodromy } => {
                let tangent = dense_tangent(jac, previous_tangent)?;
                let multipliers = map_multipliers(monodromy, symmetric).ok()?;
                let tests = TestValues::at(jac, &tangent, monodromy, &multipliers, 0, symmetric);
                (tangent, multipliers, tests)
            }
            Linear::Krylov { .. } => {
                // The tangent and the multipliers are independent: one
                // thread each (the same numbers on any thread count).
                let operators = self.operators(&solved.linear)?;
                let m = self.opts.krylov?;
                let (tangent, map_eigenvalues) = rayon::join(
                    || operators.tangent(previous_tangent),
                    || operators.dominant_map_eigenvalues(m),
                );
                let (tangent, map_eigenvalues) = (tangent?, map_eigenvalues?);
                let multipliers = multipliers_of_map(map_eigenvalues.clone(), symmetric);
                let tests = TestValues::from_spectrum(
                    tangent[self.d],
                    &map_eigenvalues,
                    &multipliers,
                    symmetric,
                );
                (tangent, multipliers, tests)
            }
        };
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
    /// amplitudes over the period and the impacts per period. A symmetric
    /// orbit (`u(t + nT/2) = S u(t)`) is summarised over its first half:
    /// the second half is the mirror image, so max |u_i| over the period is
    /// the larger of the half's max |u_i| and max |u_{N-1-i}|, and each
    /// impact of the first half has its mirror image in the second.
    pub(super) fn add_orbit(&mut self, mut e: Evaluated) -> Option<Evaluated> {
        let p = e.point.parameter;
        let model = self.model(p).ok()?;
        let symmetric = self.opts.shooting.symmetric;
        let period =
            forcing_period(&model).ok()? * f64::from(self.opts.shooting.subharmonic.max(1));
        let span = if symmetric { 0.5 * period } else { period };
        let orbit = orbit_summary_by(
            &model,
            &e.point.state,
            (span, 0), // (no samples: the extrema are exact)
            self.opts.shooting.rtol,
            self.opts.shooting.integrator,
        )
        .ok()?;
        let mut impacts = orbit.impacts_per_period();
        let (mut max_u, mut max_v) = (orbit.max_displacement, orbit.max_velocity);
        let mut margin = orbit.impact_margin;
        if symmetric {
            impacts *= 2;
            let n = max_u.len();
            max_u = (0..n).map(|i| max_u[i].max(max_u[n - 1 - i])).collect();
            max_v = (0..n).map(|i| max_v[i].max(max_v[n - 1 - i])).collect();
            let mirror = model.mirror_contacts()?;
            margin = (0..margin.len())
                .map(|k| margin[k].max(margin[mirror[k]]))
                .collect();
        }
        e.tests.grazing_margin = margin
            .iter()
            .copied()
            .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(f64::NAN);
        e.tests.impacts = impacts;
        e.point.impacts_per_period = impacts;
        e.point.max_displacement = max_u;
        e.point.max_velocity = max_v;
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
        let (solved, _) = self.correct(&pred, &held, Some(&a.solved.linear))?;
        self.evaluate_with(solved, &a.tangent, false)
    }
}

/// Ĝ at an iterate, with its linearisation when evaluated in full.
pub(super) struct Residual {
    /// Ĝ(z), scaled.
    pub(super) g: Vec<f64>,
    /// The linearisation, if evaluated in full.
    pub(super) linear: Option<Linear>,
}

/// The bordered matrix `[J; tᵀ]` ((d+1) × (d+1)) of a d × (d+1) Jacobian.
fn bordered(jac: &DMatrix<f64>, t: &[f64]) -> DMatrix<f64> {
    let d = jac.nrows();
    let mut a = DMatrix::zeros(d + 1, d + 1);
    a.view_mut((0, 0), (d, d + 1)).copy_from(jac);
    for (col, &tc) in t.iter().enumerate() {
        a[(d, col)] = tc;
    }
    a
}

/// Broyden's ("good") rank-one update of `b` for the secant condition
/// `b (z1 − z0) = f1 − f0`. The border row is linear and exact, so the
/// update leaves it unchanged.
fn broyden_update(b: &mut DMatrix<f64>, z0: &[f64], f0: &[f64], z1: &[f64], f1: &[f64]) {
    let dz = DVector::from_iterator(z0.len(), z1.iter().zip(z0).map(|(a, b)| a - b));
    let df = DVector::from_iterator(f0.len(), f1.iter().zip(f0).map(|(a, b)| a - b));
    let dz2 = dz.norm_squared();
    if dz2 > 0.0 {
        let u = (df - &*b * &dz) / dz2;
        *b += u * dz.transpose();
    }
}

/// The pseudo-arclength corrector as a Newton system: unknowns z (scaled),
/// residual `[Ĝ(z); t·(z − z_pred)]`, direction from the LU factors of
/// `[Ĵ; tᵀ]` (at the iterate, or the chord factors for the first step).
struct Corrector<'p, 'a, F> {
    problem: &'p mut Problem<F>,
    pred: &'a [f64],
    t: &'a [f64],
    chord: Option<DMatrix<f64>>,
    /// Residual norms of the chord iterates so far.
    chord_norms: Vec<f64>,
    /// The last chord iterate and its residual `[Ĝ; c]` (Broyden update).
    last: Option<(Vec<f64>, Vec<f64>)>,
    /// Whether an iterate was evaluated in full (Newton from then on).
    full_seen: bool,
    /// Chord iterations only, never a full evaluation.
    chord_only: bool,
    /// Residual norm of the last matrix-free iterate (divergence test).
    krylov_norm: Option<f64>,
}

impl<'p, 'a, F> Corrector<'p, 'a, F> {
    fn new(
        problem: &'p mut Problem<F>,
        pred: &'a [f64],
        t: &'a [f64],
        chord: Option<DMatrix<f64>>,
        chord_only: bool,
    ) -> Self {
        Self {
            problem,
            pred,
            t,
            chord,
            chord_norms: Vec::new(),
            last: None,
            full_seen: false,
            chord_only,
            krylov_norm: None,
        }
    }
}

impl<F: Family> NewtonSystem for Corrector<'_, '_, F> {
    /// Ĝ(z) (with its linearisation unless a chord step follows) and the
    /// constraint residual.
    type Point = (Residual, f64);
    /// Any failure (model, integration) ends the correction.
    type Error = ();

    fn evaluate(&mut self, z: &[f64]) -> Result<Self::Point, ()> {
        let tol = self.problem.opts.shooting.tol;
        let full = !self.chord_only
            && (self.chord.is_none()
                || self.full_seen
                || match self.chord_norms[..] {
                    [.., a, b] => b > 0.25 * a || 10.0 * b * b / a <= tol,
                    // After the first chord iterate: the last correction's
                    // contraction, with a factor 4 to spare, predicts
                    // convergence (R2 N = 2: right 88 times in 89, each time
                    // one state-only map saved).
                    [a] => 4.0 * self.problem.chord_rate * a <= tol,
                    _ => false,
                });
        self.full_seen |= full;
        let r = self.problem.residual(z, full).ok_or(())?;
        let c = (0..z.len())
            .map(|i| self.t[i] * (z[i] - self.pred[i]))
            .sum::<f64>();
        let point = (r, c);
        if !full {
            let norm = self.residual_norm(&point);
            self.chord_norms.push(norm);
            let f: Vec<f64> = point.0.g.iter().copied().chain([c]).collect();
            if let (Some((z0, f0)), Some(b)) = (&self.last, &mut self.chord) {
                broyden_update(b, z0, f0, z, &f);
            }
            self.last = Some((z.to_vec(), f));
        }
        Ok(point)
    }

    fn residual_norm(&self, (r, c): &Self::Point) -> f64 {
        r.g.iter().fold(c.abs(), |m, v| m.max(v.abs()))
    }

    fn direction(&mut self, _z: &[f64], point: &Self::Point) -> Result<Option<Vec<f64>>, ()> {
        let (r, c) = point;
        let d = self.problem.d;
        let mut rhs = DVector::zeros(d + 1);
        for (row, gr) in r.g.iter().enumerate() {
            rhs[row] = -gr;
        }
        rhs[d] = -c;
        Ok(match (&r.linear, &self.chord) {
            (Some(Linear::Dense { jac, .. }), _) => bordered(jac, self.t)
                .lu()
                .solve(&rhs)
                .map(|d| d.as_slice().to_vec()),
            (Some(krylov @ Linear::Krylov { .. }), _) => {
                // An iterate whose residual grew is off the branch, often
                // deep in a contact where every product is an expensive
                // integration and GMRES needs a hundred of them (R2 N = 100
                // near 0.68 ω0: 40 s for one direction): the correction
                // fails and the step is halved (docs/decisions.md D20).
                let norm = self.residual_norm(point);
                if self.krylov_norm.is_some_and(|previous| norm > previous) {
                    return Err(());
                }
                self.krylov_norm = Some(norm);
                // Inexact Newton: the direction to 1e-4 relative.
                self.problem
                    .operators(krylov)
                    .and_then(|o| o.bordered_solve(self.t, rhs.as_slice(), 1e-4))
            }
            (None, Some(b)) => b.clone().lu().solve(&rhs).map(|d| d.as_slice().to_vec()),
            (None, None) => None,
        })
    }

    /// Max-norm in the residual's scales (the state part of the unknowns
    /// × `state_unit`): the damping `corrector_max_step` limits a state
    /// step to the same physical size at any N.
    fn step_norm(&self, delta: &[f64]) -> f64 {
        let (d, unit) = (self.problem.d, self.problem.state_unit);
        delta[..d]
            .iter()
            .fold(delta[d].abs(), |m, v| m.max(unit * v.abs()))
    }
}

impl Evaluated {
    /// The point as an event sees it.
    pub(super) fn observed(&self) -> Observed<'_> {
        Observed {
            tests: &self.tests,
            point: &self.point,
        }
    }
}

impl<F: Family> Problem<F> {
    /// Location of the event that occurs between `a` and `b` on the
    /// arclength in (0, ds) from `a`: regula falsi (Illinois) on the event's
    /// scalar test function where it has one, bisection otherwise, until
    /// the parameter is bracketed to `locate_tol`; returns the located
    /// point.
    pub(super) fn locate(
        &mut self,
        event: &dyn BranchEvent,
        a: &Evaluated,
        b: &Evaluated,
        ds: f64,
    ) -> Option<Evaluated> {
        let (mut lo, mut hi) = (0.0, ds);
        let (mut p_lo, mut p_hi) = (a.point.parameter, b.point.parameter);
        let scalar = event.scalar(a.observed(), b.observed());
        let (mut g_lo, mut g_hi) =
            scalar.map_or((f64::NAN, f64::NAN), |f| (f(&a.tests), f(&b.tests)));
        // Which end moved last (Illinois: the end kept twice has its value
        // halved, so that the secant does not stall).
        let mut moved_hi: Option<bool> = None;
        let mut best: Option<Evaluated> = None;
        let mut lo_point: Option<Evaluated> = None;
        let light = event.kind() == SpecialKind::Grazing;
        let mut provisional = false;
        for _ in 0..80 {
            if (p_hi - p_lo).abs() <= self.opts.locate_tol && best.is_some() {
                break;
            }
            let width = hi - lo;
            let secant = lo - g_lo * width / (g_hi - g_lo);
            // A secant within 2 % of the end that moved last: the root is
            // next to that point, and a step of half the tolerance past it
            // closes the bracket (R2 N = 2: one evaluation less a location,
            // where the 2 % step had taken two). Else at least 2 % in.
            let near = 0.02 * width;
            let half_tol = 0.5 * width * self.opts.locate_tol / (p_hi - p_lo).abs();
            let (m_lo, m_hi) = match moved_hi {
                Some(true) if secant > hi - near => (near, near.min(half_tol)),
                Some(false) if secant < lo + near => (near.min(half_tol), near),
                _ => (near, near),
            };
            let mid = if secant.is_finite() && g_lo * g_hi < 0.0 {
                secant.clamp(lo + m_lo, hi - m_hi)
            } else {
                0.5 * (lo + hi)
            };
            let pred = a.predict(mid);
            let trial = light.then(|| self.trial_on_orbit(&pred, a)).flatten();
            provisional = trial.is_some();
            let e = match trial {
                Some(e) => e,
                None => {
                    let (solved, _) = self.correct(&pred, &a.tangent, Some(&a.solved.linear))?;
                    self.evaluate_with(solved, &a.tangent, event.needs_orbit())?
                }
            };
            let g = scalar.map_or(f64::NAN, |f| f(&e.tests));
            if event.between(lo_point.as_ref().unwrap_or(a).observed(), e.observed()) {
                hi = mid;
                p_hi = e.point.parameter;
                g_hi = g;
                if moved_hi == Some(true) {
                    g_lo *= 0.5;
                }
                moved_hi = Some(true);
            } else {
                lo = mid;
                p_lo = e.point.parameter;
                g_lo = g;
                lo_point = Some(e.clone());
                if moved_hi == Some(false) {
                    g_hi *= 0.5;
                }
                moved_hi = Some(false);
            }
            best = Some(e);
            if hi - lo < 1e-14 {
                break;
            }
        }
        match best {
            // Evaluated in full where it lies (its own Jacobian, tangent
            // and multipliers): one chord iterate converges at once.
            Some(e) if provisional => {
                let (solved, _) = self.correct(&e.solved.z, &a.tangent, Some(&a.solved.linear))?;
                self.evaluate_with(solved, &a.tangent, true)
            }
            best => best,
        }
    }
}
