//! Variational equations: a system integrated together with the
//! sensitivity of its state to the initial state (docs/theory.md §5).
//!
//! For `y' = f(t, y)`, the matrix `Φ(t) = ∂y(t)/∂y(0)` obeys
//! `Φ' = J(t, y(t)) Φ`, `Φ(0) = I`, with the Jacobian `J = ∂f/∂y`. Over a
//! forcing period `Φ(T)` is the monodromy matrix whose eigenvalues are the
//! Floquet multipliers, and the Newton matrix of shooting is `Φ(T) - I`.
//!
//! The extended state is `[y, Φ e_1, …, Φ e_p]` (p columns, `p <= dim`,
//! usually all). The Jacobian is the system's own (analytic and banded for
//! [`ChainDynamics`](crate::dynamics::ChainDynamics): a right-hand side then
//! costs O(dim · bandwidth · p)); a system without an analytic Jacobian gets
//! one by forward differences of `f` (dim extra evaluations).
//!
//! With a parameter ([`Variational::with_parameter`]) one more column
//! carries the sensitivity `s = ∂y(t)/∂p` to a parameter p of the system:
//! `s' = J s + ∂f/∂p`, `s(0) = 0`, with `∂f/∂p` by a forward difference of
//! the right-hand side against a copy of the system at `p + δp` (same t and
//! y: one more right-hand side per stage instead of a second integration).
//! Only the state enters the error norm by default
//! ([`Variational::error_components`]); including the columns controls the
//! accuracy of Φ itself.

use crate::integrate::{BandMatrix, Harmonic, LinearForm, OdeSystem};

/// A system extended by its variational equations.
#[derive(Clone, Debug)]
pub struct Variational<S> {
    sys: S,
    dim: usize,
    columns: usize,
    jac: BandMatrix,
    f0: Vec<f64>,
    f1: Vec<f64>,
    yp: Vec<f64>,
    /// The shifted system's right-hand side (parameter column).
    fp: Vec<f64>,
    /// The system at `p + δp` and `δp`, for the parameter column.
    parameter: Option<(S, f64)>,
    /// Whether p enters through the forcing alone (the shifted system's
    /// right-hand side then reuses the rest of the system's).
    forcing_only: bool,
}

impl<S: OdeSystem> Variational<S> {
    /// Extends `sys` by `columns` columns of Φ (0 with a parameter: the
    /// state and its parameter sensitivity alone; more than the dimension:
    /// tangent vectors of a larger system restricted to this one's rows).
    pub fn new(sys: S, columns: usize) -> Self {
        Self::carrying(sys, columns, None, false)
    }

    /// Extends `sys` by `columns` columns of Φ and, after them, the
    /// sensitivity to a parameter p: `shifted` is the same system at
    /// `p + δp` (`dp != 0`).
    pub fn with_parameter(sys: S, columns: usize, shifted: S, dp: f64) -> Self {
        Self::carrying(sys, columns, Some((shifted, dp)), false)
    }

    /// [`with_parameter`](Self::with_parameter) for a parameter of the
    /// forcing alone (its amplitude or frequency): the shifted system's
    /// right-hand side takes the rest, contact forces included, from the
    /// system's ([`OdeSystem::rhs_reforced`]).
    pub fn with_forcing_parameter(sys: S, columns: usize, shifted: S, dp: f64) -> Self {
        Self::carrying(sys, columns, Some((shifted, dp)), true)
    }

    /// The extension, with the Jacobian and its work rows sized for the
    /// carried columns: none without any (a set of the local integrator
    /// that carries no tangent is built at every impact, and these five
    /// allocations were a quarter of building it).
    fn carrying(sys: S, columns: usize, parameter: Option<(S, f64)>, forcing_only: bool) -> Self {
        let dim = sys.dim();
        let rows = if columns > 0 || parameter.is_some() {
            dim
        } else {
            0
        };
        let jac = match sys.jacobian_bandwidth() {
            Some((kl, ku)) => BandMatrix::new(rows, kl, ku),
            None => BandMatrix::dense(rows),
        };
        Self {
            sys,
            dim,
            columns,
            jac,
            f0: vec![0.0; rows],
            f1: vec![0.0; rows],
            yp: vec![0.0; rows],
            fp: vec![0.0; rows],
            parameter,
            forcing_only,
        }
    }

    /// Number of carried columns: the Φ columns, plus one with a parameter.
    fn carried(&self) -> usize {
        self.columns + usize::from(self.parameter.is_some())
    }

    /// The wrapped system.
    pub fn system(&self) -> &S {
        &self.sys
    }

    /// The system at `p + dp` and `dp`, with a parameter column.
    pub fn shifted(&self) -> Option<(&S, f64)> {
        self.parameter.as_ref().map(|(s, dp)| (s, *dp))
    }

    /// The wrapped system, mutably.
    pub fn system_mut(&mut self) -> &mut S {
        &mut self.sys
    }

    /// Dimension of the underlying system.
    pub fn state_dim(&self) -> usize {
        self.dim
    }

    /// Number of Φ columns carried.
    pub fn columns(&self) -> usize {
        self.columns
    }

    /// Number of leading components (the state) for
    /// [`IntegratorOptions::error_components`](crate::integrate::IntegratorOptions).
    pub fn error_components(&self) -> usize {
        self.dim
    }

    /// Extended initial state `[y0, e_1, …, e_p]` (and `s(0) = 0` with a
    /// parameter).
    pub fn initial_state(&self, y0: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; self.dim * (1 + self.carried())];
        z[..self.dim].copy_from_slice(y0);
        for c in 0..self.columns.min(self.dim) {
            z[self.dim * (1 + c) + c] = 1.0;
        }
        z
    }

    /// Extended initial state `[y0, w_1, …, w_p]` with given initial columns
    /// (directional derivatives `Φ(t) w_j` instead of `Φ(t) e_j`).
    pub fn initial_state_with(&self, y0: &[f64], columns: &[&[f64]]) -> Vec<f64> {
        let mut z = vec![0.0; self.dim * (1 + self.carried())];
        z[..self.dim].copy_from_slice(y0);
        for (c, w) in columns.iter().enumerate().take(self.columns) {
            z[self.dim * (1 + c)..self.dim * (2 + c)].copy_from_slice(w);
        }
        z
    }

    /// Φ from an extended state, column-major (`dim × columns`).
    pub fn sensitivity<'a>(&self, z: &'a [f64]) -> &'a [f64] {
        &z[self.dim..self.dim * (1 + self.columns)]
    }

    /// The parameter sensitivity `∂y(t)/∂p` from an extended state, if
    /// carried.
    pub fn parameter_sensitivity<'a>(&self, z: &'a [f64]) -> Option<&'a [f64]> {
        let start = self.dim * (1 + self.columns);
        self.parameter.as_ref().map(|_| &z[start..start + self.dim])
    }

    /// Fills `self.jac` at (t, y), the point of the system's last
    /// right-hand side: analytic if the system provides it, else forward
    /// differences.
    fn jacobian_at(&mut self, t: f64, y: &[f64]) {
        self.jac.zero();
        if self.sys.jacobian_after_rhs(t, y, &mut self.jac) {
            return;
        }
        self.sys.rhs(t, y, &mut self.f0);
        self.yp.copy_from_slice(y);
        for (j, &yj) in y.iter().enumerate() {
            let h = f64::EPSILON.sqrt() * yj.abs().max(1e-5);
            self.yp[j] = yj + h;
            self.sys.rhs(t, &self.yp, &mut self.f1);
            self.yp[j] = yj;
            for i in 0..self.dim {
                if self.jac.in_band(i, j) {
                    self.jac.set(i, j, (self.f1[i] - self.f0[i]) / h);
                }
            }
        }
    }
}

impl<S: OdeSystem> OdeSystem for Variational<S> {
    fn dim(&self) -> usize {
        self.dim * (1 + self.carried())
    }

    fn rhs(&mut self, t: f64, z: &[f64], dzdt: &mut [f64]) {
        let d = self.dim;
        self.sys.rhs(t, &z[..d], &mut dzdt[..d]);
        if self.carried() == 0 {
            return;
        }
        // The shifted system reads the system's last right-hand side: before
        // a Jacobian by differences evaluates others.
        if let Some((shifted, _)) = &mut self.parameter {
            if self.forcing_only {
                shifted.rhs_reforced(&self.sys, t, &z[..d], &mut self.fp);
            } else {
                shifted.rhs(t, &z[..d], &mut self.fp);
            }
        }
        self.jacobian_at(t, &z[..d]);
        let k = self.carried();
        let columns = d..d * (1 + k);
        self.jac
            .mul_columns(&z[columns.clone()], &mut dzdt[columns], k);
        if let Some((_, dp)) = &self.parameter {
            let (f0, rest) = dzdt.split_at_mut(d);
            let column = &mut rest[d * self.columns..];
            for ((s, f1), f0) in column.iter_mut().zip(&self.fp).zip(&*f0) {
                *s += (f1 - f0) / *dp;
            }
        }
    }

    fn admissible(&self, t: f64, z: &[f64]) -> bool {
        self.sys.admissible(t, &z[..self.dim])
    }

    fn error_block(&self) -> Option<usize> {
        self.sys.error_block()
    }

    // Without carried columns the extended system is the system: its
    // Jacobian (for an implicit method) is the system's.
    fn jacobian_bandwidth(&self) -> Option<(usize, usize)> {
        if self.carried() == 0 {
            self.sys.jacobian_bandwidth()
        } else {
            None
        }
    }

    fn jacobian(&mut self, t: f64, z: &[f64], jac: &mut BandMatrix) -> bool {
        self.carried() == 0 && self.sys.jacobian(t, z, jac)
    }

    /// The system's form for the state and the same `A` for every
    /// column: Φ's columns unforced, the parameter's forced by the
    /// difference of the shifted system's harmonics and the system's over
    /// δp (where the shift leaves `A` as it is; else None).
    fn linear_form(&self) -> Option<LinearForm> {
        let form = self.sys.linear_form()?;
        let [own] = form.blocks.as_slice() else {
            return None;
        };
        let scaled = |h: &Harmonic, by: f64| Harmonic {
            omega: h.omega,
            cos: h.cos.iter().map(|x| x * by).collect(),
            sin: h.sin.iter().map(|x| x * by).collect(),
        };
        let mut blocks = vec![own.clone()];
        blocks.resize(1 + self.columns, Vec::new());
        if let Some((shifted, dp)) = &self.parameter {
            let theirs = shifted.linear_form()?;
            let [their] = theirs.blocks.as_slice() else {
                return None;
            };
            if theirs.a != form.a {
                return None;
            }
            let column = their
                .iter()
                .map(|h| scaled(h, 1.0 / dp))
                .chain(own.iter().map(|h| scaled(h, -1.0 / dp)))
                .collect();
            blocks.push(column);
        }
        Some(LinearForm { a: form.a, blocks })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::ChainDynamics;
    use crate::integrate::{integrate_to, IntegratorOptions};
    use crate::model::Model;

    use crate::model::reference::{DAMPING_RATIO as ZETA, NATURAL_FREQUENCY as W0};

    fn r2(n: usize, clearance: f64) -> Model {
        crate::model::reference::r2(n, clearance, 0.95 * W0).unwrap()
    }

    fn opts(tol: f64, error_components: Option<usize>) -> IntegratorOptions {
        IntegratorOptions {
            rtol: tol,
            atol: tol * 1e-3,
            error_components,
            ..IntegratorOptions::default()
        }
    }

    /// R3 (linear limit): Φ(T) is block diagonal with the damped
    /// oscillator's exact transition matrix exp(A T) in each block.
    #[test]
    fn linear_limit_monodromy_is_exact() {
        let model = r2(2, 1e3);
        let t = 2.0 * std::f64::consts::PI / (0.95 * W0);
        let mut var = Variational::new(ChainDynamics::new(&model, false), 4);
        let z0 = var.initial_state(&[0.0; 4]);
        let (z, _) = integrate_to(&mut var, 0.0, &z0, t, &opts(1e-12, None)).unwrap();
        let phi = var.sensitivity(&z).to_vec();
        let wd = W0 * (1.0 - ZETA * ZETA).sqrt();
        let (e, zw) = ((-ZETA * W0 * t).exp(), ZETA * W0 / wd);
        let (sn, cs) = (wd * t).sin_cos();
        let block = [
            [e * (cs + zw * sn), e * sn / wd],
            [-e * W0 * W0 * sn / wd, e * (cs - zw * sn)],
        ];
        for col in 0..4 {
            for row in 0..4 {
                let exact = if row / 2 == col / 2 {
                    block[row % 2][col % 2]
                } else {
                    0.0
                };
                let got = phi[col * 4 + row];
                assert!(
                    (got - exact).abs() < 1e-10 * W0,
                    "Φ[{row}][{col}] = {got} vs {exact}"
                );
            }
        }
    }

    /// With impacts: Φ from the variational equations equals central
    /// differences of the flow with respect to the initial state.
    #[test]
    fn monodromy_matches_finite_differences_with_impacts() {
        let model = r2(2, 1e-3);
        let t = 1.5 * 2.0 * std::f64::consts::PI / (0.95 * W0);
        // Start in motion so that impacts happen within the interval.
        let y0 = [4e-4, 0.01, -3e-4, -0.02];
        let mut var = Variational::new(ChainDynamics::new(&model, false), 4);
        let z0 = var.initial_state(&y0);
        let (z, _) = integrate_to(&mut var, 0.0, &z0, t, &opts(1e-12, Some(16 + 4))).unwrap();
        let phi = var.sensitivity(&z).to_vec();
        let mut sys = ChainDynamics::new(&model, false);
        for j in 0..4 {
            let h = if j % 2 == 0 { 1e-9 } else { 1e-8 };
            let mut yp = y0;
            yp[j] += h;
            let mut ym = y0;
            ym[j] -= h;
            let (fp, _) = integrate_to(&mut sys, 0.0, &yp, t, &opts(1e-13, None)).unwrap();
            let (fm, _) = integrate_to(&mut sys, 0.0, &ym, t, &opts(1e-13, None)).unwrap();
            let scale = (0..4).map(|i| phi[j * 4 + i].abs()).fold(1.0, f64::max);
            for i in 0..4 {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (phi[j * 4 + i] - fd).abs() < 1e-4 * scale,
                    "Φ[{i}][{j}] = {} vs {fd}",
                    phi[j * 4 + i]
                );
            }
        }
        assert!(
            sys.contact_evaluations() > 0,
            "the interval must contain impacts"
        );
    }
}
