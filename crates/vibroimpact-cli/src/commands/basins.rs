//! `vibroimpact basins`: basins of attraction in a plane of initial states
//! ([`vibroimpact::maps::basins`]), their CSV, JSON, figure and table of
//! attractors.

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::maps::basins::{basins, BasinError, Basins, Component};

use crate::args::{AttractorRuns, GridAxes, ImpactArgs};
use crate::error::{option_error, CliError};
use crate::figures::{attractor_label, basins_figure};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::render;

/// Options of `vibroimpact basins`.
#[derive(Args, Debug)]
pub struct BasinsArgs {
    /// Model file (TOML, see docs/model.md) with a periodic excitation.
    model: PathBuf,
    #[command(flatten)]
    grid: GridAxes,
    /// The other components of the initial states, u then v, comma
    /// separated (default: the model's initial state).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    base: Option<Vec<f64>>,
    #[command(flatten)]
    runs: AttractorRuns,
    #[command(flatten)]
    impacts: ImpactArgs,
    /// Output folder for basins.csv, basins.json and the figure; without it
    /// only the table of attractors is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Format on standard output: the table of attractors, the grid as CSV,
    /// or the whole result as JSON.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// basins.csv: one row per initial state.
fn basins_csv(b: &Basins) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row(&[
        b.x_component.clone(),
        b.y_component.clone(),
        "attractor".into(),
    ])?;
    let nx = b.x_values.len();
    for (k, cell) in b.cells.iter().enumerate() {
        w.row(&[
            format!("{:e}", b.x_values[k % nx]),
            format!("{:e}", b.y_values[k / nx]),
            cell.map_or(String::new(), |a| (a + 1).to_string()),
        ])?;
    }
    w.finish()
}

/// Table of the attractors.
fn table_text(b: &Basins) -> String {
    let mut t = format!(
        "{} × {} initial states ({} × {}), {} overlapping, {} failed\n",
        b.x_values.len(),
        b.y_values.len(),
        b.x_component,
        b.y_component,
        b.inadmissible,
        b.failed
    );
    for k in 0..b.attractors.len() {
        let a = &b.attractors[k];
        t.push_str(&format!(
            "{}  {} states, max|u| {:.4e} m\n",
            attractor_label(b, k),
            a.cells,
            a.max_displacement
        ));
    }
    for e in &b.errors {
        t.push_str(&format!("failed {e}\n"));
    }
    t
}

/// Writes basins.csv, basins.json and the figure into `dir`.
fn write_outputs(dir: &Path, b: &Basins) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(&dir.join("basins.csv"), basins_csv(b)?.as_bytes())?;
    write_atomic(
        &dir.join("basins.json"),
        serde_json::to_string_pretty(b)?.as_bytes(),
    )?;
    render(&basins_figure(b), &dir.join("basins"))?;
    Ok(())
}

/// Runs `vibroimpact basins`.
pub fn run(args: &BasinsArgs) -> Result<(), CliError> {
    let (xs, ys) = args.grid.values()?;
    let loaded = args.impacts.read(&args.model)?.build()?;
    let n = loaded.model.bodies().len();
    let parse = |flag: &str, text: &str| {
        Component::parse(text, n).map_err(|e| CliError::new(format!("--{flag}: {e}")))
    };
    let (cx, cy) = (parse("x", &args.grid.x)?, parse("y", &args.grid.y)?);
    let interrupt = crate::interrupt::on_ctrl_c();
    let options = args.runs.options(interrupt.clone());
    crate::progress::announce_long_as(
        vibroimpact::maps::attractor::map_work(&loaded, &options, xs.len() * ys.len()),
        "Ctrl-C stops it (basins are written whole: nothing then)",
    );
    let progress = crate::progress::bar(xs.len() * ys.len(), "states").with_prefix("basins");
    let result = basins(
        &loaded,
        (cx, &xs),
        (cy, &ys),
        args.base.as_deref(),
        &options,
        &|| progress.inc(1),
    )
    .map_err(|e| match e {
        BasinError::Field(f) => option_error(&f),
        other => CliError::new(other.to_string()),
    })?;
    progress.finish_and_clear();
    if interrupt.requested() {
        return Err(CliError::new(
            "interrupted (Ctrl-C): nothing written (basins are written whole)",
        ));
    }
    if let Some(dir) = &args.out {
        write_outputs(dir, &result)?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&result)?),
        Format::Csv => print!("{}", basins_csv(&result)?),
        Format::Table => print!("{}", table_text(&result)),
    }
    Ok(())
}
