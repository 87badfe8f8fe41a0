//! The binding of [`vibroimpact::seismic::pushover`]: a building's static
//! pushover as the CLI's document.

use pyo3::prelude::*;
use vibroimpact::seismic::pushover::{pushover as push, PushoverOptions};

use crate::convert::{to_python, value_error};
use crate::records::pounding_error;

/// The pushover of building `building` (None: the first) of the row file
/// text `pair_text` (named by `source`): the document of `vibroimpact
/// pushover --format json`. Errors name the argument.
#[pyfunction]
#[pyo3(signature = (pair_text, source, building, drift_ratio_limit, points, code_period))]
pub fn pushover<'py>(
    py: Python<'py>,
    pair_text: &str,
    source: &str,
    building: Option<&str>,
    drift_ratio_limit: f64,
    points: usize,
    code_period: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let row =
        vibroimpact::seismic::pounding::parse_row(pair_text, source).map_err(pounding_error)?;
    let b = match building {
        None => row.buildings.first(),
        Some(name) => row.buildings.iter().find(|b| b.name == name),
    }
    .ok_or_else(|| {
        let names: Vec<&str> = row.buildings.iter().map(|b| b.name.as_str()).collect();
        value_error(format!(
            "building: {source} has no building {:?} (it has {names:?})",
            building.unwrap_or("")
        ))
    })?;
    let opts = PushoverOptions {
        drift_ratio_limit,
        points,
        code_period,
    };
    let p = push(&b.frame, &opts).map_err(|e| {
        let key = e.split([' ', ':']).next().unwrap_or("");
        if ["drift_ratio_limit", "points", "code_period"].contains(&key) {
            value_error(e)
        } else {
            value_error(format!("pair: {source}: {}: {e}", b.name))
        }
    })?;
    to_python(py, &p.document(&b.name, &b.frame))
}
