//! `continue_`: a branch of periodic solutions by the library's
//! [`BranchStudy`], with its switched branch and, with a second parameter,
//! the curves of its special points (as `vibroimpact continue`).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::continuation::{
    BranchStudy, CheckedContinue, ContinuationError, ContinuationOptions, ContinueStudy,
    CurveSelection, CurvesRequest, Linear, StudyError, StudyField,
};
use vibroimpact::periodic::ShootingOptions;
use vibroimpact::results::{branch_special_points, continue_document, curves_document};

use crate::convert::{numerical_error, to_python, value_error};
use crate::model::PyModel;
use crate::monitor::{self, Progress};

/// The second parameter's curves: its name, bounds, kinds, step, and the
/// JSON text of an earlier branch document whose special points start them
/// (then no branch is computed).
type Second = (
    Option<String>,
    Option<f64>,
    Option<f64>,
    Vec<String>,
    f64,
    Option<String>,
);

/// The branch's settings as Python gives them: parameter, range, period
/// multiple, switch.
type Branch<'a> = (&'a str, (f64, f64), u32, Option<String>);

/// The run's settings: (points, step, guess periods), integrator, start.
type Run<'a> = ((usize, f64, f64), &'a str, &'a str);

/// The library's study of `continue_`'s arguments.
fn study(
    (parameter, (from, to), subharmonic, switch_at): Branch<'_>,
    ((max_points, ds_max, guess_periods), integrator, start): Run<'_>,
    linear: (bool, bool, usize),
    second: &Second,
) -> PyResult<ContinueStudy> {
    let (parameter2, from2, to2, kinds, step, _) = second;
    let defaults = ContinuationOptions::default();
    Ok(ContinueStudy {
        parameter: parameter.to_string(),
        branch: BranchStudy {
            from,
            to,
            start: start.parse().map_err(value_error)?,
            guess_periods,
            switch_at,
            linear: Linear::from_switches(linear.0, linear.1).map_err(value_error)?,
            arnoldi: linear.2,
            options: ContinuationOptions {
                max_points,
                ds_max,
                shooting: ShootingOptions {
                    subharmonic,
                    integrator: integrator.parse().map_err(value_error)?,
                    ..defaults.shooting.clone()
                },
                ..defaults
            },
        },
        curves: match parameter2 {
            None => None,
            Some(parameter2) => Some(CurvesRequest {
                parameter2: parameter2.clone(),
                selection: CurveSelection {
                    kinds: CurveSelection::kinds_named(kinds).map_err(value_error)?,
                    bounds2: (*from2, *to2),
                    step: *step,
                },
            }),
        },
    })
}

/// A study error in Python's words: the keyword and its value first.
fn spell(e: StudyError, study: &ContinueStudy) -> PyErr {
    let branch = &study.branch;
    let field = |f: StudyField| match f {
        StudyField::Range => format!("from_ = {}, to = {}", branch.from, branch.to),
        StudyField::From => format!("from_ = {}", branch.from),
        StudyField::Subharmonic => {
            format!("subharmonic = {}", branch.options.shooting.subharmonic)
        }
        StudyField::Parameter => format!("parameter = {:?}", study.parameter),
        StudyField::Start => format!("start = {:?}", branch.start.name()),
        StudyField::Parameter2 => format!(
            "parameter2 = {:?}",
            study.curves.as_ref().map_or("", |c| c.parameter2.as_str())
        ),
        other => other.name().to_string(),
    };
    match e {
        StudyError::Invalid { field: f, message } => {
            value_error(format!("{}: {message}", field(f)))
        }
        e @ (StudyError::Field(_) | StudyError::File(_) | StudyError::Family(_)) => value_error(e),
        StudyError::Continuation(e @ ContinuationError::Invalid(_)) => value_error(e),
        other => numerical_error(other),
    }
}

/// A branch of periodic solutions: the `continue` document (with
/// `switched_branch` when `switch_at` is given, `curves` and
/// `curves_skipped` with `parameter2`); progress counts points. The
/// library's [`ContinueStudy`] does the checks, the start (`start`: auto,
/// simulate or homotopy), the switch and the curves, as for the CLI.
#[pyfunction]
#[pyo3(signature = (model, parameter, from_, to, subharmonic, switch_at, max_points, ds_max, guess_periods, progress = None, integrator = "auto", start = "auto", krylov = false, dense = false, arnoldi = 20, second = (None, None, None, Vec::new(), 0.05, None)))]
#[allow(clippy::too_many_arguments)]
pub fn continue_branch<'py>(
    py: Python<'py>,
    model: &PyModel,
    parameter: &str,
    from_: f64,
    to: f64,
    subharmonic: u32,
    switch_at: Option<String>,
    max_points: usize,
    ds_max: f64,
    guess_periods: f64,
    progress: Option<&Bound<'py, PyAny>>,
    integrator: &str,
    start: &str,
    krylov: bool,
    dense: bool,
    arnoldi: usize,
    second: Second,
) -> PyResult<Bound<'py, PyDict>> {
    let study = study(
        (parameter, (from_, to), subharmonic, switch_at),
        ((max_points, ds_max, guess_periods), integrator, start),
        (krylov, dense, arnoldi),
        &second,
    )?;
    let mut checked = study
        .clone()
        .check(model.document.clone())
        .map_err(|e| spell(e, &study))?;
    if let Some(text) = &second.5 {
        return curves_from_document(py, progress, text, checked, &study);
    }
    let work = py.detach(|| checked.branch.guess_work());
    crate::simulate::warn_if_long(py, work)?;
    let out = monitor::run_keeping(py, progress, None, move |p: &Progress| {
        p.set_total(max_points);
        checked.branch.options.shooting.interrupt = Some(p.interrupt.clone());
        checked.run(|_| {
            p.tick();
            !p.interrupt.requested()
        })
    });
    let out = match out {
        Ok(out) => out,
        // KeyboardInterrupt keeps the branch so far (its stop
        // "Interrupted"), as the command line writes it: `result`.
        Err((e, Some(Ok(outcome)))) => {
            e.value(py)
                .setattr("result", to_python(py, &continue_document(&outcome))?)?;
            return Err(e);
        }
        Err((e, _)) => return Err(e),
    };
    let outcome = out.map_err(|e| spell(e, &study))?;
    let mut doc = continue_document(&outcome);
    if let Some(Err(e)) = &outcome.branch.switched {
        doc["switch_error"] = format!("switch_at = {:?}: {}", e.label, e.message).into();
    }
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}

/// The curves through the special points of an earlier branch document
/// (`text`, its JSON): the `curves` document.
fn curves_from_document<'py>(
    py: Python<'py>,
    progress: Option<&Bound<'py, PyAny>>,
    text: &str,
    mut checked: CheckedContinue,
    study: &ContinueStudy,
) -> PyResult<Bound<'py, PyDict>> {
    let doc: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| value_error(format!("special_points: not a branch document: {e}")))?;
    let family = &checked.branch.family;
    let read = branch_special_points(&doc, family.document(), family.parameter())
        .map_err(|e| value_error(format!("special_points: {e}")))?;
    let names = (
        family.parameter().name.clone(),
        checked
            .plane
            .as_ref()
            .map(|(plane, _)| plane.q.name.clone()),
    );
    let out = monitor::run(py, progress, None, move |p: &Progress| {
        checked.branch.options.shooting.interrupt = Some(p.interrupt.clone());
        checked.curves_from(&read)
    })?;
    let curves = out.map_err(|e| spell(e, study))?;
    let doc = curves_document(&curves, &names.0, &names.1.unwrap_or_default());
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}
