//! Two-parameter continuation of codimension-one points of periodic orbits
//! (docs/theory.md §9): folds, period doublings, symmetry-breaking branch
//! points, Neimark–Sacker points and grazings, each as the solutions
//! `z = (x, p, q[, κ])` of the minimally augmented system
//!
//! ## Files
//! - `system.rs` — the dense minimally augmented system;
//! - `krylov.rs` — its matrix-free form for long rows;
//! - `codim2.rs` — codimension-two points on a curve;
//! - `from_branch.rs` — the curves through a branch's special points;
//! - `tests.rs` — curves against the one-parameter branches.
//!
//! `G(x; p, q) = 0` (the orbit), `g(x; p, q[, κ]) = 0` (the singularity),
//!
//! where `g` is taken from the solution of the bordered system
//! `[A B; Cᵀ 0] (V, g) = (0, I)` with `A = DG − I` (fold), `DG + I` (period
//! doubling on the full map, branch point on the half map), `DG² + I`
//! (period doubling on the half map) or `DG² − 2κ DG + I` (Neimark–Sacker,
//! a pair e^{±iθ}, κ = cos θ, two borders and two of g's four entries), and
//! B, C the left and right null vectors of the previous point; on a
//! grazing curve `g` is the impact margin of the grazing contact. `g`
//! vanishes exactly where A is singular and is regular there, so the curve
//! is a regular solution curve: pseudo-arclength continuation with Newton
//! on `[G; g; tᵀ(z − z_pred)] = 0`. The Jacobian is taken by forward
//! differences (d + 2 or d + 3 period maps with their monodromy: the dense
//! form, `system.rs`, for rows of a few bodies); long rows use the
//! matrix-free extended form of `krylov.rs` (folds, flips, branch points).
//! One continuation loop serves both ([`CurveSystem`]). Codimension-two
//! points on the way are detected and located ([`Codim2Kind`],
//! `codim2.rs`).

mod codim2;
mod from_branch;
mod krylov;
mod system;

use crate::model::family::Family2;
use nalgebra::Complex;
use serde::Serialize;

use crate::model::Model;
use crate::periodic::ShootingOptions;
pub use codim2::Codim2Kind;
use codim2::{changed, test_values, CIRCLE_TEST};
pub use from_branch::{
    curves_of_branch, BranchOrigin, CurveSelection, Curves, CurvesError, CURVE_NAMES,
};
use krylov::KrylovSystem;
use system::{Augmented, Constraint, Observation};

/// A curve's augmented system as the continuation loop sees it: the dense
/// minimally augmented form ([`Augmented`]) or the matrix-free extended
/// form ([`KrylovSystem`]). `z` holds the orbit (and auxiliaries), then p
/// and q at [`CurveSystem::p_index`] and the next index.
trait CurveSystem {
    /// The index of p in z (q follows).
    fn p_index(&self) -> usize;
    /// z at the start (state, p, q), corrected with q held.
    fn start(&mut self, state: &[f64], p: f64, q: f64) -> Result<Vec<f64>, String>;
    /// Newton from `pred` with the last equation `constraint`.
    fn correct(&mut self, pred: &[f64], constraint: Constraint<'_>) -> Result<Vec<f64>, String>;
    /// The unit tangent at z, oriented along `previous`.
    fn tangent(&mut self, z: &[f64], previous: Option<&[f64]>) -> Result<Vec<f64>, String>;
    /// The point at z as the tests see it.
    fn observe(&mut self, z: &[f64]) -> Result<Observation, String>;
    /// The bound (index in z, scaled value) the step to z crossed.
    fn bound_crossed(&self, z: &[f64], bounds: &[(f64, f64); 2]) -> Option<(usize, f64)>;
    /// Follows the accepted point z (borders, normalisation, windows).
    fn move_to(&mut self, z: &[f64]) -> Result<(), String>;
}

/// The codimension-one points a curve follows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurveKind {
    /// A multiplier +1 of the shooting map (a fold of the orbit branch).
    Fold,
    /// A multiplier −1 of Φ.
    PeriodDoubling,
    /// An eigenvalue −1 of the half map's DG: a symmetry-breaking pitchfork.
    BranchPoint,
    /// A pair of multipliers e^{±iθ} on the unit circle (a torus is born).
    NeimarkSacker,
    /// A contact's approach just reaches the impact threshold: impacts
    /// appear or vanish (the contact nearest grazing at the start).
    Grazing,
}

impl CurveKind {
    /// Every kind.
    pub const ALL: [CurveKind; 5] = [
        CurveKind::Fold,
        CurveKind::BranchPoint,
        CurveKind::PeriodDoubling,
        CurveKind::NeimarkSacker,
        CurveKind::Grazing,
    ];

    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            CurveKind::Fold => "fold",
            CurveKind::PeriodDoubling => "period-doubling",
            CurveKind::BranchPoint => "branch-point",
            CurveKind::NeimarkSacker => "neimark-sacker",
            CurveKind::Grazing => "grazing",
        }
    }

    /// Borders of its bordered system: the dimension of the kernel.
    fn borders(self) -> usize {
        match self {
            CurveKind::NeimarkSacker => 2,
            CurveKind::Grazing => 0,
            _ => 1,
        }
    }
}

/// Options of a curve.
#[derive(Clone, Debug)]
pub struct CurveOptions {
    /// Shooting settings (the half map with `symmetric`, as the
    /// one-parameter branch the curve starts from).
    pub shooting: ShootingOptions,
    /// Bounds of the two parameters; the curve stops where it leaves them.
    pub bounds: [(f64, f64); 2],
    /// First step, smallest and largest step (scaled arclength).
    pub ds: f64,
    /// Smallest step: the curve stops below it.
    pub ds_min: f64,
    /// Largest step.
    pub ds_max: f64,
    /// Points at most.
    pub max_points: usize,
    /// `Some(m)`: the matrix-free form (folds, flips and branch points;
    /// multipliers from m Arnoldi vectors), for long rows; None: dense.
    pub krylov: Option<usize>,
}

impl Default for CurveOptions {
    fn default() -> Self {
        Self {
            shooting: ShootingOptions::default(),
            bounds: [(f64::NEG_INFINITY, f64::INFINITY); 2],
            ds: 0.01,
            ds_min: 1e-7,
            ds_max: 0.05,
            max_points: 500,
            krylov: None,
        }
    }
}

/// One point of a curve.
#[derive(Clone, Debug)]
pub struct CurvePoint {
    /// The first parameter.
    pub p: f64,
    /// The second parameter.
    pub q: f64,
    /// The orbit's state at t = 0 (`[u.., v..]`).
    pub state: Vec<f64>,
    /// Largest |u_i| over the period, per body (m).
    pub max_displacement: Vec<f64>,
    /// The Floquet multipliers (of Φ), largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
}

/// Why a curve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurveStop {
    /// It left the parameter bounds.
    LeftBounds,
    /// It came back to its first point (a closed curve).
    Closed,
    /// The corrector failed even at the smallest step.
    StepTooSmall,
    /// `max_points` points.
    MaxPoints,
}

impl std::fmt::Display for CurveStop {
    /// What a reader is told: "left the parameter bounds", "came back to
    /// its first point", "the corrector failed at the smallest step", "used
    /// the point budget".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::LeftBounds => "left the parameter bounds",
            Self::Closed => "came back to its first point",
            Self::StepTooSmall => "the corrector failed at the smallest step",
            Self::MaxPoints => "used the point budget",
        })
    }
}

/// A codimension-two point located on a curve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveSpecial {
    /// What it is.
    pub kind: Codim2Kind,
    /// Its index in the curve's points.
    pub point: usize,
}

/// A continued curve of codimension-one points.
#[derive(Clone, Debug)]
pub struct Curve {
    /// What it follows.
    pub kind: CurveKind,
    /// Its points, from the start (located codimension-two points
    /// included).
    pub points: Vec<CurvePoint>,
    /// The codimension-two points on it, in order.
    pub special: Vec<CurveSpecial>,
    /// Why it ended.
    pub stop: CurveStop,
}

/// The curve through a special point: `family(p, q)` builds the model,
/// `(state, p, q)` is the point (e.g. a fold of a one-parameter branch in p
/// at q), followed in the direction of increasing q first (`direction` ±1).
pub fn continue_curve<F: Family2>(
    mut family: F,
    kind: CurveKind,
    start: (&[f64], f64, f64),
    direction: f64,
    opts: &CurveOptions,
) -> Result<Curve, String> {
    let (state, p, q) = start;
    let model = family.model_at(p, q).map_err(|e| e.to_string())?;
    let d = state.len();
    if d != 2 * model.bodies().len() {
        return Err(format!(
            "start state: needs {} values, got {d}",
            2 * model.bodies().len()
        ));
    }
    if kind == CurveKind::BranchPoint && !opts.shooting.symmetric {
        return Err("a branch-point curve follows symmetry-breaking points of the half map: set shooting.symmetric".into());
    }
    match opts.krylov {
        None => {
            let mut sys = Augmented::new(family, kind, opts, &model, (p, q));
            follow(&mut sys, kind, (state, p, q), direction, opts)
        }
        Some(m) => {
            let mut sys = KrylovSystem::new(family, kind, opts, &model, (p, q), m)?;
            follow(&mut sys, kind, (state, p, q), direction, opts)
        }
    }
}

/// The continuation loop of [`continue_curve`] on either form.
fn follow<S: CurveSystem>(
    sys: &mut S,
    kind: CurveKind,
    (state, p, q): (&[f64], f64, f64),
    direction: f64,
    opts: &CurveOptions,
) -> Result<Curve, String> {
    let symmetric = opts.shooting.symmetric;
    let d = sys.p_index();
    let q_index = d + 1;
    let z0 = sys.start(state, p, q)?;
    let mut t = sys.tangent(&z0, None)?;
    if t[q_index] * direction < 0.0 {
        t.iter_mut().for_each(|v| *v = -*v);
    }
    let first = sys.observe(&z0)?;
    let mut tests = test_values(kind, symmetric, &first.eigenvalues, first.kappa);
    let mut points = vec![first.point];
    let mut special = Vec::new();
    let mut z = z0.clone();
    let mut ds = opts.ds;
    let stop = loop {
        if points.len() >= opts.max_points {
            break CurveStop::MaxPoints;
        }
        let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + ds * b).collect();
        // A failed step (the corrector, or an integration of a trial
        // point) is retried at half the step.
        let step = advance(sys, (&z, &t), &pred, &opts.bounds);
        let (next, tn, seen) = match step {
            Ok(Advance::Next(next, tn, seen)) => (next, tn, seen),
            Ok(Advance::End(point)) => {
                points.push(point);
                break CurveStop::LeftBounds;
            }
            Err(_) if 0.5 * ds >= opts.ds_min => {
                ds *= 0.5;
                continue;
            }
            Err(_) => break CurveStop::StepTooSmall,
        };
        let next_tests = test_values(kind, symmetric, &seen.eigenvalues, seen.kappa);
        // Codimension-two points between z and next, located in order of
        // arclength (with the borders of z, before they move).
        let mut found: Vec<(f64, Codim2Kind, CurvePoint)> = Vec::new();
        for k in changed(&tests, &next_tests, symmetric) {
            let test = |o: &Observation, _: &[f64]| {
                test_values(kind, symmetric, &o.eigenvalues, o.kappa)[k].1
            };
            let ends = (tests[k].1, next_tests[k].1);
            if let Some((s, f, o)) = locate(sys, (&z, &t, ds), ends, false, test) {
                // The circle test jumps where a pair turns real outside
                // the circle: a zero, not a jump, is a crossing.
                if k != CIRCLE_TEST || f.abs() <= 1e-3 * ends.0.abs().max(ends.1.abs()) {
                    found.push((s, tests[k].0, o.point));
                }
            }
        }
        if kind == CurveKind::Fold && reverses(&t, &tn, d) {
            let test = |_: &Observation, ts: &[f64]| pq_dot(ts, &t, d);
            let ends = (pq_dot(&t, &t, d), pq_dot(&tn, &t, d));
            if let Some((s, _, o)) = locate(sys, (&z, &t, ds), ends, true, test) {
                found.push((s, Codim2Kind::Cusp, o.point));
            }
        }
        found.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (_, kind, point) in found {
            special.push(CurveSpecial {
                kind,
                point: points.len(),
            });
            points.push(point);
        }
        sys.move_to(&next)?;
        z = next;
        t = tn;
        tests = next_tests;
        points.push(seen.point);
        let back: f64 = z
            .iter()
            .zip(&z0)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        if points.len() > 3 && back < 0.5 * ds {
            break CurveStop::Closed;
        }
        ds = (1.5 * ds).min(opts.ds_max);
    };
    Ok(Curve {
        kind,
        points,
        special,
        stop,
    })
}

/// The impact margin nearest zero over the contacts (m): how far the orbit
/// from `state` is from grazing (a contact's closest approach over one
/// period at the impact threshold). A grazing curve starts where it is
/// below 1e-3 displacement scales; a change of the impact count where it
/// is not (an impact splitting in two) has no grazing curve.
pub fn grazing_margin(
    model: &Model,
    state: &[f64],
    shooting: &ShootingOptions,
) -> Result<f64, String> {
    let period = crate::periodic::forcing_period(model).map_err(|e| e.to_string())?
        * f64::from(shooting.subharmonic.max(1));
    let orbit = crate::periodic::orbit_summary(model, state, period, 0, shooting.rtol)
        .map_err(|e| e.to_string())?;
    orbit
        .impact_margin
        .iter()
        .copied()
        .min_by(|a, b| a.abs().total_cmp(&b.abs()))
        .ok_or_else(|| "the model has no contacts".into())
}

/// Whether a grazing curve starts at a margin (m) of [`grazing_margin`].
pub fn starts_grazing(margin: f64, shooting: &ShootingOptions) -> bool {
    margin.abs() <= system::GRAZING_START * shooting.displacement_scale
}

/// The outcome of one step.
enum Advance {
    /// The next point, its tangent and what the tests see there.
    Next(Vec<f64>, Vec<f64>, Observation),
    /// The curve left the bounds: its last point, on the bound crossed.
    End(CurvePoint),
}

/// One step from z (tangent t) with the predictor `pred`: corrected, and
/// ended exactly on a parameter bound it crossed.
fn advance<S: CurveSystem>(
    sys: &mut S,
    (z, t): (&[f64], &[f64]),
    pred: &[f64],
    bounds: &[(f64, f64); 2],
) -> Result<Advance, String> {
    let next = sys.correct(pred, Constraint::Arclength(t))?;
    if let Some((k, bound)) = sys.bound_crossed(&next, bounds) {
        let s = (bound - z[k]) / (next[k] - z[k]);
        let guess: Vec<f64> = z.iter().zip(&next).map(|(a, b)| a + s * (b - a)).collect();
        let end = sys.correct(&guess, Constraint::Fixed(k, bound))?;
        return Ok(Advance::End(sys.observe(&end)?.point));
    }
    let tn = sys.tangent(&next, Some(t))?;
    let seen = sys.observe(&next)?;
    Ok(Advance::Next(next, tn, seen))
}

/// What both forms of a curve scale and integrate with: the shooting
/// options for the test functions — the tolerance of reported multipliers
/// (shooting's, 100× tighter) with the monodromy's columns in the step
/// control, else g = 0 leaves a multiplier up to 1e-6 from the critical
/// value — the orbit's scales (displacement scale for u, × Ω for v) and
/// the parameters' scales (their start values).
struct Scales {
    shooting: ShootingOptions,
    orbit: Vec<f64>,
    parameters: [f64; 2],
}

impl Scales {
    fn new(opts: &CurveOptions, model: &Model, (p, q): (f64, f64)) -> Self {
        let n = model.bodies().len();
        let w = model.forcing_frequency().unwrap_or(1.0);
        let ds = opts.shooting.displacement_scale;
        Self {
            shooting: ShootingOptions {
                rtol: (opts.shooting.rtol / 100.0).max(crate::periodic::MULTIPLIER_RTOL),
                control_monodromy: true,
                ..opts.shooting.clone()
            },
            orbit: (0..2 * n)
                .map(|i| if i < n { ds } else { ds * w })
                .collect(),
            parameters: [p.abs().max(1e-12), q.abs().max(1e-12)],
        }
    }
}

/// Newton on a curve's corrector (either form) from `pred`, to the
/// residual `tol` in at most `max_iterations` (full steps of at most 0.5
/// scaled units, a stall at the noise floor accepted): the corrected z.
fn run_corrector<S: crate::newton::NewtonSystem<Error = String>>(
    corr: &mut S,
    pred: &[f64],
    tol: f64,
    max_iterations: usize,
) -> Result<Vec<f64>, String> {
    let opts = crate::newton::NewtonOptions {
        tol,
        max_iterations,
        max_step: 0.5,
        line_search: false,
        stall: Some((1.0, 10.0)),
    };
    let out = crate::newton::damped_newton(corr, pred, &opts)?;
    if out.converged() {
        Ok(out.x)
    } else {
        Err(format!("the corrector stopped ({:?})", out.stop))
    }
}

/// The parameter bound (index in z and scaled value) that z crossed, if
/// any: p at `p_index`, q after it, scaled by `scales`.
fn bound_crossed(
    z: &[f64],
    p_index: usize,
    scales: [f64; 2],
    bounds: &[(f64, f64); 2],
) -> Option<(usize, f64)> {
    (0..2).find_map(|i| {
        let v = z[p_index + i] * scales[i];
        let (lo, hi) = bounds[i];
        if v < lo {
            Some((p_index + i, lo / scales[i]))
        } else if v > hi {
            Some((p_index + i, hi / scales[i]))
        } else {
            None
        }
    })
}

/// The (p, q) components of two tangents, dotted.
fn pq_dot(a: &[f64], b: &[f64], d: usize) -> f64 {
    a[d] * b[d] + a[d + 1] * b[d + 1]
}

/// Whether the curve's direction in the parameter plane turned by more
/// than 120° between two tangents: a cusp between them.
fn reverses(a: &[f64], b: &[f64], d: usize) -> bool {
    let norms = pq_dot(a, a, d).sqrt() * pq_dot(b, b, d).sqrt();
    pq_dot(a, b, d) < -0.5 * norms
}

/// Locates the zero of `test` (from the observed point and, if
/// `with_tangent`, its tangent; else an empty slice) on the curve between z (arclength 0, tangent t) and the next point (at
/// ds), given the values at both ends: regula falsi (Illinois) on the
/// arclength, each trial corrected onto the curve: the arclength, the
/// test's value and the point. None if a correction fails.
fn locate<S: CurveSystem>(
    sys: &mut S,
    (z, t, ds): (&[f64], &[f64], f64),
    (f0, f1): (f64, f64),
    with_tangent: bool,
    test: impl Fn(&Observation, &[f64]) -> f64,
) -> Option<(f64, f64, Observation)> {
    let (mut a, mut fa, mut b, mut fb) = (0.0, f0, ds, f1);
    let mut side = 0;
    let mut best = None;
    for _ in 0..40 {
        let s = (a * fb - b * fa) / (fb - fa);
        let pred: Vec<f64> = z.iter().zip(t).map(|(zi, ti)| zi + s * ti).collect();
        let zs = sys.correct(&pred, Constraint::Arclength(t)).ok()?;
        let ts = if with_tangent {
            sys.tangent(&zs, Some(t)).ok()?
        } else {
            Vec::new()
        };
        let o = sys.observe(&zs).ok()?;
        let f = test(&o, &ts);
        best = Some((s, f, o));
        if f == 0.0 || (b - a).abs() < 1e-9 * ds.max(1e-3) {
            break;
        }
        if f * fa > 0.0 {
            (a, fa) = (s, f);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = (s, f);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    best
}

#[cfg(test)]
mod tests;
