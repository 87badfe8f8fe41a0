//! `simulate`: a time history with its summary and impact log.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::results::{simulation_summary, Provenance};
use vibroimpact::simulate::{estimate_work, SimulationOptions, WorkEstimate};

use crate::convert::{array1, document, method, split_states, value_error};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// A time history: the `simulate` summary plus `t`, `displacement`,
/// `velocity` (rows per output time) and the impact log as arrays.
#[pyfunction]
#[pyo3(signature = (model, duration, rtol, atol, method_name, output_step, energy, impact_force_threshold, integrator, impacts, restitution, progress = None))]
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
    impacts: Option<&str>,
    restitution: Option<f64>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let mut job = vibroimpact::model::file::LoadedModel::clone(&model.loaded);
    job.model = job
        .model
        .with_impact_options(impacts, restitution)
        .map_err(|e| value_error(e.spelled(e.field, " = ")))?;
    let m = &job.model;
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
    let opts = SimulationOptions {
        t_end: duration,
        rtol,
        atol,
        output_step,
        impact_force_threshold,
        energy,
        method,
        integrator,
        ..SimulationOptions::default()
    };
    let work = py.detach(|| estimate_work(m, &opts));
    let expected = warn_if_long(py, work)?;
    let provenance = Provenance::new(&model.document, &opts);
    let effective = job.model.clone();
    let result = monitor::run_keeping(py, progress, expected, move |p: &Progress| {
        p.track_time(duration);
        let opts = SimulationOptions {
            interrupt: Some(p.interrupt.clone()),
            ..opts
        };
        vibroimpact::simulate::simulate(&job.model, &opts)
    });
    let sim = match result {
        Ok(r) => r.map_err(value_error)?,
        // KeyboardInterrupt keeps the history up to the stop, as the
        // command line does: `result`.
        Err((e, Some(Ok(sim)))) => {
            e.value(py).setattr(
                "result",
                history(py, (model, &effective), sim, &provenance)?,
            )?;
            return Err(e);
        }
        Err((e, _)) => return Err(e),
    };
    history(py, (model, &effective), sim, &provenance)
}

/// The `simulate` document of `sim`: the summary (with its provenance),
/// the history's arrays and the impact log.
fn history<'py>(
    py: Python<'py>,
    (model, m): (&PyModel, &vibroimpact::model::Model),
    sim: vibroimpact::simulate::Simulation,
    provenance: &Provenance,
) -> PyResult<Bound<'py, PyDict>> {
    let n = m.bodies().len();
    let mut summary = simulation_summary(m, &sim);
    summary.record = model.loaded.record.clone();
    summary.provenance = Some(provenance.clone());
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
    // A rigid impact's peak force and duration are the soft law's
    // estimates; its impulse and loss exact (NaN for a soft impact).
    let rigid = |f: &dyn Fn(&vibroimpact::impact::rigid::RigidImpact) -> f64| {
        col(&|i| i.rigid.as_ref().map_or(f64::NAN, f))
    };
    let duration = col(&|i| i.rigid.as_ref().map_or(i.duration(), |r| r.duration));
    log.set_item("duration", array1(py, duration))?;
    let kinds: Vec<&str> = sim
        .impacts
        .iter()
        .map(|i| if i.rigid.is_some() { "rigid" } else { "soft" })
        .collect();
    log.set_item("impacts", kinds)?;
    log.set_item("impulse", array1(py, rigid(&|r| r.impulse)))?;
    log.set_item("energy_lost", array1(py, rigid(&|r| r.energy_lost)))?;
    d.set_item("impacts", log)?;
    Ok(d)
}

/// A `LongRunWarning` with the estimate, if the run will take long; the
/// seconds it expects, for [`monitor::run`](crate::monitor::run).
pub(crate) fn warn_if_long(py: Python<'_>, work: Option<WorkEstimate>) -> PyResult<Option<f64>> {
    let expected = work.map(|w| w.seconds);
    let Some(work) = work.filter(|w| w.is_long()) else {
        return Ok(expected);
    };
    let text = format!(
        "{}; Ctrl-C stops it and keeps what is complete",
        work.describe()
    );
    let text = std::ffi::CString::new(text).map_err(crate::convert::value_error)?;
    // Level 2: the user's call of vi.simulate, not the package's.
    PyErr::warn(py, &py.get_type::<crate::LongRunWarning>(), &text, 2)?;
    Ok(expected)
}
