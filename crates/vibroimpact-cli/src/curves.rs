//! `continue --parameter2`: the two-parameter curves through the special
//! points of a one-parameter branch ([`vibroimpact::continuation::continue_curve`]),
//! their JSON and figure.

use std::path::{Path, PathBuf};

use clap::Args;
use serde_json::{json, Value};
use vibroimpact::continuation::{
    continue_curve, grazing_margin, starts_grazing, Curve, CurveKind, CurveOptions, CurveStop,
    SpecialKind, SpecialPoint,
};
use vibroimpact::family::{Family2, ParameterizedModel2};
use vibroimpact::model_file::ModelDocument;
use vibroimpact::parameter::ModelParameter;
use vibroimpact::periodic::ShootingOptions;

use crate::error::CliError;
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Marker, Series};

/// The second parameter of `continue` and the curves to follow.
#[derive(Args, Debug)]
pub struct SecondParameter {
    /// A second parameter: continue every fold, branch point, period
    /// doubling, Neimark–Sacker point and grazing of the branch (or those
    /// of --curves) as a curve in both parameters, with the
    /// codimension-two points on it (`curves.json`, figure `curves`).
    #[arg(long)]
    pub parameter2: Option<String>,
    /// Lower bound of the second parameter (default: 0, or half its value
    /// if negative).
    #[arg(long, allow_hyphen_values = true)]
    pub from2: Option<f64>,
    /// Upper bound of the second parameter (default: twice its value).
    #[arg(long, allow_hyphen_values = true)]
    pub to2: Option<f64>,
    /// Kinds of special points to continue, comma separated: fold, bp, pd,
    /// ns, grazing.
    #[arg(long, value_delimiter = ',', default_value = "fold,bp,pd,ns,grazing")]
    pub curves: Vec<String>,
    /// Largest step along a curve (arclength in scaled variables: the
    /// orbit in displacement scales, the parameters relative to their
    /// start values); larger is faster and coarser, the special points on
    /// the curves are located all the same.
    #[arg(long, default_value_t = 0.05)]
    pub curve_step: f64,
    /// Start the curves from the special points of an earlier run's
    /// `branch.json` (`continue --out`: its `special_points`, `symmetric`
    /// and `subharmonic`) instead of computing the branch again.
    #[arg(long)]
    pub special_points: Option<PathBuf>,
}

/// The special points of a `branch.json`, whether the branch is on the
/// half map, and its period multiple; its parameter must be `first`.
pub fn read_special_points(
    path: &Path,
    document: &ModelDocument,
    first: &ModelParameter,
) -> Result<(Vec<SpecialPoint>, bool, u32), CliError> {
    let at = |what: String| CliError::new(format!("{}: {what}", path.display()));
    let text = crate::input::read_text(path).map_err(|e| at(e.to_string()))?;
    let doc: Value = serde_json::from_str(&text)
        .map_err(|e| at(format!("not a branch.json of `continue --out`: {e}")))?;
    let name = doc["parameter_name"]
        .as_str()
        .ok_or_else(|| at("no `parameter_name`".into()))?;
    let key = document.parameter(name).map(|p| p.key).ok();
    if key.as_ref() != Some(&first.key) {
        return Err(at(format!(
            "a branch in `{name}`, not in --parameter {}",
            first.name
        )));
    }
    let symmetric = doc["symmetric"]
        .as_bool()
        .ok_or_else(|| at("no `symmetric`".into()))?;
    let subharmonic = doc["subharmonic"]
        .as_u64()
        .and_then(|n| u32::try_from(n).ok())
        .filter(|&n| n >= 1)
        .ok_or_else(|| at("no `subharmonic` (a whole number ≥ 1)".into()))?;
    let list = doc["special_points"]
        .as_array()
        .ok_or_else(|| at("no `special_points` list".into()))?;
    let mut out = Vec::new();
    for (k, s) in list.iter().enumerate() {
        let field = |f: &str| at(format!("special_points[{k}]: no valid `{f}`"));
        let kind = match s["kind"].as_str() {
            Some("fold") => SpecialKind::Fold,
            Some("branch-point") => SpecialKind::BranchPoint,
            Some("period-doubling") => SpecialKind::PeriodDoubling,
            Some("neimark-sacker") => SpecialKind::NeimarkSacker,
            Some("grazing") => SpecialKind::Grazing,
            Some("user") => SpecialKind::User,
            _ => return Err(field("kind")),
        };
        let state: Vec<f64> = s["initial_state"]
            .as_array()
            .ok_or_else(|| field("initial_state"))?
            .iter()
            .map(|v| v.as_f64().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| field("initial_state"))?;
        out.push(SpecialPoint {
            kind,
            label: s["label"]
                .as_str()
                .ok_or_else(|| field("label"))?
                .to_string(),
            parameter: s["parameter"]
                .as_f64()
                .filter(|v| v.is_finite())
                .ok_or_else(|| field("parameter"))?,
            state,
            multipliers: Vec::new(),
            tangent: Vec::new(),
            after_point: 0,
            symmetry_breaking: s["symmetry_breaking"]
                .as_bool()
                .ok_or_else(|| field("symmetry_breaking"))?,
        });
    }
    Ok((out, symmetric, subharmonic))
}

/// The names --curves takes.
const CURVE_NAMES: [&str; 5] = ["fold", "bp", "pd", "ns", "grazing"];

/// The curve kind of a special point, if one is followed.
fn kind_of(kind: SpecialKind, symmetry_breaking: bool, wanted: &[String]) -> Option<CurveKind> {
    let (k, name) = match kind {
        SpecialKind::Fold => (CurveKind::Fold, "fold"),
        SpecialKind::BranchPoint if symmetry_breaking => (CurveKind::BranchPoint, "bp"),
        SpecialKind::PeriodDoubling => (CurveKind::PeriodDoubling, "pd"),
        SpecialKind::NeimarkSacker => (CurveKind::NeimarkSacker, "ns"),
        SpecialKind::Grazing => (CurveKind::Grazing, "grazing"),
        SpecialKind::BranchPoint | SpecialKind::User => return None,
    };
    wanted.iter().any(|w| w == name).then_some(k)
}

/// Checks --curves and --parameter2 against the first parameter.
pub fn validate(
    second: &SecondParameter,
    document: &ModelDocument,
    first: &ModelParameter,
) -> Result<Option<ModelParameter>, CliError> {
    if !(second.curve_step.is_finite() && second.curve_step > 0.0) {
        return Err(CliError::new(format!(
            "--curve-step {}: give a positive step",
            second.curve_step
        )));
    }
    for c in &second.curves {
        if !CURVE_NAMES.contains(&c.as_str()) {
            return Err(CliError::new(format!(
                "--curves {c}: give any of {}",
                CURVE_NAMES.join(", ")
            )));
        }
    }
    let Some(name) = &second.parameter2 else {
        if second.special_points.is_some() {
            return Err(CliError::new(
                "--special-points: give --parameter2 too (the curves' second parameter)",
            ));
        }
        return Ok(None);
    };
    let q = document.parameter(name)?;
    if q.key == first.key {
        return Err(CliError::new(format!(
            "--parameter2 {name}: the same key as --parameter {}; give another",
            first.name
        )));
    }
    Ok(Some(q))
}

/// The curves of a branch's special points.
#[derive(Debug)]
pub struct Curves {
    /// Each curve with the label of the special point it starts from.
    pub followed: Vec<(String, Curve)>,
    /// Special points without a curve (label, why): a change of the impact
    /// count that is an impact splitting in two, not a grazing.
    pub skipped: Vec<(String, String)>,
}

/// Every curve through the wanted special points (both directions from
/// each) of a branch (on the half map if `symmetric`), within `[from, to]`
/// of the first parameter and the second parameter's bounds.
pub fn curves(
    document: &ModelDocument,
    (p, q): (&ModelParameter, &ModelParameter),
    (special, symmetric): (&[SpecialPoint], bool),
    (from, to): (f64, f64),
    second: &SecondParameter,
    (shooting, krylov): (&ShootingOptions, Option<usize>),
) -> Result<Curves, CliError> {
    let q0 = q.initial;
    let lo = second
        .from2
        .unwrap_or(if q0 >= 0.0 { 0.0 } else { 2.0 * q0 });
    let hi = second
        .to2
        .unwrap_or(if q0 >= 0.0 { 2.0 * q0 } else { 0.5 * q0 });
    if !(lo < hi && lo <= q0 && q0 <= hi) {
        return Err(CliError::new(format!(
            "--from2 {lo} --to2 {hi}: a range around the model's {} = {q0}",
            q.name
        )));
    }
    let opts = CurveOptions {
        shooting: ShootingOptions {
            symmetric,
            ..shooting.clone()
        },
        bounds: [(from.min(to), from.max(to)), (lo, hi)],
        ds_max: second.curve_step,
        ds: second.curve_step.min(CurveOptions::default().ds),
        krylov,
        ..CurveOptions::default()
    };
    let mut out: Vec<(String, Curve)> = Vec::new();
    let mut skipped = Vec::new();
    let mut family = ParameterizedModel2 {
        document: document.clone(),
        p: p.clone(),
        q: q.clone(),
    };
    for s in special {
        let Some(kind) = kind_of(s.kind, s.symmetry_breaking, &second.curves) else {
            continue;
        };
        // A special point that a curve already passed (both BPs of R2 N = 1
        // lie on one closed curve) is not followed again.
        if out
            .iter()
            .any(|(_, c)| c.kind == kind && passes(c, s.parameter, q0))
        {
            continue;
        }
        if krylov.is_some() && matches!(kind, CurveKind::NeimarkSacker | CurveKind::Grazing) {
            skipped.push((
                s.label.clone(),
                format!(
                    "{} curves have no matrix-free form yet (the dense form takes rows up to 2048 bodies: --dense)",
                    kind.name()
                ),
            ));
            continue;
        }
        if kind == CurveKind::Grazing {
            let model = family.model_at(s.parameter, q0)?;
            let margin = grazing_margin(&model, &s.state, &opts.shooting).map_err(CliError::new)?;
            if !starts_grazing(margin, &opts.shooting) {
                skipped.push((
                    s.label.clone(),
                    format!("an impact splits in two: no contact's closest approach grazes (margin {margin:.2e} m)"),
                ));
                continue;
            }
        }
        for direction in [1.0, -1.0] {
            let curve = continue_curve(
                &mut family,
                kind,
                (&s.state, s.parameter, q0),
                direction,
                &opts,
            )
            .map_err(|e| {
                CliError::new(format!("the {} curve from {}: {e}", kind.name(), s.label))
            })?;
            let closed = curve.stop == CurveStop::Closed;
            out.push((s.label.clone(), curve));
            if closed {
                break;
            }
        }
    }
    Ok(Curves {
        followed: out,
        skipped,
    })
}

/// Whether the curve crosses the second parameter's value `q0` at the
/// first parameter `p0`: within 1e-4 relative, or a quarter of the chord's
/// extent in p (the chord between two points misses a bending curve).
fn passes(curve: &Curve, p0: f64, q0: f64) -> bool {
    curve.points.windows(2).any(|w| {
        let (a, b) = (&w[0], &w[1]);
        if (a.q - q0) * (b.q - q0) > 0.0 || a.q == b.q {
            return false;
        }
        let p = a.p + (q0 - a.q) / (b.q - a.q) * (b.p - a.p);
        (p - p0).abs() <= (1e-4 * p0.abs()).max(0.25 * (b.p - a.p).abs())
    })
}

/// The `curves` document: each curve with its kind, start label, stop,
/// points (both parameters, max |u| per body, multipliers) and its
/// codimension-two points (kind, index in `points`, both parameters).
pub fn curves_document(curves: &Curves, p: &str, q: &str) -> Value {
    let list: Vec<Value> = curves
        .followed
        .iter()
        .map(|(label, c)| {
            json!({
                "kind": c.kind.name(),
                "from": label,
                "stop": c.stop,
                "special": c.special.iter().map(|sp| {
                    let pt = &c.points[sp.point];
                    json!({ "kind": sp.kind.name(), "point": sp.point, p: pt.p, q: pt.q })
                }).collect::<Vec<_>>(),
                "points": c.points.iter().map(|pt| json!({
                    p: pt.p,
                    q: pt.q,
                    "max_displacement": pt.max_displacement,
                    "floquet_multipliers": pt.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
                    "initial_state": pt.state,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let skipped: Vec<Value> = curves
        .skipped
        .iter()
        .map(|(label, why)| json!({ "from": label, "reason": why }))
        .collect();
    json!({ "parameter": p, "parameter2": q, "curves": list, "skipped": skipped })
}

/// Writes curves.json and the figure of the curves in the parameter plane.
pub fn write_curves(dir: &Path, curves: &Curves, p: &str, q: &str) -> Result<(), CliError> {
    ensure_dir(dir)?;
    let doc = curves_document(curves, p, q);
    write_atomic(
        &dir.join("curves.json"),
        serde_json::to_string_pretty(&doc)?.as_bytes(),
    )?;
    let mut fig = Figure::new("Curves of special points", p, q).legend_at(LegendPosition::Best);
    let mut labelled = Vec::new();
    for (_, c) in &curves.followed {
        let color = match c.kind {
            CurveKind::Fold => 0,
            CurveKind::BranchPoint => 1,
            CurveKind::PeriodDoubling => 2,
            CurveKind::NeimarkSacker => 3,
            CurveKind::Grazing => 4,
        };
        let label = if labelled.contains(&color) {
            ""
        } else {
            c.kind.name()
        };
        labelled.push(color);
        fig.push(Series::line(label, c.points.iter().map(|pt| (pt.p, pt.q))).with_color(color));
    }
    let codim2: Vec<(f64, f64)> = curves
        .followed
        .iter()
        .flat_map(|(_, c)| {
            c.special
                .iter()
                .map(|sp| (c.points[sp.point].p, c.points[sp.point].q))
        })
        .collect();
    if !codim2.is_empty() {
        fig.push(Series::markers("codimension two", codim2, Marker::Square).with_color(5));
    }
    render(&fig, &dir.join("curves"))?;
    Ok(())
}
