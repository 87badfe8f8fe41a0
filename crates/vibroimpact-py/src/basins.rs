//! The binding of [`vibroimpact::maps::basins`]: basins of attraction in a plane
//! of initial states as the `basins` document.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::maps::attractor::map_work;
use vibroimpact::maps::basins::{basins as run_basins, Component};
use vibroimpact::maps::sweep::SweepOptions;

use crate::convert::method;
use crate::convert::{document, floats, thread_pool, value_error};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// Basins of attraction: the `basins` document of the CLI (`attractors`
/// with their fractions, `cells` row by row). `x`, `y`: state components
/// (`u1`, `v2`, …); `base`: the other components (None: the model's initial
/// state); `threads`: the size of the thread pool (None: all cores).
#[pyfunction]
#[pyo3(signature = (model, x, x_values, y, y_values, base, transient, record, rtol, atol, method_name, cluster_tolerance, threads, progress = None, integrator = "auto", settle = None))]
#[allow(clippy::too_many_arguments)]
pub fn basins<'py>(
    py: Python<'py>,
    model: &PyModel,
    x: &str,
    x_values: PyReadonlyArray1<'py, f64>,
    y: &str,
    y_values: PyReadonlyArray1<'py, f64>,
    base: Option<PyReadonlyArray1<'py, f64>>,
    transient: usize,
    record: usize,
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
    let base = base.map(|b| floats(&b, "base")).transpose()?;
    let method = method(method_name)?;
    let loaded = model
        .document
        .build()
        .map_err(|e| value_error(e.to_string()))?;
    let n = loaded.model.bodies().len();
    let component = |name: &str, arg: &str| {
        Component::parse(name, n).map_err(|e| value_error(format!("{arg}: {e}")))
    };
    let (cx, cy) = (component(x, "x")?, component(y, "y")?);
    let pool = thread_pool(threads)?;
    let total = xs.len() * ys.len();
    let options = SweepOptions {
        transient,
        settle,
        record,
        rtol,
        atol,
        method,
        cluster_tolerance,
        integrator,
        ..SweepOptions::default()
    };
    let work = py.detach(|| map_work(&loaded, &options, total));
    crate::simulate::warn_if_long(py, work)?;
    let out = monitor::run(py, progress, move |p: &Progress| {
        p.set_total(total);
        let options = SweepOptions {
            interrupt: Some(p.interrupt.clone()),
            ..options
        };
        pool.install(|| {
            run_basins(
                &loaded,
                (cx, &xs),
                (cy, &ys),
                base.as_deref(),
                &options,
                &|| p.tick(),
            )
        })
    })?
    .map_err(|e| value_error(e.to_string().replace("base state:", "base:")))?;
    document(py, &out)
}
