//! `vibroimpact chart`: the brute-force stability chart of
//! [`vibroimpact::maps::chart`] over two parameters, its CSV, JSON, figure and
//! table of classes.

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::maps::chart::{chart, Chart, ChartError, ChartOptions};
use vibroimpact::maps::sweep::SweepOptions;

use crate::args::{AttractorRuns, GridAxes, ImpactArgs};
use crate::error::{option_error, CliError};
use crate::figures::{chart_figure, class, curve_series, CLASSES};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Series};

/// Options of `vibroimpact chart`.
#[derive(Args, Debug)]
pub struct ChartArgs {
    /// Model file (TOML, see docs/model.md); its excitation must be periodic
    /// with one frequency over the whole chart.
    model: PathBuf,
    #[command(flatten)]
    grid: GridAxes,
    #[command(flatten)]
    runs: AttractorRuns,
    #[command(flatten)]
    impacts: ImpactArgs,
    /// Initial states per cell: the model's own, then points spread over
    /// |u| ≤ 0.9 gap, |v| ≤ 0.9 gap × Ω; runs that end on different
    /// attractors mark the cell as coexisting.
    #[arg(long, default_value_t = 1)]
    starts: usize,
    /// Also compute each run's largest Lyapunov exponent (positive: chaos;
    /// about twice the cost).
    #[arg(long)]
    lyapunov: bool,
    /// Output folder for chart.csv, chart.json and the figure; without it
    /// only the summary is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Curves of special points to draw over the chart: the `curves.json`
    /// of `continue --parameter2` in the same two parameters.
    #[arg(long)]
    overlay: Option<PathBuf>,
    /// Summary format on standard output: a table of the classes, the
    /// cells as CSV, or the whole chart as JSON.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// chart.csv: one row per run.
fn chart_csv(chart: &Chart) -> Result<String, CliError> {
    let mut w = CsvText::new();
    let n = chart
        .cells
        .iter()
        .flat_map(|c| c.runs.first())
        .map(|r| r.start.len())
        .max()
        .unwrap_or(0);
    let mut header: Vec<String> = vec![
        chart.x_name.clone(),
        chart.y_name.clone(),
        "start".into(),
        "attractors".into(),
        "period".into(),
        "impacts_per_period".into(),
        "max_displacement".into(),
        "lyapunov".into(),
        "error".into(),
    ];
    header.extend((0..n).map(|i| format!("start_{i}")));
    w.row(&header)?;
    for cell in &chart.cells {
        for (k, r) in cell.runs.iter().enumerate() {
            let mut rec = vec![
                format!("{:e}", cell.x),
                format!("{:e}", cell.y),
                k.to_string(),
                cell.attractors.to_string(),
                r.period.map_or(String::new(), |p| p.to_string()),
                format!("{:e}", r.impacts_per_period),
                format!("{:e}", r.max_displacement),
                r.lyapunov.map_or(String::new(), |l| format!("{l:e}")),
                r.error.clone().unwrap_or_default(),
            ];
            rec.extend(r.start.iter().map(|x| format!("{x:e}")));
            w.row(&rec)?;
        }
    }
    w.finish()
}

/// Table of the classes: cells per class, and cells with coexisting
/// attractors.
fn table_text(chart: &Chart) -> String {
    let mut counts = [0usize; CLASSES.len()];
    for cell in &chart.cells {
        counts[class(cell)] += 1;
    }
    let mut t = format!(
        "{} × {} cells ({} × {}), {} runs\n",
        chart.x_values.len(),
        chart.y_values.len(),
        chart.x_name,
        chart.y_name,
        chart.cells.iter().map(|c| c.runs.len()).sum::<usize>()
    );
    for (c, name) in CLASSES.iter().enumerate() {
        if counts[c] > 0 {
            t.push_str(&format!("{name:>20}  {:>8} cells\n", counts[c]));
        }
    }
    let coexisting = chart.cells.iter().filter(|c| c.attractors > 1).count();
    t.push_str(&format!("{:>20}  {coexisting:>8} cells\n", "coexisting"));
    t
}

/// Writes chart.csv, chart.json and the figure into `dir`.
fn write_outputs(dir: &Path, chart: &Chart, overlay: &[Series]) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(&dir.join("chart.csv"), chart_csv(chart)?.as_bytes())?;
    write_atomic(
        &dir.join("chart.json"),
        serde_json::to_string(chart)?.as_bytes(),
    )?;
    let mut fig = chart_figure(chart);
    for s in overlay {
        fig.push(s.clone());
    }
    render(&fig, &dir.join("chart"))?;
    Ok(())
}

/// The curves of a `curves.json` (from `continue --parameter2`) as line
/// series in the chart's (x, y) plane; the file must name the chart's two
/// parameters.
fn overlay_series(path: &Path, x: &str, y: &str) -> Result<Vec<Series>, CliError> {
    let text = crate::input::read_text(path)
        .map_err(|e| CliError::new(format!("{}: {e}", path.display())))?;
    let doc: serde_json::Value = serde_json::from_str(&text)
        .map_err(|e| CliError::new(format!("{}: not a curves document: {e}", path.display())))?;
    let (p, q) = (doc["parameter"].as_str(), doc["parameter2"].as_str());
    if (p, q) != (Some(x), Some(y)) {
        return Err(CliError::new(format!(
            "{}: curves in ({}, {}), the chart is in ({x}, {y})",
            path.display(),
            p.unwrap_or("?"),
            q.unwrap_or("?")
        )));
    }
    let Some(curves) = doc["curves"].as_array() else {
        return Err(CliError::new(format!(
            "{}: no `curves` list",
            path.display()
        )));
    };
    let mut labelled: Vec<String> = Vec::new();
    let mut out = Vec::new();
    for (k, c) in curves.iter().enumerate() {
        let kind = c["kind"].as_str().unwrap_or("curve").to_string();
        let points: Option<Vec<(f64, f64)>> = c["points"].as_array().map(|pts| {
            pts.iter()
                .filter_map(|pt| Some((pt[x].as_f64()?, pt[y].as_f64()?)))
                .collect()
        });
        let Some(points) = points else {
            return Err(CliError::new(format!(
                "{}: curve {k} has no `points`",
                path.display()
            )));
        };
        let label = if labelled.contains(&kind) {
            String::new()
        } else {
            labelled.push(kind.clone());
            format!("{kind} curve")
        };
        out.push(curve_series(&kind, label, points));
    }
    Ok(out)
}

/// Runs `vibroimpact chart`.
pub fn run(args: &ChartArgs) -> Result<(), CliError> {
    let (xs, ys) = args.grid.values()?;
    let document = args.impacts.read(&args.model)?;
    let overlay = match &args.overlay {
        Some(path) => overlay_series(path, &args.grid.x, &args.grid.y)?,
        None => Vec::new(),
    };
    let interrupt = crate::interrupt::on_ctrl_c();
    let options = ChartOptions {
        sweep: SweepOptions {
            lyapunov: args.lyapunov.then_some(1),
            ..args.runs.options(interrupt.clone())
        },
        starts: args.starts,
    };
    if let Ok(base) = document.build() {
        crate::progress::announce_long_as(
            vibroimpact::maps::attractor::map_work(
                &base,
                &options.sweep,
                xs.len() * ys.len() * options.starts,
            ),
            "Ctrl-C stops it (a chart is written whole: nothing then)",
        );
    }
    let progress = crate::progress::bar(xs.len() * ys.len(), "cells").with_prefix("chart");
    let chart = chart(
        &document,
        (&args.grid.x, &xs),
        (&args.grid.y, &ys),
        &options,
        &|| progress.inc(1),
    )
    .map_err(|e| match e {
        ChartError::Field(f) => option_error(&f),
        other => CliError::new(other.to_string()),
    })?;
    progress.finish_and_clear();
    if interrupt.requested() {
        return Err(CliError::new(
            "interrupted (Ctrl-C): nothing written (a chart is written whole)",
        ));
    }
    if let Some(dir) = &args.out {
        write_outputs(dir, &chart, &overlay)?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&chart)?),
        Format::Csv => print!("{}", chart_csv(&chart)?),
        Format::Table => print!("{}", table_text(&chart)),
    }
    Ok(())
}
