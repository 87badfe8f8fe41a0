//! Section "Maps of the motion" (docs/theory.md §7–§9): brute-force
//! stability charts of R2 N = 1 and N = 2 in (frequency, amplitude) with
//! the continued curves of special points drawn over them, the largest
//! Lyapunov exponent of N = 2 under its brute-force diagram, and the basins
//! of N = 2's coexisting attractors at 1.1 ω0. [`compute`] runs the
//! studies; [`render`] writes the section.

use std::time::Instant;

use vibroimpact::continuation::{
    Branch, BranchStudy, ContinuationOptions, ContinueStudy, Curve, CurveKind, CurveSelection,
    Curves, CurvesRequest, Linear, Start,
};
use vibroimpact::integrate::Interrupt;
use vibroimpact::maps::basins::{basins, Basins, Component};
use vibroimpact::maps::chart::{chart, Chart, ChartOptions};
use vibroimpact::maps::sweep::{sweep, SweepOptions, SweepSummary};
use vibroimpact::model::file::ModelDocument;
use vibroimpact::model::parameter::ParameterizedModel;
use vibroimpact::model::reference::NATURAL_FREQUENCY as W0;
use vibroimpact::periodic::ShootingOptions;

use super::{html_table, DataFile, Report};
use crate::error::CliError;
use crate::figures::{
    basins_figure, chart_figure, class, curve_series, diagram_figure, lyapunov_figure,
    sweep_directions, CLASSES,
};
use crate::plot::{Figure, Marker, Series};

/// The R2 model file with N = 2 (the other sizes by its `count`).
const ROW_N2: &str = include_str!("../../../../examples/fujita-row-n2.toml");

/// The plane of the charts: Ω from 0.5 to 1.5 ω0, base amplitude (m/s²).
const FREQUENCY: (f64, f64) = (0.5 * W0, 1.5 * W0);
const AMPLITUDE: (f64, f64) = (0.005, 0.1);

/// Cells per chart (frequency × amplitude) and transient periods, by N:
/// the lightly damped rows need long transients to settle.
const GRIDS: [(usize, usize, usize, usize); 2] = [(1, 40, 24, 100), (2, 32, 20, 150)];

/// Largest step along the curves (twice the command's default: the
/// special points on them are located all the same).
const CURVE_STEP: f64 = 0.1;

/// The chart and the curves of one row size.
pub(super) struct RowMap {
    pub n: usize,
    pub chart: Chart,
    /// The one-parameter branch the curves start from (at 0.05 m/s²).
    pub branch: Branch,
    pub curves: Curves,
}

/// Every study of the section.
pub(super) struct Maps {
    pub rows: Vec<RowMap>,
    /// R2 N = 2 brute force with λ1 at every frequency.
    pub sweep: SweepSummary,
    /// R2 N = 2 at 1.1 ω0 over (u1, v1) at t = 0.
    pub basins: Basins,
}

fn document(n: usize) -> Result<ModelDocument, CliError> {
    let text = ROW_N2.replace("count = 2", &format!("count = {n}"));
    Ok(ModelDocument::from_toml(
        &text,
        "examples/fujita-row-n2.toml",
    )?)
}

fn grid((a, b): (f64, f64), n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| a + (b - a) * i as f64 / (n - 1) as f64)
        .collect()
}

fn runs(transient: usize, record: usize, stop: &Interrupt) -> SweepOptions {
    SweepOptions {
        transient,
        record,
        interrupt: Some(stop.clone()),
        ..SweepOptions::default()
    }
}

/// Frequencies of the N = 2 orbit diagram (and its Lyapunov exponents).
const DIAGRAM_POINTS: usize = 301;

/// Runs every study of the section; `stop` interrupts them. The charts
/// take every core; then the curves are continued on this thread while
/// the brute-force runs (diagram, basins) take one other thread, the core
/// the continuation leaves idle. Every result is the same whatever the
/// threads (each run is deterministic on its own).
pub(super) fn compute(stop: &Interrupt) -> Result<Maps, CliError> {
    let charts = GRIDS
        .iter()
        .map(|&grid| chart_of(grid, stop))
        .collect::<Result<Vec<_>, _>>()?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| CliError::new(format!("the brute-force runs' thread: {e}")))?;
    let (rows, brute) = std::thread::scope(|s| {
        let brute = s.spawn(|| pool.install(|| brute_force(stop)));
        let rows = charts
            .into_iter()
            .map(|(n, doc, chart)| with_curves(n, &doc, chart, stop))
            .collect::<Result<Vec<_>, _>>();
        (rows, brute.join())
    });
    let (sweep, basins) =
        brute.map_err(|_| CliError::new("the brute-force runs stopped unexpectedly"))??;
    Ok(Maps {
        rows: rows?,
        sweep,
        basins,
    })
}

/// The chart of one row size (`n`, cells `nx × ny`, `transient` periods).
fn chart_of(
    (n, nx, ny, transient): (usize, usize, usize, usize),
    stop: &Interrupt,
) -> Result<(usize, ModelDocument, Chart), CliError> {
    let doc = document(n)?;
    let t0 = Instant::now();
    let options = ChartOptions {
        sweep: SweepOptions {
            lyapunov: Some(1),
            ..runs(transient, 20, stop)
        },
        starts: 1,
    };
    let chart = chart(
        &doc,
        ("frequency", &grid(FREQUENCY, nx)),
        ("amplitude", &grid(AMPLITUDE, ny)),
        &options,
        &|| {},
    )
    .map_err(|e| CliError::new(e.to_string()))?;
    eprintln!(
        "R2 N = {n}: chart of {} cells in {:.1} s",
        chart.cells.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok((n, doc, chart))
}

/// The chart of `n` bodies with the curves of its branch.
fn with_curves(
    n: usize,
    doc: &ModelDocument,
    chart: Chart,
    stop: &Interrupt,
) -> Result<RowMap, CliError> {
    let t0 = Instant::now();
    let (branch, curves) = branch_and_curves(doc, stop)?;
    eprintln!(
        "R2 N = {n}: {} curves in {:.1} s",
        curves.followed.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(RowMap {
        n,
        chart,
        branch,
        curves,
    })
}

/// R2 N = 2 by brute force: the orbit diagram with λ1 over
/// [`DIAGRAM_POINTS`] frequencies, and the basins at 1.1 ω0.
fn brute_force(stop: &Interrupt) -> Result<(SweepSummary, Basins), CliError> {
    let t0 = Instant::now();
    let doc = document(2)?;
    let family = ParameterizedModel::new(doc.clone(), "frequency")?;
    let values = grid(FREQUENCY, DIAGRAM_POINTS);
    let sweep = sweep(
        &family,
        &values,
        &SweepOptions {
            lyapunov: Some(1),
            ..runs(150, 100, stop)
        },
        &|| {},
    )
    .map_err(|e| CliError::new(e.to_string()))?;
    let loaded = doc.with_parameter(family.parameter(), 1.1 * W0)?;
    let clearance = 1e-3;
    let u = grid((-0.9 * clearance, 0.9 * clearance), 20);
    let v = grid((-7.0 * clearance, 7.0 * clearance), 20);
    let basins = basins(
        &loaded,
        (Component::Displacement(0), &u),
        (Component::Velocity(0), &v),
        None,
        &runs(200, 30, stop),
        &|| {},
    )
    .map_err(|e| CliError::new(e.to_string()))?;
    eprintln!(
        "R2 N = 2: orbit diagram at {} frequencies and basins of {} states in {:.1} s",
        values.len(),
        u.len() * v.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok((sweep, basins))
}

/// The branch in frequency at the model's amplitude from its orbit at
/// 0.5 ω0 (the homotopy in the amplitude from rest), and the curves of its folds, branch points, period
/// doublings and Neimark–Sacker points in (frequency, amplitude).
fn branch_and_curves(doc: &ModelDocument, stop: &Interrupt) -> Result<(Branch, Curves), CliError> {
    let defaults = ContinuationOptions::default();
    // The orbit at 0.5 ω0 on the branch that grows from rest (a simulated
    // guess there ends a chaotic transient wherever its last bits take it).
    let study = ContinueStudy {
        parameter: "frequency".into(),
        branch: BranchStudy {
            from: FREQUENCY.0,
            to: FREQUENCY.1,
            start: Start::Homotopy,
            guess_periods: 200.0,
            switch_at: None,
            linear: Linear::Auto,
            arnoldi: 20,
            options: ContinuationOptions {
                shooting: ShootingOptions {
                    interrupt: Some(stop.clone()),
                    ..defaults.shooting.clone()
                },
                ..defaults
            },
        },
        curves: Some(CurvesRequest {
            parameter2: "amplitude".into(),
            selection: CurveSelection {
                kinds: vec![
                    CurveKind::Fold,
                    CurveKind::BranchPoint,
                    CurveKind::PeriodDoubling,
                    CurveKind::NeimarkSacker,
                ],
                bounds2: (Some(AMPLITUDE.0), Some(AMPLITUDE.1)),
                step: CURVE_STEP,
            },
        }),
    };
    let outcome = study.check(doc.clone())?.run(|_| true)?;
    let curves = outcome.curves.map(|(c, _)| c).unwrap_or_default();
    Ok((outcome.branch.branch, curves))
}

/// The chart of one row with its curves and their codimension-two points.
fn chart_with_curves(row: &RowMap) -> Figure {
    let mut fig = chart_figure(&row.chart);
    let mut labelled: Vec<&str> = Vec::new();
    for (_, c) in &row.curves.followed {
        let kind = c.kind.name();
        let label = if labelled.contains(&kind) {
            String::new()
        } else {
            labelled.push(kind);
            format!("{kind} curve")
        };
        fig.push(curve_series(kind, label, points(c)));
    }
    let codim2: Vec<(f64, f64)> = row
        .curves
        .followed
        .iter()
        .flat_map(|(_, c)| {
            c.special
                .iter()
                .map(|s| (c.points[s.point].p, c.points[s.point].q))
        })
        .collect();
    if !codim2.is_empty() {
        fig.push(
            Series::markers("codimension two", codim2, Marker::Square)
                .with_color(6)
                .with_halo(),
        );
    }
    fig
}

fn points(c: &Curve) -> Vec<(f64, f64)> {
    c.points.iter().map(|p| (p.p, p.q)).collect()
}

/// Cells per class of a chart, as table cells.
fn class_counts(chart: &Chart) -> Vec<usize> {
    let mut counts = vec![0usize; CLASSES.len()];
    for cell in &chart.cells {
        counts[class(cell)] += 1;
    }
    counts
}

/// Writes the section.
pub(super) fn render(report: &mut Report, maps: &Maps) -> Result<(), CliError> {
    report.section(
        "Maps of the motion: charts, curves of special points, Lyapunov exponents, basins",
        "<p>Where in the (frequency, amplitude) plane is the motion periodic, \
         multi-impact, chaotic, or coexisting with another attractor? \
         The brute-force charts run every cell from the model's initial state \
         (a transient, then 20 recorded periods; the period is the smallest p \
         with equal Poincaré samples, docs/theory.md §8; a non-periodic run is \
         chaotic where its largest Lyapunov exponent is positive). Over them, the \
         special points of the branch at 0.05 m/s² continued in both \
         parameters (§9): folds, symmetry-breaking branch points, period \
         doublings and Neimark–Sacker points, with the codimension-two points \
         on them. The Lyapunov exponent (§7) marks chaos on a brute-force \
         diagram, and the basins (§8) show which initial states reach which \
         attractor.</p>\n"
            .to_string(),
    );
    summary_table(report, &maps.rows);
    for row in &maps.rows {
        chart_figure_of(report, row)?;
    }
    sweep_figures(report, &maps.sweep)?;
    basins_figure_of(report, &maps.basins)
}

/// The cells per class and the curves of each row: a table and the
/// summary's counts.
fn summary_table(report: &mut Report, rows: &[RowMap]) {
    let mut table = Vec::new();
    for row in rows {
        let counts = class_counts(&row.chart);
        let codim2: usize = row
            .curves
            .followed
            .iter()
            .map(|(_, c)| c.special.len())
            .sum();
        let mut cells = vec![format!("N = {}", row.n)];
        cells.extend(counts.iter().take(7).map(|c| c.to_string()));
        cells.push(row.curves.followed.len().to_string());
        cells.push(codim2.to_string());
        table.push(cells);
        report.summary(
            &format!("chart_n{}_cells_per_class", row.n),
            serde_json::json!(CLASSES
                .iter()
                .zip(&counts)
                .map(|(k, c)| (k.to_string(), serde_json::json!(c)))
                .collect::<serde_json::Map<_, _>>()),
        );
        report.summary(
            &format!("curves_n{}", row.n),
            serde_json::json!(row
                .curves
                .followed
                .iter()
                .map(|(from, c)| serde_json::json!({
                    "kind": c.kind.name(),
                    "from": from,
                    "points": c.points.len(),
                    "special": c.special.iter().map(|s| serde_json::json!({
                        "kind": s.kind.name(),
                        "frequency": c.points[s.point].p,
                        "amplitude": c.points[s.point].q,
                    })).collect::<Vec<_>>(),
                }))
                .collect::<Vec<_>>()),
        );
    }
    let mut header = vec!["row"];
    header.extend(CLASSES.iter().take(7));
    header.extend(["curves", "codim-2 points"]);
    report.append_html(&format!(
        "<p>Cells per class and curves continued:</p>\n{}",
        html_table(&header, &table)
    ));
}

/// One row's chart with its curves, and their data.
fn chart_figure_of(report: &mut Report, row: &RowMap) -> Result<(), CliError> {
    let chart = &row.chart;
    let special: Vec<String> = row.branch.special.iter().map(|s| s.label.clone()).collect();
    let caption = format!(
        "R2 with N = {}: the attractor reached from the model's initial state in each of \
         {} × {} cells ({} transient + {} recorded periods; light blue: not periodic \
         or still settling, chaotic where such a run has λ1 > 0), and the curves of the special points {} of the branch at 0.05 m/s² \
         (black: folds solid, branch points dashed; vermillion: period doublings dashed, \
         Neimark–Sacker points solid; squares: codimension-two points on them).",
        row.n,
        chart.x_values.len(),
        chart.y_values.len(),
        chart.transient_periods,
        chart.record_periods,
        special.join(", ")
    );
    let cells = chart
        .cells
        .iter()
        .map(|c| {
            let run = c.runs.first();
            vec![
                Some(c.x),
                Some(c.y),
                Some(class(c) as f64),
                run.and_then(|r| r.period.map(|p| p as f64)),
                run.map(|r| r.impacts_per_period),
                run.map(|r| r.max_displacement),
            ]
        })
        .collect();
    let curve_rows = row
        .curves
        .followed
        .iter()
        .enumerate()
        .flat_map(|(k, (_, c))| {
            c.points
                .iter()
                .map(move |p| vec![Some(k as f64), Some(p.p), Some(p.q)])
        })
        .collect();
    report.figure(
        &chart_with_curves(row),
        &format!("fig_map_chart_n{}", row.n),
        &caption,
        vec![
            DataFile {
                name: format!("map_chart_n{}.csv", row.n),
                columns: vec![
                    "frequency_rad_s",
                    "amplitude_m_s2",
                    "class",
                    "period",
                    "impacts_per_period",
                    "max_displacement_m",
                ],
                rows: cells,
            },
            DataFile {
                name: format!("map_curves_n{}.csv", row.n),
                columns: vec!["curve", "frequency_rad_s", "amplitude_m_s2"],
                rows: curve_rows,
            },
        ],
    )?;
    Ok(())
}

/// The N = 2 brute-force diagram and its largest Lyapunov exponent.
fn sweep_figures(report: &mut Report, sweep: &SweepSummary) -> Result<(), CliError> {
    let lyapunov: Vec<(f64, f64)> = sweep
        .points
        .iter()
        .filter_map(|p| Some((p.parameter, *p.lyapunov.as_ref()?.first()?)))
        .collect();
    let chaotic = lyapunov.iter().filter(|(_, l)| *l > 0.0).count();
    report.summary(
        "sweep_n2_positive_lyapunov_frequencies",
        serde_json::json!(chaotic),
    );
    let samples = sweep
        .points
        .iter()
        .flat_map(|p| {
            p.sections
                .iter()
                .map(move |s| vec![p.parameter, 1e3 * s[0]])
        })
        .collect();
    report.figure(
        &diagram_figure(sweep),
        "fig_map_diagram_n2",
        &format!(
            "R2 with N = 2, brute force from the model's initial state at {} frequencies: \
             the Poincaré samples of u1 over {} periods after {} (one dot per period).",
            sweep.points.len(),
            sweep.record_periods,
            sweep.transient_periods
        ),
        vec![DataFile::new(
            "map_diagram_n2.csv",
            vec!["frequency_rad_s", "u1_mm"],
            samples,
        )],
    )?;
    report.figure(
        &lyapunov_figure(sweep, &sweep_directions(sweep)),
        "fig_map_lyapunov_n2",
        &format!(
            "Under the diagram: the largest Lyapunov exponent of the same runs (QR of the \
             tangent vectors once per period over the recorded window; dashed: zero). \
             Positive (chaos) at {chaotic} of the {} frequencies.",
            lyapunov.len()
        ),
        vec![DataFile::new(
            "map_lyapunov_n2.csv",
            vec!["frequency_rad_s", "lambda1_per_s"],
            lyapunov.iter().map(|&(w, l)| vec![w, l]).collect(),
        )],
    )?;
    Ok(())
}

/// The N = 2 basins at 1.1 ω0 and their fractions.
fn basins_figure_of(report: &mut Report, b: &Basins) -> Result<(), CliError> {
    let nx = b.x_values.len();
    let fractions: Vec<String> = b
        .attractors
        .iter()
        .enumerate()
        .map(|(k, a)| {
            format!(
                "A{} ({}): {:.0} %",
                k + 1,
                a.period
                    .map_or("not periodic".to_string(), |p| format!("period {p}")),
                100.0 * a.fraction
            )
        })
        .collect();
    report.summary(
        "basins_n2_fractions",
        serde_json::json!(b.attractors.iter().map(|a| a.fraction).collect::<Vec<_>>()),
    );
    report.figure(
        &basins_figure(b),
        "fig_map_basins_n2",
        &format!(
            "R2 with N = 2 at Ω = 1.1 ω0: the attractor reached from each of {} × {} initial \
             states (u1, v1; the other body at rest) after {} periods, matched by their \
             Poincaré cycles over {} more: {}.",
            nx,
            b.y_values.len(),
            b.transient_periods,
            b.record_periods,
            fractions.join(", ")
        ),
        vec![DataFile {
            name: "map_basins_n2.csv".into(),
            columns: vec!["u1_m", "v1_m_s", "attractor"],
            rows: b
                .cells
                .iter()
                .enumerate()
                .map(|(k, c)| {
                    vec![
                        Some(b.x_values[k % nx]),
                        Some(b.y_values[k / nx]),
                        c.map(|a| (a + 1) as f64),
                    ]
                })
                .collect(),
        }],
    )?;
    Ok(())
}
