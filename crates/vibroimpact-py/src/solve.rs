//! The computations, one function per CLI subcommand. Arguments arrive
//! checked and defaulted by the Python package (`vibroimpact/__init__.py`);
//! the library validates them again and its messages become `ValueError`.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use vibroimpact::contact::ContactLaw;
use vibroimpact::continuation::{amplitude_homotopy, ContinuationOptions, Linear};
use vibroimpact::identify::{AccelerationSample, RestitutionSample};
use vibroimpact::impact::direct::DirectOptions;
use vibroimpact::impact::{ImpactError, TwoBodies};
use vibroimpact::integrate::{IntegrationError, Method};
use vibroimpact::model_file::LawSpec;
use vibroimpact::parameter::ParameterizedModel;
use vibroimpact::periodic::{
    guess_by_simulation_with, orbit_summary_by, shoot, shoot_krylov, ShootingOptions,
};
use vibroimpact::results::{
    impact_document, periodic_document, simulation_summary, ImpactMethod, ImpactRelations,
    IMPACT_COLUMNS,
};
use vibroimpact::simulate::SimulationOptions;
use vibroimpact::sweep::{sweep as run_sweep, Direction, SweepOptions};

use crate::convert::{
    array1, array2, document, floats, numerical_error, thread_pool, to_python, value_error,
};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

fn law(spec: &str) -> PyResult<ContactLaw> {
    let spec: LawSpec = serde_json::from_str(spec).map_err(|e| value_error(format!("law: {e}")))?;
    spec.build().map_err(|e| value_error(format!("law: {e}")))
}

/// Velocities per task of `impact`.
const CHUNK: usize = 4096;

/// An impact error: bad input is `ValueError`, a failed solve or
/// integration `VibroimpactError`.
fn impact_error(e: ImpactError) -> PyErr {
    match e {
        ImpactError::InvalidParameter { .. } | ImpactError::Unsupported(_) => value_error(e),
        _ => numerical_error(e),
    }
}

/// The integration method named `name`.
pub(crate) fn method(name: &str) -> PyResult<Method> {
    match name {
        "dop853" => Ok(Method::Dop853),
        "dopri5" => Ok(Method::Dopri5),
        "rodas" => Ok(Method::Rodas),
        "auto" => Ok(Method::Auto),
        other => Err(value_error(format!(
            "method = {other:?}: give \"dop853\", \"dopri5\", \"rodas\" or \"auto\""
        ))),
    }
}

/// Impact relations at every velocity: the `impact` document with each
/// column of its rows as an array.
#[pyfunction]
#[pyo3(signature = (velocity, law_spec, mass1, mass2, method, rtol, duration_level, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn impact<'py>(
    py: Python<'py>,
    velocity: PyReadonlyArray1<'py, f64>,
    law_spec: &str,
    mass1: f64,
    mass2: f64,
    method: &str,
    rtol: f64,
    duration_level: Option<f64>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law(law_spec)?;
    let bodies = TwoBodies::new(mass1, mass2).map_err(value_error)?;
    let velocities = floats(&velocity, "velocity")?;
    let m = match method {
        "closed-form" => ImpactMethod::ClosedForm,
        "integrate" => ImpactMethod::Integrate,
        other => {
            return Err(value_error(format!(
                "method = {other:?}: give \"closed-form\" or \"integrate\""
            )))
        }
    };
    let opts = DirectOptions {
        rtol,
        duration_level,
        ..DirectOptions::default()
    };
    // Checks the method against the law before anything runs.
    ImpactRelations::new(&law, bodies, m, &opts).map_err(impact_error)?;
    let ncol = if m == ImpactMethod::Integrate { 10 } else { 9 };
    let job_law = law;
    // Columns straight from the rows, chunk by chunk in parallel; the first
    // error in velocity order is reported; an interrupt stops at the next
    // chunk.
    let chunks = monitor::run(py, progress, move |p: &Progress| {
        let relations = ImpactRelations::new(&job_law, bodies, m, &opts)?;
        p.set_total(velocities.len().div_ceil(CHUNK));
        let chunks: Vec<Result<Vec<Vec<f64>>, ImpactError>> = velocities
            .par_chunks(CHUNK)
            .map(|chunk| {
                if p.interrupt.requested() {
                    return Err(ImpactError::Integration(IntegrationError::Interrupted {
                        t: 0.0,
                    }));
                }
                let mut cols = vec![Vec::with_capacity(chunk.len()); ncol];
                for &u in chunk {
                    let values = relations.row(u)?.values();
                    for (col, x) in cols.iter_mut().zip(values) {
                        col.push(x.unwrap_or(f64::NAN));
                    }
                }
                p.tick();
                Ok(cols)
            })
            .collect();
        let mut columns = vec![Vec::with_capacity(velocities.len()); ncol];
        for chunk in chunks {
            for (all, part) in columns.iter_mut().zip(chunk?) {
                all.extend(part);
            }
        }
        Ok::<_, ImpactError>(columns)
    })?;
    let columns = chunks.map_err(impact_error)?;
    let doc = to_python(py, &impact_document(&law, bodies, m, &[]))?.cast_into::<PyDict>()?;
    doc.del_item("rows")?;
    for (name, col) in IMPACT_COLUMNS.iter().zip(columns) {
        doc.set_item(*name, array1(py, col))?;
    }
    Ok(doc)
}

/// Force and partial derivatives of a contact law at arrays of
/// penetration, rate and onset velocity.
#[pyfunction]
pub fn contact_force<'py>(
    py: Python<'py>,
    law_spec: &str,
    s: PyReadonlyArray1<'py, f64>,
    sdot: PyReadonlyArray1<'py, f64>,
    impact_velocity: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law(law_spec)?;
    let s = floats(&s, "s")?;
    let sdot = floats(&sdot, "sdot")?;
    let v0 = floats(&impact_velocity, "impact_velocity")?;
    if sdot.len() != s.len() || v0.len() != s.len() {
        return Err(value_error(format!(
            "s, sdot and impact_velocity must have one length: {}, {}, {}",
            s.len(),
            sdot.len(),
            v0.len()
        )));
    }
    let (mut f, mut ds, mut dsdot) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..s.len() {
        let c = law.eval(s[i], sdot[i], v0[i]);
        f.push(c.force);
        ds.push(c.d_ds);
        dsdot.push(c.d_dsdot);
    }
    let d = PyDict::new(py);
    d.set_item("force", array1(py, f))?;
    d.set_item("d_ds", array1(py, ds))?;
    d.set_item("d_dsdot", array1(py, dsdot))?;
    Ok(d)
}

/// a/b and α from measured impacts (empty arrays: not measured).
#[pyfunction]
#[pyo3(signature = (restitution_velocity, restitution, acceleration_velocity, peak_acceleration, mass1, mass2, a_over_b, joint))]
#[allow(clippy::too_many_arguments)]
pub fn identify<'py>(
    py: Python<'py>,
    restitution_velocity: PyReadonlyArray1<'py, f64>,
    restitution: PyReadonlyArray1<'py, f64>,
    acceleration_velocity: PyReadonlyArray1<'py, f64>,
    peak_acceleration: PyReadonlyArray1<'py, f64>,
    mass1: f64,
    mass2: f64,
    a_over_b: Option<f64>,
    joint: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let bodies = TwoBodies::new(mass1, mass2).map_err(value_error)?;
    let ru = floats(&restitution_velocity, "restitution_velocity")?;
    let re = floats(&restitution, "restitution")?;
    let au = floats(&acceleration_velocity, "acceleration_velocity")?;
    let aa = floats(&peak_acceleration, "peak_acceleration")?;
    let rest: Vec<RestitutionSample> = ru
        .iter()
        .zip(&re)
        .map(|(&u, &e)| RestitutionSample {
            impact_velocity: u,
            restitution: e,
        })
        .collect();
    let acc: Vec<AccelerationSample> = au
        .iter()
        .zip(&aa)
        .map(|(&u, &a)| AccelerationSample {
            impact_velocity: u,
            peak_acceleration: a,
        })
        .collect();
    let r = monitor::run(py, None, move |_: &Progress| {
        vibroimpact::identify::identify(&rest, &acc, bodies, a_over_b, joint)
    })?
    .map_err(value_error)?;
    document(py, &r)
}

/// Sampled states (`rows` of `[u_1..u_N, v_1..v_N]`) as two `rows × N`
/// arrays: displacements and velocities.
fn split_states<'py>(
    py: Python<'py>,
    states: &[f64],
    rows: usize,
    n: usize,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let (mut u, mut v) = (Vec::with_capacity(rows * n), Vec::with_capacity(rows * n));
    for row in states.chunks_exact(2 * n).take(rows) {
        u.extend_from_slice(&row[..n]);
        v.extend_from_slice(&row[n..]);
    }
    Ok((array2(py, u, rows, n)?, array2(py, v, rows, n)?))
}

/// A time history: the `simulate` summary plus `t`, `displacement`,
/// `velocity` (rows per output time) and the impact log as arrays.
#[pyfunction]
#[pyo3(signature = (model, duration, rtol, atol, method_name, output_step, energy, impact_force_threshold, integrator, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate<'py>(
    py: Python<'py>,
    model: &PyModel,
    duration: f64,
    rtol: Option<f64>,
    atol: Option<f64>,
    method_name: &str,
    output_step: Option<f64>,
    energy: bool,
    impact_force_threshold: Option<f64>,
    integrator: &str,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &model.loaded.model;
    let settings = &model.loaded.simulation;
    let method = method(method_name)?;
    let integrator: vibroimpact::simulate::Integrator = integrator.parse().map_err(value_error)?;
    // The CLI's defaults: the model's [simulation] settings, else these.
    let rtol = rtol.or(settings.rtol).unwrap_or(1e-8);
    let atol = atol.or(settings.atol).unwrap_or(rtol * 1e-4);
    let impact_force_threshold = impact_force_threshold
        .or(settings.impact_force_threshold)
        .unwrap_or(1e-3);
    let output_step = match output_step {
        Some(0.0) => None,
        Some(dt) => Some(dt),
        None => Some(match m.forcing_frequency() {
            Some(w) => 2.0 * std::f64::consts::PI / w / 100.0,
            None => duration / 2000.0,
        }),
    };
    let job = model.loaded.clone();
    let result = monitor::run(py, progress, move |p: &Progress| {
        p.track_time(duration);
        let opts = SimulationOptions {
            t_end: duration,
            rtol,
            atol,
            output_step,
            impact_force_threshold,
            energy,
            method,
            integrator,
            interrupt: Some(p.interrupt.clone()),
            ..SimulationOptions::default()
        };
        vibroimpact::simulate::simulate(&job.model, &opts)
    })?;
    let sim = result.map_err(value_error)?;
    let n = m.bodies().len();
    let mut summary = simulation_summary(m, &sim);
    summary.record = model.loaded.record.clone();
    let d = document(py, &summary)?;
    let (u, v) = split_states(py, &sim.states, sim.times.len(), n)?;
    d.set_item("t", array1(py, sim.times))?;
    d.set_item("displacement", u)?;
    d.set_item("velocity", v)?;
    let log = PyDict::new(py);
    let col = |f: &dyn Fn(&vibroimpact::simulate::ImpactRecord) -> f64| {
        sim.impacts.iter().map(f).collect::<Vec<f64>>()
    };
    let contact: Vec<i64> = sim.impacts.iter().map(|i| i.contact as i64).collect();
    log.set_item("contact", numpy::PyArray1::from_vec(py, contact))?;
    log.set_item("start_time", array1(py, col(&|i| i.start_time)))?;
    log.set_item("end_time", array1(py, col(&|i| i.end_time)))?;
    log.set_item("impact_velocity", array1(py, col(&|i| i.impact_velocity)))?;
    log.set_item("rebound_velocity", array1(py, col(&|i| i.rebound_velocity)))?;
    log.set_item("restitution", array1(py, col(&|i| i.restitution())))?;
    log.set_item("peak_force", array1(py, col(&|i| i.peak_force)))?;
    log.set_item("duration", array1(py, col(&|i| i.duration())))?;
    d.set_item("impacts", log)?;
    Ok(d)
}

/// A periodic solution: the `periodic` document plus the orbit over one
/// period (`orbit_t`, `orbit_displacement`, `orbit_velocity`).
#[pyfunction]
#[pyo3(signature = (model, subharmonic, guess, guess_periods, rtol, tol, krylov, arnoldi, symmetric, progress = None, integrator = "auto", dense = false, homotopy = false))]
#[allow(clippy::too_many_arguments)]
pub fn periodic<'py>(
    py: Python<'py>,
    model: &PyModel,
    subharmonic: u32,
    guess: Option<PyReadonlyArray1<'py, f64>>,
    guess_periods: f64,
    rtol: f64,
    tol: f64,
    krylov: bool,
    arnoldi: usize,
    symmetric: bool,
    progress: Option<&Bound<'py, PyAny>>,
    integrator: &str,
    dense: bool,
    homotopy: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let m = &model.loaded.model;
    let linear = Linear::from_switches(krylov, dense).map_err(value_error)?;
    let krylov = linear.krylov(m.bodies().len(), arnoldi).is_some();
    let amplitude = if homotopy {
        Some(
            ParameterizedModel::new(model.document.clone(), "amplitude").map_err(|e| {
                value_error(format!(
                    "guess = 'homotopy' needs a forcing amplitude to vary: {e}"
                ))
            })?,
        )
    } else {
        None
    };
    if m.forcing_frequency().is_none() {
        return Err(value_error(format!(
            "{}: the model has no periodic forcing with one frequency, so it has no periodic solutions",
            model.document.source()
        )));
    }
    if subharmonic == 0 {
        return Err(value_error("subharmonic must be >= 1"));
    }
    if symmetric && (!m.is_mirror_symmetric() || subharmonic % 2 == 0) {
        return Err(value_error(format!(
            "{}: symmetric=True needs a mirror-symmetric model (mirrored bodies, contacts, walls and forcing) and an odd subharmonic",
            model.document.source()
        )));
    }
    let integrator: vibroimpact::simulate::Integrator = integrator.parse().map_err(value_error)?;
    let need = vibroimpact::periodic::MIN_ARNOLDI.min(2 * m.bodies().len());
    if krylov && arnoldi < need {
        return Err(value_error(format!(
            "arnoldi = {arnoldi}: at least {need} Krylov vectors are needed for a stability verdict"
        )));
    }
    let guess = match guess {
        Some(g) => {
            let g = floats(&g, "guess")?;
            if g.len() != 2 * m.bodies().len() {
                return Err(value_error(format!(
                    "guess has {} values, the model needs {} (u then v)",
                    g.len(),
                    2 * m.bodies().len()
                )));
            }
            Some(g)
        }
        None => None,
    };
    let job = model.loaded.clone();
    let out = monitor::run(py, progress, move |p: &Progress| {
        let m = &job.model;
        let interrupt = Some(p.interrupt.clone());
        let x0 = match (guess, amplitude) {
            (Some(g), _) => g,
            (None, Some(family)) => amplitude_homotopy(
                &family,
                family.initial(),
                &ContinuationOptions {
                    shooting: ShootingOptions {
                        interrupt: interrupt.clone(),
                        ..ContinuationOptions::default().shooting
                    },
                    ..ContinuationOptions::default()
                },
            )
            .map_err(|e| format!("guess by homotopy: {e}"))?,
            (None, None) => guess_by_simulation_with(
                m,
                guess_periods,
                rtol.max(1e-9),
                interrupt.clone(),
                integrator,
            )
            .map_err(|e| format!("guess by simulation: {e}"))?,
        };
        let opts = ShootingOptions {
            subharmonic,
            rtol,
            tol,
            symmetric,
            interrupt,
            integrator,
            ..ShootingOptions::default()
        };
        let sol = if krylov {
            shoot_krylov(m, &x0, &opts, arnoldi)
        } else {
            shoot(m, &x0, &opts)
        }
        .map_err(|e| e.to_string())?;
        let orbit = orbit_summary_by(m, &sol.initial_state, (sol.period, 512), rtol, integrator)
            .map_err(|e| e.to_string())?;
        let symmetric_orbit = symmetric
            || vibroimpact::continuation::is_symmetric_orbit(m, &sol.initial_state, &opts);
        Ok::<_, String>((sol, orbit, symmetric_orbit))
    })?;
    let (sol, orbit, symmetric_orbit) = out.map_err(numerical_error)?;
    let doc = periodic_document(m, &sol, &orbit, subharmonic, symmetric_orbit, krylov);
    let d = to_python(py, &doc)?.cast_into::<PyDict>()?;
    let n = m.bodies().len();
    let (u, v) = split_states(py, &orbit.states, orbit.times.len(), n)?;
    d.set_item("orbit_t", array1(py, orbit.times))?;
    d.set_item("orbit_displacement", u)?;
    d.set_item("orbit_velocity", v)?;
    Ok(d)
}

/// `k` values evenly spaced from `from_` to `to`, both ends exact (the
/// values of `vibroimpact sweep --from --to --points`).
#[pyfunction]
pub fn parameter_values<'py>(
    py: Python<'py>,
    from_: f64,
    to: f64,
    k: usize,
) -> Bound<'py, numpy::PyArray1<f64>> {
    array1(py, vibroimpact::sweep::parameter_values(from_, to, k))
}

/// A brute-force sweep: the `sweep` document; every point also carries its
/// Poincaré samples as a `record × 2N` array (`sections`), and with
/// `lyapunov = k` its k largest Lyapunov exponents. `threads`: the size of
/// the thread pool (None: all cores).
#[pyfunction]
#[pyo3(signature = (model, parameter, values, transient, record, up_down, rtol, atol, method_name, cluster_tolerance, threads, only = None, progress = None, lyapunov = None, integrator = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn sweep<'py>(
    py: Python<'py>,
    model: &PyModel,
    parameter: &str,
    values: PyReadonlyArray1<'py, f64>,
    transient: usize,
    record: usize,
    up_down: bool,
    rtol: Option<f64>,
    atol: Option<f64>,
    method_name: &str,
    cluster_tolerance: Option<f64>,
    threads: Option<usize>,
    only: Option<&str>,
    progress: Option<&Bound<'py, PyAny>>,
    lyapunov: Option<usize>,
    integrator: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let family = ParameterizedModel::new(model.document.clone(), parameter).map_err(value_error)?;
    let integrator: vibroimpact::simulate::Integrator = integrator.parse().map_err(value_error)?;
    let values = floats(&values, "values")?;
    let method = method(method_name)?;
    let pool = thread_pool(threads)?;
    let only = match only {
        None => None,
        Some("up") => Some(Direction::Up),
        Some("down") => Some(Direction::Down),
        Some(other) => {
            return Err(value_error(format!(
                "only = {other:?}: give \"up\" or \"down\""
            )))
        }
    };
    let total = values.len() * if up_down && only.is_none() { 2 } else { 1 };
    let summary = monitor::run(py, progress, move |p: &Progress| {
        p.set_total(total);
        let options = SweepOptions {
            transient,
            record,
            up_down,
            only,
            rtol,
            atol,
            method,
            cluster_tolerance,
            lyapunov,
            interrupt: Some(p.interrupt.clone()),
            integrator,
        };
        pool.install(|| run_sweep(&family, &values, &options, &|| p.tick()))
    })?
    .map_err(value_error)?;
    let d = document(py, &summary)?;
    let points = d
        .get_item("points")?
        .ok_or_else(|| numerical_error("no points"))?;
    let n2 = 2 * summary.bodies.len();
    for (k, point) in summary.points.iter().enumerate() {
        let rows = point.sections.len();
        let flat: Vec<f64> = point.sections.iter().flatten().copied().collect();
        points
            .get_item(k)?
            .set_item("sections", array2(py, flat, rows, n2)?)?;
    }
    Ok(d)
}
