//! The binding of [`vibroimpact::record`] and [`vibroimpact::spectrum`]:
//! ground-motion records parsed from text (the Python side reads the
//! file) and their response spectra.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::pounding::{PoundingPair, RunSettings};
use vibroimpact::record::{parse_record as parse, Record, Units};
use vibroimpact::spectrum::response_spectrum as spectrum;

use crate::convert::{array1, floats, value_error};

/// A record from the text of a file (`source` names it): `source`,
/// `header`, `units` (of the file), `dt` (None if not uniform), `times`
/// (s), `acceleration` (m/s²), `pga` (m/s²).
#[pyfunction]
#[pyo3(signature = (text, source, units = None))]
pub fn parse_record<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    units: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let units = units
        .map(Units::parse)
        .transpose()
        .map_err(|e| value_error(format!("units: {e}")))?;
    let r = parse(text, source, units).map_err(value_error)?;
    let d = PyDict::new(py);
    d.set_item("source", &r.source)?;
    d.set_item("header", &r.header)?;
    d.set_item("units", r.units.name())?;
    d.set_item("dt", r.dt)?;
    d.set_item("pga", r.pga())?;
    d.set_item("times", array1(py, r.times))?;
    d.set_item("acceleration", array1(py, r.acceleration))?;
    Ok(d)
}

/// The response spectrum of the piecewise-linear record (`times` s,
/// `acceleration` m/s²) × `scale` at `damping` for `periods` (s): arrays
/// `period`, `pseudo_acceleration` (m/s²), `pseudo_velocity` (m/s),
/// `displacement` (m); peaks over the record's time steps.
#[pyfunction]
pub fn response_spectrum<'py>(
    py: Python<'py>,
    times: PyReadonlyArray1<'py, f64>,
    acceleration: PyReadonlyArray1<'py, f64>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: f64,
    scale: f64,
) -> PyResult<Bound<'py, PyDict>> {
    let t = floats(&times, "times")?;
    let a = floats(&acceleration, "acceleration")?;
    let p = floats(&periods, "periods")?;
    let record = Record::from_samples("record", t, &a).map_err(value_error)?;
    let rows = py
        .detach(|| spectrum(&record, scale, damping, &p))
        .map_err(value_error)?;
    let d = PyDict::new(py);
    let col = |f: fn(&vibroimpact::spectrum::SpectralPoint) -> f64| {
        rows.iter().map(f).collect::<Vec<f64>>()
    };
    d.set_item("period", array1(py, col(|r| r.period)))?;
    d.set_item(
        "pseudo_acceleration",
        array1(py, col(|r| r.pseudo_acceleration)),
    )?;
    d.set_item("pseudo_velocity", array1(py, col(|r| r.pseudo_velocity)))?;
    d.set_item("displacement", array1(py, col(|r| r.displacement)))?;
    Ok(d)
}

/// A pounding run's pair (TOML `pair_text` named by `source`), record and
/// settings.
fn inputs(
    pair_text: &str,
    source: &str,
    (times, acceleration): (&PyReadonlyArray1<'_, f64>, &PyReadonlyArray1<'_, f64>),
    (sample, rtol, method, integrator): (f64, f64, &str, &str),
) -> PyResult<(PoundingPair, Record, RunSettings)> {
    let run = RunSettings {
        sample,
        rtol,
        method: crate::solve::method(method)?,
        integrator: integrator.parse().map_err(value_error)?,
    };
    let pair = vibroimpact::pounding::parse_pair(pair_text, source).map_err(value_error)?;
    let t = floats(times, "times")?;
    let a = floats(acceleration, "acceleration")?;
    let record = Record::from_samples("record", t, &a).map_err(value_error)?;
    Ok((pair, record, run))
}

/// One record's pounding study of the pair in `pair_text` (TOML, named by
/// `source`): `left_period`, `right_period`, `pounding` and `free` (each
/// with `peak_drift`, `peak_floor_acceleration`, `peak_displacement` as
/// [left, right] lists, `peak_impact_force`, `impacts`, `closing`),
/// `required_gap` and `code_gaps`; with `free` false, the pounding run
/// alone (`pounding` and the periods).
#[pyfunction]
#[pyo3(signature = (pair_text, source, times, acceleration, scale, sample, rtol, method, integrator, free))]
#[allow(clippy::too_many_arguments)]
pub fn pounding<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    times: PyReadonlyArray1<'py, f64>,
    acceleration: PyReadonlyArray1<'py, f64>,
    scale: f64,
    sample: f64,
    rtol: f64,
    method: &str,
    integrator: &str,
    free: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let (pair, record, run) = inputs(
        pair_text,
        source,
        (&times, &acceleration),
        (sample, rtol, method, integrator),
    )?;
    let response = |r: &vibroimpact::pounding::Response| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("peak_drift", [r.drift[0].clone(), r.drift[1].clone()])?;
        d.set_item(
            "peak_floor_acceleration",
            [r.acceleration[0].clone(), r.acceleration[1].clone()],
        )?;
        d.set_item(
            "peak_displacement",
            [r.displacement[0].clone(), r.displacement[1].clone()],
        )?;
        d.set_item("peak_impact_force", r.peak_impact_force)?;
        d.set_item("impacts", r.impacts)?;
        d.set_item("closing", r.closing.clone())?;
        Ok(d)
    };
    let d = PyDict::new(py);
    d.set_item("left_period", pair.left.period())?;
    d.set_item("right_period", pair.right.period())?;
    if !free {
        let r = py
            .detach(|| pair.respond(&record, scale, true, &run))
            .map_err(value_error)?;
        d.set_item("pounding", response(&r)?)?;
        return Ok(d);
    }
    let res = py
        .detach(|| pair.analyse(&record, scale, &run))
        .map_err(value_error)?;
    d.set_item("pounding", response(&res.pounding)?)?;
    d.set_item("free", response(&res.free)?)?;
    d.set_item("required_gap", res.required_gap)?;
    let g = PyDict::new(py);
    g.set_item("absolute_sum", res.code_gaps.absolute_sum)?;
    g.set_item("srss", res.code_gaps.srss)?;
    g.set_item("double_difference", res.code_gaps.double_difference)?;
    g.set_item("correlation", res.code_gaps.correlation)?;
    d.set_item("code_gaps", g)?;
    Ok(d)
}

/// The time history of the pair (TOML `pair_text`) with its contacts under
/// the record × `scale`: `t`, `left` and `right` (floor displacements,
/// floors × samples, m), and the impact log `impact_time`,
/// `impact_floor` (1-based), `impact_peak_force` (N).
#[pyfunction]
#[pyo3(signature = (pair_text, source, times, acceleration, scale, sample, rtol, method, integrator))]
#[allow(clippy::too_many_arguments)]
pub fn pounding_history<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    times: PyReadonlyArray1<'py, f64>,
    acceleration: PyReadonlyArray1<'py, f64>,
    scale: f64,
    sample: f64,
    rtol: f64,
    method: &str,
    integrator: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let (pair, record, run) = inputs(
        pair_text,
        source,
        (&times, &acceleration),
        (sample, rtol, method, integrator),
    )?;
    let sim = py
        .detach(|| pair.history(&record, scale, &run))
        .map_err(value_error)?;
    let (nl, n) = (pair.left.masses.len(), sim.final_displacement.len());
    let floors = |range: std::ops::Range<usize>| -> Vec<Vec<f64>> {
        range
            .map(|i| sim.states.chunks(2 * n).map(|row| row[i]).collect())
            .collect()
    };
    let d = PyDict::new(py);
    d.set_item("left", floors(0..nl))?;
    d.set_item("right", floors(nl..n))?;
    d.set_item(
        "impact_time",
        array1(py, sim.impacts.iter().map(|i| i.start_time).collect()),
    )?;
    d.set_item(
        "impact_floor",
        sim.impacts
            .iter()
            .map(|i| pair.floors[i.contact])
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "impact_peak_force",
        array1(py, sim.impacts.iter().map(|i| i.peak_force).collect()),
    )?;
    d.set_item("t", array1(py, sim.times))?;
    Ok(d)
}
