//! Lyapunov exponents of a periodically forced system (docs/theory.md §7):
//! the state integrated with k tangent vectors (the variational equations
//! of [`Variational`], valid through soft impacts because the contact laws
//! are smooth; through rigid impacts the vectors jump by each impact's
//! saltation matrix, §12), re-orthonormalised by a QR factorisation at the
//! end of every forcing period (Benettin, Galgani, Giorgilli and Strelcyn
//! 1980). The exponents are the time averages of `ln R_ii`, largest
//! first.
//!
//! Files: `mod.rs` (the exponents), `tests.rs` (against independent
//! computations).
//!
//! The inner product of the QR step weighs a displacement by the body's
//! natural frequency (`ω_i u_i` against `v_i`, an energy norm): a lightly
//! damped free oscillation then turns its tangent vectors almost without
//! stretching them, so that the exponents of a complex pair of
//! multipliers (equal moduli) converge with an error ~ ζ / t instead of ~ 1
//! / t. The uncertainty of each exponent is its standard error by batch
//! means: the window cut into [`BATCHES`] batches of consecutive periods
//! (fewer, of 10 periods at least, in a short window),
//! the standard deviation of the batches' exponents divided by
//! √batches. It estimates the scatter that repeated runs show (the
//! running average's settling, used before, understated it by about half
//! on a chaotic attractor).
//!
//! The tangent vectors enter the step-size control with the state: the
//! exponents come from them, and during an impact of the seed's stiff
//! exponential law a step accurate for the state alone leaves them
//! inaccurate (R2 N = 2: the spectrum's sum off Liouville's value by
//! 4e-6 relative with the state alone at rtol 1e-9, 1e-7 with them).

use thiserror::Error;

use crate::dynamics::variational::Variational;
use crate::dynamics::{from_interleaved, to_interleaved, ChainDynamics};
use crate::integrate::{Dop853, IntegrationError, IntegratorOptions, Interrupt, OdeSystem};
use crate::model::Model;
use crate::periodic::forcing_period;
use crate::simulate::{local_flow, Integrator, SimulationOptions};

/// Batches of the standard error (fewer for windows under 200 periods).
/// Batches of one chaotic run are close to independent when each is many
/// correlation times long.
pub const BATCHES: usize = 20;

/// Shortest batch (periods; two batches at least). On R2 N = 2 at 0.8409
/// ω0 batches of 10 and of 20 periods stated the same error (0.049 and
/// 0.047 over 200 periods).
const MIN_BATCH_PERIODS: usize = 10;

/// Options of [`lyapunov_spectrum`].
#[derive(Clone, Debug)]
pub struct LyapunovOptions {
    /// Number of exponents, the largest ones (`1..=2N`); `None`: the full
    /// spectrum.
    pub count: Option<usize>,
    /// Forcing periods before averaging, during which the state approaches
    /// the attractor and the tangent vectors align with the most expanding
    /// directions (≥ 0).
    pub transient: usize,
    /// Forcing periods of the average (≥ 2).
    pub periods: usize,
    /// Relative tolerance of the integration of the state and the tangent
    /// vectors; the absolute one is `rtol` × 1e-3 (a 1 mm displacement).
    pub rtol: f64,
    /// Cooperative interruption (Ctrl-C).
    pub interrupt: Option<Interrupt>,
    /// Global: the state and tangents integrated together; local: the
    /// tangents carried by the exact transition matrices of the free
    /// motion and integrated in the active set only (docs/theory.md §10).
    pub integrator: Integrator,
}

impl Default for LyapunovOptions {
    fn default() -> Self {
        Self {
            count: None,
            transient: 20,
            periods: 200,
            rtol: 1e-9,
            interrupt: None,
            integrator: Integrator::Auto,
        }
    }
}

/// Lyapunov exponents and how far they have converged.
#[derive(Clone, Debug, PartialEq)]
pub struct LyapunovSpectrum {
    /// The exponents (1/s), largest first.
    pub exponents: Vec<f64>,
    /// Standard error of each exponent (1/s), by batch means over the
    /// window ([`BATCHES`] batches).
    pub uncertainty: Vec<f64>,
    /// Length of the averaging window (s).
    pub averaging_time: f64,
    /// The forcing period (s).
    pub period: f64,
    /// The state at the end (body order `[u.., v..]`), at time
    /// `t0 + (transient + periods) T`.
    pub final_state: Vec<f64>,
}

/// Why the exponents could not be computed.
#[derive(Debug, Error)]
pub enum LyapunovError {
    /// Options or state out of range.
    #[error("{0}")]
    Invalid(String),
    /// The integration failed (time and state in the source).
    #[error("integrating the tangent vectors: {0}")]
    Integration(#[from] IntegrationError),
    /// The tangent vectors became linearly dependent to machine precision
    /// or overflowed (a contraction or expansion beyond f64 within one
    /// period).
    #[error("at t = {t}: the tangent vectors degenerated within one forcing period (column {column} has norm {norm:e})")]
    Degenerate {
        /// Time (s).
        t: f64,
        /// Index of the column.
        column: usize,
        /// Its norm after orthogonalisation.
        norm: f64,
    },
}

/// The `count` largest Lyapunov exponents (or all) of `model` from the
/// state `x0` (body order `[u.., v..]`) at time `t0`, by QR
/// re-orthonormalisation once per forcing period. Needs a periodic forcing
/// (harmonic base or harmonic forces of one frequency).
pub fn lyapunov_spectrum(
    model: &Model,
    x0: &[f64],
    t0: f64,
    opts: &LyapunovOptions,
) -> Result<LyapunovSpectrum, LyapunovError> {
    let invalid = |m: String| Err(LyapunovError::Invalid(m));
    if let Err(m) = crate::periodic::refuse_onset_laws(model) {
        return invalid(m);
    }
    let n = model.bodies().len();
    let d = 2 * n;
    if x0.len() != d {
        return invalid(format!(
            "initial state: needs {d} values (u then v), got {}",
            x0.len()
        ));
    }
    if x0.iter().any(|v| !v.is_finite()) || !t0.is_finite() {
        return invalid("initial state and time must be finite".into());
    }
    let k = opts.count.unwrap_or(d);
    if k == 0 || k > d {
        return invalid(format!(
            "count = {k}: between 1 and the state dimension {d}"
        ));
    }
    if opts.periods < 2 {
        return invalid(format!("periods = {}: at least 2", opts.periods));
    }
    if let Err(e) = crate::field_error::FieldError::tolerance("rtol", opts.rtol) {
        return invalid(e.to_string());
    }
    let period = forcing_period(model).map_err(|e| LyapunovError::Invalid(e.to_string()))?;
    let weights = energy_weights(model);
    let mut var = Variational::new(ChainDynamics::new(model, false), k);
    // Initial tangent vectors: generic (no symmetry of the row, which
    // would keep them in an invariant subspace), orthonormal.
    let mut z = var.initial_state(&to_interleaved(x0));
    for (i, v) in z[d..].iter_mut().enumerate() {
        *v = 1.0 + ((i * 7919 + 13) % 101) as f64 / 101.0;
    }
    orthonormalise(&mut z[d..], d, k, &weights, t0)?;
    let int_opts = IntegratorOptions {
        rtol: opts.rtol,
        // Displacements of ~1 mm (the seed's gaps) to rtol.
        atol: opts.rtol * 1e-3,
        error_components: None,
        interrupt: opts.interrupt.clone(),
        ..IntegratorOptions::default()
    };
    let delayed = || {
        model.delayed(t0).ok_or_else(|| {
            LyapunovError::Invalid("a recorded excitation has no forcing period".into())
        })
    };
    let mut flow = match opts.integrator.resolve(model) {
        // Rigid impacts: the events' flow, a period at a time from the
        // same phase (auto resolves to global).
        Integrator::Global | Integrator::Auto if model.has_rigid_impacts() => Flow::Rigid {
            var: Variational::new(ChainDynamics::new(&delayed()?, false), k),
            period,
            options: int_opts,
        },
        // (`resolve` gives global or local.)
        Integrator::Global | Integrator::Auto => {
            let mut solver = Dop853::new(var.dim(), int_opts)?;
            solver.reset(&mut var, t0, &z)?;
            Flow::Global {
                var,
                solver,
                fresh: true,
            }
        }
        Integrator::Local => {
            // Each period is a run of its own.
            Flow::Local {
                model: delayed()?,
                options: SimulationOptions {
                    t_end: period,
                    rtol: opts.rtol,
                    atol: opts.rtol * 1e-3,
                    interrupt: opts.interrupt.clone(),
                    integrator: Integrator::Local,
                    ..SimulationOptions::default()
                },
                k,
            }
        }
    };
    let total = opts.transient + opts.periods;
    let batches = (opts.periods / MIN_BATCH_PERIODS).clamp(2, BATCHES);
    // Per batch: the sum of each column's logs, and its periods.
    let mut batch_sums = vec![0.0; batches * k];
    let mut batch_periods = vec![0usize; batches];
    for j in 1..=total {
        let t_end = t0 + period * j as f64;
        flow.advance(t_end, &mut z)?;
        let logs = orthonormalise(&mut z[d..], d, k, &weights, t_end)?;
        let averaged = j.saturating_sub(opts.transient);
        if averaged > 0 {
            let b = (averaged - 1) * batches / opts.periods;
            batch_periods[b] += 1;
            for (s, l) in batch_sums[b * k..(b + 1) * k].iter_mut().zip(&logs) {
                *s += l;
            }
        }
    }
    let window = period * opts.periods as f64;
    let mut pairs: Vec<(f64, f64)> = (0..k)
        .map(|c| {
            let batch = |b: usize| batch_sums[b * k + c] / (period * batch_periods[b] as f64);
            let l = (0..batches).map(|b| batch_sums[b * k + c]).sum::<f64>() / window;
            let mean = (0..batches).map(batch).sum::<f64>() / batches as f64;
            let var = (0..batches).map(|b| (batch(b) - mean).powi(2)).sum::<f64>()
                / (batches * (batches - 1)) as f64;
            (l, var.sqrt())
        })
        .collect();
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0));
    Ok(LyapunovSpectrum {
        exponents: pairs.iter().map(|p| p.0).collect(),
        uncertainty: pairs.iter().map(|p| p.1).collect(),
        averaging_time: window,
        period,
        final_state: from_interleaved(&z[..d], n),
    })
}

/// How the state and its tangent columns `z = [y, w_1, …, w_k]` advance
/// by one forcing period. (One lives per spectrum: the size difference of
/// the variants does not matter.)
#[allow(clippy::large_enum_variant)]
enum Flow {
    /// The variational equations integrated with the state.
    Global {
        var: Variational<ChainDynamics>,
        solver: Dop853,
        /// Reset at the start: no restart before the first period.
        fresh: bool,
    },
    /// Through rigid impacts: the events' flow of the model delayed to the
    /// start (each period from the same phase), the tangent vectors
    /// multiplied by each impact's saltation.
    Rigid {
        var: Variational<ChainDynamics>,
        period: f64,
        options: IntegratorOptions,
    },
    /// The local integrator's flow with tangents, of the model delayed to
    /// the start (each period starts at the same phase).
    Local {
        model: Model,
        options: SimulationOptions,
        k: usize,
    },
}

impl Flow {
    /// `z` (its columns re-orthonormalised since the last call) carried to
    /// `t_end`, one period on.
    fn advance(&mut self, t_end: f64, z: &mut [f64]) -> Result<(), LyapunovError> {
        match self {
            Flow::Global { var, solver, fresh } => {
                if !*fresh {
                    solver.restart(var, z)?;
                }
                *fresh = false;
                while solver.t() < t_end {
                    solver.step(var, t_end)?;
                }
                z.copy_from_slice(solver.y());
            }
            Flow::Rigid {
                var,
                period,
                options,
            } => {
                let (end, _, _) = crate::simulate::flow_through_events(
                    var,
                    z,
                    *period,
                    options,
                    crate::periodic::saltation,
                )?;
                z.copy_from_slice(&end);
            }
            Flow::Local { model, options, k } => {
                let d = 2 * model.bodies().len();
                let flow = local_flow(model, options, &z[..d], (&z[d..], *k), false)
                    .map_err(|e| LyapunovError::Invalid(e.to_string()))??;
                z[..d].copy_from_slice(&flow.y);
                z[d..].copy_from_slice(&flow.columns);
            }
        }
        Ok(())
    }
}

/// Weights of the interleaved state components in the QR inner product:
/// `ω_i` for a displacement (the natural frequency of the body on its
/// spring, the forcing frequency for a free body), 1 for a velocity.
fn energy_weights(model: &Model) -> Vec<f64> {
    let forcing = model.forcing_frequency().unwrap_or(1.0);
    model
        .bodies()
        .iter()
        .flat_map(|b| {
            let omega = if b.stiffness > 0.0 {
                (b.stiffness / b.mass).sqrt()
            } else {
                forcing
            };
            [omega, 1.0]
        })
        .collect()
}

/// Modified Gram–Schmidt (twice) of the k columns of `cols` (column-major,
/// `d × k`, interleaved components) in the inner product weighted by
/// `weights`; returns `ln R_ii` and leaves the orthonormal columns.
fn orthonormalise(
    cols: &mut [f64],
    d: usize,
    k: usize,
    weights: &[f64],
    t: f64,
) -> Result<Vec<f64>, LyapunovError> {
    // Work in weighted coordinates.
    for c in 0..k {
        cols[c * d..(c + 1) * d]
            .iter_mut()
            .zip(weights)
            .for_each(|(v, w)| *v *= w);
    }
    let mut logs = Vec::with_capacity(k);
    for c in 0..k {
        let (done, rest) = cols.split_at_mut(c * d);
        let col = &mut rest[..d];
        for _ in 0..2 {
            for q in done.chunks_exact(d) {
                let r: f64 = q.iter().zip(col.iter()).map(|(a, b)| a * b).sum();
                col.iter_mut().zip(q).for_each(|(v, a)| *v -= r * a);
            }
        }
        let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > f64::MIN_POSITIVE * 1e10) {
            return Err(LyapunovError::Degenerate { t, column: c, norm });
        }
        col.iter_mut().for_each(|v| *v /= norm);
        logs.push(norm.ln());
    }
    for c in 0..k {
        cols[c * d..(c + 1) * d]
            .iter_mut()
            .zip(weights)
            .for_each(|(v, w)| *v /= w);
    }
    Ok(logs)
}

#[cfg(test)]
mod tests;
