//! The shooting map and its derivatives (docs/theory.md §5): the period
//! (or half) map, its dense Jacobian, the parameter's column, and products
//! replayed on the integration's tape; by the global integrator, or the
//! dense map by the local one (§10).

use super::rigid::{rigid_image, rigid_map, rigid_product};
use super::*;

/// Evaluates the shooting map (the period map, or the symmetric half map
/// with `opts.symmetric`) and its Jacobian at `x` (body order).
pub fn period_map(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
) -> Result<PeriodMap, IntegrationError> {
    period_map_with(model, x, opts, None, true, MAX_STEPS).map(|m| m.map)
}

/// What [`period_map_with`] computes besides the map.
pub(crate) struct MapDerivatives {
    /// The map and, dense, its Jacobian (0 × 0 otherwise).
    pub(crate) map: PeriodMap,
    /// `∂P/∂p`, with a shifted model.
    pub(crate) dp_column: Option<Vec<f64>>,
    /// Integration steps taken.
    pub(crate) steps: u64,
    /// Without the dense Jacobian: products with it, replayed on the
    /// integration's own steps.
    pub(crate) tangent: Option<MapTangent>,
}

/// Products with the shooting map's Jacobian (Φ, or DG = S Φ_{1/2} for the
/// half map) replayed on the steps of the integration that computed the
/// map (`integrate::tangent`): the same numbers, to rounding, as one
/// integration of the state with the column, without integrating.
#[derive(Clone, Debug)]
pub(crate) struct MapTangent {
    pub(super) tape: Tape,
    pub(super) n: usize,
    pub(super) symmetric: bool,
}

/// The record of the integration that computed a map: the global
/// integrator's steps, or the local integrator's sets and exact motion;
/// through rigid impacts, the dense Φ itself (interleaved, column-major).
#[derive(Clone, Debug)]
pub(crate) enum Tape {
    Global(Box<TangentTape<ChainDynamics>>),
    Local(Box<LocalTape>),
    Dense(Vec<f64>),
}

impl Tape {
    /// `Φ v`, interleaved.
    fn apply(&self, v: &[f64]) -> Vec<f64> {
        match self {
            Tape::Global(tape) => tape.apply(v),
            Tape::Local(tape) => tape.apply(v),
            Tape::Dense(phi) => {
                let mut w = vec![0.0; v.len()];
                for (column, vc) in phi.chunks_exact(v.len()).zip(v) {
                    w.iter_mut().zip(column).for_each(|(a, p)| *a += p * vc);
                }
                w
            }
        }
    }

    /// Contact Jacobian entries recorded.
    #[cfg(test)]
    pub(crate) fn entries(&self) -> usize {
        match self {
            Tape::Global(tape) => tape.entries(),
            Tape::Local(tape) => tape.entries(),
            Tape::Dense(_) => 0,
        }
    }
}

impl MapTangent {
    /// `Φ v` (or `DG v`), body order.
    pub(crate) fn product(&self, v: &[f64]) -> Vec<f64> {
        let w = from_interleaved(&self.tape.apply(&to_interleaved(v)), self.n);
        if self.symmetric {
            mirror(&w)
        } else {
            w
        }
    }

    /// `Φ v` in scaled variables: `v` in units of `scale · unit`, the
    /// product in units of `scale`, i.e. `Φ (s u v) / s`.
    pub(crate) fn scaled_product(&self, v: &[f64], scale: &[f64], unit: f64) -> Vec<f64> {
        let unscaled: Vec<f64> = v.iter().zip(scale).map(|(a, s)| a * s * unit).collect();
        let mut phi_v = self.product(&unscaled);
        phi_v.iter_mut().zip(scale).for_each(|(a, s)| *a /= s);
        phi_v
    }

    /// `(Φ − I) v` in the same variables: `Φ (s u v) / s − u v`.
    pub(crate) fn shifted_scaled(&self, v: &[f64], scale: &[f64], unit: f64) -> Vec<f64> {
        let mut w = self.scaled_product(v, scale, unit);
        w.iter_mut().zip(v).for_each(|(a, b)| *a -= unit * b);
        w
    }
}

/// [`period_map`] and, with `shifted = Some((model at p + dp, dp))`, the
/// derivative `∂P/∂p` of the map with respect to the parameter p of the
/// family: the sensitivity column of the variational equations at the
/// end time plus the flow times the change of the end time,
/// `∂P/∂p = s(T) + f(T, y(T)) dT/dp` (mirrored for the half map); at
/// most `max_steps` integration steps. Without `dense` no column of Φ is
/// carried (the monodromy is 0 × 0) and the integration records its tape
/// for products with Φ: the map, its parameter derivative and the
/// products for matrix-free continuation.
pub(crate) fn period_map_with(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    shifted: Option<(&Model, f64)>,
    dense: bool,
    max_steps: u64,
) -> Result<MapDerivatives, IntegrationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    if dense && d > MAX_DENSE_DIM {
        // About 40 state-sized vectors of d(d + 1) values in the integrator.
        let gb = 40.0 * (d * (d + 1)) as f64 * 8.0 / 1e9;
        return Err(IntegrationError::InvalidOptions(format!(
            "a dense period map of {n} bodies integrates {d}×{d} variational equations (about {gb:.0} GB); \
             above {} bodies use Newton–Krylov shooting (matrix-free)",
            MAX_DENSE_DIM / 2
        )));
    }
    let invalid = |e: PeriodicError| IntegrationError::InvalidOptions(e.to_string());
    let t = map_time(model, opts).map_err(invalid)?;
    // Auto keeps a parameter beyond the forcing on the global integrator.
    let local = match opts.integrator {
        Integrator::Auto => {
            opts.integrator.resolve(model) == Integrator::Local
                && shifted.is_none_or(|(model_p, _)| model.differs_only_in_forcing(model_p))
        }
        chosen => chosen == Integrator::Local,
    };
    if local {
        return local_map(model, x, opts, (shifted, dense), t, max_steps);
    }
    if model.has_rigid_impacts() {
        return rigid_map(model, x, opts, (shifted, dense), t, max_steps);
    }
    if let Some((model_p, dp)) = shifted {
        // The state's steps alone choose the steps, with or without the
        // column: the column can then be replayed on the tape.
        if !dense && !opts.control_monodromy && model.differs_only_in_forcing(model_p) {
            let t_p = map_time(model_p, opts).map_err(invalid)?;
            return forced_map(model, x, opts, (model_p, dp, t_p), t, max_steps);
        }
    }
    let columns = if dense { d } else { 0 };
    let recorded = |m: &Model, on: bool| Recorder::new(ChainDynamics::new(m, false), on);
    let (mut var, dt_dp) = variational_map(
        (model, recorded(model, !dense)),
        columns,
        shifted.map(|(m, dp)| (m, recorded(m, false), dp)),
        (opts, t),
        Recorder::system,
    )?;
    let z0 = var.initial_state(&to_interleaved(x));
    // The state controls the steps: Φ rides along on the same steps, so a
    // period map costs O(N) steps × O(N² · bandwidth) per step.
    let int_opts = opts.integrator_options(max_steps, Some(d));
    let (z, stats, tangent) = if dense {
        let (z, stats) = integrate_to(&mut var, 0.0, &z0, t, &int_opts)?;
        (z, stats, None)
    } else {
        let (z, stats, tape) =
            integrate_recorded(&mut var, Variational::system_mut, 0.0, &z0, t, &int_opts)?;
        let symmetric = opts.symmetric;
        let tape = Tape::Global(Box::new(tape));
        (z, stats, Some(MapTangent { tape, n, symmetric }))
    };
    let image = from_interleaved(&z, n);
    let phi = var.sensitivity(&z);
    let dp_column = var.parameter_sensitivity(&z).map(|s| {
        let mut flow = vec![0.0; d];
        var.system_mut().rhs(t, &z[..d], &mut flow);
        parameter_column(s, &flow, dt_dp, opts.symmetric)
    });
    let map = shooting_map(image, phi, columns, n, opts.symmetric);
    Ok(MapDerivatives {
        map,
        dp_column,
        steps: stats.steps,
        tangent,
    })
}

/// The variational system of a period map: `sys` (of `model`) with
/// `columns` columns of Φ and, with `shifted = (model at p + dp, its
/// system, dp)`, the parameter's column (the shifted system reusing the
/// rest of the right-hand side where only the forcing differs); and dT/dp
/// of the map's time `t`. `chain` reads a system's dynamics.
pub(super) fn variational_map<S: OdeSystem>(
    (model, sys): (&Model, S),
    columns: usize,
    shifted: Option<(&Model, S, f64)>,
    (opts, t): (&ShootingOptions, f64),
    chain: impl Fn(&S) -> &ChainDynamics,
) -> Result<(Variational<S>, f64), IntegrationError> {
    let Some((model_p, shifted_sys, dp)) = shifted else {
        return Ok((Variational::new(sys, columns), 0.0));
    };
    let t_p =
        map_time(model_p, opts).map_err(|e| IntegrationError::InvalidOptions(e.to_string()))?;
    let reforced = model.differs_only_in_forcing(model_p)
        && chain(&sys).same_contact_terms(chain(&shifted_sys));
    let var = if reforced {
        Variational::with_forcing_parameter(sys, columns, shifted_sys, dp)
    } else {
        Variational::with_parameter(sys, columns, shifted_sys, dp)
    };
    Ok((var, (t_p - t) / dp))
}

/// The shooting map's image alone (body order) in at most `max_steps`
/// steps of the options' integrator, and the steps taken.
pub(crate) fn map_image(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    max_steps: u64,
) -> Result<(Vec<f64>, u64), IntegrationError> {
    let n = model.bodies().len();
    let t = map_time(model, opts).map_err(|e| IntegrationError::InvalidOptions(e.to_string()))?;
    let y0 = to_interleaved(x);
    let (y, steps) = if opts.integrator.resolve(model) == Integrator::Local {
        let sim_opts = local_options(opts, t, max_steps);
        let flow = local_flow(model, &sim_opts, &y0, (&[], 0), false)
            .map_err(|e| IntegrationError::InvalidOptions(e.to_string()))??;
        (flow.y, flow.stats.steps)
    } else if model.has_rigid_impacts() {
        rigid_image(model, &y0, t, &opts.integrator_options(max_steps, None))?
    } else {
        let mut sys = ChainDynamics::new(model, false);
        let int_opts = opts.integrator_options(max_steps, None);
        let (y, stats) = integrate_to(&mut sys, 0.0, &y0, t, &int_opts)?;
        (y, stats.steps)
    };
    let image = from_interleaved(&y, n);
    Ok((
        if opts.symmetric {
            mirror(&image)
        } else {
            image
        },
        steps,
    ))
}

/// The parameter's column `∂P/∂p = s(T) + f(T, y(T)) dT/dp` (docs/theory.md
/// §5) in body order, mirrored for the half map, from the sensitivity
/// column `s` and the flow `f(T, y(T))` (both interleaved).
pub(super) fn parameter_column(s: &[f64], flow: &[f64], dt_dp: f64, symmetric: bool) -> Vec<f64> {
    let column: Vec<f64> = s.iter().zip(flow).map(|(s, f)| s + f * dt_dp).collect();
    let column = from_interleaved(&column, column.len() / 2);
    if symmetric {
        mirror(&column)
    } else {
        column
    }
}

/// The shooting map from the flow's image (body order) and Φ's `k`
/// columns (interleaved, column-major): the period map, or for the half map
/// `G = S P_{nT/2}` the mirrored image and `DG = S Φ_{1/2}` (rows mirrored
/// and negated).
pub(super) fn shooting_map(
    image: Vec<f64>,
    phi: &[f64],
    k: usize,
    n: usize,
    symmetric: bool,
) -> PeriodMap {
    let d = 2 * n;
    let inter = |k: usize| interleaved_index(k, n);
    if symmetric {
        PeriodMap {
            image: mirror(&image),
            monodromy: DMatrix::from_fn(k, k, |r, c| {
                -phi[inter(c) * d + inter(mirror_index(r, n))]
            }),
        }
    } else {
        PeriodMap {
            image,
            monodromy: DMatrix::from_fn(k, k, |r, c| phi[inter(c) * d + inter(r)]),
        }
    }
}

/// The local integrator's options for a map over `t`: the shooting
/// tolerances, at most `max_steps` steps, the stop request.
pub(super) fn local_options(opts: &ShootingOptions, t: f64, max_steps: u64) -> SimulationOptions {
    SimulationOptions {
        t_end: t,
        rtol: opts.rtol,
        atol: opts.rtol * opts.displacement_scale,
        max_steps,
        interrupt: opts.interrupt.clone(),
        integrator: Integrator::Local,
        ..SimulationOptions::default()
    }
}

/// The shooting map over `t` by the local integrator (docs/theory.md §10):
/// dense, Φ's columns carried by the exact free motion and in the active
/// set (where they enter the step control, as with `control_monodromy`);
/// otherwise the run records its tape for products with Φ. With `shifted =
/// (model at p + dp, dp)` for a parameter of the forcing alone, the
/// parameter's column `∂P/∂p = s(T) + f(T, y(T)) dT/dp` is replayed on the
/// tape.
fn local_map(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    (shifted, dense): (Option<(&Model, f64)>, bool),
    t: f64,
    max_steps: u64,
) -> Result<MapDerivatives, IntegrationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    let invalid = |e: String| IntegrationError::InvalidOptions(e);
    if let Some((model_p, _)) = shifted {
        if !model.differs_only_in_forcing(model_p) {
            return Err(invalid(
                "the local integrator continues in a parameter of the forcing (frequency, \
                 amplitude) only; use the global integrator for this parameter"
                    .into(),
            ));
        }
    }
    let k = if dense { d } else { 0 };
    let mut identity = vec![0.0; k * k];
    for c in 0..k {
        identity[c * d + c] = 1.0;
    }
    let sim_opts = local_options(opts, t, max_steps);
    let taped = !dense || shifted.is_some();
    let flow = local_flow(model, &sim_opts, &to_interleaved(x), (&identity, k), taped)
        .map_err(|e| invalid(e.to_string()))??;
    let dp_column = match (shifted, &flow.tape) {
        (Some((model_p, dp)), Some(tape)) => {
            let t_p = map_time(model_p, opts).map_err(|e| invalid(e.to_string()))?;
            let s = tape
                .parameter_column(model, model_p, dp)
                .map_err(|e| invalid(e.to_string()))?;
            let mut f = vec![0.0; d];
            ChainDynamics::new(model, false).rhs(t, &flow.y, &mut f);
            Some(parameter_column(&s, &f, (t_p - t) / dp, opts.symmetric))
        }
        _ => None,
    };
    let symmetric = opts.symmetric;
    let image = from_interleaved(&flow.y, n);
    Ok(MapDerivatives {
        map: shooting_map(image, &flow.columns, k, n, symmetric),
        dp_column,
        steps: flow.stats.steps,
        tangent: flow.tape.filter(|_| !dense).map(|tape| MapTangent {
            tape: Tape::Local(Box::new(tape)),
            n,
            symmetric,
        }),
    })
}

/// [`period_map_with`] without the dense Jacobian for a parameter that
/// only changes the forcing (`shifted = (model at p + dp, dp, its map
/// time)`): the state alone is integrated, recording its tape, and the
/// parameter's sensitivity column is replayed on the tape with the source
/// `∂f/∂p = (q_{p+dp}(t) − q_p(t)) / dp`, `q` the time-only part of the
/// equations (docs/theory.md §5): the recurrence of the integrated column,
/// stage by stage, at the cost of one product instead of a state-sized
/// column carried through every stage, error estimate and rejected step.
pub(super) fn forced_map(
    model: &Model,
    x: &[f64],
    opts: &ShootingOptions,
    (model_p, dp, t_p): (&Model, f64, f64),
    t: f64,
    max_steps: u64,
) -> Result<MapDerivatives, IntegrationError> {
    let n = model.bodies().len();
    let d = 2 * n;
    let mut sys = Recorder::new(ChainDynamics::new(model, false), true);
    let int_opts = opts.integrator_options(max_steps, None);
    fn identity(r: &mut Recorder<ChainDynamics>) -> &mut Recorder<ChainDynamics> {
        r
    }
    let (y, stats, tape) =
        integrate_recorded(&mut sys, identity, 0.0, &to_interleaved(x), t, &int_opts)?;
    let (here, shifted) = (sys.system(), ChainDynamics::new(model_p, false));
    let mut q_p = vec![0.0; d];
    let mut source = |time: f64, out: &mut [f64]| {
        here.source(time, out);
        shifted.source(time, &mut q_p);
        out.iter_mut()
            .zip(&q_p)
            .for_each(|(o, s)| *o = (s - *o) / dp);
    };
    let s = tape.apply_with_source(&vec![0.0; d], &mut source);
    let mut flow = vec![0.0; d];
    sys.rhs(t, &y, &mut flow);
    let symmetric = opts.symmetric;
    let column = parameter_column(&s, &flow, (t_p - t) / dp, symmetric);
    Ok(MapDerivatives {
        map: shooting_map(from_interleaved(&y, n), &[], 0, n, symmetric),
        dp_column: Some(column),
        steps: stats.steps,
        tangent: Some(MapTangent {
            tape: Tape::Global(Box::new(tape)),
            n,
            symmetric,
        }),
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
        let sim_opts = local_options(opts, t, MAX_STEPS);
        let column = to_interleaved(v);
        let flow = local_flow(model, &sim_opts, &to_interleaved(x), (&column, 1), false)
            .map_err(|e| IntegrationError::InvalidOptions(e.to_string()))??;
        (flow.y, flow.columns)
    } else if model.has_rigid_impacts() {
        let int_opts = opts.integrator_options(MAX_STEPS, Some(d));
        rigid_product(model, &to_interleaved(x), &to_interleaved(v), t, &int_opts)?
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
