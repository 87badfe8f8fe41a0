//! The minimally augmented system of a curve (docs/theory.md §9) in scaled
//! variables: the orbit residual, the test function(s) from a bordered
//! system, their forward-difference Jacobian and the Newton corrector.

use crate::model::family::Family2;
use nalgebra::{Complex, DMatrix, DVector};

use super::{CurveKind, CurveOptions, CurvePoint, CurveSystem, Scales};
use crate::continuation::problem::period_image;
use crate::model::Model;
use crate::newton::NewtonSystem;
use crate::periodic::{
    floquet_multipliers, forcing_period, multipliers_of_map, orbit_summary, period_map,
    ShootingOptions,
};
use crate::simulate::{simulate, SimulationOptions};

/// Residual tolerance of the curve's corrector on the scaled orbit
/// residual.
const CURVE_TOL: f64 = 1e-11;

/// Tolerance on the test functions g (the grazing margin in displacement
/// scales): the multiplier's distance from its critical value is about
/// g / wᵀv (w, v the left and right null vectors, wᵀb = cᵀv = 1), larger
/// where the eigenvectors are nearly parallel: at g = 1e-11 a multiplier
/// of the R2 N = 1 fold curve was 1e-8 from +1 (dividing g by wᵀv instead
/// makes g singular at double multipliers, where curves meet). The test
/// rows enter the corrector weighted by `CURVE_TOL / TEST_TOL`.
const TEST_TOL: f64 = 1e-12;

/// The largest impact margin (in displacement scales) at which a grazing
/// curve starts: the point's margin is then driven to zero.
pub(super) const GRAZING_START: f64 = 1e-3;

/// The augmented system in scaled variables `z = (x / scale, p / p_scale,
/// q / q_scale[, κ])`: κ = cos θ of the critical pair e^{±iθ} on a
/// Neimark–Sacker curve.
pub(super) struct Augmented<F> {
    family: F,
    pub(super) kind: CurveKind,
    pub(super) opts: ShootingOptions,
    scale: Vec<f64>,
    p_scale: f64,
    q_scale: f64,
    /// Borders B (right) and C (left) of the bordered system, d × k with k
    /// = 1 (fold, flip, branch point), 2 (Neimark–Sacker) or 0 (grazing).
    b: DMatrix<f64>,
    c: DMatrix<f64>,
    /// The test equations among the k² entries of the bordered solution
    /// (row major) that enter the corrector; for grazing, entry 0 is the
    /// impact margin.
    rows: Vec<usize>,
    /// The contact whose impact margin vanishes on a grazing curve.
    contact: usize,
    /// Start of the window in which the grazing contact's closest approach
    /// is sought, centred on it: the margin is then a smooth interior
    /// maximum, not the window's end value (an approach peaking at t = 0
    /// would be cut in two). The window is half a period long on the half
    /// map, where a contact that is its own mirror image approaches twice
    /// per period with equal peaks (a maximum over both has a kink).
    window: f64,
}

/// The bordered solution: the k × k matrix g, the right and left null
/// vectors (d × k each).
type Bordered = (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>);

/// An accepted or trial point as the tests see it.
pub(super) struct Observation {
    /// The point with its multipliers and amplitudes.
    pub point: CurvePoint,
    /// Eigenvalues of the shooting map's Jacobian (DG of the half map when
    /// symmetric).
    pub eigenvalues: Vec<Complex<f64>>,
    /// κ on a Neimark–Sacker curve (NaN on the others).
    pub kappa: f64,
}

impl Observation {
    /// The point (p, q) of the orbit from `x` with the eigenvalues of its
    /// shooting map: the multipliers from them (squared on the half map)
    /// and the orbit's amplitudes from one integrated period.
    pub(super) fn new(
        model: &Model,
        x: Vec<f64>,
        (p, q): (f64, f64),
        eigenvalues: Vec<Complex<f64>>,
        kappa: f64,
        opts: &ShootingOptions,
    ) -> Result<Observation, String> {
        let multipliers = multipliers_of_map(eigenvalues.clone(), opts.symmetric);
        let period =
            forcing_period(model).map_err(|e| e.to_string())? * f64::from(opts.subharmonic.max(1));
        let orbit = orbit_summary(model, &x, period, 0, opts.rtol).map_err(|e| e.to_string())?;
        Ok(Observation {
            point: CurvePoint {
                p,
                q,
                state: x,
                max_displacement: orbit.max_displacement,
                multipliers,
            },
            eigenvalues,
            kappa,
        })
    }
}

impl<F: Family2> Augmented<F> {
    pub(super) fn new(
        family: F,
        kind: CurveKind,
        opts: &CurveOptions,
        model: &Model,
        (p, q): (f64, f64),
    ) -> Self {
        let n = model.bodies().len();
        let k = kind.borders();
        let scales = Scales::new(opts, model, (p, q));
        Self {
            family,
            kind,
            opts: scales.shooting,
            scale: scales.orbit,
            p_scale: scales.parameters[0],
            q_scale: scales.parameters[1],
            b: DMatrix::zeros(2 * n, k),
            c: DMatrix::zeros(2 * n, k),
            rows: if k == 2 { vec![0, 3] } else { vec![0] },
            contact: 0,
            window: 0.0,
        }
    }

    /// The orbit's dimension d.
    pub(super) fn dim(&self) -> usize {
        self.scale.len()
    }

    /// Sets up the test function at the start z: the borders from the
    /// singular vectors of A's smallest singular values, or the grazing
    /// contact (the one whose impact margin is nearest zero).
    pub(super) fn init(&mut self, z: &[f64]) -> Result<(), String> {
        if self.kind == CurveKind::Grazing {
            let margins = self.margins(z)?;
            self.contact = (0..margins.len())
                .min_by(|&i, &j| margins[i].abs().total_cmp(&margins[j].abs()))
                .ok_or("a grazing curve needs a contact")?;
            let margin = margins[self.contact];
            self.centre_window(z)?;
            if margin.abs() > GRAZING_START {
                return Err(format!(
                    "not a grazing of a contact's closest approach: the smallest impact margin is {:.3e} m \
                     (an impact that splits in two changes the count without one)",
                    margin * self.scale[0]
                ));
            }
            return Ok(());
        }
        let (_, a) = self.test_matrix(z)?;
        let svd = a.svd(true, true);
        let (Some(u), Some(vt)) = (svd.u, svd.v_t) else {
            return Err("no singular vectors of the test matrix".into());
        };
        let mut order: Vec<usize> = (0..svd.singular_values.len()).collect();
        order.sort_by(|&i, &j| svd.singular_values[i].total_cmp(&svd.singular_values[j]));
        for (col, &i) in order.iter().take(self.b.ncols()).enumerate() {
            self.b.set_column(col, &u.column(i));
            self.c.set_column(col, &vt.row(i).transpose());
        }
        Ok(())
    }

    /// z from the orbit state, the parameters and κ (ignored off
    /// Neimark–Sacker curves).
    pub(super) fn scale_in(&self, x: &[f64], p: f64, q: f64, kappa: f64) -> Vec<f64> {
        let extra = (self.kind == CurveKind::NeimarkSacker).then_some(kappa);
        x.iter()
            .zip(&self.scale)
            .map(|(v, s)| v / s)
            .chain([p / self.p_scale, q / self.q_scale])
            .chain(extra)
            .collect()
    }

    fn unscale(&self, z: &[f64]) -> (Vec<f64>, f64, f64, f64) {
        let d = self.dim();
        let x = z[..d].iter().zip(&self.scale).map(|(v, s)| v * s).collect();
        let kappa = z.get(d + 2).copied().unwrap_or(f64::NAN);
        (x, z[d] * self.p_scale, z[d + 1] * self.q_scale, kappa)
    }

    /// The scaled orbit residual and the (scaled) test matrix A at z:
    /// DG − I (fold), DG + I (flip of Φ, branch point of the half map),
    /// DG² + I (flip on the half map), DG² − 2κ DG + I (Neimark–Sacker).
    fn test_matrix(&mut self, z: &[f64]) -> Result<(DVector<f64>, DMatrix<f64>), String> {
        let (x, p, q, kappa) = self.unscale(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
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
            (CurveKind::NeimarkSacker, _) => &dg * &dg - &dg * (2.0 * kappa) + &id,
            (CurveKind::Grazing, _) => DMatrix::zeros(0, 0),
        };
        Ok((self.orbit_residual(&map.image, &x), a))
    }

    fn orbit_residual(&self, image: &[f64], x: &[f64]) -> DVector<f64> {
        DVector::from_iterator(
            x.len(),
            (0..x.len()).map(|i| (image[i] - x[i]) / self.scale[i]),
        )
    }

    /// The impact margins of every contact over one period (scaled).
    fn margins(&mut self, z: &[f64]) -> Result<Vec<f64>, String> {
        let (x, p, q, _) = self.unscale(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let period = self.period(&model)?;
        let orbit =
            orbit_summary(&model, &x, period, 0, self.opts.rtol).map_err(|e| e.to_string())?;
        Ok(orbit
            .impact_margin
            .iter()
            .map(|m| m / self.scale[0])
            .collect())
    }

    /// Centres the grazing window on the grazing contact's closest
    /// approach on the orbit from z.
    fn centre_window(&mut self, z: &[f64]) -> Result<(), String> {
        let (x, p, q, _) = self.unscale(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let period = self.period(&model)?;
        let orbit =
            orbit_summary(&model, &x, period, 400, self.opts.rtol).map_err(|e| e.to_string())?;
        let n = x.len() / 2;
        let peak = (0..orbit.times.len())
            .max_by(|&i, &j| {
                let s = |k: usize| model.approach(self.contact, &orbit.states[k * 2 * n..]);
                s(i).total_cmp(&s(j))
            })
            .map_or(0.0, |i| orbit.times[i]);
        self.window = (peak - 0.5 * self.window_span(period)).rem_euclid(period);
        Ok(())
    }

    /// The grazing window's length: one period, half on the half map.
    fn window_span(&self, period: f64) -> f64 {
        if self.opts.symmetric {
            0.5 * period
        } else {
            period
        }
    }

    /// The grazing contact's impact margin (scaled) over the window.
    fn grazing_margin(&mut self, model: &Model, x: &[f64]) -> Result<f64, String> {
        let span = self.window_span(self.period(model)?);
        let opts = SimulationOptions {
            t_end: self.window + span,
            rtol: self.opts.rtol,
            atol: self.opts.rtol * 1e-4,
            output_step: None,
            start: Some(x.to_vec()),
            extrema_window: Some((self.window, self.window + span)),
            ..SimulationOptions::default()
        };
        let sim = simulate(model, &opts).map_err(|e| e.0)?;
        if let Some(e) = sim.error {
            return Err(e.to_string());
        }
        let extrema = sim.extrema.ok_or("the orbit's extrema were not tracked")?;
        Ok(extrema.impact_margin[self.contact] / self.scale[0])
    }

    fn period(&self, model: &Model) -> Result<f64, String> {
        Ok(forcing_period(model).map_err(|e| e.to_string())?
            * f64::from(self.opts.subharmonic.max(1)))
    }

    /// The bordered solution: `[A B; Cᵀ 0] (V, G) = (0, I)` and its
    /// transpose, giving the k × k matrix G (zero exactly where A has a
    /// k-dimensional kernel) and the right and left null vectors V, W.
    fn bordered(&self, a: &DMatrix<f64>) -> Result<Bordered, String> {
        let d = a.nrows();
        let k = self.b.ncols();
        let mut m = DMatrix::zeros(d + k, d + k);
        m.view_mut((0, 0), (d, d)).copy_from(a);
        m.view_mut((0, d), (d, k)).copy_from(&self.b);
        m.view_mut((d, 0), (k, d)).copy_from(&self.c.transpose());
        let mut e = DMatrix::zeros(d + k, k);
        e.view_mut((d, 0), (k, k)).fill_with_identity();
        let singular = "the bordered system is singular";
        let v = m.clone().lu().solve(&e).ok_or(singular)?;
        let w = m.transpose().lu().solve(&e).ok_or(singular)?;
        Ok((
            v.rows(d, k).into_owned(),
            v.rows(0, d).into_owned(),
            w.rows(0, d).into_owned(),
        ))
    }

    /// Every equation at z: the orbit residual, then the k² entries of G
    /// (row major), or the grazing contact's impact margin.
    fn residual_full(&mut self, z: &[f64]) -> Result<DVector<f64>, String> {
        if self.kind == CurveKind::Grazing {
            let (x, p, q, _) = self.unscale(z);
            let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
            let image = period_image(&model, &x, &self.opts)
                .ok_or("the period map failed at a grazing-curve iterate")?;
            let g = self.orbit_residual(&image, &x);
            let margin = self.grazing_margin(&model, &x)? * CURVE_TOL / TEST_TOL;
            return Ok(DVector::from_iterator(
                g.len() + 1,
                g.iter().copied().chain([margin]),
            ));
        }
        let (g, a) = self.test_matrix(z)?;
        let (s, _, _) = self.bordered(&a)?;
        let k = s.nrows();
        let scale = TEST_TOL / CURVE_TOL;
        let entries = (0..k * k).map(|i| s[(i / k, i % k)] / scale);
        Ok(DVector::from_iterator(
            g.len() + k * k,
            g.iter().copied().chain(entries),
        ))
    }

    /// Every equation at z and its Jacobian by forward differences (each
    /// column a period map with its monodromy).
    pub(super) fn linearise(&mut self, z: &[f64]) -> Result<(DVector<f64>, DMatrix<f64>), String> {
        let f0 = self.residual_full(z)?;
        let mut jac = DMatrix::zeros(f0.len(), z.len());
        for k in 0..z.len() {
            let h = 1e-7 * z[k].abs().max(1.0);
            let mut zk = z.to_vec();
            zk[k] += h;
            let fk = self.residual_full(&zk)?;
            jac.set_column(k, &((fk - &f0) / h));
        }
        Ok((f0, jac))
    }

    /// The corrector's equations among all: the orbit and the chosen test
    /// entries.
    pub(super) fn select(
        &self,
        r: &DVector<f64>,
        jac: &DMatrix<f64>,
    ) -> (DVector<f64>, DMatrix<f64>) {
        let d = self.dim();
        let keep: Vec<usize> = (0..d).chain(self.rows.iter().map(|i| d + i)).collect();
        (r.select_rows(&keep), jac.select_rows(&keep))
    }

    /// On a Neimark–Sacker curve, the two of G's four entries whose
    /// equations with the orbit's are best conditioned (largest smallest
    /// singular value of their Jacobian), from the full Jacobian at an
    /// accepted point.
    pub(super) fn choose_rows(&mut self, jac: &DMatrix<f64>) {
        if self.kind != CurveKind::NeimarkSacker {
            return;
        }
        let d = self.dim();
        let pairs = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];
        let conditioning = |pair: &[usize; 2]| {
            let keep: Vec<usize> = (0..d).chain(pair.iter().map(|i| d + i)).collect();
            let sub = jac.select_rows(&keep);
            sub.singular_values().min()
        };
        if let Some(best) = pairs
            .iter()
            .max_by(|a, b| conditioning(a).total_cmp(&conditioning(b)))
        {
            self.rows = best.to_vec();
        }
    }

    /// Newton on `[G; g; constraint] = 0` from `pred`, to a residual of
    /// [`CURVE_TOL`].
    fn correct(&mut self, pred: &[f64], constraint: Constraint<'_>) -> Result<Vec<f64>, String> {
        let mut corr = Corrector {
            sys: self,
            pred,
            constraint,
            chord: None,
        };
        super::run_corrector(&mut corr, pred, CURVE_TOL, 12)
    }

    /// Follows the accepted point z: new borders (the null vectors of A
    /// there, orthonormalised), or the grazing window re-centred.
    fn move_to(&mut self, z: &[f64]) -> Result<(), String> {
        if self.kind == CurveKind::Grazing {
            return self.centre_window(z);
        }
        let (_, a) = self.test_matrix(z)?;
        let (_, v, w) = self.bordered(&a)?;
        self.b = w.qr().q();
        self.c = v.qr().q();
        Ok(())
    }

    /// The point at z with its multipliers, amplitudes and the map's
    /// eigenvalues.
    fn observe(&mut self, z: &[f64]) -> Result<Observation, String> {
        let (x, p, q, kappa) = self.unscale(z);
        let model = self.family.model_at(p, q).map_err(|e| e.to_string())?;
        let map = period_map(&model, &x, &self.opts).map_err(|e| e.to_string())?;
        let eigenvalues = floquet_multipliers(&map.monodromy).map_err(|e| e.to_string())?;
        Observation::new(&model, x, (p, q), eigenvalues, kappa, &self.opts)
    }
}

impl<F: Family2> CurveSystem for Augmented<F> {
    fn p_index(&self) -> usize {
        self.dim()
    }

    fn start(&mut self, state: &[f64], p: f64, q: f64) -> Result<Vec<f64>, String> {
        let d = self.dim();
        let mut z0 = self.scale_in(state, p, q, 0.0);
        if self.kind == CurveKind::NeimarkSacker {
            z0[d + 2] = critical_kappa(&self.observe(&z0)?.eigenvalues)?;
        }
        self.init(&z0)?;
        let (_, jac) = self.linearise(&z0)?;
        self.choose_rows(&jac);
        self.correct(&z0, Constraint::Fixed(d + 1, z0[d + 1]))
    }

    fn correct(&mut self, pred: &[f64], constraint: Constraint<'_>) -> Result<Vec<f64>, String> {
        Augmented::correct(self, pred, constraint)
    }

    fn tangent(&mut self, z: &[f64], previous: Option<&[f64]>) -> Result<Vec<f64>, String> {
        let (r, jac) = self.linearise(z)?;
        self.choose_rows(&jac);
        let (_, jac) = self.select(&r, &jac);
        let mut t = null_direction(&jac, previous).ok_or("the augmented system is singular")?;
        if let Some(prev) = previous {
            if t.iter().zip(prev).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                t.iter_mut().for_each(|v| *v = -*v);
            }
        }
        Ok(t)
    }

    fn observe(&mut self, z: &[f64]) -> Result<Observation, String> {
        Augmented::observe(self, z)
    }

    fn bound_crossed(&self, z: &[f64], bounds: &[(f64, f64); 2]) -> Option<(usize, f64)> {
        super::bound_crossed(z, self.dim(), [self.p_scale, self.q_scale], bounds)
    }

    fn move_to(&mut self, z: &[f64]) -> Result<(), String> {
        Augmented::move_to(self, z)
    }
}

/// κ = cos θ of the pair e^{±iθ} nearest the unit circle (the start of a
/// Neimark–Sacker curve).
fn critical_kappa(eigenvalues: &[Complex<f64>]) -> Result<f64, String> {
    eigenvalues
        .iter()
        .filter(|l| l.im > 0.0)
        .min_by(|a, b| (a.norm() - 1.0).abs().total_cmp(&(b.norm() - 1.0).abs()))
        .map(|l| l.re / l.norm())
        .ok_or_else(|| {
            "no complex pair of multipliers at the start of a Neimark–Sacker curve".into()
        })
}

/// The last equation of the corrector.
#[derive(Clone, Copy)]
pub(super) enum Constraint<'a> {
    /// `tᵀ(z − pred) = 0`.
    Arclength(&'a [f64]),
    /// `z_k = value` (scaled): a parameter held fixed.
    Fixed(usize, f64),
}

/// The corrector as a Newton system: `[G; g; constraint]`.
/// A chord method: the Jacobian of the first iterate is kept while the
/// residual falls by 4× or more per iteration, and taken again otherwise
/// (each Jacobian costs d + 2 or d + 3 period maps, a residual one).
struct Corrector<'a, 's, F> {
    sys: &'s mut Augmented<F>,
    pred: &'a [f64],
    constraint: Constraint<'a>,
    /// The Jacobian in use (the corrector's rows) and the last residual.
    chord: Option<(DMatrix<f64>, f64)>,
}

impl<F: Family2> NewtonSystem for Corrector<'_, '_, F> {
    type Point = (DVector<f64>, DMatrix<f64>);
    type Error = String;

    fn evaluate(&mut self, z: &[f64]) -> Result<Self::Point, String> {
        let (r, jac) = match self.chord.take() {
            Some((jac, last)) => {
                let full = self.sys.residual_full(z)?;
                let (r, _) = self.sys.select(&full, &DMatrix::zeros(full.len(), 0));
                if r.amax() <= 0.25 * last {
                    (r, jac)
                } else {
                    let (r, jac) = self.sys.linearise(z)?;
                    self.sys.select(&r, &jac)
                }
            }
            None => {
                let (r, jac) = self.sys.linearise(z)?;
                self.sys.select(&r, &jac)
            }
        };
        self.chord = Some((jac.clone(), r.amax()));
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

/// The unit null direction of an (n − 1) × n Jacobian: the solution of
/// `[J; tᵀ] t_new = e` (with the previous tangent), else from the SVD.
pub(super) fn null_direction(jac: &DMatrix<f64>, previous: Option<&[f64]>) -> Option<Vec<f64>> {
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
