//! `hysteresis`: a storey law under a cyclic drift protocol or a drift
//! history (as `vibroimpact hysteresis`).

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::model::hysteresis::{
    cyclic_protocol, parse_drifts as parse, seconds_per_drift, under_drift, StoreySpec,
};
use vibroimpact::results::hysteresis_summary;
use vibroimpact::simulate::LONG_RUN;

use crate::convert::{array1, floats, numerical_error, to_python, value_error};

/// The law's name and parameters as Python gives them: law, stiffness,
/// yield drift, post-yield ratio, exponent, β, γ, δ_A, δ_ν, δ_η.
type Law = (String, f64, Option<f64>, f64, f64, f64, f64, f64, f64, f64);

/// An IMK storey's keys as Python gives them: the five of
/// [`vibroimpact::model::hysteresis::IMK_KEYS`],
/// λ_S, λ_C, λ_K (None: no such deterioration), c_S, c_C, c_K.
type ImkKeys = ([Option<f64>; 5], [Option<f64>; 3], [f64; 3]);

/// The spec of the law named `name` (`imk`: the IMK storey's keys).
fn spec(
    (name, _, yield_drift, post_yield_ratio, exponent, beta, gamma, a, nu, eta): &Law,
    imk: Option<ImkKeys>,
) -> PyResult<StoreySpec> {
    let uy = || yield_drift.ok_or_else(|| value_error("yield_drift: give the yield drift (m)"));
    let post_yield_ratio = *post_yield_ratio;
    let (exponent, beta, gamma) = (*exponent, *beta, *gamma);
    let (a, nu, eta) = (*a, *nu, *eta);
    Ok(match name.as_str() {
        "elastic" if yield_drift.is_some() => return Err(value_error(
            "yield_drift: an elastic storey has no yield drift (give law='bilinear' or 'bouc-wen')",
        )),
        "elastic" => StoreySpec::Elastic {},
        "bilinear" => StoreySpec::Bilinear {
            yield_drift: uy()?,
            post_yield_ratio,
        },
        "bouc-wen" => StoreySpec::BoucWen {
            yield_drift: uy()?,
            post_yield_ratio,
            exponent: Some(exponent),
            beta: Some(beta),
            gamma: Some(gamma),
            degradation_a: Some(a),
            degradation_nu: Some(nu),
            degradation_eta: Some(eta),
        },
        "imk" => {
            let (keys, lambda, c) = imk.unwrap_or(([None; 5], [None; 3], [1.0; 3]));
            StoreySpec::imk(*yield_drift, keys, lambda, c)
                .map_err(|key| value_error(format!("{key}: give it for law='imk'")))?
        }
        other => {
            return Err(value_error(format!(
                "law = {other:?}: give \"elastic\", \"bilinear\", \"bouc-wen\" or \"imk\""
            )))
        }
    })
}

/// The `hysteresis` document with the rows as the arrays `drift`,
/// `force` and `dissipated`: the law under `drift` (m, linear between the
/// values, from rest) or, without it, the cyclic protocol of `amplitudes`
/// (m) × `cycles`, `points` samples a cycle.
#[pyfunction]
#[pyo3(signature = (law, amplitudes, cycles, points, drift, rtol, imk = None))]
#[allow(clippy::too_many_arguments)]
pub fn hysteresis<'py>(
    py: Python<'py>,
    law: Law,
    amplitudes: Vec<f64>,
    cycles: usize,
    points: usize,
    drift: Option<PyReadonlyArray1<'py, f64>>,
    rtol: f64,
    imk: Option<ImkKeys>,
) -> PyResult<Bound<'py, PyDict>> {
    let storey = spec(&law, imk)?.law(law.1).map_err(value_error)?;
    let drifts = match drift {
        Some(d) => floats(&d, "drift")?,
        None => cyclic_protocol(&amplitudes, cycles, points).map_err(value_error)?,
    };
    let seconds = drifts.len() as f64 * seconds_per_drift(&storey);
    if seconds > LONG_RUN {
        let text = format!(
            "a long run: {} drift samples, about {seconds:.0} s on one core",
            drifts.len()
        );
        let text = std::ffi::CString::new(text).map_err(value_error)?;
        PyErr::warn(py, &py.get_type::<crate::LongRunWarning>(), &text, 2)?;
    }
    let rows = py
        .detach(|| under_drift(&storey, &drifts, rtol))
        .map_err(numerical_error)?;
    // The arrays, not a row object per sample (1.5 kB each).
    let doc = to_python(py, &hysteresis_summary(&storey, &rows))?.cast_into::<PyDict>()?;
    doc.set_item("force", array1(py, rows.iter().map(|r| r.0).collect()))?;
    doc.set_item("dissipated", array1(py, rows.iter().map(|r| r.1).collect()))?;
    doc.set_item("drift", array1(py, drifts))?;
    Ok(doc)
}

/// The drifts of a drift file's text (`source` names it in errors), as
/// `vibroimpact hysteresis --drift` reads them.
#[pyfunction]
pub fn parse_drifts<'py>(
    py: Python<'py>,
    text: &str,
    source: &str,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    let drifts = parse(text, source).map_err(|e| value_error(format!("drift: {e}")))?;
    Ok(array1(py, drifts))
}
