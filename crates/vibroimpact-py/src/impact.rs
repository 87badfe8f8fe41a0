//! `impact`, `contact_force` and `identify`: the impact relations of two
//! bodies, a contact law's force, and a law identified from measured
//! impacts.

use numpy::PyReadonlyArray1;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use vibroimpact::contact::ContactLaw;
use vibroimpact::identify::{AccelerationSample, RestitutionSample};
use vibroimpact::impact::direct::DirectOptions;
use vibroimpact::impact::{ImpactError, TwoBodies};
use vibroimpact::integrate::IntegrationError;
use vibroimpact::model::file::LawSpec;
use vibroimpact::results::{impact_document, ImpactMethod, ImpactRelations, IMPACT_COLUMNS};

use crate::convert::{array1, document, floats, numerical_error, to_python, value_error};
use crate::monitor::{self, Progress};

fn law(spec: &str) -> PyResult<ContactLaw> {
    let spec: LawSpec = serde_json::from_str(spec).map_err(|e| value_error(format!("law: {e}")))?;
    spec.build().map_err(|e| value_error(format!("law: {e}")))
}

/// Velocities per task of `impact`.
const CHUNK: usize = 4096;

/// An impact error: bad input is `ValueError`, a failed solve or
/// integration `VibroimpactError`.
fn impact_error(e: ImpactError) -> PyErr {
    match e {
        ImpactError::InvalidParameter { .. } | ImpactError::Unsupported(_) => value_error(e),
        _ => numerical_error(e),
    }
}

/// Impact relations at every velocity: the `impact` document with each
/// column of its rows as an array.
#[pyfunction]
#[pyo3(signature = (velocity, law_spec, mass1, mass2, method, rtol, duration_level, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn impact<'py>(
    py: Python<'py>,
    velocity: PyReadonlyArray1<'py, f64>,
    law_spec: &str,
    mass1: f64,
    mass2: f64,
    method: &str,
    rtol: f64,
    duration_level: Option<f64>,
    progress: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law(law_spec)?;
    let bodies = TwoBodies::new(mass1, mass2).map_err(value_error)?;
    let velocities = floats(&velocity, "velocity")?;
    let m = match method {
        "closed-form" => ImpactMethod::ClosedForm,
        "integrate" => ImpactMethod::Integrate,
        other => {
            return Err(value_error(format!(
                "method = {other:?}: give \"closed-form\" or \"integrate\""
            )))
        }
    };
    let opts = DirectOptions {
        rtol,
        duration_level,
        ..DirectOptions::default()
    };
    // Checks the method against the law before anything runs.
    ImpactRelations::new(&law, bodies, m, &opts).map_err(impact_error)?;
    let ncol = if m == ImpactMethod::Integrate { 10 } else { 9 };
    let job_law = law;
    // Columns straight from the rows, chunk by chunk in parallel; the first
    // error in velocity order is reported; an interrupt stops at the next
    // chunk.
    let chunks = monitor::run(py, progress, None, move |p: &Progress| {
        let relations = ImpactRelations::new(&job_law, bodies, m, &opts)?;
        p.set_total(velocities.len().div_ceil(CHUNK));
        let chunks: Vec<Result<Vec<Vec<f64>>, ImpactError>> = velocities
            .par_chunks(CHUNK)
            .map(|chunk| {
                if p.interrupt.requested() {
                    return Err(ImpactError::Integration(IntegrationError::Interrupted {
                        t: 0.0,
                    }));
                }
                let mut cols = vec![Vec::with_capacity(chunk.len()); ncol];
                for &u in chunk {
                    let values = relations.row(u)?.values();
                    for (col, x) in cols.iter_mut().zip(values) {
                        col.push(x.unwrap_or(f64::NAN));
                    }
                }
                p.tick();
                Ok(cols)
            })
            .collect();
        let mut columns = vec![Vec::with_capacity(velocities.len()); ncol];
        for chunk in chunks {
            for (all, part) in columns.iter_mut().zip(chunk?) {
                all.extend(part);
            }
        }
        Ok::<_, ImpactError>(columns)
    })?;
    let columns = chunks.map_err(impact_error)?;
    let doc = to_python(py, &impact_document(&law, bodies, m, &[]))?.cast_into::<PyDict>()?;
    doc.del_item("rows")?;
    for (name, col) in IMPACT_COLUMNS.iter().zip(columns) {
        doc.set_item(*name, array1(py, col))?;
    }
    Ok(doc)
}

/// Force and partial derivatives of a contact law at arrays of
/// penetration, rate and onset velocity.
#[pyfunction]
pub fn contact_force<'py>(
    py: Python<'py>,
    law_spec: &str,
    s: PyReadonlyArray1<'py, f64>,
    sdot: PyReadonlyArray1<'py, f64>,
    impact_velocity: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law(law_spec)?;
    let s = floats(&s, "s")?;
    let sdot = floats(&sdot, "sdot")?;
    let v0 = floats(&impact_velocity, "impact_velocity")?;
    if sdot.len() != s.len() || v0.len() != s.len() {
        return Err(value_error(format!(
            "s, sdot and impact_velocity must have one length: {}, {}, {}",
            s.len(),
            sdot.len(),
            v0.len()
        )));
    }
    let (mut f, mut ds, mut dsdot) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..s.len() {
        let c = law.eval(s[i], sdot[i], v0[i]);
        f.push(c.force);
        ds.push(c.d_ds);
        dsdot.push(c.d_dsdot);
    }
    let d = PyDict::new(py);
    d.set_item("force", array1(py, f))?;
    d.set_item("d_ds", array1(py, ds))?;
    d.set_item("d_dsdot", array1(py, dsdot))?;
    Ok(d)
}

/// a/b and α from measured impacts (empty arrays: not measured).
#[pyfunction]
#[pyo3(signature = (restitution_velocity, restitution, acceleration_velocity, peak_acceleration, mass1, mass2, a_over_b, joint))]
#[allow(clippy::too_many_arguments)]
pub fn identify<'py>(
    py: Python<'py>,
    restitution_velocity: PyReadonlyArray1<'py, f64>,
    restitution: PyReadonlyArray1<'py, f64>,
    acceleration_velocity: PyReadonlyArray1<'py, f64>,
    peak_acceleration: PyReadonlyArray1<'py, f64>,
    mass1: f64,
    mass2: f64,
    a_over_b: Option<f64>,
    joint: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let bodies = TwoBodies::new(mass1, mass2).map_err(value_error)?;
    let ru = floats(&restitution_velocity, "restitution_velocity")?;
    let re = floats(&restitution, "restitution")?;
    let au = floats(&acceleration_velocity, "acceleration_velocity")?;
    let aa = floats(&peak_acceleration, "peak_acceleration")?;
    let rest: Vec<RestitutionSample> = ru
        .iter()
        .zip(&re)
        .map(|(&u, &e)| RestitutionSample {
            impact_velocity: u,
            restitution: e,
        })
        .collect();
    let acc: Vec<AccelerationSample> = au
        .iter()
        .zip(&aa)
        .map(|(&u, &a)| AccelerationSample {
            impact_velocity: u,
            peak_acceleration: a,
        })
        .collect();
    let r = monitor::run(py, None, None, move |_: &Progress| {
        vibroimpact::identify::identify(&rest, &acc, bodies, a_over_b, joint)
    })?
    .map_err(value_error)?;
    document(py, &r)
}
