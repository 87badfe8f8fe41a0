//! The binding of [`vibroimpact::maps::chart`]: a stability chart over two
//! parameters as the `chart` document.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::maps::attractor::map_work;
use vibroimpact::maps::chart::{chart as run_chart, ChartOptions};
use vibroimpact::maps::sweep::SweepOptions;

use crate::convert::method;
use crate::convert::{document, floats, thread_pool, value_error};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// A stability chart: the `chart` document of the CLI (`cells` row by row,
/// each with its `runs`). `lyapunov`: each run's largest exponent;
/// `threads`: the size of the thread pool (None: all cores).
#[pyfunction]
#[pyo3(signature = (model, x, x_values, y, y_values, transient, record, starts, lyapunov, rtol, atol, method_name, cluster_tolerance, threads, progress = None, integrator = "auto", settle = None))]
#[allow(clippy::too_many_arguments)]
pub fn chart<'py>(
    py: Python<'py>,
    model: &PyModel,
    x: &str,
    x_values: PyReadonlyArray1<'py, f64>,
    y: &str,
    y_values: PyReadonlyArray1<'py, f64>,
    transient: usize,
    record: usize,
    starts: usize,
    lyapunov: bool,
    rtol: Option<f64>,
    atol: Option<f64>,
    method_name: &str,
    cluster_tolerance: Option<f64>,
    threads: Option<usize>,
    progress: Option<&Bound<'py, PyAny>>,
    integrator: &str,
    settle: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let integrator: vibroimpact::simulate::Integrator = integrator.parse().map_err(value_error)?;
    let xs = floats(&x_values, "x_values")?;
    let ys = floats(&y_values, "y_values")?;
    let method = method(method_name)?;
    let pool = thread_pool(threads)?;
    let doc = model.document.clone();
    let (x, y) = (x.to_string(), y.to_string());
    let total = xs.len() * ys.len();
    let sweep = SweepOptions {
        transient,
        settle,
        record,
        rtol,
        atol,
        method,
        cluster_tolerance,
        lyapunov: lyapunov.then_some(1),
        integrator,
        ..SweepOptions::default()
    };
    if let Ok(base) = doc.build() {
        let work = py.detach(|| map_work(&base, &sweep, total * starts));
        crate::simulate::warn_if_long(py, work)?;
    }
    let out = monitor::run(py, progress, None, move |p: &Progress| {
        p.set_total(total);
        let options = ChartOptions {
            sweep: SweepOptions {
                interrupt: Some(p.interrupt.clone()),
                ..sweep
            },
            starts,
        };
        pool.install(|| run_chart(&doc, (&x, &xs), (&y, &ys), &options, &|| p.tick()))
    })?
    .map_err(value_error)?;
    document(py, &out)
}
