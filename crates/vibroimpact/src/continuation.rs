//! Pseudo-arclength continuation of periodic solutions in a parameter, with
//! Floquet stability and detection and location of special points
//! (docs/theory.md §5).
//!
//! ## Formulation
//! Unknowns `z = (x, p)`: the state at t = 0 of an nT-periodic orbit and the
//! parameter, in scaled variables (`x̂ = x / scale`, displacement scale and
//! ×Ω for velocities, `p̂ = p / |p0|`). The branch solves `G(x, p) =
//! P_p(x) - x = 0`; its Jacobian is `[Φ - I, ∂G/∂p]` (Φ from the variational
//! equations, `∂G/∂p` by a forward difference of the period map).
//!
//! - Predictor: `z + ds t` along the unit tangent t.
//! - Corrector: Newton on `G(z) = 0, t·(z - z_pred) = 0`.
//! - Tangent: `[J; t_old] t_new = e`, normalised, oriented along t_old.
//! - Step control: ds grows (×1.6) after easy corrections (<= 2 Newton
//!   iterations), shrinks (×0.7) after hard ones (>= 5) and halves on
//!   failure; the branch stops when ds < ds_min.
//!
//! ## Special points (test functions between consecutive points)
//! - fold: the parameter component of the tangent changes sign;
//! - branch point: `det [J; t]` changes sign (it does not at a fold):
//!   a multiplier crosses +1 where the parameter does not turn;
//! - period doubling: `det(Φ + I)` changes sign (a real multiplier
//!   crosses -1);
//! - Neimark–Sacker: the number of multipliers outside the unit circle
//!   changes while no real multiplier crosses +1 or -1 (a complex pair
//!   crossed);
//! - grazing: the number of impacts per period changes.
//!
//! Each is located by bisection of the arclength between the two points
//! (re-correcting from the earlier point), until the parameter is known to
//! `locate_tol`.

use nalgebra::{Complex, DMatrix, DVector};

use crate::integrate::{integrate_to, IntegratorOptions};
use crate::model::Model;
use crate::periodic::{
    forcing_period, map_multipliers, map_time, mirror, orbit_summary, period_map, shoot,
    PeriodicError, ShootingOptions,
};

/// Kinds of special points.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpecialKind {
    /// Turning point of the branch (saddle-node).
    Fold,
    /// A multiplier crosses +1 without a turn: branches cross.
    BranchPoint,
    /// A real multiplier crosses -1.
    PeriodDoubling,
    /// A complex pair crosses the unit circle (torus).
    NeimarkSacker,
    /// The number of impacts per period changes.
    Grazing,
}

impl SpecialKind {
    /// Name used in files: `fold`, `branch-point`, `period-doubling`,
    /// `neimark-sacker`, `grazing`.
    pub fn name(self) -> &'static str {
        match self {
            SpecialKind::Fold => "fold",
            SpecialKind::BranchPoint => "branch-point",
            SpecialKind::PeriodDoubling => "period-doubling",
            SpecialKind::NeimarkSacker => "neimark-sacker",
            SpecialKind::Grazing => "grazing",
        }
    }

    /// Label prefix: LP, BP, PD, NS, GR.
    pub fn prefix(self) -> &'static str {
        match self {
            SpecialKind::Fold => "LP",
            SpecialKind::BranchPoint => "BP",
            SpecialKind::PeriodDoubling => "PD",
            SpecialKind::NeimarkSacker => "NS",
            SpecialKind::Grazing => "GR",
        }
    }
}

/// Options of a continuation.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// Shooting options (subharmonic n, tolerances, scales).
    pub shooting: ShootingOptions,
    /// Initial arclength step (scaled units).
    pub ds: f64,
    /// Smallest step before giving up.
    pub ds_min: f64,
    /// Largest step.
    pub ds_max: f64,
    /// Points at most.
    pub max_points: usize,
    /// Corrector iterations at most.
    pub max_corrector: usize,
    /// Location tolerance of special points in the parameter.
    pub locate_tol: f64,
    /// Samples per period for amplitudes.
    pub orbit_samples: usize,
    /// Largest change of the Floquet multipliers between consecutive points
    /// ([`spectral_distance`]); a larger change halves the step, so that two
    /// crossings of the unit circle do not hide in one step.
    pub max_multiplier_change: f64,
    /// Parameter interval the branch must stay in (default: between the
    /// start and the end value).
    pub bounds: Option<(f64, f64)>,
    /// Follow symmetric orbits of a mirror-symmetric model on the half map
    /// (see [`ShootingOptions::symmetric`]) when the start orbit is
    /// symmetric: half the cost, and symmetry-breaking pitchforks are
    /// regular points of the half map, found by its eigenvalue -1 instead
    /// of a singular extended Jacobian.
    pub use_symmetry: bool,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            // The period map with impacts is accurate to ~1e-9 (scaled) at
            // rtol 1e-11; a corrector tolerance above that noise floor.
            shooting: ShootingOptions {
                rtol: 1e-11,
                tol: 1e-7,
                ..ShootingOptions::default()
            },
            ds: 0.01,
            ds_min: 1e-7,
            ds_max: 0.05,
            max_points: 2000,
            max_corrector: 8,
            locate_tol: 1e-8,
            orbit_samples: 256,
            max_multiplier_change: 0.25,
            bounds: None,
            use_symmetry: true,
        }
    }
}

/// One point of a branch.
#[derive(Clone, Debug)]
pub struct BranchPoint {
    /// Parameter value.
    pub parameter: f64,
    /// State at t = 0 (body order).
    pub state: Vec<f64>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// max |u_i| over the period (m).
    pub max_displacement: Vec<f64>,
    /// max |v_i| over the period (m/s).
    pub max_velocity: Vec<f64>,
    /// Impacts per period (all contacts).
    pub impacts_per_period: usize,
    /// Special-point label at this point (e.g. `LP1`), if it is one.
    pub label: Option<String>,
}

impl BranchPoint {
    /// Largest |multiplier|.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }
}

/// A located special point.
#[derive(Clone, Debug)]
pub struct SpecialPoint {
    /// Kind.
    pub kind: SpecialKind,
    /// Label, e.g. `PD1`.
    pub label: String,
    /// Parameter value (to `locate_tol`).
    pub parameter: f64,
    /// State at t = 0 (body order).
    pub state: Vec<f64>,
    /// Multipliers there.
    pub multipliers: Vec<Complex<f64>>,
    /// Unit tangent of the branch there (scaled variables, x then p).
    pub tangent: Vec<f64>,
    /// Index of the branch point after which it lies.
    pub after_point: usize,
    /// A branch point where a symmetric orbit loses its symmetry (an
    /// eigenvalue -1 of the half map's Jacobian): a pitchfork whose
    /// crossing branch is a pair of mirror-image asymmetric orbits.
    pub symmetry_breaking: bool,
}

/// Why a continuation ended.
#[derive(Clone, Debug, PartialEq)]
pub enum StopReason {
    /// The parameter left the requested range.
    ReachedEnd,
    /// The point budget was used.
    MaxPoints,
    /// The caller asked to stop (e.g. Ctrl-C).
    Interrupted,
    /// The corrector failed down to the smallest step: where and why.
    CannotContinue(String),
    /// The branch returned to its first point (a closed loop, e.g. the
    /// asymmetric branch between two symmetry-breaking points and its
    /// mirror image); it is not traversed again.
    ClosedLoop,
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::ReachedEnd => write!(f, "reached the end of the range"),
            Self::MaxPoints => write!(f, "used the point budget"),
            Self::Interrupted => write!(f, "interrupted"),
            Self::CannotContinue(why) => write!(f, "cannot continue: {why}"),
            Self::ClosedLoop => write!(
                f,
                "closed loop (back at its first point or its mirror image)"
            ),
        }
    }
}

/// A computed branch.
#[derive(Clone, Debug)]
pub struct Branch {
    /// Points in order along the branch.
    pub points: Vec<BranchPoint>,
    /// Special points in order along the branch.
    pub special: Vec<SpecialPoint>,
    /// Why it ended.
    pub stop: StopReason,
    /// Period multiple n of the branch.
    pub subharmonic: u32,
    /// Whether the branch was followed on the symmetric half map (its
    /// orbits satisfy `x(t + nT/2) = S x(t)`).
    pub symmetric: bool,
}

/// Errors before a branch exists.
#[derive(Debug, Clone, thiserror::Error)]
pub enum ContinuationError {
    /// The family could not build a model at a parameter value.
    #[error("model at parameter {parameter}: {message}")]
    Model {
        /// Parameter value.
        parameter: f64,
        /// The model error.
        message: String,
    },
    /// Shooting failed.
    #[error(transparent)]
    Periodic(#[from] PeriodicError),
    /// The start did not converge.
    #[error("no periodic solution at the start: Newton stopped at scaled residual {0:e}")]
    StartNotConverged(f64),
    /// Invalid options or range.
    #[error("{0}")]
    Invalid(String),
    /// An integration failed.
    #[error("integration failed: {0}")]
    Integration(#[from] crate::integrate::IntegrationError),
}

/// A converged point of the extended system with its linearisation.
#[derive(Clone, Debug)]
struct Solved {
    z: Vec<f64>,
    jac: DMatrix<f64>,
    monodromy: DMatrix<f64>,
}

/// The continuation problem in scaled variables.
struct Problem<'a, F> {
    family: &'a mut F,
    opts: &'a ContinuationOptions,
    scale: Vec<f64>,
    p_scale: f64,
    d: usize,
}

impl<'a, F: FnMut(f64) -> Result<Model, String>> Problem<'a, F> {
    /// Scales: the displacement scale for u, × Ω of `model` for v, |p0| for p.
    fn new(family: &'a mut F, opts: &'a ContinuationOptions, model: &Model, p0: f64) -> Self {
        let d = 2 * model.bodies().len();
        let w = model.forcing_frequency().unwrap_or(1.0);
        let u = opts.shooting.displacement_scale;
        Self {
            family,
            opts,
            scale: (0..d).map(|i| if i < d / 2 { u } else { u * w }).collect(),
            p_scale: p0.abs(),
            d,
        }
    }

    fn model(&mut self, p: f64) -> Result<Model, ContinuationError> {
        (self.family)(p).map_err(|message| ContinuationError::Model {
            parameter: p,
            message,
        })
    }

    fn unscale(&self, z: &[f64]) -> (Vec<f64>, f64) {
        let x = z[..self.d]
            .iter()
            .zip(&self.scale)
            .map(|(a, s)| a * s)
            .collect();
        (x, z[self.d] * self.p_scale)
    }

    fn scale_state(&self, x: &[f64], p: f64) -> Vec<f64> {
        let mut z: Vec<f64> = x.iter().zip(&self.scale).map(|(a, s)| a / s).collect();
        z.push(p / self.p_scale);
        z
    }

    /// Ĝ(z) and its Jacobian [Ĵ_x, Ĝ_p] (d × (d+1)), and Φ.
    fn residual(&mut self, z: &[f64]) -> Option<(Vec<f64>, DMatrix<f64>, DMatrix<f64>)> {
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

    /// Newton on [Ĝ(z) = 0, t·(z - z_pred) = 0] from `pred`. Returns the
    /// solution and the iterations used.
    fn correct(&mut self, pred: &[f64], t: &[f64]) -> Option<(Solved, usize)> {
        let d = self.d;
        let mut z = pred.to_vec();
        for it in 1..=self.opts.max_corrector {
            let (g, jac, monodromy) = self.residual(&z)?;
            let gn = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut a = DMatrix::zeros(d + 1, d + 1);
            a.view_mut((0, 0), (d, d + 1)).copy_from(&jac);
            for c in 0..=d {
                a[(d, c)] = t[c];
            }
            let mut rhs = DVector::zeros(d + 1);
            for r in 0..d {
                rhs[r] = -g[r];
            }
            rhs[d] = -(0..=d).map(|c| t[c] * (z[c] - pred[c])).sum::<f64>();
            if gn <= self.opts.shooting.tol && rhs[d].abs() <= self.opts.shooting.tol {
                return Some((Solved { z, jac, monodromy }, it));
            }
            let delta = a.lu().solve(&rhs)?;
            let step = delta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // Stagnation at the period map's noise floor: the correction is
            // negligible although the residual is a little above tol.
            if step <= 1e-2 * self.opts.shooting.tol && gn <= 100.0 * self.opts.shooting.tol {
                return Some((Solved { z, jac, monodromy }, it));
            }
            let lambda = (0.5 / step).min(1.0);
            for c in 0..=d {
                z[c] += lambda * delta[c];
            }
        }
        None
    }

    /// Unit tangent at a solution, oriented along `previous`.
    fn tangent(&self, jac: &DMatrix<f64>, previous: &[f64]) -> Option<Vec<f64>> {
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
fn period_image(model: &Model, x: &[f64], opts: &ShootingOptions) -> Option<Vec<f64>> {
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

/// Test-function values at a point.
#[derive(Clone, Copy, Debug)]
struct Tests {
    tangent_p: f64,
    det_ext: f64,
    /// det(DG + I) of the symmetric half map (an eigenvalue -1 of DG is a
    /// symmetry-breaking pitchfork); 1 off the half map.
    det_sym: f64,
    det_pd: f64,
    /// Multipliers outside the unit circle.
    outside: usize,
    impacts: usize,
}

fn tests_at(
    jac: &DMatrix<f64>,
    t: &[f64],
    monodromy: &DMatrix<f64>,
    multipliers: &[Complex<f64>],
    impacts: usize,
    symmetric: bool,
) -> Tests {
    let d = jac.nrows();
    let mut a = DMatrix::zeros(d + 1, d + 1);
    a.view_mut((0, 0), (d, d + 1)).copy_from(jac);
    for c in 0..=d {
        a[(d, c)] = t[c];
    }
    let identity = DMatrix::<f64>::identity(d, d);
    // Φ + I; on the half map Φ = DG².
    let (det_sym, pd) = if symmetric {
        (
            (monodromy + &identity).determinant(),
            monodromy * monodromy + &identity,
        )
    } else {
        (1.0, monodromy + &identity)
    };
    Tests {
        tangent_p: t[d],
        det_ext: a.determinant(),
        det_sym,
        det_pd: pd.determinant(),
        outside: multipliers.iter().filter(|m| m.norm() > 1.0).count(),
        impacts,
    }
}

fn changed(kind: SpecialKind, a: &Tests, b: &Tests) -> bool {
    match kind {
        SpecialKind::Fold => a.tangent_p.signum() != b.tangent_p.signum(),
        SpecialKind::BranchPoint => {
            (a.det_ext.signum() != b.det_ext.signum()
                && a.tangent_p.signum() == b.tangent_p.signum())
                || a.det_sym.signum() != b.det_sym.signum()
        }
        SpecialKind::PeriodDoubling => a.det_pd.signum() != b.det_pd.signum(),
        // A change of the number of multipliers outside the circle that no
        // real crossing at +1 (fold, branch point) or -1 (period doubling)
        // explains: a complex pair crossed. (Two real multipliers that
        // collide and turn complex outside the circle change nothing.)
        SpecialKind::NeimarkSacker => {
            a.outside != b.outside
                && a.det_pd.signum() == b.det_pd.signum()
                && a.det_ext.signum() == b.det_ext.signum()
                && a.det_sym.signum() == b.det_sym.signum()
                && a.tangent_p.signum() == b.tangent_p.signum()
        }
        SpecialKind::Grazing => a.impacts != b.impacts,
    }
}

const KINDS: [SpecialKind; 5] = [
    SpecialKind::Fold,
    SpecialKind::BranchPoint,
    SpecialKind::PeriodDoubling,
    SpecialKind::NeimarkSacker,
    SpecialKind::Grazing,
];

/// A point in full detail (for test functions and output).
struct Evaluated {
    solved: Solved,
    tangent: Vec<f64>,
    point: BranchPoint,
    tests: Tests,
}

impl<F: FnMut(f64) -> Result<Model, String>> Problem<'_, F> {
    fn evaluate(&mut self, solved: Solved, previous_tangent: &[f64]) -> Option<Evaluated> {
        let tangent = self.tangent(&solved.jac, previous_tangent)?;
        let (x, p) = self.unscale(&solved.z);
        let model = self.model(p).ok()?;
        let period =
            forcing_period(&model).ok()? * f64::from(self.opts.shooting.subharmonic.max(1));
        let orbit = orbit_summary(
            &model,
            &x,
            period,
            self.opts.orbit_samples,
            self.opts.shooting.rtol,
        )
        .ok()?;
        let symmetric = self.opts.shooting.symmetric;
        let multipliers = map_multipliers(&solved.monodromy, symmetric).ok()?;
        let impacts = orbit.impacts_per_period();
        let tests = tests_at(
            &solved.jac,
            &tangent,
            &solved.monodromy,
            &multipliers,
            impacts,
            symmetric,
        );
        let point = BranchPoint {
            parameter: p,
            state: x,
            stable: multipliers.first().is_none_or(|m| m.norm() < 1.0),
            multipliers,
            max_displacement: orbit.max_displacement,
            max_velocity: orbit.max_velocity,
            impacts_per_period: impacts,
            label: None,
        };
        Some(Evaluated {
            solved,
            tangent,
            point,
            tests,
        })
    }

    /// Bisection of the arclength in (0, ds) from `a` for the change of
    /// `kind` that occurs before `b`; returns the located point.
    /// The solution at parameter `bound`, between the solutions `a` and
    /// `b` that bracket it: predicted by linear interpolation and corrected
    /// with the parameter held.
    fn end_point(&mut self, a: &Evaluated, b: &Evaluated, bound: f64) -> Option<Evaluated> {
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

    fn locate(
        &mut self,
        kind: SpecialKind,
        a: &Evaluated,
        b: &Evaluated,
        ds: f64,
    ) -> Option<Evaluated> {
        let (mut lo, mut hi) = (0.0, ds);
        let (mut p_lo, mut p_hi) = (a.point.parameter, b.point.parameter);
        let mut best: Option<Evaluated> = None;
        let mut lo_tests = a.tests;
        for _ in 0..80 {
            if (p_hi - p_lo).abs() <= self.opts.locate_tol && best.is_some() {
                break;
            }
            let mid = 0.5 * (lo + hi);
            let pred: Vec<f64> = a
                .solved
                .z
                .iter()
                .zip(&a.tangent)
                .map(|(z, t)| z + mid * t)
                .collect();
            let (solved, _) = self.correct(&pred, &a.tangent)?;
            let e = self.evaluate(solved, &a.tangent)?;
            if changed(kind, &lo_tests, &e.tests) {
                hi = mid;
                p_hi = e.point.parameter;
            } else {
                lo = mid;
                p_lo = e.point.parameter;
                lo_tests = e.tests;
            }
            best = Some(e);
            if hi - lo < 1e-14 {
                break;
            }
        }
        best
    }
}

/// Continues the branch of nT-periodic solutions from `(x0, p0)` toward
/// `p_end`. `family(p)` builds the model at parameter p; `on_point` sees
/// every accepted point and returns false to stop (the branch so far is
/// returned). `x0` need not be converged: it is refined by shooting first.
pub fn continue_branch<F, C>(
    mut family: F,
    p0: f64,
    x0: &[f64],
    p_end: f64,
    opts: &ContinuationOptions,
    mut on_point: C,
) -> Result<Branch, ContinuationError>
where
    F: FnMut(f64) -> Result<Model, String>,
    C: FnMut(&BranchPoint) -> bool,
{
    if !(p0.is_finite() && p_end.is_finite()) || p0 == p_end || p0 == 0.0 {
        return Err(ContinuationError::Invalid(format!(
            "the range from {p0} to {p_end} is empty or not finite (and the start must be nonzero)"
        )));
    }
    for (name, value) in [
        ("ds", opts.ds),
        ("ds_min", opts.ds_min),
        ("ds_max", opts.ds_max),
    ] {
        if !(value > 0.0 && value.is_finite()) {
            return Err(ContinuationError::Invalid(format!(
                "{name} = {value}: must be finite and > 0"
            )));
        }
    }
    if opts.max_points < 2 {
        return Err(ContinuationError::Invalid(format!(
            "max_points = {}: at least 2",
            opts.max_points
        )));
    }
    let model = family(p0).map_err(|message| ContinuationError::Model {
        parameter: p0,
        message,
    })?;
    let start = shoot(&model, x0, &opts.shooting)?;
    if !start.converged {
        return Err(ContinuationError::StartNotConverged(
            *start.residual_history.last().unwrap_or(&f64::NAN),
        ));
    }
    let d = x0.len();
    let symmetric = opts.shooting.symmetric
        || (opts.use_symmetry
            && opts.shooting.subharmonic.max(1) % 2 == 1
            && model.is_mirror_symmetric()
            && is_symmetric_orbit(&model, &start.initial_state, &opts.shooting));
    let local = ContinuationOptions {
        shooting: ShootingOptions {
            symmetric,
            ..opts.shooting.clone()
        },
        ..opts.clone()
    };
    let opts = &local;
    let mut problem = Problem::new(&mut family, opts, &model, p0);
    let (lo, hi) = opts
        .bounds
        .map_or((p0.min(p_end), p0.max(p_end)), |(a, b)| {
            (a.min(b), a.max(b))
        });
    let z0 = problem.scale_state(&start.initial_state, p0);
    // The start point: corrected with the parameter held (t = e_p).
    let mut dir = vec![0.0; d + 1];
    dir[d] = 1.0;
    let (solved0, _) = problem
        .correct(&z0, &dir)
        .ok_or(ContinuationError::StartNotConverged(f64::NAN))?;
    dir[d] = (p_end - p0).signum();
    let first = problem
        .evaluate(solved0, &dir)
        .ok_or_else(|| ContinuationError::Invalid("cannot evaluate the start point".into()))?;
    let mut points = vec![first.point.clone()];
    let mut special: Vec<SpecialPoint> = Vec::new();
    let mut counts = [0usize; 5];
    if !on_point(&first.point) {
        return Ok(Branch {
            points,
            special,
            stop: StopReason::Interrupted,
            subharmonic: opts.shooting.subharmonic,
            symmetric,
        });
    }
    // Closing the loop: the branch is back at its first point, or (for an
    // asymmetric branch of a mirror-symmetric row) at the mirror image
    // S x(nT/2) of a point already traversed, which happens right after it
    // passes a pitchfork on the symmetric branch; the rest would be the
    // mirror image of what is known.
    let mirrored = !symmetric
        && opts.use_symmetry
        && opts.shooting.subharmonic.max(1) % 2 == 1
        && model.is_mirror_symmetric();
    let half = ShootingOptions {
        symmetric: true,
        ..opts.shooting.clone()
    };
    let mirror_of = |problem: &mut Problem<'_, F>, z: &[f64]| -> Option<Vec<f64>> {
        let (x, p) = problem.unscale(z);
        let model = problem.model(p).ok()?;
        period_image(&model, &x, &half).map(|image| problem.scale_state(&image, p))
    };
    let origin = (first.solved.z.clone(), first.tangent.clone());
    let mut mirrors: Vec<Vec<f64>> = Vec::new();
    if mirrored {
        mirrors.extend(mirror_of(&mut problem, &first.solved.z));
    }
    let mut current = first;
    let mut ds = opts.ds;
    let stop = loop {
        if points.len() >= opts.max_points {
            break StopReason::MaxPoints;
        }
        let pred: Vec<f64> = current
            .solved
            .z
            .iter()
            .zip(&current.tangent)
            .map(|(z, t)| z + ds * t)
            .collect();
        let attempt = problem
            .correct(&pred, &current.tangent)
            .and_then(|(s, it)| {
                // Reject corrections that jump (angle between tangents > ~35°).
                let e = problem.evaluate(s, &current.tangent)?;
                let cos: f64 = e
                    .tangent
                    .iter()
                    .zip(&current.tangent)
                    .map(|(a, b)| a * b)
                    .sum();
                (cos > 0.8).then_some((e, it))
            });
        // Step too long for the spectrum: the multipliers moved so far that
        // two crossings could cancel in the test functions (kept at ds_min).
        let attempt = attempt.filter(|(next, _)| {
            0.5 * ds < opts.ds_min
                || spectral_distance(&current.point.multipliers, &next.point.multipliers)
                    <= opts.max_multiplier_change
        });
        let Some((next, iterations)) = attempt else {
            ds *= 0.5;
            if ds < opts.ds_min {
                let p = current.point.parameter;
                break StopReason::CannotContinue(format!(
                    "the corrector does not converge beyond parameter {p} even with step {ds:e}"
                ));
            }
            continue;
        };
        let p = next.point.parameter;
        let inside = |q: f64| q >= lo - opts.locate_tol && q <= hi + opts.locate_tol;
        for (k, kind) in KINDS.iter().enumerate() {
            if changed(*kind, &current.tests, &next.tests) {
                let located = problem.locate(*kind, &current, &next, ds);
                if let Some(loc) = located.filter(|l| inside(l.point.parameter)) {
                    counts[k] += 1;
                    let label = format!("{}{}", kind.prefix(), counts[k]);
                    special.push(SpecialPoint {
                        kind: *kind,
                        label,
                        parameter: loc.point.parameter,
                        state: loc.point.state.clone(),
                        multipliers: loc.point.multipliers.clone(),
                        tangent: loc.tangent.clone(),
                        after_point: points.len() - 1,
                        symmetry_breaking: *kind == SpecialKind::BranchPoint
                            && current.tests.det_sym.signum() != next.tests.det_sym.signum(),
                    });
                }
            }
        }
        ds = if iterations <= 2 {
            (ds * 1.6).min(opts.ds_max)
        } else if iterations >= 5 {
            (ds * 0.7).max(opts.ds_min)
        } else {
            ds
        };
        // A step past the end of the range: the last point is the solution
        // at the end itself (the parameter held there), if it converges.
        let beyond = !inside(p);
        let next = if beyond {
            let bound = if p > hi { hi } else { lo };
            match problem.end_point(&current, &next, bound) {
                Some(end) => end,
                None => break StopReason::ReachedEnd,
            }
        } else {
            next
        };
        let mut point = next.point.clone();
        if let Some(sp) = special
            .iter()
            .rev()
            .find(|s| s.after_point == points.len() - 1)
        {
            point.label = Some(sp.label.clone());
        }
        points.push(point);
        let previous_z = std::mem::replace(&mut current, next).solved.z;
        if beyond {
            on_point(points.last().expect("just pushed"));
            break StopReason::ReachedEnd;
        }
        let closed = points.len() > 4
            && (returns_to(&origin.0, Some(&origin.1), &previous_z, &current)
                || mirrors[..mirrors.len().saturating_sub(2)]
                    .iter()
                    .any(|m| returns_to(m, None, &previous_z, &current)));
        if closed {
            on_point(points.last().expect("just pushed"));
            break StopReason::ClosedLoop;
        }
        if mirrored {
            mirrors.extend(mirror_of(&mut problem, &current.solved.z));
        }
        if !on_point(points.last().expect("just pushed")) {
            break StopReason::Interrupted;
        }
    };
    Ok(Branch {
        points,
        special,
        stop,
        subharmonic: opts.shooting.subharmonic,
        symmetric,
    })
}

/// Whether the step from `previous` to `current` (scaled unknowns) passes
/// through the point `origin`: within a quarter step of the chord (a chord
/// of the same curve deviates from it by O(curvature × step²)) and, if the
/// origin's tangent is given, in the same direction.
fn returns_to(z0: &[f64], t0: Option<&[f64]>, previous: &[f64], current: &Evaluated) -> bool {
    let z1 = &current.solved.z;
    let chord: Vec<f64> = z1.iter().zip(previous).map(|(b, a)| b - a).collect();
    let len2: f64 = chord.iter().map(|c| c * c).sum();
    if len2 == 0.0 {
        return false;
    }
    let along: f64 = z0
        .iter()
        .zip(previous)
        .zip(&chord)
        .map(|((z, a), c)| (z - a) * c)
        .sum::<f64>()
        / len2;
    let dist2: f64 = z0
        .iter()
        .zip(previous)
        .zip(&chord)
        .map(|((z, a), c)| (z - a - along.clamp(0.0, 1.0) * c).powi(2))
        .sum();
    let aligned = t0.is_none_or(|t0| {
        t0.iter()
            .zip(&current.tangent)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            > 0.5
    });
    (0.0..=1.0).contains(&along) && dist2 <= 0.0625 * len2 && aligned
}

/// Distance between two spectra (each closed under conjugation): the
/// Hausdorff distance with `d(a, b) = |a - b| / max(1/2, min(|a|, |b|))`,
/// absolute near and inside the unit circle and relative for large
/// multipliers.
pub fn spectral_distance(a: &[Complex<f64>], b: &[Complex<f64>]) -> f64 {
    let d = |x: &Complex<f64>, y: &Complex<f64>| (x - y).norm() / x.norm().min(y.norm()).max(0.5);
    let one_way = |p: &[Complex<f64>], q: &[Complex<f64>]| {
        p.iter()
            .map(|x| q.iter().map(|y| d(x, y)).fold(f64::INFINITY, f64::min))
            .fold(0.0, f64::max)
    };
    one_way(a, b).max(one_way(b, a))
}

/// Whether the periodic orbit through `x` is symmetric, `x(t + nT/2) =
/// S x(t)`: the model is mirror-symmetric and the half map fixes x to
/// 100 × the shooting tolerance.
pub fn is_symmetric_orbit(model: &Model, x: &[f64], opts: &ShootingOptions) -> bool {
    let half = ShootingOptions {
        symmetric: true,
        ..opts.clone()
    };
    let Some(image) = period_image(model, x, &half) else {
        return false;
    };
    let n = x.len() / 2;
    let w = model.forcing_frequency().unwrap_or(1.0);
    image.iter().zip(x).enumerate().all(|(k, (g, x))| {
        let scale = opts.displacement_scale * if k < n { 1.0 } else { w };
        (g - x).abs() <= 100.0 * opts.tol * scale
    })
}

/// A start on the period-2n branch that emanates from a period-doubling
/// point: shoots the 2nT map from `x* ± ε v` (v the eigenvector of the
/// multiplier nearest -1) at parameters just beyond and before the point,
/// and returns the first genuinely period-2n solution `(p, x)`.
pub fn period_doubled_start<F>(
    mut family: F,
    point: &SpecialPoint,
    opts: &ContinuationOptions,
) -> Result<(f64, Vec<f64>), ContinuationError>
where
    F: FnMut(f64) -> Result<Model, String>,
{
    let model = family(point.parameter).map_err(|message| ContinuationError::Model {
        parameter: point.parameter,
        message,
    })?;
    let map = period_map(&model, &point.state, &opts.shooting)?;
    let d = point.state.len();
    // Null vector of Φ + I.
    let v = null_vector(&map.monodromy + DMatrix::<f64>::identity(d, d))?;
    let mut doubled = opts.shooting.clone();
    doubled.subharmonic = opts.shooting.subharmonic * 2;
    let scale = doubled.displacement_scale;
    for dp in [1e-3, -1e-3, 1e-2, -1e-2] {
        let p = point.parameter * (1.0 + dp);
        let model = family(p).map_err(|message| ContinuationError::Model {
            parameter: p,
            message,
        })?;
        for eps in [0.05, -0.05, 0.2, -0.2] {
            let guess: Vec<f64> = point
                .state
                .iter()
                .zip(&v)
                .map(|(x, v)| x + eps * scale * v * (d as f64).sqrt())
                .collect();
            let Ok(sol) = shoot(&model, &guess, &doubled) else {
                continue;
            };
            if !sol.converged {
                continue;
            }
            // Genuinely period-2n: the nT map does not fix it.
            let single = period_map(&model, &sol.initial_state, &opts.shooting)?;
            let gap = single
                .image
                .iter()
                .zip(&sol.initial_state)
                .map(|(a, b)| (a - b).abs() / scale)
                .fold(0.0, f64::max);
            if gap > 1e3 * opts.shooting.tol {
                return Ok((p, sol.initial_state));
            }
        }
    }
    Err(ContinuationError::Invalid(format!(
        "no period-{} solution found next to the period doubling at {}",
        2 * opts.shooting.subharmonic,
        point.parameter
    )))
}

/// Unit right null vector of a square matrix (the right singular vector of
/// its smallest singular value).
fn null_vector(m: DMatrix<f64>) -> Result<Vec<f64>, ContinuationError> {
    let d = m.ncols();
    let svd = m.svd(false, true);
    let v_t = svd
        .v_t
        .ok_or_else(|| ContinuationError::Invalid("SVD failed".into()))?;
    let imin = svd
        .singular_values
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i);
    Ok((0..d).map(|j| v_t[(imin, j)]).collect())
}

/// A start on the other branch through a branch point. At a
/// symmetry-breaking point the direction is the eigenvector of the half
/// map's Jacobian for the eigenvalue -1 (the asymmetric mode) and a
/// corrected point that is still symmetric is refused; otherwise it is the
/// direction of the 2-D null space of `[Φ - I, G_p]` orthogonal to the
/// branch tangent. Steps `step` (then a quarter and 2.5 times it) both ways
/// and corrects in the full period map. Returns `(p, x)`; the side of the
/// point it lands on is not guaranteed: continue both ways if needed.
pub fn branch_switch_start<F>(
    mut family: F,
    point: &SpecialPoint,
    p0: f64,
    opts: &ContinuationOptions,
    step: f64,
) -> Result<(f64, Vec<f64>), ContinuationError>
where
    F: FnMut(f64) -> Result<Model, String>,
{
    let d = point.state.len();
    let model = family(point.parameter).map_err(|message| ContinuationError::Model {
        parameter: point.parameter,
        message,
    })?;
    // The predictor off the branch is poorer than along it: a larger
    // corrector budget, in the full period map (the crossing branch of a
    // symmetry-breaking point is asymmetric).
    let opts = &ContinuationOptions {
        max_corrector: 4 * opts.max_corrector,
        shooting: ShootingOptions {
            symmetric: false,
            ..opts.shooting.clone()
        },
        ..opts.clone()
    };
    let mut problem = Problem::new(&mut family, opts, &model, p0);
    let z = problem.scale_state(&point.state, point.parameter);
    let t = &point.tangent;
    let mut directions: Vec<Vec<f64>> = Vec::new();
    if point.symmetry_breaking {
        let half = ShootingOptions {
            symmetric: true,
            ..opts.shooting.clone()
        };
        let map = period_map(&model, &point.state, &half)?;
        let v = null_vector(&map.monodromy + DMatrix::<f64>::identity(d, d))?;
        let mut dir: Vec<f64> = v.iter().zip(&problem.scale).map(|(a, s)| a / s).collect();
        dir.push(0.0);
        directions.push(dir);
    } else {
        let (_, jac, _) = problem
            .residual(&z)
            .ok_or_else(|| ContinuationError::Invalid("cannot evaluate the branch point".into()))?;
        // The two eigenvectors of JᵀJ of the smallest eigenvalues span the
        // null space of the d × (d+1) Jacobian at a simple branch point.
        let eig = (jac.transpose() * &jac).symmetric_eigen();
        let mut idx: Vec<usize> = (0..=d).collect();
        idx.sort_by(|&a, &b| {
            eig.eigenvalues[a]
                .abs()
                .total_cmp(&eig.eigenvalues[b].abs())
        });
        directions.extend(
            idx.iter()
                .take(2)
                .map(|&i| eig.eigenvectors.column(i).iter().copied().collect()),
        );
    }
    // Predictor along the null vector v; constraint along its part
    // orthogonal to the tangent, which the old branch satisfies to first
    // order with zero: the corrector cannot fall back onto it nearby.
    let mut found = None;
    for v in &directions {
        let vn = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let v: Vec<f64> = v.iter().map(|a| a / vn).collect();
        let proj: f64 = v.iter().zip(t).map(|(a, b)| a * b).sum();
        let o: Vec<f64> = v.iter().zip(t).map(|(a, b)| a - proj * b).collect();
        let n = o.iter().map(|a| a * a).sum::<f64>().sqrt();
        if n > 1e-3 {
            found = Some((v, o.iter().map(|a| a / n).collect::<Vec<f64>>()));
            break;
        }
    }
    let (v, constraint) = found.ok_or_else(|| {
        ContinuationError::Invalid("no second direction at the branch point".into())
    })?;
    for h in [step, 0.25 * step, 2.5 * step] {
        for sign in [1.0, -1.0] {
            let pred: Vec<f64> = z.iter().zip(&v).map(|(a, b)| a + sign * h * b).collect();
            let Some((solved, _)) = problem.correct(&pred, &constraint) else {
                continue;
            };
            // A corrector that wandered off to some other branch far away.
            let jump = solved
                .z
                .iter()
                .zip(&pred)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            if jump > 5.0 * h {
                continue;
            }
            let (x, p) = problem.unscale(&solved.z);
            if point.symmetry_breaking {
                let model = problem.model(p)?;
                if is_symmetric_orbit(&model, &x, &opts.shooting) {
                    continue; // back on the symmetric branch
                }
            }
            return Ok((p, x));
        }
    }
    Err(ContinuationError::Invalid(format!(
        "the corrector fails on the crossing branch at {}",
        point.parameter
    )))
}

/// Why a branch switch could not start.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SwitchError(pub String);

/// The branch through special point `label` of `branch` (a branch point's
/// crossing branch or a period doubling's period-2n branch), continued
/// within `range` (the main branch's start and end values), away from the
/// special point.
pub fn switch_branch<F, C>(
    mut family: F,
    branch: &Branch,
    label: &str,
    range: (f64, f64),
    opts: &ContinuationOptions,
    progress: C,
) -> Result<Branch, SwitchError>
where
    F: FnMut(f64) -> Result<Model, String>,
    C: FnMut(&BranchPoint) -> bool,
{
    let sp = branch
        .special
        .iter()
        .find(|s| s.label == label)
        .ok_or_else(|| {
            SwitchError(format!(
                "--switch-at {label}: no such special point on the branch (found: {})",
                branch
                    .special
                    .iter()
                    .map(|s| s.label.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
    let fail = |e: ContinuationError| {
        SwitchError(format!(
            "--switch-at {label}: {e} (the main branch is kept)"
        ))
    };
    let sub = opts.shooting.subharmonic;
    let (p1, x1, sub) = match sp.kind {
        SpecialKind::PeriodDoubling => {
            let (p, x) = period_doubled_start(&mut family, sp, opts).map_err(fail)?;
            (p, x, sub * 2)
        }
        SpecialKind::BranchPoint => {
            let (p, x) = branch_switch_start(&mut family, sp, range.0, opts, 0.02).map_err(fail)?;
            (p, x, sub)
        }
        other => {
            return Err(SwitchError(format!(
                "--switch-at {label}: cannot switch at a {} point (only BP and PD)",
                other.name()
            )))
        }
    };
    let switched_opts = ContinuationOptions {
        shooting: ShootingOptions {
            subharmonic: sub,
            ..opts.shooting.clone()
        },
        bounds: Some(range),
        ..opts.clone()
    };
    // Onward from the start, away from the special point (the branch stays
    // within the range).
    let (lo, hi) = (range.0.min(range.1), range.0.max(range.1));
    let target = if p1 >= sp.parameter { hi } else { lo };
    continue_branch(family, p1, &x1, target, &switched_opts, progress).map_err(fail)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{simulate, SimulationOptions};

    use crate::reference::NATURAL_FREQUENCY as W0;

    fn r2(n: usize, clearance: f64, omega: f64) -> Result<Model, String> {
        crate::reference::r2(n, clearance, omega).map_err(|e| e.to_string())
    }

    /// R3 along a branch: amplitude equals the exact steady state, no
    /// special points, all stable.
    #[test]
    fn linear_branch_is_exact() {
        let family = |w: f64| r2(2, 1e3, w);
        let opts = ContinuationOptions {
            shooting: ShootingOptions {
                rtol: 1e-12,
                tol: 1e-10,
                displacement_scale: 1e-2,
                ..Default::default()
            },
            ..Default::default()
        };
        let b = continue_branch(family, 0.8 * W0, &[0.0; 4], 1.2 * W0, &opts, |_| true).unwrap();
        assert_eq!(b.stop, StopReason::ReachedEnd);
        assert!(
            b.special.is_empty(),
            "{:?}",
            b.special.iter().map(|s| &s.label).collect::<Vec<_>>()
        );
        assert!(b.points.len() > 10);
        for p in &b.points {
            let w = p.parameter;
            let exact = crate::reference::r3_steady_amplitude(w);
            // The exact extremum (located on the dense output).
            assert!(
                (p.max_displacement[0] / exact - 1.0).abs() < 1e-8,
                "at {w}: {} vs {exact}",
                p.max_displacement[0]
            );
            assert!(p.stable);
        }
    }

    /// AUTO-07p's special points of the R2, N = 2 branch (bench/auto,
    /// Ω/ω0): six symmetry-breaking branch points and a torus bifurcation.
    const AUTO_BP: [f64; 6] = [0.983100, 0.949393, 0.794528, 0.552497, 0.534043, 0.509475];
    const AUTO_TR: f64 = 0.502479;

    fn r2_branch(from: f64, to: f64) -> Branch {
        let family = |w: f64| r2(2, 1e-3, w);
        let start = r2(2, 1e-3, from * W0).unwrap();
        let guess = crate::periodic::guess_by_simulation(&start, 200.0, 1e-9).unwrap();
        let opts = ContinuationOptions::default();
        continue_branch(family, from * W0, &guess, to * W0, &opts, |_| true).unwrap()
    }

    /// R2, N = 2 (a mirror-symmetric row): the branch from 1.5 ω0 down is
    /// followed on the half map and has exactly AUTO-07p's special points
    /// (plus grazing, which AUTO does not detect), located from either
    /// direction to the same values; stable points agree with brute-force
    /// simulation.
    #[test]
    fn r2_symmetric_branch_matches_auto() {
        let down = r2_branch(1.5, 0.5);
        assert_eq!(down.stop, StopReason::ReachedEnd);
        // The branch runs from one end of the range exactly to the other.
        let ends = |b: &Branch| {
            let p = |q: &BranchPoint| q.parameter / W0;
            (p(&b.points[0]), p(b.points.last().expect("points")))
        };
        let (first, last) = ends(&down);
        assert!(
            (first - 1.5).abs() < 1e-12 && (last - 0.5).abs() < 1e-12,
            "{first}..{last}"
        );
        assert!(down.symmetric);
        let of = |b: &Branch, kind| {
            b.special
                .iter()
                .filter(|s| s.kind == kind)
                .map(|s| s.parameter / W0)
                .collect::<Vec<f64>>()
        };
        let bps = of(&down, SpecialKind::BranchPoint);
        assert_eq!(bps.len(), AUTO_BP.len(), "{bps:?}");
        for (ours, auto) in bps.iter().zip(AUTO_BP) {
            // AUTO's collocation (NTST 300) agrees to ~5e-6.
            assert!((ours / auto - 1.0).abs() < 2e-5, "BP {ours} vs AUTO {auto}");
        }
        let ns = of(&down, SpecialKind::NeimarkSacker);
        assert_eq!(ns.len(), 1);
        assert!((ns[0] / AUTO_TR - 1.0).abs() < 2e-5, "NS {}", ns[0]);
        assert!(of(&down, SpecialKind::Fold).is_empty());
        assert!(of(&down, SpecialKind::PeriodDoubling).is_empty());
        for s in down
            .special
            .iter()
            .filter(|s| s.kind == SpecialKind::BranchPoint)
        {
            assert!(s.symmetry_breaking);
            let near_one = s
                .multipliers
                .iter()
                .map(|m| (m - Complex::new(1.0, 0.0)).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(near_one < 1e-4, "{}: {:?}", s.label, s.multipliers);
        }
        // Every point is symmetric: u1 and u2 have the same amplitude (to
        // 1e-7 where the orbit is unstable with multipliers ~200, 4e-8 on
        // stable ones: integration at rtol 1e-10 through contact pulses).
        for p in &down.points {
            let (a, b) = (p.max_displacement[0], p.max_displacement[1]);
            assert!((a - b).abs() < 1e-6 * a, "{}: {a} vs {b}", p.parameter);
        }
        // The same special points from 0.5 ω0 upward.
        let up = r2_branch(0.5, 1.5);
        assert_eq!(up.stop, StopReason::ReachedEnd);
        let (first, last) = ends(&up);
        assert!(
            (first - 0.5).abs() < 1e-12 && (last - 1.5).abs() < 1e-12,
            "{first}..{last}"
        );
        let mut a: Vec<(SpecialKind, f64)> =
            down.special.iter().map(|s| (s.kind, s.parameter)).collect();
        let b: Vec<(SpecialKind, f64)> = up.special.iter().map(|s| (s.kind, s.parameter)).collect();
        a.reverse();
        assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.0, y.0);
            let tol = if x.0 == SpecialKind::Grazing {
                1e-4
            } else {
                1e-7
            };
            assert!((x.1 / y.1 - 1.0).abs() < tol, "{x:?} vs {y:?}");
        }
        // Stable points agree with brute-force simulation.
        let stable: Vec<&BranchPoint> = down
            .points
            .iter()
            .filter(|p| p.stable && p.spectral_radius() < 0.95)
            .step_by(15)
            .take(3)
            .collect();
        assert!(stable.len() >= 2);
        for p in stable {
            assert_brute_force_agrees(p);
        }
    }

    /// Simulation from a 0.1 % perturbation of the orbit settles back on it:
    /// max |u_i| to 1e-6. (A larger perturbation can leave the basin: below
    /// 0.51 ω0 the symmetric orbit coexists with other attractors, and a 1 %
    /// kick lands on one with max |u| 11 % smaller.)
    fn assert_brute_force_agrees(p: &BranchPoint) {
        let model = r2(2, 1e-3, p.parameter).unwrap();
        let t = 2.0 * std::f64::consts::PI / p.parameter;
        let sim = simulate(
            &model,
            &SimulationOptions {
                t_end: 400.0 * t,
                rtol: 1e-11,
                atol: 1e-15,
                start: Some(p.state.iter().map(|x| x * 0.999).collect()),
                ..Default::default()
            },
        )
        .unwrap();
        let end: Vec<f64> = sim.final_state();
        let orbit = orbit_summary(&model, &end, t, 256, 1e-11).unwrap();
        for i in 0..2 {
            assert!(
                (orbit.max_displacement[i] - p.max_displacement[i]).abs()
                    < 1e-6 * p.max_displacement[i].max(1e-3),
                "at {}: {} vs {}",
                p.parameter,
                orbit.max_displacement[i],
                p.max_displacement[i]
            );
        }
    }

    /// Switching at the first two pitchforks onto the asymmetric branches:
    /// a period doubling confirmed by the period-2 orbit next to it, a fold
    /// confirmed by the change of stability on either side.
    #[test]
    fn r2_asymmetric_branches_fold_and_period_doubling() {
        let family = |w: f64| r2(2, 1e-3, w);
        let main = r2_branch(1.5, 0.9);
        let opts = ContinuationOptions {
            max_points: 45,
            bounds: Some((0.5 * W0, 1.5 * W0)),
            ..Default::default()
        };
        let switched = |label: &str| {
            let bp = main.special.iter().find(|s| s.label == label).unwrap();
            let (p, x) = branch_switch_start(family, bp, 1.5 * W0, &opts, 0.02).unwrap();
            let model = r2(2, 1e-3, p).unwrap();
            // Off the symmetric branch: the two bodies move differently.
            let orbit =
                orbit_summary(&model, &x, 2.0 * std::f64::consts::PI / p, 256, 1e-11).unwrap();
            let (a, b) = (orbit.max_displacement[0], orbit.max_displacement[1]);
            assert!((a - b).abs() > 1e-7, "{label}: still symmetric ({a} {b})");
            let b = continue_branch(family, p, &x, 0.5 * W0, &opts, |_| true).unwrap();
            assert!(!b.symmetric);
            b
        };
        let unstable_count =
            |p: &BranchPoint| p.multipliers.iter().filter(|m| m.norm() > 1.0).count();
        // BP1 (0.9831 ω0): a period doubling at 0.97820 ω0.
        let b1 = switched("BP1");
        let pd = b1
            .special
            .iter()
            .find(|s| s.kind == SpecialKind::PeriodDoubling)
            .expect("a period doubling");
        assert!(
            (pd.parameter / W0 - 0.978202).abs() < 1e-5,
            "{}",
            pd.parameter / W0
        );
        assert!(
            pd.multipliers
                .iter()
                .any(|m| (m.re + 1.0).abs() < 1e-3 && m.im.abs() < 1e-6),
            "{:?}",
            pd.multipliers
        );
        // Its stable points (between the pitchfork and the period doubling)
        // agree with brute-force simulation as well.
        let stable: Vec<&BranchPoint> = b1
            .points
            .iter()
            .filter(|p| p.stable && p.spectral_radius() < 0.95)
            .collect();
        assert!(!stable.is_empty());
        for p in stable.iter().step_by(stable.len().div_ceil(2).max(1)) {
            assert_brute_force_agrees(p);
        }
        let (p2, x2) = period_doubled_start(family, pd, &opts).unwrap();
        assert!((p2 / pd.parameter - 1.0).abs() < 0.02);
        let model = r2(2, 1e-3, p2).unwrap();
        let two = shoot(
            &model,
            &x2,
            &ShootingOptions {
                subharmonic: 2,
                ..opts.shooting.clone()
            },
        )
        .unwrap();
        assert!(two.converged);
        let one = period_map(&model, &two.initial_state, &opts.shooting).unwrap();
        let gap = one
            .image
            .iter()
            .zip(&two.initial_state)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(gap > 1e-7, "the period-2 orbit is period-1 (gap {gap:e})");
        // BP2 (0.9494 ω0): a fold at 0.91225 ω0, stability changes across it.
        let b2 = switched("BP2");
        let fold = b2
            .special
            .iter()
            .find(|s| s.kind == SpecialKind::Fold)
            .expect("a fold");
        assert!((fold.parameter / W0 - 0.912249).abs() < 1e-5);
        let (a, c) = (
            &b2.points[fold.after_point],
            &b2.points[fold.after_point + 1],
        );
        assert_ne!(
            unstable_count(a),
            unstable_count(c),
            "fold at {}",
            fold.parameter
        );
    }

    /// The asymmetric branch from BP2 (0.9494 ω0) is a connection: it meets
    /// the symmetric branch again at BP3 (AUTO: 0.794528 ω0), where it turns
    /// (a fold of the pitchfork) onto its mirror image; the continuation
    /// stops there as a closed loop instead of retracing the mirror.
    #[test]
    fn r2_asymmetric_branch_connects_bp2_to_bp3() {
        let family = |w: f64| r2(2, 1e-3, w);
        let main = r2_branch(1.5, 0.9);
        let opts = ContinuationOptions {
            max_points: 3000,
            bounds: Some((0.5 * W0, 1.5 * W0)),
            ..Default::default()
        };
        let bp = main.special.iter().find(|s| s.label == "BP2").unwrap();
        let (p, x) = branch_switch_start(family, bp, 1.5 * W0, &opts, 0.02).unwrap();
        let b = continue_branch(family, p, &x, 0.5 * W0, &opts, |_| true).unwrap();
        assert_eq!(b.stop, StopReason::ClosedLoop);
        let last = b.special.last().expect("special points");
        assert_eq!(last.kind, SpecialKind::Fold);
        assert!(
            (last.parameter / W0 / AUTO_BP[2] - 1.0).abs() < 2e-5,
            "{}",
            last.parameter / W0
        );
        // At the fold the orbit is (nearly) symmetric again.
        let model = r2(2, 1e-3, last.parameter).unwrap();
        let period = 2.0 * std::f64::consts::PI / last.parameter;
        let at = orbit_summary(&model, &last.state, period, 256, 1e-11).unwrap();
        let (u1, u2) = (at.max_displacement[0], at.max_displacement[1]);
        assert!((u1 - u2).abs() < 1e-3 * u1, "{u1} vs {u2}");
        assert!(b.points.len() < 1500, "{} points", b.points.len());
    }
}
