//! `vibroimpact._core`: the Python binding of the vibroimpact library.
//!
//! A thin layer: it converts arguments, runs the library with the GIL
//! released and converts results. The user-facing API (keyword defaults,
//! result objects, plots, Dask) is the Python package `vibroimpact` beside
//! this crate, which calls these functions with checked, contiguous `float64`
//! arrays. Results come back as the same documents the CLI prints as JSON
//! ([`vibroimpact::results`]), as Python dicts, plus numpy arrays for the
//! bulky parts (time histories, Poincaré samples, orbits).
//!
//! Long calls run on a worker thread while the calling thread, holding the
//! GIL only briefly, reports progress and checks for Ctrl-C
//! ([`monitor::run`]); a request to stop reaches the integrators through
//! [`vibroimpact::integrate::Interrupt`]. A simulation or a pounding
//! study its estimate puts under 20 ms runs on the calling thread, the
//! GIL released.

/// The allocator: the rigid period maps build and drop a run's small
/// buffers per evaluation (docs/decisions.md D45).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod basins;
mod branch;
mod chart;
mod collapse;
mod convert;
mod hysteresis;
mod impact;
mod model;
mod monitor;
mod periodic;
mod pushover;
mod records;
mod simulate;
mod sweep;

use pyo3::prelude::*;

pyo3::create_exception!(
    _core,
    VibroimpactError,
    pyo3::exceptions::PyException,
    "A numerical failure of vibroimpact (an integration that cannot go on, a Newton iteration that does not converge)."
);

pyo3::create_exception!(
    _core,
    LongRunWarning,
    pyo3::exceptions::PyUserWarning,
    "A run that will take long: its estimated steps and time, said before it starts (it still runs)."
);

/// The extension module.
#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("VibroimpactError", m.py().get_type::<VibroimpactError>())?;
    m.add("LongRunWarning", m.py().get_type::<LongRunWarning>())?;
    m.add_class::<model::PyModel>()?;
    m.add_function(wrap_pyfunction!(impact::impact, m)?)?;
    m.add_function(wrap_pyfunction!(impact::contact_force, m)?)?;
    m.add_function(wrap_pyfunction!(impact::identify, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(periodic::periodic, m)?)?;
    m.add_function(wrap_pyfunction!(branch::continue_branch, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(chart::chart, m)?)?;
    m.add_function(wrap_pyfunction!(basins::basins, m)?)?;
    m.add_function(wrap_pyfunction!(basins::basin_runs, m)?)?;
    m.add_function(wrap_pyfunction!(basins::basins_merge, m)?)?;
    m.add_function(wrap_pyfunction!(records::parse_record, m)?)?;
    m.add_function(wrap_pyfunction!(records::parse_measured, m)?)?;
    m.add_function(wrap_pyfunction!(records::response_spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(hysteresis::hysteresis, m)?)?;
    m.add_function(wrap_pyfunction!(hysteresis::parse_drifts, m)?)?;
    m.add_function(wrap_pyfunction!(records::pounding, m)?)?;
    m.add_function(wrap_pyfunction!(records::pounding_history, m)?)?;
    m.add_function(wrap_pyfunction!(records::value_range, m)?)?;
    m.add_function(wrap_pyfunction!(pushover::pushover, m)?)?;
    m.add_function(wrap_pyfunction!(collapse::collapse_record, m)?)?;
    m.add_function(wrap_pyfunction!(collapse::collapse_document, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::parameter_values, m)?)?;
    Ok(())
}
