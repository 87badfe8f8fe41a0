//! The binding of [`vibroimpact::seismic::collapse`]: one record's part of a
//! collapse study (the task a cluster runs per record), and the study's
//! document from the records' parts.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::Value;
use vibroimpact::seismic::collapse::{
    check_margins, record_document, study_document, summary_document, CollapseStudy, Criterion,
    DriftLimit, IdaSettings, RecordCollapse, RecordIda,
};

use crate::convert::{to_python, value_error};
use crate::monitor::{self, Progress};
use crate::records::{pair_and_run, pounding_error, record_of, RecordInput};

/// The study's settings as Python hands them over: (drift limit (m),
/// drift-ratio limit (one of the two), capacity, contacts), (first, growth, max scale, tolerance), (period,
/// damping), (sample, rtol, method, integrator).
type Settings = (
    (Option<f64>, Option<f64>, bool, bool),
    (f64, f64, f64, f64),
    (Option<f64>, f64),
    (f64, f64, String, String),
);

/// The row of `pair_text` and the study of `settings`.
fn study(
    pair_text: &str,
    source: &str,
    settings: Settings,
) -> PyResult<(vibroimpact::seismic::pounding::Row, CollapseStudy)> {
    let (
        (drift, ratio, capacity, contacts),
        (first, growth, max_scale, tolerance),
        (period, damping),
        run,
    ) = settings;
    let (sample, rtol, method, integrator) = run;
    let (row, run) = pair_and_run(pair_text, source, (sample, rtol, &method, &integrator))?;
    let study = CollapseStudy {
        criterion: Criterion {
            drift: match (drift, ratio) {
                (Some(d), _) => DriftLimit::Drift(d),
                (None, Some(r)) => DriftLimit::Ratio(r),
                (None, None) => DriftLimit::FEMA,
            },
            capacity,
            contacts,
        },
        ida: IdaSettings {
            first,
            growth,
            max_scale,
            tolerance,
        },
        run,
        period,
        damping,
    };
    study.check().map_err(pounding_error)?;
    Ok((row, study))
}

/// One record's part of the collapse study of the row in `pair_text`:
/// its IDA and spectral acceleration, as `vibroimpact collapse` writes it
/// under `records` (JSON text: cheap to send back from a worker).
#[pyfunction]
pub fn collapse_record<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    record: RecordInput<'py>,
    settings: Settings,
) -> PyResult<String> {
    let (row, mut study) = study(pair_text, source, settings)?;
    let record = record_of(&record)?;
    crate::simulate::warn_if_long(py, study.estimate(&row, &record).map_err(pounding_error)?)?;
    // Monitored: Ctrl-C stops the IDA at its next step (KeyboardInterrupt).
    let part = monitor::run(py, None, None, move |p: &Progress| {
        study.run.interrupt = Some(p.interrupt.clone());
        study.record(&row, &record)
    })?
    .map_err(pounding_error)?;
    serde_json::to_string(&record_document(&part)).map_err(value_error)
}

/// A record's part back from its document (what the summary reads:
/// source, bracket, spectral acceleration).
fn part_of(doc: &Value) -> PyResult<RecordCollapse> {
    let bad = || value_error(format!("records: not a collapse record document: {doc}"));
    Ok(RecordCollapse {
        ida: RecordIda {
            source: doc["source"].as_str().ok_or_else(bad)?.to_string(),
            points: Vec::new(),
            survived: doc["survived"].as_f64().ok_or_else(bad)?,
            collapse: doc["collapse"].as_f64(),
        },
        sa: doc["sa"].as_f64(),
    })
}

/// The collapse study's document (`vibroimpact collapse`'s JSON) from the
/// records' documents (JSON text, in order) made by [`collapse_record`].
#[pyfunction]
#[pyo3(signature = (pair_text, source, settings, records, smt = None, ssf = None))]
pub fn collapse_document<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    settings: Settings,
    records: Vec<String>,
    smt: Option<f64>,
    ssf: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let (row, study) = study(pair_text, source, settings)?;
    check_margins(smt, ssf).map_err(value_error)?;
    let docs: Vec<Value> = records
        .iter()
        .map(|t| serde_json::from_str(t).map_err(value_error))
        .collect::<PyResult<_>>()?;
    let parts: Vec<RecordCollapse> = docs.iter().map(part_of).collect::<PyResult<_>>()?;
    let doc = study_document(&row, &study, docs, summary_document(&parts, smt, ssf));
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}
