//! `continue_`: a branch of periodic solutions by the library's
//! [`BranchStudy`], with its switched branch and, with a second parameter,
//! the curves of its special points (as `vibroimpact continue`).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact::continuation::{
    curves_of_branch, BranchOrigin, BranchStudy, ContinuationError, ContinuationOptions,
    CurveSelection, CurvesError, Linear, Start, StudyError, StudyField,
};
use vibroimpact::family::{Family, ParameterizedModel2};
use vibroimpact::parameter::ParameterizedModel;
use vibroimpact::periodic::ShootingOptions;
use vibroimpact::results::{branch_document, branch_special_points, curves_document};

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

/// A branch of periodic solutions: the `continue` document (with
/// `switched_branch` when `switch_at` is given, `curves` and
/// `curves_skipped` with `parameter2`); progress counts points. The
/// library's [`BranchStudy`] does the checks, the start (`start`: auto,
/// simulate or homotopy) and the switch, as for the CLI.
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
    let mut family =
        ParameterizedModel::new(model.document.clone(), parameter).map_err(value_error)?;
    let start: Start = start.parse().map_err(value_error)?;
    let linear = Linear::from_switches(krylov, dense).map_err(value_error)?;
    let mut study = BranchStudy {
        from: from_,
        to,
        start,
        guess_periods,
        switch_at,
        linear,
        arnoldi,
        options: ContinuationOptions {
            max_points,
            ds_max,
            shooting: ShootingOptions {
                subharmonic,
                integrator: integrator.parse().map_err(value_error)?,
                ..ContinuationOptions::default().shooting
            },
            ..ContinuationOptions::default()
        },
    };
    let spell = |e: StudyError| match e {
        StudyError::Invalid { field, message } => value_error(format!(
            "{}: {message}",
            match field {
                StudyField::Range => format!("from_ = {from_}, to = {to}"),
                StudyField::From => format!("from_ = {from_}"),
                StudyField::Subharmonic => format!("subharmonic = {subharmonic}"),
                StudyField::Parameter => format!("parameter = {parameter:?}"),
                StudyField::Start => format!("start = {:?}", start.name()),
            }
        )),
        StudyError::Family(e) => value_error(e),
        StudyError::Continuation(e @ ContinuationError::Invalid(_)) => value_error(e),
        other => numerical_error(other),
    };
    let (start_model, checked) = study.check(&mut family).map_err(spell)?;
    let (parameter2, from2, to2, kinds, curve_step, special_points) = second;
    let plane = match &parameter2 {
        None => None,
        Some(name) => {
            let q = model.document.parameter(name).map_err(value_error)?;
            if q.key == family.parameter.key {
                return Err(value_error(format!(
                    "parameter2 = {name:?}: the same key as parameter = {parameter:?}; give another"
                )));
            }
            let selection = CurveSelection {
                kinds: CurveSelection::kinds_named(&kinds).map_err(value_error)?,
                bounds2: (from2, to2),
                step: curve_step,
            };
            selection.check().map_err(value_error)?;
            let plane = ParameterizedModel2 {
                document: model.document.clone(),
                p: family.parameter.clone(),
                q,
            };
            Some((plane, selection))
        }
    };
    if let Some(text) = special_points {
        let Some((plane, selection)) = plane else {
            return Err(value_error(
                "special_points: give parameter2 too (the curves' second parameter)",
            ));
        };
        return curves_from_document(
            py,
            progress,
            &text,
            (plane, selection),
            (from_, to),
            checked,
        );
    }
    let mut at_start = model.document.clone();
    at_start
        .set(&family.parameter, from_)
        .map_err(value_error)?;
    let amplitude = ParameterizedModel::new(at_start, "amplitude");
    let out = monitor::run(py, progress, move |p: &Progress| {
        p.set_total(max_points);
        study.options.shooting.interrupt = Some(p.interrupt.clone());
        let mut amplitude = amplitude;
        let homotopy = amplitude.as_mut().ok().map(|a| {
            let target = a.initial();
            (a as &mut dyn Family, target)
        });
        let on_point = |_: &vibroimpact::continuation::BranchPoint| {
            p.tick();
            !p.interrupt.requested()
        };
        let outcome = study
            .run(&family, homotopy, on_point)
            .map_err(Failure::Study)?;
        let curves = match plane {
            Some((plane, selection)) => {
                let origin = BranchOrigin {
                    special: &outcome.branch.special,
                    symmetric: outcome.branch.symmetric,
                    range: (from_, to),
                    q0: plane.q.initial,
                };
                let linear = (&outcome.options.shooting, outcome.options.krylov);
                let names = (plane.p.name.clone(), plane.q.name.clone());
                let c =
                    curves_of_branch(plane, origin, &selection, linear).map_err(Failure::Curves)?;
                Some(curves_document(&c, &names.0, &names.1))
            }
            None => None,
        };
        Ok::<_, Failure>((outcome, curves))
    })?;
    let (outcome, curves) = out.map_err(|e| match e {
        Failure::Study(e) => spell(e),
        Failure::Curves(CurvesError::Field(f)) => value_error(f),
        Failure::Curves(e) => numerical_error(e),
    })?;
    let mut doc = branch_document(&outcome.branch, &start_model, parameter);
    match outcome.switched {
        Some(Ok(b)) => doc["switched_branch"] = branch_document(&b, &start_model, parameter),
        Some(Err(e)) => {
            doc["switch_error"] = format!("switch_at = {:?}: {}", e.label, e.message).into()
        }
        None => {}
    }
    if let Some(c) = curves {
        doc["curves"] = c["curves"].clone();
        doc["curves_skipped"] = c["skipped"].clone();
    }
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}

/// The curves through the special points of an earlier branch document
/// (`text`, its JSON) in the plane's parameters: the `curves` document.
fn curves_from_document<'py>(
    py: Python<'py>,
    progress: Option<&Bound<'py, PyAny>>,
    text: &str,
    (plane, selection): (ParameterizedModel2, CurveSelection),
    range: (f64, f64),
    options: ContinuationOptions,
) -> PyResult<Bound<'py, PyDict>> {
    let doc: serde_json::Value = serde_json::from_str(text)
        .map_err(|e| value_error(format!("special_points: not a branch document: {e}")))?;
    let read = branch_special_points(&doc, &plane.document, &plane.p)
        .map_err(|e| value_error(format!("special_points: {e}")))?;
    let out = monitor::run(py, progress, move |p: &Progress| {
        let shooting = ShootingOptions {
            subharmonic: read.subharmonic,
            interrupt: Some(p.interrupt.clone()),
            ..options.shooting
        };
        let origin = BranchOrigin {
            special: &read.special,
            symmetric: read.symmetric,
            range,
            q0: plane.q.initial,
        };
        let names = (plane.p.name.clone(), plane.q.name.clone());
        curves_of_branch(plane, origin, &selection, (&shooting, options.krylov))
            .map(|c| curves_document(&c, &names.0, &names.1))
    })?;
    let doc = out.map_err(|e| match e {
        CurvesError::Field(f) => value_error(f),
        other => numerical_error(other),
    })?;
    Ok(to_python(py, &doc)?.cast_into::<PyDict>()?)
}

/// How the work of [`continue_branch`] failed.
enum Failure {
    Study(StudyError),
    Curves(CurvesError),
}
