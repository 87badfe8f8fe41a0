//! Two-parameter continuation of codimension-one points of periodic orbits
//! (docs/theory.md §9): folds, period doublings and symmetry-breaking
//! branch points, each as the solutions `z = (x, p, q)` of the minimally
//! augmented system
//!
//! `G(x; p, q) = 0` (the orbit), `g(x; p, q) = 0` (the singularity),
//!
//! where `g` is the last component of the solution of the bordered system
//! `[A b; cᵀ 0] (v, g) = (0, 1)` with `A = DG − I` (fold), `DG + I` (period
//! doubling on the full map, branch point on the half map) or `DG² + I`
//! (period doubling on the half map), and b, c the left and right null
//! vectors of the previous point. `g` vanishes exactly where A is
//! singular, and is regular there, so the curve is a regular solution
//! curve: pseudo-arclength continuation with Newton on
//! `[G; g; tᵀ(z − z_pred)] = 0`. The Jacobian is taken by forward
//! differences of `[G; g]` (d + 2 period maps with their monodromy: the
//! dense form, for rows of a few bodies).

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use crate::model::Model;
use crate::newton::{damped_newton, NewtonOptions, NewtonSystem};
use crate::periodic::{
    map_multipliers, orbit_summary, period_map, ShootingOptions, MULTIPLIER_RTOL,
};

/// Residual tolerance of the curve's corrector (scaled max-norm of the
/// orbit residual and of the test function g): with the monodromy's
/// columns in the step control, a multiplier within 1e-8 of the critical
/// value (R2 N = 1 fold curve; at 1e-10, 2e-8 near the cusp, where the
/// test matrix is far from normal and g ≈ λ ŵᵀv̂ is small).
const CURVE_TOL: f64 = 1e-11;

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
}

impl CurveKind {
    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            CurveKind::Fold => "fold",
            CurveKind::PeriodDoubling => "period-doubling",
            CurveKind::BranchPoint => "branch-point",
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

/// A continued curve of codimension-one points.
#[derive(Clone, Debug)]
pub struct Curve {
    /// What it follows.
    pub kind: CurveKind,
    /// Its points, from the start.
    pub points: Vec<CurvePoint>,
    /// Why it ended.
    pub stop: CurveStop,
}

/// The curve through a special point: `family(p, q)` builds the model,
/// `(state, p, q)` is the point (e.g. a fold of a one-parameter branch in p
/// at q), followed in the direction of increasing q first (`direction` ±1).
pub fn continue_curve<F: FnMut(f64, f64) -> Result<Model, String>>(
    mut family: F,
    kind: CurveKind,
    start: (&[f64], f64, f64),
    direction: f64,
    opts: &CurveOptions,
) -> Result<Curve, String> {
    let (state, p, q) = start;
    let model = family(p, q)?;
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
    let mut sys = Augmented::new(family, kind, opts, &model, (p, q));
    let z0 = sys.scale_in(state, p, q);
    sys.init_borders(&z0)?;
    // Refine the start on the augmented system with q fixed (the tangent
    // then follows from its Jacobian).
    let q_index = z0.len() - 1;
    let z0 = sys.correct(&z0, Constraint::Fixed(q_index, z0[q_index]))?;
    let (_, jac) = sys.linearise(&z0)?;
    let mut t =
        null_direction(&jac, None).ok_or("the augmented system is singular at the start")?;
    if t[d + 1] * direction < 0.0 {
        t.iter_mut().for_each(|v| *v = -*v);
    }
    let mut points = vec![sys.point(&z0)?];
    let mut z = z0.clone();
    let mut ds = opts.ds;
    let stop = loop {
        if points.len() >= opts.max_points {
            break CurveStop::MaxPoints;
        }
        let pred: Vec<f64> = z.iter().zip(&t).map(|(a, b)| a + ds * b).collect();
        let Ok(next) = sys.correct(&pred, Constraint::Arclength(&t)) else {
            if 0.5 * ds >= opts.ds_min {
                ds *= 0.5;
                continue;
            }
            break CurveStop::StepTooSmall;
        };
        // Leaving the bounds: the curve ends exactly on the bound crossed.
        if let Some((k, bound)) = sys.bound_crossed(&next, &opts.bounds) {
            let s = (bound - z[k]) / (next[k] - z[k]);
            let guess: Vec<f64> = z.iter().zip(&next).map(|(a, b)| a + s * (b - a)).collect();
            let end = sys.correct(&guess, Constraint::Fixed(k, bound))?;
            points.push(sys.point(&end)?);
            break CurveStop::LeftBounds;
        }
        let (_, jac) = sys.linearise(&next)?;
        let Some(mut tn) = null_direction(&jac, Some(&t)) else {
            break CurveStop::StepTooSmall;
        };
        if tn.iter().zip(&t).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
            tn.iter_mut().for_each(|v| *v = -*v);
        }
        sys.update_borders(&next)?;
        z = next;
        t = tn;
        points.push(sys.point(&z)?);
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
    Ok(Curve { kind, points, stop })
}

/// The augmented system in scaled variables `(x / scale, p / p_scale, q /
/// q_scale)`.
struct Augmented<F> {
    family: F,
    kind: CurveKind,
    opts: ShootingOptions,
    scale: Vec<f64>,
    p_scale: f64,
    q_scale: f64,
    /// Borders b (right) and c (left) of the bordered system.
    b: DVector<f64>,
    c: DVector<f64>,
}

impl<F: FnMut(f64, f64) -> Result<Model, String>> Augmented<F> {
    fn new(
        family: F,
        kind: CurveKind,
        opts: &CurveOptions,
        model: &Model,
        (p, q): (f64, f64),
    ) -> Self {
        let n = model.bodies().len();
        let w = model.forcing_frequency().unwrap_or(1.0);
        let ds = opts.shooting.displacement_scale;
        Self {
            family,
            kind,
            // The test function reads the monodromy: at the tolerance of
            // reported multipliers (as shooting's, 100× tighter) and with
            // its columns in the step control, else g = 0 leaves a
            // multiplier up to 1e-6 from the critical value.
            opts: ShootingOptions {
                rtol: (opts.shooting.rtol / 100.0).max(MULTIPLIER_RTOL),
                control_monodromy: true,
                ..opts.shooting.clone()
            },
            scale: (0..2 * n)
                .map(|i| if i < n { ds } else { ds * w })
                .collect(),
            p_scale: p.abs().max(1e-12),
            q_scale: q.abs().max(1e-12),
            b: DVector::zeros(2 * n),
            c: DVector::zeros(2 * n),
        }
    }

    /// First borders: the left (b) and right (c) singular vectors of A's
    /// smallest singular value at z.
    fn init_borders(&mut self, z: &[f64]) -> Result<(), String> {
        let (_, a) = self.test_matrix(z)?;
        let svd = a.svd(true, true);
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return Err("no singular vectors of the test matrix".into());
        };
        let k = (0..svd.singular_values.len())
            .min_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]))
            .ok_or("an empty test matrix")?;
        self.b = u.column(k).into_owned();
        self.c = vt.row(k).transpose();
        Ok(())
    }

    fn scale_in(&self, x: &[f64], p: f64, q: f64) -> Vec<f64> {
        x.iter()
            .zip(&self.scale)
            .map(|(v, s)| v / s)
            .chain([p / self.p_scale, q / self.q_scale])
            .collect()
    }

    fn unscale(&self, z: &[f64]) -> (Vec<f64>, f64, f64) {
        let d = self.scale.len();
        let x = z[..d].iter().zip(&self.scale).map(|(v, s)| v * s).collect();
        (x, z[d] * self.p_scale, z[d + 1] * self.q_scale)
    }

    /// A (scaled) at z: the test matrix of the kind from the map's Jacobian.
    fn test_matrix(&mut self, z: &[f64]) -> Result<(DVector<f64>, DMatrix<f64>), String> {
        let (x, p, q) = self.unscale(z);
        let model = (self.family)(p, q)?;
        let map = period_map(&model, &x, &self.opts).map_err(|e| e.to_string())?;
        let d = x.len();
        let dg = DMatrix::from_fn(d, d, |r, c| {
            map.monodromy[(r, c)] * self.scale[c] / self.scale[r]
        });
        let id = DMatrix::<f64>::identity(d, d);
        let a = match (self.kind, self.opts.symmetric) {
            (CurveKind::Fold, _) => &dg - &id,
            (CurveKind::PeriodDoubling, true) => &dg * &dg + &id,
            (CurveKind::PeriodDoubling, false) | (CurveKind::BranchPoint, _) => &dg + &id,
        };
        let g = DVector::from_iterator(d, (0..d).map(|i| (map.image[i] - x[i]) / self.scale[i]));
        Ok((g, a))
    }

    /// g(z) of the bordered system, and its null vectors (v, w).
    fn bordered(&self, a: &DMatrix<f64>) -> Result<(f64, DVector<f64>, DVector<f64>), String> {
        let d = a.nrows();
        let mut m = DMatrix::zeros(d + 1, d + 1);
        m.view_mut((0, 0), (d, d)).copy_from(a);
        for i in 0..d {
            m[(i, d)] = self.b[i];
            m[(d, i)] = self.c[i];
        }
        let mut e = DVector::zeros(d + 1);
        e[d] = 1.0;
        let lu = m.clone().lu();
        let v = lu.solve(&e).ok_or("the bordered system is singular")?;
        let w = m
            .transpose()
            .lu()
            .solve(&e)
            .ok_or("the bordered system is singular")?;
        Ok((v[d], v.rows(0, d).into_owned(), w.rows(0, d).into_owned()))
    }

    /// The augmented residual `[G; g]` (d + 1) at z.
    fn residual(&mut self, z: &[f64]) -> Result<DVector<f64>, String> {
        let (g, a) = self.test_matrix(z)?;
        let (s, _, _) = self.bordered(&a)?;
        let d = g.len();
        Ok(DVector::from_iterator(d + 1, g.iter().copied().chain([s])))
    }

    /// The residual `[G; g]` at z and its Jacobian (d + 1) × (d + 2) by
    /// forward differences (each column a period map with its monodromy).
    fn linearise(&mut self, z: &[f64]) -> Result<(DVector<f64>, DMatrix<f64>), String> {
        let f0 = self.residual(z)?;
        let mut jac = DMatrix::zeros(f0.len(), z.len());
        for k in 0..z.len() {
            let h = 1e-7 * z[k].abs().max(1.0);
            let mut zk = z.to_vec();
            zk[k] += h;
            let fk = self.residual(&zk)?;
            jac.set_column(k, &((fk - &f0) / h));
        }
        Ok((f0, jac))
    }

    /// Newton on `[G; g; constraint] = 0` from `pred`, to a residual of
    /// [`CURVE_TOL`] (a multiplier within ~1e-9 of the critical value).
    fn correct(&mut self, pred: &[f64], constraint: Constraint<'_>) -> Result<Vec<f64>, String> {
        let opts = NewtonOptions {
            tol: CURVE_TOL,
            max_iterations: 8,
            max_step: 0.5,
            line_search: false,
            stall: Some((1e-2, 10.0)),
        };
        let mut corr = Corrector {
            sys: self,
            pred,
            constraint,
        };
        let out = damped_newton(&mut corr, pred, &opts)?;
        if out.converged() {
            Ok(out.x)
        } else {
            Err(format!("the corrector stopped ({:?})", out.stop))
        }
    }

    /// The parameter bound (index in z and scaled value) that the step to
    /// `z` crossed, if any.
    fn bound_crossed(&self, z: &[f64], bounds: &[(f64, f64); 2]) -> Option<(usize, f64)> {
        let d = self.scale.len();
        let scales = [self.p_scale, self.q_scale];
        (0..2).find_map(|i| {
            let v = z[d + i] * scales[i];
            let (lo, hi) = bounds[i];
            if v < lo {
                Some((d + i, lo / scales[i]))
            } else if v > hi {
                Some((d + i, hi / scales[i]))
            } else {
                None
            }
        })
    }

    /// New borders: the null vectors of A at the accepted point.
    fn update_borders(&mut self, z: &[f64]) -> Result<(), String> {
        let (_, a) = self.test_matrix(z)?;
        let (_, v, w) = self.bordered(&a)?;
        self.b = &w / w.norm();
        self.c = &v / v.norm();
        Ok(())
    }

    /// The point at z with its multipliers and amplitudes.
    fn point(&mut self, z: &[f64]) -> Result<CurvePoint, String> {
        let (x, p, q) = self.unscale(z);
        let model = (self.family)(p, q)?;
        let map = period_map(&model, &x, &self.opts).map_err(|e| e.to_string())?;
        let multipliers =
            map_multipliers(&map.monodromy, self.opts.symmetric).map_err(|e| e.to_string())?;
        let period = crate::periodic::forcing_period(&model).map_err(|e| e.to_string())?
            * f64::from(self.opts.subharmonic.max(1));
        let orbit =
            orbit_summary(&model, &x, period, 0, self.opts.rtol).map_err(|e| e.to_string())?;
        Ok(CurvePoint {
            p,
            q,
            state: x,
            max_displacement: orbit.max_displacement,
            multipliers,
        })
    }
}

/// The last equation of the corrector.
#[derive(Clone, Copy)]
enum Constraint<'a> {
    /// `tᵀ(z − pred) = 0`.
    Arclength(&'a [f64]),
    /// `z_k = value` (scaled): a parameter held fixed.
    Fixed(usize, f64),
}

/// The corrector as a Newton system: `[G; g; constraint]`.
struct Corrector<'a, 's, F> {
    sys: &'s mut Augmented<F>,
    pred: &'a [f64],
    constraint: Constraint<'a>,
}

impl<F: FnMut(f64, f64) -> Result<Model, String>> NewtonSystem for Corrector<'_, '_, F> {
    type Point = (DVector<f64>, DMatrix<f64>);
    type Error = String;

    fn evaluate(&mut self, z: &[f64]) -> Result<Self::Point, String> {
        let (r, jac) = self.sys.linearise(z)?;
        let n = z.len();
        let last = match self.constraint {
            Constraint::Arclength(t) => (0..n).map(|i| t[i] * (z[i] - self.pred[i])).sum(),
            Constraint::Fixed(k, value) => z[k] - value,
        };
        let mut full = DMatrix::zeros(n, n);
        full.view_mut((0, 0), (n - 1, n)).copy_from(&jac);
        for i in 0..n {
            full[(n - 1, i)] = match self.constraint {
                Constraint::Arclength(t) => t[i],
                Constraint::Fixed(k, _) => f64::from(u8::from(i == k)),
            };
        }
        let rhs = DVector::from_iterator(n, r.iter().copied().chain([last]));
        Ok((rhs, full))
    }

    fn residual_norm(&self, (r, _): &Self::Point) -> f64 {
        r.amax()
    }

    fn direction(&mut self, _z: &[f64], (r, j): &Self::Point) -> Result<Option<Vec<f64>>, String> {
        Ok(j.clone().lu().solve(&(-r)).map(|d| d.as_slice().to_vec()))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        delta.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }
}

/// The unit null direction of a (d + 1) × (d + 2) Jacobian: the solution of
/// `[J; tᵀ] t_new = e` (with the previous tangent), else from the SVD.
fn null_direction(jac: &DMatrix<f64>, previous: Option<&Vec<f64>>) -> Option<Vec<f64>> {
    let (m, n) = jac.shape();
    let t = match previous {
        Some(prev) => {
            let mut a = DMatrix::zeros(n, n);
            a.view_mut((0, 0), (m, n)).copy_from(jac);
            for i in 0..n {
                a[(m, i)] = prev[i];
            }
            let mut e = DVector::zeros(n);
            e[m] = 1.0;
            a.lu().solve(&e)?
        }
        None => {
            let mut a = DMatrix::zeros(n, n);
            a.view_mut((0, 0), (m, n)).copy_from(jac);
            let svd = a.svd(false, true);
            let vt = svd.v_t?;
            let k = (0..n)
                .min_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]))?;
            vt.row(k).transpose()
        }
    };
    let norm = t.norm();
    (norm > 0.0 && norm.is_finite()).then(|| t.iter().map(|v| v / norm).collect())
}

#[cfg(test)]
#[path = "curve_tests.rs"]
mod tests;
