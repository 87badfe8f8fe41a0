//! The binding of [`vibroimpact::model::record`] and [`vibroimpact::seismic::spectrum`]:
//! ground-motion records parsed from text (the Python side reads the
//! file) and their response spectra.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::model::record::{parse_record as parse, Record, Units};
use vibroimpact::results::spectrum_document;
use vibroimpact::seismic::pounding::{documents, PoundingError, Row, RunSettings, Study};
use vibroimpact::seismic::spectrum::response_spectrum as spectrum;

use crate::convert::{array1, floats, numerical_error, to_python, value_error};
use crate::monitor::{self, Progress};

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
    let units = units.map(Units::parse).transpose().map_err(value_error)?;
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

/// The named columns of measured data in CSV text (`source` names the file
/// in errors, with the line), as arrays.
#[pyfunction]
pub fn parse_measured<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
    wanted: Vec<String>,
) -> PyResult<Vec<Bound<'py, numpy::PyArray1<f64>>>> {
    let names: Vec<&str> = wanted.iter().map(String::as_str).collect();
    let table =
        vibroimpact::identify::measured::parse_csv(text, source, &names).map_err(value_error)?;
    Ok(table.columns.into_iter().map(|c| array1(py, c)).collect())
}

/// The `spectrum` document of the record (`source`, `header` and file
/// `units` as read; times s, `acceleration` m/s²) × `scale` at `damping`
/// for `periods` (s), as the CLI writes it, with the columns of its rows
/// as arrays: `period`, `pseudo_acceleration` (m/s²), `pseudo_velocity`
/// (m/s), `displacement` (m).
#[pyfunction]
#[pyo3(signature = (times, acceleration, periods, damping, scale, source = "record", header = Vec::new(), units = "m/s2"))]
#[allow(clippy::too_many_arguments)]
pub fn response_spectrum<'py>(
    py: Python<'py>,
    times: PyReadonlyArray1<'py, f64>,
    acceleration: PyReadonlyArray1<'py, f64>,
    periods: PyReadonlyArray1<'py, f64>,
    damping: f64,
    scale: f64,
    source: &str,
    header: Vec<String>,
    units: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let t = floats(&times, "times")?;
    let a = floats(&acceleration, "acceleration")?;
    let p = floats(&periods, "periods")?;
    let mut record = Record::from_samples(source, t, &a).map_err(value_error)?;
    record.header = header;
    record.units = Units::parse(units).map_err(value_error)?;
    let rows = py
        .detach(|| spectrum(&record, scale, damping, &p))
        .map_err(value_error)?;
    let doc =
        to_python(py, &spectrum_document(&record, scale, damping, &rows))?.cast_into::<PyDict>()?;
    doc.del_item("rows")?;
    let col = |f: fn(&vibroimpact::seismic::spectrum::SpectralPoint) -> f64| {
        rows.iter().map(f).collect::<Vec<f64>>()
    };
    doc.set_item("period", array1(py, col(|r| r.period)))?;
    doc.set_item(
        "pseudo_acceleration",
        array1(py, col(|r| r.pseudo_acceleration)),
    )?;
    doc.set_item("pseudo_velocity", array1(py, col(|r| r.pseudo_velocity)))?;
    doc.set_item("displacement", array1(py, col(|r| r.displacement)))?;
    Ok(doc)
}

/// A pounding error in Python's words: bad input is `ValueError` (a
/// setting by its keyword), a failed run `VibroimpactError`.
pub(crate) fn pounding_error(e: PoundingError) -> PyErr {
    match e {
        PoundingError::Run { .. } | PoundingError::Diverged { .. } => numerical_error(e),
        PoundingError::Interrupted => pyo3::exceptions::PyKeyboardInterrupt::new_err(e.to_string()),
        other => value_error(other),
    }
}

/// The row (TOML `pair_text` named by `source`) and the run settings
/// `(sample, rtol, method, integrator)` of a pounding study.
pub(crate) fn pair_and_run(
    pair_text: &str,
    source: &str,
    (sample, rtol, method, integrator): (f64, f64, &str, &str),
) -> PyResult<(Row, RunSettings)> {
    let run = RunSettings {
        sample,
        rtol,
        method: crate::convert::method(method)?,
        integrator: integrator.parse().map_err(value_error)?,
        interrupt: None,
        loops: false,
    };
    let pair =
        vibroimpact::seismic::pounding::parse_row(pair_text, source).map_err(pounding_error)?;
    Ok((pair, run))
}

/// A pounding run's pair (TOML `pair_text` named by `source`), record and
/// settings.
fn inputs(
    pair_text: &str,
    source: &str,
    (times, acceleration): (&PyReadonlyArray1<'_, f64>, &PyReadonlyArray1<'_, f64>),
    settings: (f64, f64, &str, &str),
) -> PyResult<(Row, Record, RunSettings)> {
    let (pair, run) = pair_and_run(pair_text, source, settings)?;
    let t = floats(times, "times")?;
    let a = floats(acceleration, "acceleration")?;
    let record = Record::from_samples("record", t, &a).map_err(value_error)?;
    Ok((pair, record, run))
}

/// A record handed over from Python: its source, header lines, units of
/// the file, times (s) and accelerations (m/s²).
pub(crate) type RecordInput<'py> = (
    String,
    Vec<String>,
    String,
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray1<'py, f64>,
);

/// The record a [`RecordInput`] hands over.
pub(crate) fn record_of(input: &RecordInput<'_>) -> PyResult<Record> {
    let (name, header, units, times, acceleration) = input;
    let t = floats(times, "times")?;
    let a = floats(acceleration, "acceleration")?;
    let mut record = Record::from_samples(name, t, &a).map_err(value_error)?;
    record.header.clone_from(header);
    record.units = Units::parse(units).map_err(value_error)?;
    Ok(record)
}

/// The pounding study of the row in `pair_text` (TOML, named by
/// `source`) under `records` × `scale`: the `vibroimpact pounding`
/// document (`row`, and `runs`, each with `record`, `pounding`, `free`,
/// `amplification` and `joints`; with `free` false the pounding response
/// alone); with `gaps` and `ratios` the pounding spectrum (`row`,
/// `records`, `cells`); with `moat_gaps` the moat-gap study (`row`,
/// `records`, `moat_cells`).
#[pyfunction]
#[pyo3(signature = (pair_text, source, records, scale, sample, rtol, method, integrator, free, gaps = None, ratios = None, moat_gaps = None))]
#[allow(clippy::too_many_arguments)]
pub fn pounding<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    records: Vec<RecordInput<'py>>,
    scale: f64,
    sample: f64,
    rtol: f64,
    method: &str,
    integrator: &str,
    free: bool,
    gaps: Option<Vec<f64>>,
    ratios: Option<Vec<f64>>,
    moat_gaps: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let (row, run) = pair_and_run(pair_text, source, (sample, rtol, method, integrator))?;
    let runs = records
        .iter()
        .map(|r| Ok((record_of(r)?, scale)))
        .collect::<PyResult<Vec<_>>>()?;
    let study = match (gaps, ratios, moat_gaps) {
        (Some(gaps), Some(ratios), _) => Study::Spectrum { gaps, ratios },
        (_, _, Some(gaps)) => Study::Moat { gaps },
        _ => Study::Runs { free },
    };
    let expected = crate::simulate::warn_if_long(
        py,
        study.estimate(&row, &runs, &run).map_err(pounding_error)?,
    )?;
    // Monitored (unless it is short: D44): Ctrl-C stops every run at its
    // next step (KeyboardInterrupt).
    let doc = monitor::run(py, None, expected, move |p: &Progress| {
        let run = RunSettings {
            interrupt: Some(p.interrupt.clone()),
            ..run
        };
        study
            .run(&row, &runs, &run)
            .map(|outcome| documents::study_document(&row, &runs, &outcome, &run))
    })?
    .map_err(pounding_error)?;
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}

/// `FROM:TO:N` as N evenly spaced values (the CLI's form of `--gaps` and
/// `--ratios`); `field` names the keyword in errors.
#[pyfunction]
pub fn value_range<'py>(
    py: Python<'py>,
    field: &str,
    text: &str,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    let field = match field {
        "gaps" => "gaps",
        "moat_gaps" => "moat_gaps",
        "ratios" => "ratios",
        other => return Err(value_error(format!("no range keyword {other:?}"))),
    };
    let values = vibroimpact::seismic::pounding::value_range(field, text).map_err(value_error)?;
    Ok(array1(py, values))
}

/// The time history of the row (TOML `pair_text`) with its contacts
/// under the record × `scale`: `t`; `floors`, per building name its floor
/// displacements (floors × samples, m); `slab`, per isolated building its
/// base slab's displacement (m); `loops`, per hysteretic storey its
/// `building`, `storey` (1-based; None for the bearings), `drift` (m) and
/// `force` (N) at the samples; and the impact log `impact_time`,
/// `impact_at` (`A–B floor F` between buildings, `A moat` on a moat
/// wall), `impact_floor` (1-based; 0 for the slab), `impact_peak_force`
/// (N).
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
    let (row, record, run) = inputs(
        pair_text,
        source,
        (&times, &acceleration),
        (sample, rtol, method, integrator),
    )?;
    let shared = row.clone();
    let h = monitor::run(py, None, None, move |p: &Progress| {
        let run = RunSettings {
            interrupt: Some(p.interrupt.clone()),
            ..run
        };
        shared.history(&record, scale, &run)
    })?
    .map_err(pounding_error)?;
    let rm = &h.model;
    let n = rm.model.bodies().len();
    let series = |i: usize| -> Vec<f64> { h.displacement.chunks(n).map(|s| s[i]).collect() };
    let floors = PyDict::new(py);
    let slab = PyDict::new(py);
    for (b, p) in row.buildings.iter().zip(&rm.placements) {
        let rows: Vec<Vec<f64>> = (0..b.floors()).map(|f| series(p.first_floor + f)).collect();
        floors.set_item(&b.name, rows)?;
        if let Some(base) = p.base {
            slab.set_item(&b.name, array1(py, series(base)))?;
        }
    }
    let mut at = Vec::with_capacity(h.impacts.len());
    let mut floor = Vec::with_capacity(h.impacts.len());
    for i in &h.impacts {
        let joint = rm.joints.iter().enumerate().find_map(|(j, cs)| {
            let k = cs.iter().position(|&c| c == i.contact)?;
            Some((j, row.joints[j].floors[k]))
        });
        match joint {
            Some((j, f)) => {
                at.push(format!(
                    "{}–{} floor {f}",
                    row.buildings[j].name,
                    row.buildings[j + 1].name
                ));
                floor.push(f);
            }
            None => {
                let k = rm
                    .placements
                    .iter()
                    .position(|p| p.moat.contains(&i.contact));
                at.push(format!(
                    "{} moat",
                    k.map_or("?", |k| row.buildings[k].name.as_str())
                ));
                floor.push(0);
            }
        }
    }
    let loops = pyo3::types::PyList::empty(py);
    for l in &h.loops {
        let e = PyDict::new(py);
        e.set_item("building", &row.buildings[l.building].name)?;
        e.set_item("storey", l.storey.map(|s| s + 1))?;
        e.set_item("drift", array1(py, l.drift.clone()))?;
        e.set_item("force", array1(py, l.force.clone()))?;
        loops.append(e)?;
    }
    let d = PyDict::new(py);
    d.set_item("floors", floors)?;
    d.set_item("slab", slab)?;
    d.set_item("loops", loops)?;
    d.set_item(
        "impact_time",
        array1(py, h.impacts.iter().map(|i| i.start_time).collect()),
    )?;
    d.set_item("impact_at", at)?;
    d.set_item("impact_floor", floor)?;
    d.set_item(
        "impact_peak_force",
        array1(py, h.impacts.iter().map(|i| i.peak_force).collect()),
    )?;
    d.set_item("t", array1(py, h.times))?;
    Ok(d)
}
