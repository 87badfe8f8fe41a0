//! Periodic solutions by shooting and their Floquet stability (docs/theory.md §5;
//! the seed's parts I–II).
//!
//! Under forcing of period `T = 2π/Ω`, a periodic solution of period `nT`
//! (n = 1 harmonic, n > 1 subharmonic) is a fixed point of the period map
//! `P(x) = φ(nT; x)` (forcing phase 0 at t = 0). Newton's method on
//! `G(x) = P(x) - x` uses the monodromy matrix `Φ = ∂P/∂x` from the
//! variational equations integrated with the orbit ([`Variational`]), not
//! finite differences:
//!
//! ```text
//! (Φ(x_k) - I) Δ = -(P(x_k) - x_k),   x_{k+1} = x_k + λ Δ
//! ```
//!
//! with a backtracking λ ∈ {1, ½, ¼, …} when the residual does not decrease.
//! Convergence: `‖P(x) - x‖ <= tol` in the scaled max norm (displacements
//! over the displacement scale, velocities over the velocity scale; see
//! [`ShootingOptions`]). The Floquet multipliers are the eigenvalues of
//! `Φ(nT)` at the solution (Schur decomposition); the orbit is
//! asymptotically stable when all have modulus < 1.
//!
//! States are in body order, `[u_1..u_N, v_1..v_N]`; Φ is returned in the
//! same order (the integration itself uses the interleaved layout of
//! [`ChainDynamics`]).

use std::convert::Infallible;

use nalgebra::{Complex, DMatrix, DVector};

use crate::dynamics::{from_interleaved, interleaved_index, to_interleaved, ChainDynamics};
use crate::integrate::{
    integrate_recorded, integrate_to, IntegrationError, IntegratorOptions, Interrupt, OdeSystem,
    Recorder, TangentTape,
};
use crate::model::Model;
use crate::newton::{damped_newton, NewtonOptions, NewtonStop, NewtonSystem};
use crate::simulate::local::LocalTape;
use crate::simulate::{local_flow, simulate, Integrator, OptionsError, SimulationOptions};
use crate::variational::Variational;

/// Largest Newton step in the scaled norm (displacement scales).
const TRUST: f64 = 0.5;
/// The fewest Arnoldi vectors behind a stability verdict of Newton–Krylov
/// shooting (R2 N = 2 with one vector: "stable, 0.887" for an orbit whose
/// largest multiplier is 1.274).
pub const MIN_ARNOLDI: usize = 8;

/// The tightest tolerance of the monodromy behind reported multipliers.
pub(crate) const MULTIPLIER_RTOL: f64 = 1e-13;

/// The largest state dimension (2N) of a dense period map: its variational
/// equations hold 2N × 2N values (about 5 GB of integrator work space at
/// this size); larger rows are refused up front in favour of Newton–Krylov.
pub const MAX_DENSE_DIM: usize = 4096;

/// Step budget of one period-map integration.
pub(crate) const MAX_STEPS: u64 = 200_000;

/// Options of the shooting method.
#[derive(Clone, Debug, PartialEq)]
pub struct ShootingOptions {
    /// Period multiple n (1 harmonic, 2 period-doubled, …).
    pub subharmonic: u32,
    /// Integration tolerance (relative; absolute = rtol × scale).
    pub rtol: f64,
    /// Newton tolerance on the scaled residual.
    pub tol: f64,
    /// Newton iterations at most.
    pub max_iterations: usize,
    /// Displacement scale (m) of the scaled norm; velocity scale = this × Ω.
    pub displacement_scale: f64,
    /// Shoot on the half map `G = S ∘ P_{nT/2}` (S the mirror image, see
    /// [`mirror`]) instead of the period map: its fixed points are the
    /// symmetric orbits, `x(t + nT/2) = S x(t)`, of a mirror-symmetric model
    /// ([`Model::is_mirror_symmetric`], n odd). Half the integration, and
    /// the Floquet multipliers are the squares of the eigenvalues of `DG`
    /// (`Φ = (DG)²`): an eigenvalue -1 of `DG` is a symmetry-breaking
    /// pitchfork of the full system.
    pub symmetric: bool,
    /// Whether the columns of Φ enter the step-size control with the state.
    /// Without (the default, and what Newton iterations need), Φ rides on
    /// the state's steps and its error under the seed's stiff contact law
    /// can exceed the tolerance by orders (R2 N = 1 near a cusp: 1e-6 in a
    /// multiplier at rtol 1e-12); with it, Φ is accurate to the tolerance,
    /// at more steps.
    pub control_monodromy: bool,
    /// Stop request checked at every integration step (see [`Interrupt`]).
    pub interrupt: Option<Interrupt>,
    /// The period map's integrator: global, or local (docs/theory.md §10:
    /// the state by the exact free motion between contacts, integrated
    /// only where bodies touch). Dense, Φ's columns ride along and enter
    /// the step control, as with `control_monodromy`; matrix-free, the
    /// products with Φ and a forcing parameter's column are replayed on
    /// the run's tape. A parameter beyond the forcing needs the global
    /// integrator.
    pub integrator: Integrator,
}

impl ShootingOptions {
    /// The integrator's options for a period map: these tolerances, at most
    /// `max_steps` steps, the stop request; with `state` = Some(d) carried
    /// columns (variational, tangent) ride along on the steps of the first
    /// d components (the state) unless `control_monodromy`.
    pub(crate) fn integrator_options(
        &self,
        max_steps: u64,
        state: Option<usize>,
    ) -> IntegratorOptions {
        IntegratorOptions {
            rtol: self.rtol,
            atol: self.rtol * self.displacement_scale,
            max_steps,
            error_components: state.filter(|_| !self.control_monodromy),
            interrupt: self.interrupt.clone(),
            ..IntegratorOptions::default()
        }
    }
}

impl Default for ShootingOptions {
    fn default() -> Self {
        Self {
            subharmonic: 1,
            rtol: 1e-10,
            tol: 1e-9,
            max_iterations: 30,
            displacement_scale: 1e-3,
            symmetric: false,
            control_monodromy: false,
            interrupt: None,
            integrator: Integrator::Auto,
        }
    }
}

/// Why shooting could not run.
#[derive(Debug, Clone, thiserror::Error)]
pub enum PeriodicError {
    /// The model has no single periodic forcing.
    #[error("the model has no periodic forcing with one frequency (harmonic base or harmonic forces), so it has no periodic solutions of a forcing period")]
    NoPeriodicForcing,
    /// The start state has the wrong size.
    #[error("initial state: needs {expected} values (u then v), got {got}")]
    BadState {
        /// Values expected.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// The integration of the period map failed.
    #[error("integrating the period map from the state at Newton iteration {iteration}: {source}")]
    Integration {
        /// Newton iteration.
        iteration: usize,
        /// The integrator's error.
        #[source]
        source: IntegrationError,
    },
    /// Invalid options.
    #[error("{0}")]
    Options(String),
    /// The eigenvalue (Schur) iteration did not converge.
    #[error("the Floquet multipliers: the Schur iteration on the {0}x{0} monodromy matrix does not converge (even with shifted spectra)")]
    Eigenvalues(usize),
}

/// The period map and its Jacobian at one state.
#[derive(Clone, Debug)]
pub struct PeriodMap {
    /// `P(x)` (or `S P_{nT/2}(x)` for the symmetric half map), body order.
    pub image: Vec<f64>,
    /// Its Jacobian: the monodromy `Φ = ∂P/∂x` (or `DG = S Φ_{1/2}`, whose
    /// square is Φ, for the half map), body order.
    pub monodromy: DMatrix<f64>,
}

/// Result of shooting.
#[derive(Clone, Debug)]
pub struct PeriodicSolution {
    /// Whether Newton converged.
    pub converged: bool,
    /// Why Newton ended ([`NewtonStop::explanation`] says what to do).
    pub stop: NewtonStop,
    /// Period nT (s).
    pub period: f64,
    /// The state at t = 0 (body order); the last iterate if not converged.
    pub initial_state: Vec<f64>,
    /// Scaled residual ‖P(x) - x‖ of every iterate.
    pub residual_history: Vec<f64>,
    /// Monodromy matrix at the solution (body order).
    pub monodromy: DMatrix<f64>,
    /// Floquet multipliers, largest modulus first.
    pub multipliers: Vec<Complex<f64>>,
}

impl PeriodicSolution {
    /// Largest |multiplier|.
    pub fn spectral_radius(&self) -> f64 {
        self.multipliers.first().map_or(0.0, |m| m.norm())
    }
    /// Asymptotically stable: every multiplier inside the unit circle.
    pub fn stable(&self) -> bool {
        self.spectral_radius() < 1.0
    }
}

/// Forcing period T of the model (error if not periodically forced).
pub fn forcing_period(model: &Model) -> Result<f64, PeriodicError> {
    model
        .forcing_frequency()
        .map(|w| 2.0 * std::f64::consts::PI / w)
        .ok_or(PeriodicError::NoPeriodicForcing)
}

/// Scales of the scaled norm: displacement scale for u, × Ω for v.
fn scales(model: &Model, opts: &ShootingOptions) -> Vec<f64> {
    let n = model.bodies().len();
    let w = model.forcing_frequency().unwrap_or(1.0);
    (0..2 * n)
        .map(|i| {
            if i < n {
                opts.displacement_scale
            } else {
                opts.displacement_scale * w
            }
        })
        .collect()
}

/// Index of the mirror image of state component `k` (body order, N bodies):
/// `u_i ↔ u_{N-1-i}`, `v_i ↔ v_{N-1-i}`.
fn mirror_index(k: usize, n: usize) -> usize {
    if k < n {
        n - 1 - k
    } else {
        3 * n - 1 - k
    }
}

/// The mirror image `S x` of a state (body order):
/// `(u_i, v_i) → (-u_{N-1-i}, -v_{N-1-i})`.
pub fn mirror(x: &[f64]) -> Vec<f64> {
    let n = x.len() / 2;
    (0..x.len()).map(|k| -x[mirror_index(k, n)]).collect()
}

/// Time over which the shooting map integrates: nT, or nT/2 for the
/// symmetric half map. Checks that the half map applies to `model`.
pub(crate) fn map_time(model: &Model, opts: &ShootingOptions) -> Result<f64, PeriodicError> {
    refuse_onset_laws(model).map_err(PeriodicError::Options)?;
    let n = opts.subharmonic.max(1);
    let period = forcing_period(model)? * f64::from(n);
    if !opts.symmetric {
        return Ok(period);
    }
    if n % 2 == 0 || !model.is_mirror_symmetric() {
        return Err(PeriodicError::Options(format!(
            "the symmetric half map needs a mirror-symmetric model and an odd period multiple (got n = {n}{})",
            if model.is_mirror_symmetric() { "" } else { ", and the model is not mirror-symmetric" }
        )));
    }
    Ok(0.5 * period)
}

/// A contact law whose force depends on the impact's onset velocity
/// (Lankarani–Nikravesh) is refused by the period maps, their derivatives
/// and the Lyapunov exponents, by contact name: the global integrator's
/// maps held the onset velocity at the law's floor (a shot orbit of R2
/// N = 2 came back 3.2 mm off in a simulated period), the local
/// integrator's track it but their derivatives miss its dependence on the
/// state (Newton stalls at 0.04); docs/decisions.md D24.
pub(crate) fn refuse_onset_laws(model: &Model) -> Result<(), String> {
    match (0..model.contacts().len()).find(|&k| model.contacts()[k].law.needs_impact_velocity()) {
        Some(k) => Err(format!(
            "contact {}: its law needs the impact's onset velocity, whose dependence on the state the period map and its derivatives do not carry yet: no shooting, continuation or Lyapunov exponents with it (simulations, sweeps and pounding runs are fine)",
            model.contact_name(k)
        )),
        None => Ok(()),
    }
}

/// Floquet multipliers from the Jacobian of the shooting map: its
/// eigenvalues, squared for the symmetric half map (largest modulus first).
pub fn map_multipliers(
    jacobian: &DMatrix<f64>,
    symmetric: bool,
) -> Result<Vec<Complex<f64>>, PeriodicError> {
    Ok(multipliers_of_map(
        floquet_multipliers(jacobian)?,
        symmetric,
    ))
}

/// The Floquet multipliers from the eigenvalues of the shooting map's
/// Jacobian: squared for the half map (Φ = DG²), largest modulus first.
pub(crate) fn multipliers_of_map(
    mut eigenvalues: Vec<Complex<f64>>,
    symmetric: bool,
) -> Vec<Complex<f64>> {
    if symmetric {
        eigenvalues.iter_mut().for_each(|m| *m = *m * *m);
        eigenvalues.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    }
    eigenvalues
}

/// Floquet multipliers (eigenvalues of the monodromy), largest modulus first.
///
/// The Francis (Schur) iteration is bounded: nalgebra's unbounded version
/// cycles forever on some spectra, e.g. the half map of a linear symmetric
/// row, whose eigenvalues come in ± pairs of equal modulus. Without
/// convergence the spectrum is shifted by a fraction of the matrix's size
/// (M + cI has eigenvalues λ + c, a pattern the iteration does not stall
/// on) and shifted back, which costs at most ~ε|c| in accuracy. Each
/// shift is first tried with 10 iterations per eigenvalue (a converging
/// iteration needs 2–3), then all again with 200: a stall would otherwise
/// burn the large budget before the shift (R2 N = 8 on the half map: 40 %
/// of the spectra stall unshifted, 3 ms each with 200 per eigenvalue,
/// against 20 µs for the shifted solve).
pub fn floquet_multipliers(monodromy: &DMatrix<f64>) -> Result<Vec<Complex<f64>>, PeriodicError> {
    let d = monodromy.nrows();
    let size = monodromy.amax().max(f64::MIN_POSITIVE);
    let attempts = [10, 200]
        .into_iter()
        .flat_map(|per| [0.0, 0.3, -0.55].map(|shift| (shift, per * d.max(10))));
    for (shift, budget) in attempts {
        let c = shift * size;
        let m = monodromy + DMatrix::<f64>::identity(d, d) * c;
        if let Some(schur) = nalgebra::linalg::Schur::try_new(m, f64::EPSILON, budget) {
            let mut mu: Vec<Complex<f64>> =
                schur.complex_eigenvalues().iter().map(|l| l - c).collect();
            mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
            return Ok(mu);
        }
    }
    // nalgebra's iteration stalls on some spectra of clustered ± pairs:
    // the EISPACK algorithm (crate::eigen) instead.
    let mut mu = crate::eigen::eigenvalues(monodromy).ok_or(PeriodicError::Eigenvalues(d))?;
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()).then(b.im.total_cmp(&a.im)));
    Ok(mu)
}

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

impl NewtonSystem for DenseShooting<'_> {
    /// The period map and the residual `P(x) − x` (unscaled).
    type Point = (PeriodMap, Vec<f64>);
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
        let tangent = self.tangent_at(x)?;
        let mut apply =
            |v: &[f64]| -> Result<_, Infallible> { Ok(tangent.shifted_scaled(v, scale, 1.0)) };
        let Ok((delta, _, _)) = gmres(&mut apply, &b, 60, 1e-3, noise);
        Ok(Some(
            delta.iter().zip(self.scale).map(|(d, s)| d * s).collect(),
        ))
    }

    fn step_norm(&self, delta: &[f64]) -> f64 {
        scaled_norm(delta, self.scale)
    }
}

/// Finds a periodic solution of period nT near `guess` (body order) by
/// Newton's method on the period map.
pub fn shoot(
    model: &Model,
    guess: &[f64],
    opts: &ShootingOptions,
) -> Result<PeriodicSolution, PeriodicError> {
    let period = forcing_period(model)? * f64::from(opts.subharmonic.max(1));
    map_time(model, opts)?;
    let d = 2 * model.bodies().len();
    if guess.len() != d {
        return Err(PeriodicError::BadState {
            expected: d,
            got: guess.len(),
        });
    }
    if !(opts.rtol > 0.0 && opts.tol > 0.0 && opts.displacement_scale > 0.0) {
        return Err(PeriodicError::Options(
            "shooting: rtol, tol and displacement scale must be > 0".into(),
        ));
    }
    let mut sys = DenseShooting {
        model,
        opts,
        scale: scales(model, opts),
        iteration: 0,
    };
    let out = damped_newton(&mut sys, guess, &newton_options(opts))?;
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

/// `(G(x), DG v)` (the map and a product with its Jacobian) by one
/// integration of the state with one tangent column (by the options'
/// integrator), body order.
pub(crate) fn map_and_product(
    model: &Model,
    x: &[f64],
    v: &[f64],
    opts: &ShootingOptions,
) -> Result<(Vec<f64>, Vec<f64>), IntegrationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    let t = map_time(model, opts).map_err(|e| IntegrationError::InvalidOptions(e.to_string()))?;
    let (y, w) = if opts.integrator.resolve(model) == Integrator::Local {
        let sim_opts = map::local_options(opts, t, MAX_STEPS);
        let column = to_interleaved(v);
        let flow = local_flow(model, &sim_opts, &to_interleaved(x), (&column, 1), false)
            .map_err(|e| IntegrationError::InvalidOptions(e.to_string()))??;
        (flow.y, flow.columns)
    } else {
        let mut var = Variational::new(ChainDynamics::new(model, false), 1);
        let z0 = var.initial_state_with(&to_interleaved(x), &[&to_interleaved(v)]);
        let int_opts = opts.integrator_options(MAX_STEPS, Some(d));
        let (mut z, _) = integrate_to(&mut var, 0.0, &z0, t, &int_opts)?;
        let w = z.split_off(d);
        (z, w)
    };
    let (image, product) = (from_interleaved(&y, n), from_interleaved(&w, n));
    if opts.symmetric {
        return Ok((mirror(&image), mirror(&product)));
    }
    Ok((image, product))
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
    let period = forcing_period(model)? * f64::from(opts.subharmonic.max(1));
    map_time(model, opts)?;
    let d = 2 * model.bodies().len();
    if guess.len() != d {
        return Err(PeriodicError::BadState {
            expected: d,
            got: guess.len(),
        });
    }
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
    let tangent = sys.tangent_at(&x)?;
    let mut apply =
        |v: &[f64]| -> Result<_, Infallible> { Ok(tangent.shifted_scaled(v, &scale, 1.0)) };
    let Ok(ritz) = arnoldi_matrix(&mut apply, d, arnoldi, noise);
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

#[path = "periodic_krylov.rs"]
mod krylov;
#[path = "periodic_map.rs"]
mod map;
#[path = "periodic_orbit.rs"]
mod orbit;

pub(crate) use krylov::{arnoldi_matrix, gmres};
pub use map::period_map;
pub(crate) use map::{map_image, period_map_with, MapTangent};
pub use orbit::{
    guess_by_simulation, guess_by_simulation_with, orbit_summary, orbit_summary_by, ContactImpacts,
    OrbitSummary,
};

#[cfg(test)]
#[path = "periodic_tests.rs"]
mod tests;
