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

/// Half the spacing of `values` either side of index `i` (a cell's extent).
fn half_widths(values: &[f64], i: usize) -> (f64, f64) {
    let step = |a: usize, b: usize| 0.5 * (values[b] - values[a]);
    let left = if i > 0 {
        step(i - 1, i)
    } else {
        step(i, i + 1)
    };
    let right = if i + 1 < values.len() {
        step(i, i + 1)
    } else {
        step(i - 1, i)
    };
    (left, right)
}

/// A grid of `xs` × `ys` cells (row by row) coloured by class: one series
/// of rectangles per class that occurs, labelled `labels[class]` with
/// palette colour `colors[class]` (runs of equal cells along a row merged
/// into one rectangle). `ys.len() * xs.len()` classes, each `< labels.len()`.
pub fn class_map(
    fig: &mut Figure,
    xs: &[f64],
    ys: &[f64],
    classes: &[usize],
    labels: &[String],
    colors: &[usize],
) {
    let mut rects: Vec<Vec<(f64, f64, f64, f64)>> = vec![Vec::new(); labels.len()];
    for (j, &y) in ys.iter().enumerate() {
        let row = &classes[j * xs.len()..(j + 1) * xs.len()];
        let (down, up) = half_widths(ys, j);
        let mut i = 0;
        while i < row.len() {
            let mut k = i;
            while k + 1 < row.len() && row[k + 1] == row[i] {
                k += 1;
            }
            let x0 = xs[i] - half_widths(xs, i).0;
            let x1 = xs[k] + half_widths(xs, k).1;
            rects[row[i]].push((x0, y - down, x1, y + up));
            i = k + 1;
        }
    }
    for ((r, label), &color) in rects.into_iter().zip(labels).zip(colors) {
        if !r.is_empty() {
            fig.push(Series::rectangles(label.clone(), r).with_color(color));
        }
    }
}
