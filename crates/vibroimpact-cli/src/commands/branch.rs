//! `vibroimpact continue`: a branch of periodic solutions by
//! pseudo-arclength continuation, with its special points, a switched
//! branch and the curves of its special points in two parameters (the
//! library's [`ContinueStudy`]).

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::continuation::{
    Branch, BranchStudy, CheckedContinue, ContinuationOptions, ContinueOutcome, ContinueStudy,
    Curves, CurvesRequest, StudyError, StudyField,
};
use vibroimpact::integrate::Interrupt;
use vibroimpact::model::Model;
use vibroimpact::periodic::ShootingOptions;
use vibroimpact::results::{branch_document, continue_document, curves_document};

use crate::args::{IntegratorName, LinearAlgebra, ParameterRange, StartMethod};
use crate::curves::{self, SecondParameter};
use crate::error::{option_error, CliError};
use crate::figures::{branch_figure, parameter_label};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::render;

/// Options of `vibroimpact continue`.
#[derive(Args, Debug)]
pub struct ContinueArgs {
    #[command(flatten)]
    range: ParameterRange,
    /// Period multiple n of the branch.
    #[arg(long, default_value_t = 1)]
    subharmonic: u32,
    /// After computing the branch, switch at this special point (e.g. BP1,
    /// PD1) and continue the crossing or period-doubled branch to --to.
    #[arg(long)]
    switch_at: Option<String>,
    /// Points at most (per branch).
    #[arg(long, default_value_t = 1500)]
    max_points: usize,
    /// Largest arclength step (scaled units).
    #[arg(long, default_value_t = 0.05)]
    ds_max: f64,
    /// How the first periodic orbit is found.
    #[arg(long, value_enum, default_value_t = StartMethod::Auto)]
    start: StartMethod,
    #[command(flatten)]
    second: SecondParameter,
    /// Periods simulated for the start guess.
    #[arg(long, default_value_t = 200.0)]
    guess_periods: f64,
    #[command(flatten)]
    linear: LinearAlgebra,
    /// Integrator of the period maps: `local` moves bodies out of contact
    /// exactly and integrates only those in touch (for a parameter of the
    /// forcing: frequency, amplitude). The start guess is simulated by
    /// `auto`'s integrator either way, so both follow the same branch.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    integrator: IntegratorName,
    /// Output folder: branch.csv, branch_special_points.json, branch.json and
    /// the response figure branch_response.svg/.png (with --switch-at the
    /// same for switched_branch).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// CSV of a branch.
pub fn branch_csv(branch: &Branch, model: &Model) -> Result<String, CliError> {
    let n = model.bodies().len();
    let mut w = CsvText::new();
    let mut header = vec!["parameter".to_string()];
    header.extend(model.bodies().iter().map(|b| format!("max_u_{}", b.name)));
    header.extend(model.bodies().iter().map(|b| format!("max_v_{}", b.name)));
    header.extend(
        [
            "impacts_per_period",
            "largest_multiplier_modulus",
            "stable",
            "label",
        ]
        .map(String::from),
    );
    w.row(&header)?;
    for p in &branch.points {
        let mut row = vec![format!("{:e}", p.parameter)];
        row.extend((0..n).map(|i| format!("{:e}", p.max_displacement[i])));
        row.extend((0..n).map(|i| format!("{:e}", p.max_velocity[i])));
        row.push(p.impacts_per_period.to_string());
        row.push(format!("{:e}", p.spectral_radius()));
        row.push(p.stable.to_string());
        row.push(p.label.clone().unwrap_or_default());
        w.row(&row)?;
    }
    w.finish()
}

fn write_branch(
    dir: &Path,
    model: &Model,
    branch: &Branch,
    name: &str,
    stem: &str,
) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(
        &dir.join(format!("{stem}.csv")),
        branch_csv(branch, model)?.as_bytes(),
    )?;
    let doc = branch_document(branch, model, name);
    write_atomic(
        &dir.join(format!("{stem}_special_points.json")),
        serde_json::to_string_pretty(&doc["special_points"])?.as_bytes(),
    )?;
    write_atomic(
        &dir.join(format!("{stem}.json")),
        serde_json::to_string_pretty(&doc)?.as_bytes(),
    )?;
    let fig = branch_figure(
        &[(branch, "branch")],
        &format!("Response curve in {name}"),
        &parameter_label(name),
        1.0,
        0,
    );
    render(&fig, &dir.join(format!("{stem}_response")))?;
    Ok(())
}

/// A study error in the command line's words: the option first.
fn study_error(e: StudyError, args: &ContinueArgs) -> CliError {
    match e {
        StudyError::Invalid { field, message } => {
            let option = match field {
                StudyField::Range => format!("--from {} --to {}", args.range.from, args.range.to),
                StudyField::From => format!("--from {}", args.range.from),
                StudyField::Subharmonic => format!("--subharmonic {}", args.subharmonic),
                StudyField::Parameter => format!("--parameter {}", args.range.parameter),
                StudyField::Start => format!("--start {}", args.start.start().name()),
                StudyField::Parameter2 => {
                    format!(
                        "--parameter2 {}",
                        args.second.parameter2.as_deref().unwrap_or("")
                    )
                }
                other => format!("--{}", other.name().replace('_', "-")),
            };
            CliError::new(format!("{option}: {message}"))
        }
        StudyError::Field(f) => option_error(&f),
        other => CliError::new(other.to_string()),
    }
}

/// The study `continue` runs.
fn continue_study(args: &ContinueArgs, interrupt: &Interrupt) -> Result<ContinueStudy, CliError> {
    let selection = args.second.selection()?;
    Ok(ContinueStudy {
        parameter: args.range.parameter.clone(),
        branch: BranchStudy {
            from: args.range.from,
            to: args.range.to,
            start: args.start.start(),
            guess_periods: args.guess_periods,
            switch_at: args.switch_at.clone(),
            linear: args.linear.linear(),
            arnoldi: args.linear.arnoldi,
            options: ContinuationOptions {
                max_points: args.max_points,
                ds_max: args.ds_max,
                shooting: ShootingOptions {
                    subharmonic: args.subharmonic,
                    interrupt: Some(interrupt.clone()),
                    integrator: args.integrator.integrator(),
                    ..ContinuationOptions::default().shooting
                },
                ..ContinuationOptions::default()
            },
        },
        curves: args
            .second
            .parameter2
            .clone()
            .map(|parameter2| CurvesRequest {
                parameter2,
                selection,
            }),
    })
}

/// Prints the branches (and curves) in the chosen format.
fn print_outcome(args: &ContinueArgs, outcome: &ContinueOutcome) -> Result<(), CliError> {
    let model = &outcome.branch.start_model;
    let mut branches = vec![&outcome.branch.branch];
    branches.extend(outcome.branch.switched.iter().flatten());
    match args.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&continue_document(outcome))?
        ),
        Format::Csv => {
            for b in branches {
                print!("{}", branch_csv(b, model)?);
            }
        }
        Format::Table => {
            if let Some((c, _)) = &outcome.curves {
                print_curves(c);
            }
            for (i, b) in branches.into_iter().enumerate() {
                let (first, last) = (
                    b.points.first().map_or(f64::NAN, |p| p.parameter),
                    b.points.last().map_or(f64::NAN, |p| p.parameter),
                );
                // Where a fold turned it, the span is not its ends'.
                let (lo, hi) = b.points.iter().fold((first, first), |(lo, hi), p| {
                    (lo.min(p.parameter), hi.max(p.parameter))
                });
                let span = if (lo, hi) == (first.min(last), first.max(last)) {
                    String::new()
                } else {
                    format!(" (spanning {lo} to {hi})")
                };
                println!(
                    "{}: {} points from {first} to {last}{span}: {}",
                    if i == 0 { "branch" } else { "switched branch" },
                    b.points.len(),
                    b.stop
                );
                for s in &b.special {
                    println!(
                        "  {:<5} {:<16} {} = {:.10}",
                        s.label,
                        s.kind.name(),
                        args.range.parameter,
                        s.parameter
                    );
                }
            }
        }
    }
    Ok(())
}

/// Writes the branches (and curves) into the output folder.
fn write_outcome(
    dir: &Path,
    args: &ContinueArgs,
    outcome: &ContinueOutcome,
) -> Result<(), CliError> {
    let name = &args.range.parameter;
    if let Some((c, q)) = &outcome.curves {
        curves::write_curves(dir, c, name, q)?;
    }
    let mut branches = vec![(&outcome.branch.branch, "branch")];
    if let Some(Ok(b)) = &outcome.branch.switched {
        branches.push((b, "switched_branch"));
    }
    for (b, stem) in branches {
        write_branch(dir, &outcome.branch.start_model, b, name, stem)?;
    }
    Ok(())
}

/// `continue --parameter2 … --special-points branch.json`: the curves of
/// an earlier branch's special points, without the branch.
fn curves_from_file(
    args: &ContinueArgs,
    checked: CheckedContinue,
    path: &Path,
    interrupt: &Interrupt,
) -> Result<(), CliError> {
    let family = &checked.branch.family;
    let read = curves::read_special_points(path, family.document(), family.parameter())?;
    let q = checked
        .plane
        .as_ref()
        .map(|(plane, _)| plane.q.name.clone());
    let c = checked
        .curves_from(&read)
        .map_err(|e| study_error(e, args))?;
    if interrupt.requested() {
        return Err(CliError::new("interrupted (Ctrl-C): nothing written"));
    }
    let (p, q) = (&args.range.parameter, q.unwrap_or_default());
    if let Some(dir) = &args.out {
        curves::write_curves(dir, &c, p, &q)?;
    }
    match args.format {
        Format::Json => println!(
            "{}",
            serde_json::to_string_pretty(&curves_document(&c, p, &q))?
        ),
        _ => print_curves(&c),
    }
    Ok(())
}

/// The curves, one line each, with their codimension-two points.
fn print_curves(c: &Curves) {
    for (label, curve) in &c.followed {
        let special: Vec<String> = curve
            .special
            .iter()
            .map(|sp| {
                let pt = &curve.points[sp.point];
                format!("{} at ({:.8}, {:.8})", sp.kind.name(), pt.p, pt.q)
            })
            .collect();
        println!(
            "{} curve from {label}: {} points, {}{}{}",
            curve.kind.name(),
            curve.points.len(),
            curve.stop,
            if special.is_empty() { "" } else { "; " },
            special.join(", ")
        );
    }
    for (label, why) in &c.skipped {
        println!("no curve from {label}: {why}");
    }
}

/// Runs `vibroimpact continue`.
pub fn run_continue(args: &ContinueArgs) -> Result<(), CliError> {
    let interrupt = crate::interrupt::on_ctrl_c();
    let checked = continue_study(args, &interrupt)?
        .check(args.range.impacts.read(&args.range.model)?)
        .map_err(|e| study_error(e, args))?;
    if let Some(path) = &args.second.special_points {
        return curves_from_file(args, checked, path, &interrupt);
    }
    crate::progress::announce_long(checked.branch.guess_work());
    let bar = crate::progress::status();
    let progress = |p: &vibroimpact::continuation::BranchPoint| {
        bar.inc(1);
        bar.set_message(format!(
            "{} = {:.8}  max|u| = {:.4e}  {}",
            args.range.parameter,
            p.parameter,
            p.max_displacement[0],
            if p.stable { "stable" } else { "unstable" }
        ));
        !interrupt.requested()
    };
    let outcome = checked.run(progress).map_err(|e| study_error(e, args))?;
    bar.finish_and_clear();
    if let Some(dir) = &args.out {
        write_outcome(dir, args, &outcome)?;
    }
    print_outcome(args, &outcome)?;
    // A failed switch keeps the main branch: it is written, then reported.
    if let Some(Err(e)) = &outcome.branch.switched {
        return Err(CliError::new(format!(
            "--switch-at {}: {}",
            e.label, e.message
        )));
    }
    if interrupt.requested() {
        return Err(CliError::new(
            "interrupted (Ctrl-C): the points computed so far are kept",
        ));
    }
    match &outcome.branch.branch.stop {
        vibroimpact::continuation::StopReason::CannotContinue(why) => Err(CliError::new(format!(
            "the branch cannot continue: {why} (the points computed so far are kept)"
        ))),
        _ => Ok(()),
    }
}
