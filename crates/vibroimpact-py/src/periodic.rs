//! `periodic`: one periodic orbit by the library's [`OrbitStudy`].

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::continuation::{
    ContinuationError, Guess, Linear, OrbitStudy, StudyError, StudyField,
};
use vibroimpact::periodic::ShootingOptions;
use vibroimpact::results::periodic_document;

use crate::convert::{array1, floats, numerical_error, split_states, to_python, value_error};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// A study error in Python's words: the keyword first.
fn spell(e: StudyError, study: &OrbitStudy, interrupted: bool) -> PyErr {
    let field = |f: StudyField| match f {
        StudyField::Subharmonic => format!("subharmonic = {}", study.options.subharmonic),
        StudyField::Arnoldi => format!("arnoldi = {}", study.arnoldi),
        StudyField::Guess => match study.guess {
            Guess::Homotopy => "guess = 'homotopy'".to_string(),
            _ => "guess".to_string(),
        },
        other => format!("{} = True", other.name()),
    };
    match e {
        StudyError::Invalid { field: f, message } => {
            value_error(format!("{}: {message}", field(f)))
        }
        StudyError::Model(_) | StudyError::File(_) | StudyError::Field(_) => value_error(e),
        StudyError::Continuation(ContinuationError::Invalid(_)) if !interrupted => value_error(e),
        other => numerical_error(other),
    }
}

/// A periodic solution: the `periodic` document plus the orbit over one
/// period (`orbit_t`, `orbit_displacement`, `orbit_velocity`). The
/// library's [`OrbitStudy`] does the checks, the guess (by simulation,
/// given, or by the homotopy), shooting and the orbit's summary, as for
/// the CLI.
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
    let study = OrbitStudy {
        guess: match (guess, homotopy) {
            (Some(g), _) => Guess::State(floats(&g, "guess")?),
            (None, true) => Guess::Homotopy,
            (None, false) => Guess::Simulate,
        },
        guess_periods,
        linear: Linear::from_switches(krylov, dense).map_err(value_error)?,
        arnoldi,
        options: ShootingOptions {
            subharmonic,
            rtol,
            tol,
            symmetric,
            integrator: integrator.parse().map_err(value_error)?,
            ..ShootingOptions::default()
        },
    };
    let checked = study
        .clone()
        .check(model.document.clone())
        .map_err(|e| spell(e, &study, false))?;
    let work = py.detach(|| checked.work());
    crate::simulate::warn_if_long(py, work)?;
    let (m, krylov) = (checked.model.clone(), checked.krylov.is_some());
    let out = monitor::run(py, progress, None, move |p: &Progress| {
        let mut checked = checked;
        checked.study.options.interrupt = Some(p.interrupt.clone());
        checked.run().map_err(|e| (e, p.interrupt.requested()))
    })?;
    let out = out.map_err(|(e, stopped)| spell(e, &study, stopped))?;
    let doc = periodic_document(
        &m,
        &out.solution,
        &out.orbit,
        subharmonic,
        out.symmetric,
        krylov,
    );
    let d = to_python(py, &doc)?.cast_into::<PyDict>()?;
    let (orbit, n) = (out.orbit, m.bodies().len());
    let (u, v) = split_states(py, &orbit.states, orbit.times.len(), n)?;
    d.set_item("orbit_t", array1(py, orbit.times))?;
    d.set_item("orbit_displacement", u)?;
    d.set_item("orbit_velocity", v)?;
    Ok(d)
}
