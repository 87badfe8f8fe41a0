//! The binding of [`vibroimpact::maps::basins`]: basins of attraction in a plane
//! of initial states as the `basins` document.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::maps::attractor::map_work;
use vibroimpact::maps::basins::{
    basin_runs as run_basin_runs, basins as run_basins, basins_of, BasinRuns, Component,
};
use vibroimpact::maps::sweep::SweepOptions;
use vibroimpact::model::file::LoadedModel;

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
    let options = SweepOptions {
        transient,
        settle,
        record,
        rtol,
        atol,
        method: method(method_name)?,
        cluster_tolerance,
        integrator,
        ..SweepOptions::default()
    };
    let Plane {
        loaded,
        cx,
        cy,
        xs,
        ys,
        base,
    } = plane(model, (x, &x_values), (y, &y_values), base)?;
    let pool = thread_pool(threads)?;
    let total = xs.len() * ys.len();
    let work = py.detach(|| map_work(&loaded, &options, total));
    crate::simulate::warn_if_long(py, work)?;
    let out = monitor::run(py, progress, None, move |p: &Progress| {
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

/// The checked plane of a basin computation.
struct Plane {
    loaded: LoadedModel,
    cx: Component,
    cy: Component,
    xs: Vec<f64>,
    ys: Vec<f64>,
    base: Option<Vec<f64>>,
}

/// The plane `x` × `y` of `model`'s state components through `base`.
fn plane(
    model: &PyModel,
    (x, x_values): (&str, &PyReadonlyArray1<'_, f64>),
    (y, y_values): (&str, &PyReadonlyArray1<'_, f64>),
    base: Option<PyReadonlyArray1<'_, f64>>,
) -> PyResult<Plane> {
    let loaded = model
        .document
        .build()
        .map_err(|e| value_error(e.to_string()))?;
    let n = loaded.model.bodies().len();
    let component = |name: &str, arg: &str| {
        Component::parse(name, n).map_err(|e| value_error(format!("{arg}: {e}")))
    };
    Ok(Plane {
        cx: component(x, "x")?,
        cy: component(y, "y")?,
        xs: floats(x_values, "x_values")?,
        ys: floats(y_values, "y_values")?,
        base: base.map(|b| floats(&b, "base")).transpose()?,
        loaded,
    })
}

/// The options of a distributed basin computation, from the dict
/// `vibroimpact.basins` checked (`transient`, `settle`, `record`, `rtol`,
/// `atol`, `method`, `cluster_tolerance`, `integrator`).
fn options_of(options: &Bound<'_, PyDict>) -> PyResult<SweepOptions> {
    fn item<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
        d.get_item(key)?
            .ok_or_else(|| value_error(format!("options: no `{key}`")))?
            .extract()
            .map_err(Into::into)
    }
    let integrator: String = item(options, "integrator")?;
    let method_name: String = item(options, "method")?;
    Ok(SweepOptions {
        transient: item(options, "transient")?,
        settle: item(options, "settle")?,
        record: item(options, "record")?,
        rtol: item(options, "rtol")?,
        atol: item(options, "atol")?,
        method: method(&method_name)?,
        cluster_tolerance: item(options, "cluster_tolerance")?,
        integrator: integrator.parse().map_err(value_error)?,
        ..SweepOptions::default()
    })
}

/// One task's share of basins on a Dask cluster: the runs of the rows
/// `y_values` on one thread, as JSON (it reads back bit for bit);
/// [`basins_merge`] joins the tasks' runs and identifies the attractors.
#[pyfunction]
pub fn basin_runs<'py>(
    model: &PyModel,
    x: &str,
    x_values: PyReadonlyArray1<'py, f64>,
    y: &str,
    y_values: PyReadonlyArray1<'py, f64>,
    base: Option<PyReadonlyArray1<'py, f64>>,
    options: &Bound<'py, PyDict>,
) -> PyResult<String> {
    let options = options_of(options)?;
    let p = plane(model, (x, &x_values), (y, &y_values), base)?;
    let runs = thread_pool(Some(1))?
        .install(|| {
            run_basin_runs(
                &p.loaded,
                (p.cx, &p.xs),
                (p.cy, &p.ys),
                p.base.as_deref(),
                &options,
                &|| {},
            )
        })
        .map_err(|e| value_error(e.to_string()))?;
    serde_json::to_string(&runs).map_err(value_error)
}

/// The basins from the tasks' runs (`parts`, [`basin_runs`] of consecutive
/// rows of `y_values`, in order): the `basins` document, bit for bit that
/// of one run here.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn basins_merge<'py>(
    py: Python<'py>,
    model: &PyModel,
    x: &str,
    x_values: PyReadonlyArray1<'py, f64>,
    y: &str,
    y_values: PyReadonlyArray1<'py, f64>,
    base: Option<PyReadonlyArray1<'py, f64>>,
    options: &Bound<'py, PyDict>,
    parts: Vec<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = options_of(options)?;
    let p = plane(model, (x, &x_values), (y, &y_values), base)?;
    let parts = parts
        .iter()
        .map(|text| serde_json::from_str::<BasinRuns>(text))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| value_error(format!("parts: {e}")))?;
    let out = basins_of(
        &p.loaded,
        ((p.cx, &p.xs), (p.cy, &p.ys)),
        p.base.as_deref(),
        &options,
        BasinRuns::concat(parts),
    )
    .map_err(|e| value_error(e.to_string().replace("base state:", "base:")))?;
    document(py, &out)
}
