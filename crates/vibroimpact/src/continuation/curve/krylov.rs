//! The matrix-free form of a curve (docs/theory.md §9), for long rows: the
//! extended system of Moore and Spence in scaled variables
//! `Z = (x, v, p, q)`,
//!
//! `G(x; p, q) − x = 0`, `A(x; p, q) v = 0`, `cᵀv = 1`,
//!
//! with A = DG − I (fold), DG + I (flip of Φ, branch point of the half
//! map) or DG² + I (flip on the half map) and c the previous point's null
//! vector (normalised so that cᵀv = 1 there). Every residual is one
//! integration of the orbit with the tangent column v (two for DG²); the
//! Newton directions and the tangent are solved by GMRES on
//! forward-difference products of the residual, and the multipliers are
//! the Ritz values of an Arnoldi iteration (its products, and those of the
//! start's inverse iteration, replayed on the tape of one integration of
//! the map: `integrate::tangent`): nothing of size d² is formed.

use super::system::{Constraint, Observation};
use super::{bound_crossed, CurveKind, CurveOptions, CurveSystem, Scales};
use crate::linalg::{arnoldi_matrix, gmres};
use crate::model::family::Family2;
use crate::model::Model;
use crate::newton::NewtonSystem;
use crate::periodic::{
    floquet_multipliers, map_and_product, period_map_with, MapTangent, ShootingOptions, MAX_STEPS,
};

/// Residual tolerance of the corrector (scaled max-norm).
const TOL: f64 = 1e-10;

/// Largest GMRES basis.
const MAX_GMRES: usize = 400;

/// The extended system of a curve, matrix-free.
pub(super) struct KrylovSystem<F> {
    family: F,
    kind: CurveKind,
    opts: ShootingOptions,
    scale: Vec<f64>,
    p_scale: f64,
    q_scale: f64,
    /// Normalisation of the null vector: cᵀv = 1.
    c: Vec<f64>,
    /// Arnoldi vectors for the multipliers.
    arnoldi: usize,
}

impl<F: Family2> KrylovSystem<F> {
    pub(super) fn new(
        family: F,
        kind: CurveKind,
        opts: &CurveOptions,
        model: &Model,
        (p, q): (f64, f64),
        arnoldi: usize,
    ) -> Result<Self, String> {
        if matches!(kind, CurveKind::NeimarkSacker | CurveKind::Grazing) {
            return Err(format!(
                "{} curves have no matrix-free form yet: use the dense form (rows up to 2048 bodies)",
                kind.name()
            ));
        }
        let n = model.bodies().len();
        let scales = Scales::new(opts, model, (p, q));
        Ok(Self {
            family,
            kind,
            opts: scales.shooting,
            scale: scales.orbit,
            p_scale: scales.parameters[0],
            q_scale: scales.parameters[1],
            c: vec![0.0; 2 * n],
            arnoldi: arnoldi.max(1),
        })
    }

    fn d(&self) -> usize {
        self.scale.len()
    }

    /// (x, v, p, q) unscaled (v stays scaled).
    fn split<'z>(&self, z: &'z [f64]) -> (Vec<f64>, &'z [f64], f64, f64) {
        let d = self.d();
        let x = z[..d].iter().zip(&self.scale).map(|(a, s)| a * s).collect();
        (
            x,
            &z[d..2 * d],
            z[2 * d] * self.p_scale,
            z[2 * d + 1] * self.q_scale,
        )
    }

    /// `(G(x), DG u)` for a scaled u, both scaled.
    fn map(&mut self, model: &Model, x: &[f64], u: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
        let unscaled: Vec<f64> = u.iter().zip(&self.scale).map(|(a, s)| a * s).collect();
        let (image, product) =
            map_and_product(model, x, &unscaled, &self.opts).map_err(|e| e.to_string())?;
        let scaled =
            |v: Vec<f64>| -> Vec<f64> { v.iter().zip(&self.scale).map(|(a, s)| a / s).collect() };
        Ok((scaled(image), scaled(product)))
    }

    /// Products `DG u` at the orbit `x` (unscaled) of `model`, replayed on
    /// the steps of one integration of the map (`MapTangent`): for the
    /// many products at one point (inverse iteration, Arnoldi).
    fn tangent_at(&self, model: &Model, x: &[f64]) -> Result<MapTangent, String> {
        period_map_with(model, x, &self.opts, None, false, MAX_STEPS)
            .map_err(|e| e.to_string())?
            .tangent
            .ok_or_else(|| "the period map recorded no tape".to_string())
    }

    /// The residual `[G − x; A v; cᵀv − 1]` (2d + 1), scaled.
    fn residual(&mut self, z: &[f64]) -> Result<Vec<f64>, String> {
        let d = self.d();
        let (x, v, p, q) = self.split(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let (image, dgv) = self.map(&model, &x, v)?;
        let av: Vec<f64> = match (self.kind, self.opts.symmetric) {
            (CurveKind::Fold, _) => (0..d).map(|i| dgv[i] - v[i]).collect(),
            (CurveKind::PeriodDoubling, true) => {
                let (_, dg2v) = self.map(&model, &x, &dgv)?;
                (0..d).map(|i| dg2v[i] + v[i]).collect()
            }
            _ => (0..d).map(|i| dgv[i] + v[i]).collect(),
        };
        let mut r: Vec<f64> = (0..d).map(|i| image[i] - z[i]).collect();
        r.extend(av);
        r.push(self.c.iter().zip(v).map(|(a, b)| a * b).sum::<f64>() - 1.0);
        Ok(r)
    }

    /// `J δ` by a forward difference of the residual from `r0` at z.
    fn product(&mut self, z: &[f64], r0: &[f64], delta: &[f64]) -> Result<Vec<f64>, String> {
        let size = delta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if size == 0.0 {
            return Ok(vec![0.0; r0.len()]);
        }
        let h = 1e-7 * z.iter().fold(1.0f64, |m, v| m.max(v.abs())) / size;
        let shifted: Vec<f64> = z.iter().zip(delta).map(|(a, b)| a + h * b).collect();
        let r = self.residual(&shifted)?;
        Ok(r.iter().zip(r0).map(|(a, b)| (a - b) / h).collect())
    }

    /// Solves `[J; rowᵀ] u = rhs` by GMRES to `rel_tol` at z (residual r0).
    fn solve(
        &mut self,
        z: &[f64],
        r0: &[f64],
        row: &[f64],
        rhs: &[f64],
        rel_tol: f64,
    ) -> Result<Vec<f64>, String> {
        let n = z.len();
        let noise = 1e3 * self.opts.rtol;
        let mut apply = |u: &[f64]| -> Result<Vec<f64>, String> {
            let mut out = self.product(z, r0, u)?;
            out.push(row.iter().zip(u).map(|(a, b)| a * b).sum());
            Ok(out)
        };
        let (u, _, _) = gmres(&mut apply, rhs, n.min(MAX_GMRES), rel_tol, noise)?;
        if u.iter().all(|v| v.is_finite()) {
            Ok(u)
        } else {
            Err("GMRES gave a non-finite direction".into())
        }
    }
}

impl<F: Family2> CurveSystem for KrylovSystem<F> {
    fn p_index(&self) -> usize {
        2 * self.d()
    }

    /// The null vector of A at the start by two steps of inverse iteration
    /// (GMRES on A v = b), then the start corrected with q held.
    fn start(&mut self, state: &[f64], p: f64, q: f64) -> Result<Vec<f64>, String> {
        let d = self.d();
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let x: Vec<f64> = state.iter().zip(&self.scale).map(|(a, s)| a / s).collect();
        let mut v: Vec<f64> = (0..d)
            .map(|i| 1.0 + 0.1 * ((i * 7919) % 97) as f64 / 97.0)
            .collect();
        let tangent = self.tangent_at(&model, state)?;
        for _ in 0..2 {
            let norm = v.iter().map(|a| a * a).sum::<f64>().sqrt();
            let b: Vec<f64> = v.iter().map(|a| a / norm).collect();
            let noise = 1e3 * self.opts.rtol;
            let kind = self.kind;
            let symmetric = self.opts.symmetric;
            let mut apply = |u: &[f64]| -> Result<Vec<f64>, String> {
                let dgu = tangent.scaled_product(u, &self.scale, 1.0);
                Ok(match (kind, symmetric) {
                    (CurveKind::Fold, _) => (0..d).map(|i| dgu[i] - u[i]).collect(),
                    (CurveKind::PeriodDoubling, true) => {
                        let dg2u = tangent.scaled_product(&dgu, &self.scale, 1.0);
                        (0..d).map(|i| dg2u[i] + u[i]).collect()
                    }
                    _ => (0..d).map(|i| dgu[i] + u[i]).collect(),
                })
            };
            v = gmres(&mut apply, &b, d.min(MAX_GMRES), 1e-10, noise)?.0;
        }
        let norm2: f64 = v.iter().map(|a| a * a).sum();
        let v: Vec<f64> = v.iter().map(|a| a / norm2.sqrt()).collect();
        self.c = v.clone();
        let mut z = x;
        z.extend(v);
        z.extend([p / self.p_scale, q / self.q_scale]);
        let q_index = 2 * d + 1;
        self.correct(&z.clone(), Constraint::Fixed(q_index, z[q_index]))
    }

    fn correct(&mut self, pred: &[f64], constraint: Constraint<'_>) -> Result<Vec<f64>, String> {
        let mut corr = Corrector {
            sys: self,
            pred,
            constraint,
        };
        super::run_corrector(&mut corr, pred, TOL, 10)
    }

    /// `[J; t_prevᵀ] t = e` by GMRES (without a previous tangent: the
    /// direction with dq = 1).
    fn tangent(&mut self, z: &[f64], previous: Option<&[f64]>) -> Result<Vec<f64>, String> {
        let n = z.len();
        let r0 = self.residual(z)?;
        let row: Vec<f64> = match previous {
            Some(t) => t.to_vec(),
            None => (0..n).map(|i| f64::from(u8::from(i == n - 1))).collect(),
        };
        let mut e = vec![0.0; n];
        e[n - 1] = 1.0;
        let mut t = self.solve(z, &r0, &row, &e, 1e-8)?;
        let norm = t.iter().map(|a| a * a).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return Err("the extended system is singular".into());
        }
        let sign = match previous {
            Some(prev) if t.iter().zip(prev).map(|(a, b)| a * b).sum::<f64>() < 0.0 => -1.0,
            _ => 1.0,
        };
        t.iter_mut().for_each(|a| *a *= sign / norm);
        Ok(t)
    }

    /// The multipliers from the Ritz values of `arnoldi` vectors of DG.
    fn observe(&mut self, z: &[f64]) -> Result<Observation, String> {
        let d = self.d();
        let (x, _, p, q) = self.split(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let noise = 1e3 * self.opts.rtol;
        let m = self.arnoldi.min(d);
        let tangent = self.tangent_at(&model, &x)?;
        let mut apply = |u: &[f64]| -> Result<Vec<f64>, String> {
            let dgu = tangent.scaled_product(u, &self.scale, 1.0);
            Ok((0..d).map(|i| dgu[i] - u[i]).collect())
        };
        let ritz = arnoldi_matrix(&mut apply, d, m, noise)?;
        let eigenvalues = floquet_multipliers(&ritz).map_err(|e| e.to_string())?;
        Observation::new(&model, x, (p, q), eigenvalues, f64::NAN, &self.opts)
    }

    fn bound_crossed(&self, z: &[f64], bounds: &[(f64, f64); 2]) -> Option<(usize, f64)> {
        bound_crossed(z, self.p_index(), [self.p_scale, self.q_scale], bounds)
    }

    /// The normalisation follows the null vector: c = v / |v|².
    fn move_to(&mut self, z: &[f64]) -> Result<(), String> {
        let d = self.d();
        let v = &z[d..2 * d];
        let norm2: f64 = v.iter().map(|a| a * a).sum();
        self.c = v.iter().map(|a| a / norm2).collect();
        Ok(())
    }
}

/// The corrector as a Newton system: `[residual; constraint]`, directions
/// by GMRES (inexact Newton, relative residual 1e-6).
struct Corrector<'a, 's, F> {
    sys: &'s mut KrylovSystem<F>,
    pred: &'a [f64],
    constraint: Constraint<'a>,
}

impl<F: Family2> NewtonSystem for Corrector<'_, '_, F> {
    type Point = (Vec<f64>, f64);
    type Error = String;

    fn evaluate(&mut self, z: &[f64]) -> Result<Self::Point, String> {
        let r = self.sys.residual(z)?;
        let last = match self.constraint {
            Constraint::Arclength(t) => (0..z.len()).map(|i| t[i] * (z[i] - self.pred[i])).sum(),
            Constraint::Fixed(k, value) => z[k] - value,
        };
        Ok((r, last))
    }

    fn residual_norm(&self, (r, last): &Self::Point) -> f64 {
        r.iter().fold(last.abs(), |m, v| m.max(v.abs()))
    }

    fn direction(
        &mut self,
        z: &[f64],
        (r, last): &Self::Point,
    ) -> Result<Option<Vec<f64>>, String> {
        let n = z.len();
        let row: Vec<f64> = match self.constraint {
            Constraint::Arclength(t) => t.to_vec(),
            Constraint::Fixed(k, _) => (0..n).map(|i| f64::from(u8::from(i == k))).collect(),
        };
        let rhs: Vec<f64> = r.iter().chain([last]).map(|v| -v).collect();
        let r0 = r.clone();
        Ok(Some(self.sys.solve(z, &r0, &row, &rhs, 1e-6)?))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        delta.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    }
}
