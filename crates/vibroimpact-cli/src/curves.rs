//! `continue --parameter2`: the two-parameter curves through the special
//! points of a one-parameter branch ([`vibroimpact::continuation::continue_curve`]),
//! their JSON and figure.

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::continuation::BranchSpecialPoints;
use vibroimpact::continuation::{CurveKind, CurveSelection, Curves};
use vibroimpact::model::file::ModelDocument;
use vibroimpact::model::parameter::ModelParameter;
use vibroimpact::results::{branch_special_points, curves_document};

use crate::error::{option_error, CliError};
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
    #[arg(long, requires = "parameter2")]
    pub special_points: Option<PathBuf>,
}

/// The special points of a `branch.json` (`continue --out`) whose
/// parameter must be `first`.
pub fn read_special_points(
    path: &Path,
    document: &ModelDocument,
    first: &ModelParameter,
) -> Result<BranchSpecialPoints, CliError> {
    let at = |what: String| CliError::new(format!("{}: {what}", path.display()));
    let text = crate::input::read_text(path).map_err(|e| at(e.to_string()))?;
    let doc = serde_json::from_str(&text)
        .map_err(|e| at(format!("not a branch.json of `continue --out`: {e}")))?;
    branch_special_points(&doc, document, first).map_err(|e| at(e.to_string()))
}

impl SecondParameter {
    /// The library's selection of curves.
    pub fn selection(&self) -> Result<CurveSelection, CliError> {
        let selection = CurveSelection {
            kinds: CurveSelection::kinds_named(&self.curves).map_err(|e| option_error(&e))?,
            bounds2: (self.from2, self.to2),
            step: self.curve_step,
        };
        selection.check().map_err(|e| option_error(&e))?;
        Ok(selection)
    }
}

/// Writes curves.json and the figure of the curves in the parameter plane.
pub fn write_curves(dir: &Path, curves: &Curves, p: &str, q: &str) -> Result<(), CliError> {
    ensure_dir(dir)?;
    let doc = curves_document(curves, p, q);
    write_atomic(
        &dir.join("curves.json"),
        serde_json::to_string_pretty(&doc)?.as_bytes(),
    )?;
    let mut fig = Figure::new(
        "Curves of special points",
        crate::figures::parameter_label(p),
        crate::figures::parameter_label(q),
    )
    .legend_at(LegendPosition::Best);
    let mut labelled = Vec::new();
    for (_, c) in &curves.followed {
        // A colour and a dash per kind, none two alike.
        let (color, dashed) = match c.kind {
            CurveKind::Fold => (6, false),
            CurveKind::BranchPoint => (0, true),
            CurveKind::PeriodDoubling => (1, true),
            CurveKind::NeimarkSacker => (2, false),
            CurveKind::Grazing => (4, false),
        };
        let label = if labelled.contains(&color) {
            ""
        } else {
            c.kind.name()
        };
        labelled.push(color);
        let points = c.points.iter().map(|pt| (pt.p, pt.q));
        let series = if dashed {
            Series::dashed(label, points)
        } else {
            Series::line(label, points)
        };
        fig.push(series.with_color(color));
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
        fig.push(Series::markers("codimension two", codim2, Marker::Square).with_color(3));
    }
    render(&fig, &dir.join("curves"))?;
    Ok(())
}
