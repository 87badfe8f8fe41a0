//! Figures drawn by more than one command or by a command and the report.

use vibroimpact::continuation::{Branch, SpecialKind};
use vibroimpact::maps::basins::Basins;
use vibroimpact::maps::chart::{Chart, ChartCell};
use vibroimpact::maps::sweep::{Direction, SweepSummary};

use crate::plot::{Figure, LegendPosition, Marker, Series};

/// The marker and palette colour of each kind of special point: a shape
/// and a colour of its own (the shapes those of Python's figure).
const SPECIAL_MARKERS: [(SpecialKind, Marker, usize); 5] = [
    (SpecialKind::Fold, Marker::Circle, 3),
    (SpecialKind::BranchPoint, Marker::Square, 5),
    (SpecialKind::PeriodDoubling, Marker::Diamond, 1),
    (SpecialKind::NeimarkSacker, Marker::Triangle, 4),
    (SpecialKind::Grazing, Marker::Cross, 6),
];

/// One vertex of a drawn branch: a point (with its stability) or a special
/// point between two (None).
type Vertex = ((f64, f64), Option<bool>);

/// The vertices of `branch` in order: its points, and after each point the
/// special points located after it that carry their own amplitude (so the
/// curve passes through them).
fn vertices(branch: &Branch, x_scale: f64, body: usize) -> Vec<Vertex> {
    let mut out = Vec::with_capacity(branch.points.len() + branch.special.len());
    for (i, p) in branch.points.iter().enumerate() {
        let Some(&u) = p.max_displacement.get(body) else {
            continue;
        };
        out.push(((p.parameter * x_scale, 1e3 * u), Some(p.stable)));
        let mut after: Vec<_> = branch
            .special
            .iter()
            .filter(|s| s.after_point == i)
            .filter_map(|s| Some((s.parameter, *s.max_displacement.get(body)?)))
            .collect();
        // Along the step from point i: nearest first.
        after.sort_by(|a, b| {
            (a.0 - p.parameter)
                .abs()
                .total_cmp(&(b.0 - p.parameter).abs())
        });
        out.extend(
            after
                .into_iter()
                .map(|(q, u)| ((q * x_scale, 1e3 * u), None)),
        );
    }
    out
}

/// Frequency-response figure: max |u| of the first body against the
/// parameter, stable solid, unstable dashed, through the special points,
/// which are marked and labelled (`BP1`, `GR2`, …).
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
        let v = vertices(branch, x_scale, body);
        // A segment is drawn as the point it starts from is stable, or
        // from a special point as the next point.
        let style = |k: usize| {
            v[k].1
                .or_else(|| v[k + 1..].iter().find_map(|w| w.1))
                .unwrap_or(true)
        };
        let (mut stable_labelled, mut unstable_labelled) = (false, false);
        let mut start = 0;
        while start + 1 < v.len() {
            let stable = style(start);
            let mut end = start + 1;
            while end + 1 < v.len() && style(end) == stable {
                end += 1;
            }
            let seg: Vec<(f64, f64)> = v[start..=end].iter().map(|w| w.0).collect();
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
        for (kind, marker, c) in SPECIAL_MARKERS {
            let (sp, tags): (Vec<(f64, f64)>, Vec<String>) = branch
                .special
                .iter()
                .filter(|s| s.kind == kind)
                .filter_map(|s| {
                    // Its own amplitude; from a file without it, the nearest
                    // point's.
                    let own = s.max_displacement.get(body).copied();
                    let near = || {
                        let p = &branch.points[s.after_point.min(branch.points.len() - 1)];
                        p.max_displacement.get(body).copied()
                    };
                    let u = own.or_else(near)?;
                    Some(((s.parameter * x_scale, 1e3 * u), s.label.clone()))
                })
                .unzip();
            if !sp.is_empty() {
                // Each kind in the legend once, wherever it first appears.
                let name = if labelled.contains(&kind) {
                    ""
                } else {
                    labelled.push(kind);
                    kind.name()
                };
                fig.push(
                    Series::markers(name, sp, marker)
                        .with_color(c)
                        .with_tags(tags),
                );
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

/// The classes of the figure: periods 1–4, 5 and more, non-periodic (with
/// Lyapunov exponents split into chaotic and not), failed.
pub const CLASSES: [&str; 8] = [
    "period 1",
    "period 2",
    "period 3",
    "period 4",
    "period ≥ 5",
    "not periodic (or settling)",
    "chaotic (λ1 > 0)",
    "failed",
];

/// The class (index into [`CLASSES`]) of a cell: that of its first run.
pub fn class(cell: &ChartCell) -> usize {
    let Some(run) = cell.runs.first() else {
        return 7;
    };
    match (run.error.is_some(), run.period, run.lyapunov) {
        (true, _, _) => 7,
        (false, Some(p), _) => (p.min(5)) - 1,
        (false, None, Some(l)) if l > 0.0 => 6,
        (false, None, _) => 5,
    }
}

/// The chart's figure: a rectangle per cell coloured by its class, cells
/// with coexisting attractors marked.
pub fn chart_figure(chart: &Chart) -> Figure {
    let mut fig = Figure::new(
        "Attractor of the model's initial state",
        parameter_label(&chart.x_name),
        parameter_label(&chart.y_name),
    )
    .legend_at(LegendPosition::Outside);
    let classes: Vec<usize> = chart.cells.iter().map(class).collect();
    let labels: Vec<String> = CLASSES.iter().map(|c| c.to_string()).collect();
    let colors: Vec<usize> = (0..CLASSES.len()).collect();
    class_map(
        &mut fig,
        &chart.x_values,
        &chart.y_values,
        &classes,
        &labels,
        &colors,
    );
    let coexisting: Vec<(f64, f64)> = chart
        .cells
        .iter()
        .filter(|c| c.attractors > 1)
        .map(|c| (c.x, c.y))
        .collect();
    if !coexisting.is_empty() {
        fig.push(
            Series::markers("coexisting attractors", coexisting, Marker::Triangle).with_color(9),
        );
    }
    fig
}

/// A continued curve of special points over a chart, by kind, each kind
/// a colour and a dash of its own: black folds (solid), sky-blue branch
/// points (dashed), vermillion period doublings (dashed), purple
/// Neimark–Sacker points (solid) and black grazings (dashed); over a
/// white halo, so that it stays visible over cells of every colour (black
/// chaotic ones included).
pub fn curve_series(kind: &str, label: String, points: Vec<(f64, f64)>) -> Series {
    match kind {
        "fold" => Series::line(label, points).with_color(6),
        "branch-point" => Series::dashed(label, points).with_color(5),
        "neimark-sacker" => Series::line(label, points).with_color(4),
        "grazing" => Series::dashed(label, points).with_color(6),
        _ => Series::dashed(label, points).with_color(1),
    }
    .with_halo()
}

/// Legend text of attractor `k`.
pub fn attractor_label(b: &Basins, k: usize) -> String {
    let a = &b.attractors[k];
    let kind = a
        .period
        .map_or("not periodic".to_string(), |p| format!("period {p}"));
    format!(
        "A{}: {kind}, {:.1} impacts/T ({:.1} %)",
        k + 1,
        a.impacts_per_period,
        100.0 * a.fraction
    )
}

/// The basins as coloured rectangles, grey where no attractor
/// (overlapping or failed start).
pub fn basins_figure(b: &Basins) -> Figure {
    let unit = |c: &str| if c.starts_with('u') { "[m]" } else { "[m/s]" };
    let mut fig = Figure::new(
        "Basins of attraction",
        format!("{} at t = 0  {}", b.x_component, unit(&b.x_component)),
        format!("{} at t = 0  {}", b.y_component, unit(&b.y_component)),
    )
    .legend_at(LegendPosition::Outside);
    let none = b.attractors.len();
    let classes: Vec<usize> = b.cells.iter().map(|c| c.unwrap_or(none)).collect();
    let mut labels: Vec<String> = (0..none).map(|k| attractor_label(b, k)).collect();
    labels.push("no attractor (overlap or failure)".into());
    let mut colors: Vec<usize> = (0..none).map(|k| if k >= 7 { k + 1 } else { k }).collect();
    colors.push(7);
    class_map(
        &mut fig,
        &b.x_values,
        &b.y_values,
        &classes,
        &labels,
        &colors,
    );
    fig
}

/// The largest Lyapunov exponent against the parameter, the zero line
/// dashed: the companion of the diagram (positive: chaos).
pub fn lyapunov_figure(summary: &SweepSummary, directions: &[Direction]) -> Figure {
    let mut fig = Figure::new(
        "Largest Lyapunov exponent over the recorded periods",
        parameter_label(&summary.parameter_name),
        "λ1  [1/s]",
    )
    .legend_at(if summary.up_down {
        LegendPosition::Best
    } else {
        LegendPosition::None
    });
    for (c, d) in directions.iter().enumerate() {
        let pts: Vec<(f64, f64)> = summary
            .points
            .iter()
            .filter(|p| p.direction == *d)
            .filter_map(|p| Some((p.parameter, *p.lyapunov.as_ref()?.first()?)))
            .collect();
        let label = if summary.up_down { d.name() } else { "" };
        fig.push(Series::line(label, pts).with_color(c));
    }
    fig.push(Series::dashed("", vec![(summary.from, 0.0), (summary.to, 0.0)]).with_color(7));
    fig
}

/// Axis label of a swept parameter.
pub fn parameter_label(name: &str) -> String {
    match name {
        "frequency" | "excitation.frequency" => return "forcing frequency Ω  [rad/s]".into(),
        "amplitude" | "excitation.amplitude" => {
            return "base acceleration amplitude  [m/s²]".into()
        }
        _ => {}
    }
    // A model key's units from its last name (issue 38: axes read
    // "frequency" and "amplitude" with no units).
    let last = name.rsplit('.').next().unwrap_or(name);
    let units = match last {
        "mass" => "kg",
        "stiffness" => "N/m",
        "damping" => "N s/m",
        "clearance" | "displacement" => "m",
        "velocity" => "m/s",
        "frequency" | "natural_frequency" => "rad/s",
        "phase" => "rad",
        "alpha" => "1/m",
        "amplitude" if name.starts_with("force") => "N",
        "amplitude" => "m/s²",
        "a" => "N",
        _ => return name.to_string(),
    };
    format!("{name}  [{units}]")
}

/// The directions of a sweep's points: up and down, or the one.
pub fn sweep_directions(summary: &SweepSummary) -> Vec<Direction> {
    if summary.up_down {
        vec![Direction::Up, Direction::Down]
    } else {
        vec![Direction::None]
    }
}

/// The brute-force bifurcation diagram: the Poincaré samples of the first
/// body against the parameter (up and down apart).
pub fn diagram_figure(summary: &SweepSummary) -> Figure {
    let first = summary.bodies.first().cloned().unwrap_or_default();
    let mut fig = Figure::new(
        format!("Poincaré samples of {first}"),
        parameter_label(&summary.parameter_name),
        format!("u_{first} at t = kT  [mm]"),
    )
    .legend_at(if summary.up_down {
        LegendPosition::Best
    } else {
        LegendPosition::None
    });
    for (c, d) in sweep_directions(summary).iter().enumerate() {
        let pts: Vec<(f64, f64)> = summary
            .points
            .iter()
            .filter(|p| p.direction == *d)
            .flat_map(|p| p.sections.iter().map(move |s| (p.parameter, 1e3 * s[0])))
            .collect();
        let label = if summary.up_down { d.name() } else { "" };
        fig.push(Series::markers(label, pts, Marker::Dot).with_color(c));
    }
    fig
}

#[cfg(test)]
mod tests {
    use super::parameter_label;

    /// Axes carry their units (issue 38: "frequency" and "amplitude" had
    /// none): the excitation's, and a model key's by its last name.
    #[test]
    fn parameter_axes_carry_units() {
        assert_eq!(parameter_label("frequency"), "forcing frequency Ω  [rad/s]");
        assert_eq!(
            parameter_label("amplitude"),
            "base acceleration amplitude  [m/s²]"
        );
        assert_eq!(parameter_label("row.mass"), "row.mass  [kg]");
        assert_eq!(parameter_label("row.clearance"), "row.clearance  [m]");
        assert_eq!(
            parameter_label("force.1.amplitude"),
            "force.1.amplitude  [N]"
        );
        assert_eq!(parameter_label("row.count"), "row.count");
    }
}
