//! Figures drawn by more than one command or by a command and the report.

use vibroimpact::continuation::{Branch, SpecialKind};

use crate::plot::{Figure, LegendPosition, Marker, Series};

/// Frequency-response figure: max |u| of the first body against the
/// parameter, stable solid, unstable dashed, special points marked.
pub fn branch_figure(
    branches: &[(&Branch, &str)],
    title: &str,
    x_label: &str,
    x_scale: f64,
    body: usize,
) -> Figure {
    let mut fig = Figure::new(title, x_label, "max |u| over the period  [mm]")
        .legend_at(LegendPosition::Best);
    let mut labelled: Vec<SpecialKind> = Vec::new();
    for (bi, (branch, name)) in branches.iter().enumerate() {
        let color = 2 * bi;
        let mut start = 0;
        let pts = &branch.points;
        let (mut stable_labelled, mut unstable_labelled) = (false, false);
        while start < pts.len() {
            let stable = pts[start].stable;
            let mut end = start + 1;
            while end < pts.len() && pts[end].stable == stable {
                end += 1;
            }
            let seg: Vec<(f64, f64)> = pts[start..(end + 1).min(pts.len())]
                .iter()
                .map(|p| (p.parameter * x_scale, 1e3 * p.max_displacement[body]))
                .collect();
            let label = match (stable, stable_labelled, unstable_labelled) {
                (true, false, _) => {
                    stable_labelled = true;
                    format!("{name}, stable")
                }
                (false, _, false) => {
                    unstable_labelled = true;
                    format!("{name}, unstable")
                }
                _ => String::new(),
            };
            fig.push(
                if stable {
                    Series::line(label, seg)
                } else {
                    Series::dashed(label, seg)
                }
                .with_color(color),
            );
            start = end;
        }
        for (kind, marker, c) in [
            (SpecialKind::Fold, Marker::Triangle, 1),
            (SpecialKind::PeriodDoubling, Marker::Square, 3),
            (SpecialKind::BranchPoint, Marker::Circle, 4),
            (SpecialKind::NeimarkSacker, Marker::Triangle, 5),
        ] {
            let sp: Vec<(f64, f64)> = branch
                .special
                .iter()
                .filter(|s| s.kind == kind)
                .filter_map(|s| {
                    let p = &branch.points[s.after_point.min(pts.len() - 1)];
                    Some((s.parameter * x_scale, 1e3 * p.max_displacement.get(body)?))
                })
                .collect();
            if !sp.is_empty() {
                // Each kind in the legend once, wherever it first appears.
                let name = if labelled.contains(&kind) {
                    ""
                } else {
                    labelled.push(kind);
                    kind.name()
                };
                fig.push(Series::markers(name, sp, marker).with_color(c));
            }
        }
    }
    fig
}
