//! `sweep` and `parameter_values`: a brute-force bifurcation diagram.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::maps::sweep::{sweep as run_sweep, sweep_work, Direction, SweepOptions};
use vibroimpact::model::parameter::ParameterizedModel;

use crate::convert::{
    array1, array2, document, floats, method, numerical_error, thread_pool, value_error,
};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// `k` values evenly spaced from `from_` to `to`, both ends exact (the
/// values of `vibroimpact sweep --from --to --points`).
#[pyfunction]
pub fn parameter_values<'py>(
    py: Python<'py>,
    from_: f64,
    to: f64,
    k: usize,
) -> Bound<'py, numpy::PyArray1<f64>> {
    array1(py, vibroimpact::maps::sweep::parameter_values(from_, to, k))
}

/// A brute-force sweep: the `sweep` document; every point also carries its
/// Poincaré samples as a `record × 2N` array (`sections`), and with
/// `lyapunov = k` its k largest Lyapunov exponents. `threads`: the size of
/// the thread pool (None: all cores).
#[pyfunction]
#[pyo3(signature = (model, parameter, values, transient, record, up_down, rtol, atol, method_name, cluster_tolerance, threads, only = None, progress = None, lyapunov = None, integrator = "auto", settle = None))]
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
    settle: Option<usize>,
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
    let options = SweepOptions {
        transient,
        settle,
        record,
        up_down,
        only,
        rtol,
        atol,
        method,
        cluster_tolerance,
        lyapunov,
        interrupt: None,
        integrator,
    };
    // A long sweep warns before any work, as the command line's note.
    if let Some(base) = values.first().and_then(|&v| family.loaded_at(v).ok()) {
        let work = py.detach(|| sweep_work(&base, &options, values.len()));
        crate::simulate::warn_if_long(py, work)?;
    }
    let summary = monitor::run_keeping(py, progress, None, move |p: &Progress| {
        p.set_total(total);
        let options = SweepOptions {
            interrupt: Some(p.interrupt.clone()),
            ..options
        };
        pool.install(|| run_sweep(&family, &values, &options, &|| p.tick()))
    });
    let summary = match summary {
        Ok(r) => r.map_err(value_error)?,
        // KeyboardInterrupt keeps the values computed so far, as the
        // command line writes them: `result`.
        Err((e, Some(Ok(summary)))) => {
            e.value(py)
                .setattr("result", sweep_document(py, &summary)?)?;
            return Err(e);
        }
        Err((e, _)) => return Err(e),
    };
    sweep_document(py, &summary)
}

/// The `sweep` document of `summary`, each point's `sections` an array.
fn sweep_document<'py>(
    py: Python<'py>,
    summary: &vibroimpact::maps::sweep::SweepSummary,
) -> PyResult<Bound<'py, PyDict>> {
    let d = document(py, summary)?;
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
