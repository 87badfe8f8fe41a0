//! Periodic solutions by shooting and their Floquet stability (docs/theory.md §5;
//! the seed's parts I–II).
//!
//! ## Files
//! - `map.rs` — the period map and its derivatives;
//! - `rigid.rs` — the period map through rigid impacts (saltation);
//! - `shooting.rs` — dense and Newton–Krylov shooting;
//! - `floquet.rs` — Floquet multipliers;
//! - `orbit.rs` — orbits from simulation (guesses, summaries);
//! - `settling.rs` — whether a run's Poincaré samples have settled:
//!   periodic, still settling (and for how long), or irregular (the
//!   sweeps' verdict, and whether a simulated guess is worth a Newton
//!   solve);
//! - `tests/` — the checks (`rigid.rs`: through rigid impacts).
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

use nalgebra::{Complex, DMatrix};

use crate::dynamics::variational::Variational;
use crate::dynamics::{from_interleaved, interleaved_index, to_interleaved, ChainDynamics};
use crate::integrate::{
    integrate_recorded, integrate_to, IntegrationError, IntegratorOptions, Interrupt, OdeSystem,
    Recorder, TangentTape,
};
use crate::model::Model;
use crate::newton::NewtonStop;
use crate::simulate::local::LocalTape;
use crate::simulate::{local_flow, simulate, Integrator, OptionsError, SimulationOptions};

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
    /// Refuses tolerances outside [`FieldError::tolerance`](crate::field_error::FieldError::tolerance)'s range and a
    /// displacement scale that is not positive, by name.
    pub fn check(&self) -> Result<(), PeriodicError> {
        use crate::field_error::FieldError;
        let named = |e: FieldError| PeriodicError::Options(e.to_string());
        FieldError::tolerance("rtol", self.rtol).map_err(named)?;
        FieldError::tolerance("tol", self.tol).map_err(named)?;
        if !(self.displacement_scale > 0.0 && self.displacement_scale.is_finite()) {
            return Err(named(FieldError::new(
                "displacement_scale",
                self.displacement_scale,
                "must be finite and > 0",
            )));
        }
        Ok(())
    }

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
    // Hysteretic storeys: their branches and states are not in the map's
    // state (D26).
    if !model.storeys().is_empty() {
        return Err("hysteretic storeys: their history is not part of the period map's state: no shooting, continuation or Lyapunov exponents with them (simulations and pounding runs are fine)".into());
    }
    match (0..model.contacts().len()).find(|&k| model.contacts()[k].law.needs_impact_velocity()) {
        Some(k) => Err(format!(
            "contact {}: its law needs the impact's onset velocity, whose dependence on the state the period map and its derivatives do not carry yet: no shooting, continuation or Lyapunov exponents with it (simulations, sweeps and pounding runs are fine)",
            model.contact_name(k)
        )),
        None => Ok(()),
    }
}

mod floquet;
mod map;
mod orbit;
mod rigid;
pub mod settling;
mod shooting;

pub(crate) use floquet::multipliers_of_map;
pub use floquet::{floquet_multipliers, map_multipliers};
pub use map::period_map;
pub(crate) use map::{map_and_product, map_image, period_map_with, MapTangent};
pub(crate) use orbit::settled_guess;
pub use orbit::{
    guess_by_simulation, guess_by_simulation_with, orbit_summary, orbit_summary_by, ContactImpacts,
    OrbitSummary,
};
pub(crate) use rigid::{rigid_impacts_over, saltation};

pub(crate) use shooting::shoot_orbit;
pub use shooting::{shoot, shoot_krylov};

#[cfg(test)]
mod tests;
