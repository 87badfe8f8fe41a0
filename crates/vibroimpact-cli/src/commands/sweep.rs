//! `vibroimpact sweep`: the brute-force bifurcation diagram of
//! [`vibroimpact::maps::sweep`], its CSV, figures and table.

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::maps::sweep::{
    parameter_values, sweep, sweep_work, Direction, SweepError, SweepOptions, SweepPoint,
    SweepSummary,
};
use vibroimpact::periodic::settling::Motion;

use crate::args::ParameterRange;
use crate::args::{IntegratorName, MethodName};
use crate::error::{option_error, CliError};
use crate::figures::{diagram_figure, lyapunov_figure, parameter_label, sweep_directions};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};
use vibroimpact::model::parameter::ParameterizedModel;

/// Options of `vibroimpact sweep`.
#[derive(Args, Debug)]
pub struct SweepArgs {
    #[command(flatten)]
    range: ParameterRange,
    /// Number of parameter values (>= 2), evenly spaced, both ends included.
    #[arg(long)]
    points: usize,
    /// Forcing periods simulated and discarded before recording.
    #[arg(long, default_value_t = 100)]
    transient: usize,
    /// Forcing periods recorded (one Poincaré sample at the end of each).
    #[arg(long, default_value_t = 20)]
    record: usize,
    /// At most this many forcing periods added to a value's transient while
    /// its Poincaré samples still converge onto an orbit (default 9 ×
    /// --transient; 0: only report it as settling).
    #[arg(long)]
    settle: Option<usize>,
    /// Sweep up from --from to --to and down from --to to --from, each value
    /// continuing from the previous value's final state.
    #[arg(long)]
    up_down: bool,
    /// Relative tolerance (default: the model's [simulation] rtol, else 1e-8).
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance in m and m/s (default: [simulation] atol, else rtol × 1e-4).
    #[arg(long)]
    atol: Option<f64>,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = MethodName::Dop853)]
    method: MethodName,
    /// Integrator of the transient, the recorded periods and `--lyapunov`:
    /// `local` moves bodies out of contact exactly.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    integrator: IntegratorName,
    /// Relative tolerance under which two Poincaré samples count as the same
    /// point (relative to the largest |u| and |v| in the recorded window);
    /// default max(1e-5, 1000 rtol), above the integration noise of
    /// impacting orbits (measured 1–3e-6 at rtol 1e-8).
    #[arg(long)]
    cluster_tolerance: Option<f64>,
    /// Also compute the K largest Lyapunov exponents of every value
    /// (default K: all 2N, at most 8), averaged over the recorded periods
    /// from the first Poincaré sample; summary.json gains `lyapunov` and
    /// `lyapunov_uncertainty` per point, the table the largest exponent,
    /// and a figure shows it under the diagram (a positive one: chaos).
    #[arg(long, value_name = "K", num_args = 0..=1)]
    lyapunov: Option<Option<usize>>,
    /// Output folder for sweep.csv, summary.json and the figures; without it
    /// only the summary is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Summary format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// Axis label of the parameter.
fn sweep_csv(summary: &SweepSummary) -> Result<String, CliError> {
    let mut w = CsvText::new();
    // `section`: which recorded forcing period's Poincaré sample (1, 2,
    // …), not an orbit's period (the summary's distinct section points).
    let mut header: Vec<String> = vec!["parameter".into(), "direction".into(), "section".into()];
    header.extend(summary.bodies.iter().map(|b| format!("u_{b}")));
    header.extend(summary.bodies.iter().map(|b| format!("v_{b}")));
    w.row(&header)?;
    for p in &summary.points {
        for (k, s) in p.sections.iter().enumerate() {
            let mut rec: Vec<String> = vec![
                format!("{:e}", p.parameter),
                p.direction.name().into(),
                (k + 1).to_string(),
            ];
            rec.extend(s.iter().map(|x| format!("{x:e}")));
            w.row(&rec)?;
        }
    }
    w.finish()
}

/// Writes sweep.csv, summary.json and the figures into `dir`.
fn write_outputs(dir: &Path, summary: &SweepSummary) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(&dir.join("sweep.csv"), sweep_csv(summary)?.as_bytes())?;
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(summary)?.as_bytes(),
    )?;
    let directions = sweep_directions(summary);
    let x_label = parameter_label(&summary.parameter_name);
    let fig = diagram_figure(summary);
    render(&fig, &dir.join("sweep"))?;
    let n = summary.bodies.len();
    let shown: Vec<usize> = if n <= 8 {
        (0..n).collect()
    } else {
        (0..8).map(|j| j * (n - 1) / 7).collect()
    };
    let mut fig = Figure::new(
        "Largest displacement over the recorded periods",
        x_label,
        "max |u|  [mm]",
    )
    .legend_at(LegendPosition::Best);
    for (c, &i) in shown.iter().enumerate() {
        for d in &directions {
            let pts: Vec<(f64, f64)> = summary
                .points
                .iter()
                .filter(|p| p.direction == *d)
                .map(|p| (p.parameter, 1e3 * p.max_displacement[i]))
                .collect();
            let label = match d {
                Direction::None => format!("u_{}", summary.bodies[i]),
                _ => format!("u_{} {}", summary.bodies[i], d.name()),
            };
            let s = if *d == Direction::Down {
                Series::dashed(label, pts)
            } else {
                Series::line(label, pts)
            };
            fig.push(s.with_color(c));
        }
    }
    render(&fig, &dir.join("sweep_amplitude"))?;
    if summary.points.iter().any(|p| p.lyapunov.is_some()) {
        render(
            &lyapunov_figure(summary, &directions),
            &dir.join("sweep_lyapunov"),
        )?;
    }
    Ok(())
}

/// What a value's samples say: its period once they repeat, the periods
/// a settling one still needs, or that they do not repeat.
fn motion_text(p: &SweepPoint) -> String {
    match (p.motion, p.period, p.settle_periods) {
        _ if !p.completed => "-".into(),
        (Motion::Periodic, Some(k), _) => format!("period {k}"),
        (Motion::Settling, _, Some(more)) => format!("settling (+{more:.0})"),
        (Motion::Settling, _, None) => "settling".into(),
        _ => "irregular".into(),
    }
}

/// Human-readable table (with the largest Lyapunov exponent when
/// computed).
fn table_text(summary: &SweepSummary) -> String {
    let first = summary.bodies.first().cloned().unwrap_or_default();
    let lyapunov = summary.points.iter().any(|p| p.lyapunov.is_some());
    let mut header = vec![
        "parameter".to_string(),
        "direction".to_string(),
        format!("max|u_{first}| [m]"),
        "distinct".to_string(),
        "spread".to_string(),
        "motion".to_string(),
        "transient".to_string(),
        "impacts/T".to_string(),
    ];
    if lyapunov {
        header.push("λ1 [1/s]".to_string());
    }
    header.push("status".to_string());
    let rows: Vec<Vec<String>> = summary
        .points
        .iter()
        .map(|p| {
            let mut row = vec![
                format!("{:.6e}", p.parameter),
                p.direction.name().to_string(),
                p.max_displacement
                    .first()
                    .filter(|x| x.is_finite())
                    .map_or("-".into(), |x| format!("{x:.6e}")),
                p.distinct_section_points.to_string(),
                if p.section_spread.is_finite() {
                    format!("{:.1e}", p.section_spread)
                } else {
                    "-".into()
                },
                motion_text(p),
                p.transient_periods.to_string(),
                if p.impacts_per_period.is_finite() {
                    format!("{:.2}", p.impacts_per_period)
                } else {
                    "-".into()
                },
            ];
            if lyapunov {
                row.push(
                    p.lyapunov
                        .as_ref()
                        .and_then(|l| l.first())
                        .map_or("-".into(), |l| format!("{l:+.4}")),
                );
            }
            row.push(if p.completed { "ok" } else { "FAILED" }.into());
            row
        })
        .collect();
    let widths: Vec<usize> = (0..header.len())
        .map(|c| {
            rows.iter()
                .map(|r| r[c].chars().count())
                .chain([header[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[String]| {
        let parts: Vec<String> = cells
            .iter()
            .zip(&widths)
            .map(|(s, w)| format!("{s:>w$}"))
            .collect();
        format!("{}\n", parts.join("  ").trim_end())
    };
    let mut t = line(&header);
    for r in &rows {
        t.push_str(&line(r));
    }
    t
}

/// Runs `vibroimpact sweep`.
pub fn run(args: &SweepArgs) -> Result<(), CliError> {
    if !args.range.from.is_finite() || !args.range.to.is_finite() {
        return Err(CliError::new(format!(
            "--from {} --to {}: the values must be finite",
            args.range.from, args.range.to
        )));
    }
    if args.range.from == args.range.to {
        return Err(CliError::new(format!(
            "--from and --to are both {}: give a range",
            args.range.from
        )));
    }
    if !(2..=10_000_000).contains(&args.points) {
        return Err(CliError::new(format!(
            "--points {}: a sweep needs at least 2 values and at most 10000000",
            args.points
        )));
    }
    let document = args.range.impacts.read(&args.range.model)?;
    let family = ParameterizedModel::new(document, &args.range.parameter)?;
    let values = parameter_values(args.range.from, args.range.to, args.points);
    let lyapunov = match args.lyapunov {
        Some(None) => Some(
            family
                .loaded_at(family.initial())?
                .model
                .bodies()
                .len()
                .min(4)
                * 2,
        ),
        Some(k) => k,
        None => None,
    };
    let interrupt = crate::interrupt::on_ctrl_c();
    let options = SweepOptions {
        transient: args.transient,
        settle: args.settle,
        record: args.record,
        up_down: args.up_down,
        only: None,
        rtol: args.rtol,
        atol: args.atol,
        method: args.method.method(),
        cluster_tolerance: args.cluster_tolerance,
        lyapunov,
        interrupt: Some(interrupt.clone()),
        integrator: args.integrator.integrator(),
    };
    if let Ok(base) = family.loaded_at(values[0]) {
        crate::progress::announce_long_as(
            sweep_work(&base, &options, values.len()),
            "Ctrl-C stops it and keeps the values computed",
        );
    }
    let progress = crate::progress::bar(if args.up_down { 2 } else { 1 } * values.len(), "values")
        .with_prefix("sweep");
    let summary = sweep(&family, &values, &options, &|| progress.inc(1)).map_err(|e| match e {
        SweepError::Field(f) => option_error(&f),
        other => other.into(),
    })?;
    progress.finish_and_clear();
    if let Some(dir) = &args.out {
        write_outputs(dir, &summary)?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&summary)?),
        Format::Csv => print!("{}", sweep_csv(&summary)?),
        Format::Table => print!("{}", table_text(&summary)),
    }
    let failed: Vec<String> = summary
        .points
        .iter()
        .filter(|p| p.error.is_some())
        .map(|p| {
            format!(
                "{} = {} ({}): {}",
                summary.parameter_name,
                p.parameter,
                p.direction.name(),
                p.error.as_deref().unwrap_or("failed")
            )
        })
        .collect();
    if interrupt.requested() {
        return Err(CliError::new(format!(
            "interrupted (Ctrl-C): the values computed so far are kept{}",
            if args.out.is_some() {
                " in the output folder"
            } else {
                ""
            }
        )));
    }
    let expected = if args.up_down { 2 } else { 1 } * values.len();
    let skipped = expected - summary.points.len();
    if failed.is_empty() {
        return Ok(());
    }
    Err(CliError::new(format!(
        "{} of {expected} sweep values failed{} (the computed values are kept{}); {}",
        failed.len(),
        if skipped > 0 {
            format!(", {skipped} not run after a failure ended their direction")
        } else {
            String::new()
        },
        if args.out.is_some() {
            " in the output folder"
        } else {
            ""
        },
        failed.join("; ")
    )))
}
