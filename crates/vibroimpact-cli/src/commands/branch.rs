//! `vibroimpact periodic` (one periodic solution by shooting, with Floquet
//! stability) and `vibroimpact continue` (a branch of them by
//! pseudo-arclength continuation, with special points).

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::continuation::{
    primary_orbit, Branch, BranchStudy, CheckedContinue, ContinuationOptions, ContinueOutcome,
    ContinueStudy, Curves, CurvesRequest, StudyError, StudyField,
};
use vibroimpact::integrate::Interrupt;
use vibroimpact::model::Model;
use vibroimpact::periodic::{
    guess_by_simulation, guess_by_simulation_with, orbit_summary_by, shoot, shoot_krylov,
    OrbitSummary, PeriodicSolution, ShootingOptions,
};

use crate::args::{IntegratorName, LinearAlgebra, ParameterRange, StartMethod};
use crate::curves::{self, SecondParameter};
use crate::error::{option_error, CliError};
use crate::figures::branch_figure;
use crate::format::{history_csv, CsvText, Format, SummaryFormat};
use crate::model_io::{read_document, read_model};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};
use vibroimpact::results::{
    branch_document, continue_document, curves_document, periodic_document,
};

/// Options of `vibroimpact periodic`.
#[derive(Args, Debug)]
pub struct PeriodicArgs {
    /// Model file (TOML).
    model: PathBuf,
    /// Period multiple n: look for a solution of period n T.
    #[arg(long, default_value_t = 1)]
    subharmonic: u32,
    /// Start guess: `simulate` (the state after --guess-periods periods from
    /// the model's initial state), `homotopy` (continued in the forcing
    /// amplitude from the rest state: the primary orbit) or a JSON file
    /// with `initial_state` (e.g. an earlier output).
    #[arg(long, default_value = "simulate")]
    guess: String,
    /// Periods simulated for the guess.
    #[arg(long, default_value_t = 200.0)]
    guess_periods: f64,
    /// Integration tolerance of the period map.
    #[arg(long, default_value_t = 1e-10)]
    rtol: f64,
    /// Newton tolerance (scaled residual).
    #[arg(long, default_value_t = 1e-9)]
    tol: f64,
    #[command(flatten)]
    linear: LinearAlgebra,
    /// Look for a mirror-symmetric orbit (u_i(t + nT/2) = -u_{N+1-i}(t)) with
    /// the half map S P_{nT/2}: half the integration per Newton step; needs
    /// a mirror-symmetric model and an odd --subharmonic.
    #[arg(long)]
    symmetric: bool,
    /// Integrator of the period map: `local` carries the state (and the
    /// monodromy matrix, or the record its products replay) by the exact
    /// motion between contacts.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    integrator: IntegratorName,
    /// Output format.
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    format: SummaryFormat,
    /// Output folder: orbit.csv, summary.json, orbit figures.
    #[arg(long)]
    out: Option<PathBuf>,
}

fn read_guess(spec: &str, model: &Model, periods: f64, rtol: f64) -> Result<Vec<f64>, CliError> {
    if spec == "simulate" {
        return guess_by_simulation(model, periods, rtol.max(1e-9))
            .map_err(|e| CliError::new(format!("guess by simulation: {e}")));
    }
    let text = crate::input::read_text(Path::new(spec))
        .map_err(|e| CliError::new(format!("{spec}: cannot read the guess: {e}")))?;
    let doc: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| CliError::new(format!("{spec}: not JSON: {e}")))?;
    let state: Vec<f64> = doc["initial_state"]
        .as_array()
        .ok_or_else(|| CliError::new(format!("{spec}: no `initial_state` array")))?
        .iter()
        .map(|v| {
            v.as_f64()
                .ok_or_else(|| CliError::new(format!("{spec}: `initial_state` must hold numbers")))
        })
        .collect::<Result<_, _>>()?;
    let d = 2 * model.bodies().len();
    if state.len() != d {
        return Err(CliError::new(format!(
            "{spec}: `initial_state` has {} values, the model needs {d} (u then v)",
            state.len()
        )));
    }
    Ok(state)
}

/// Runs `vibroimpact periodic`.
pub fn run_periodic(args: &PeriodicArgs) -> Result<(), CliError> {
    let model = read_model(&args.model)?.model;
    if model.forcing_frequency().is_none() {
        return Err(CliError::new(format!(
            "{}: the model has no periodic forcing with one frequency, so it has no periodic solutions",
            args.model.display()
        )));
    }
    if args.subharmonic == 0 {
        return Err(CliError::new("--subharmonic must be >= 1"));
    }
    let interrupt = crate::interrupt::on_ctrl_c();
    let stopped = |e: &dyn std::fmt::Display| {
        if interrupt.requested() {
            CliError::new("interrupted (Ctrl-C): no periodic solution was written")
        } else {
            CliError::new(e.to_string())
        }
    };
    let guess = match args.guess.as_str() {
        "simulate" => guess_by_simulation_with(
            &model,
            args.guess_periods,
            args.rtol.max(1e-9),
            Some(interrupt.clone()),
            args.integrator.integrator(),
        )
        .map_err(|e| stopped(&format!("guess by simulation: {e}")))?,
        "homotopy" => {
            let opts = ContinuationOptions {
                shooting: ShootingOptions {
                    interrupt: Some(interrupt.clone()),
                    ..ShootingOptions::default()
                },
                ..ContinuationOptions::default()
            };
            primary_orbit(&read_document(&args.model)?, &opts).map_err(|e| match e {
                StudyError::Invalid { message, .. } => {
                    CliError::new(format!("--guess homotopy: {message}"))
                }
                e => stopped(&e),
            })?
        }
        _ => read_guess(&args.guess, &model, args.guess_periods, args.rtol)?,
    };
    let opts = ShootingOptions {
        subharmonic: args.subharmonic,
        rtol: args.rtol,
        tol: args.tol,
        symmetric: args.symmetric,
        interrupt: Some(interrupt.clone()),
        integrator: args.integrator.integrator(),
        ..ShootingOptions::default()
    };
    if args.symmetric && (!model.is_mirror_symmetric() || args.subharmonic % 2 == 0) {
        return Err(CliError::new(format!(
            "{}: --symmetric needs a mirror-symmetric model (mirrored bodies, contacts, walls and forcing) and an odd --subharmonic",
            args.model.display()
        )));
    }
    let arnoldi = args.linear.krylov(model.bodies().len());
    let krylov = arnoldi.is_some();
    let sol = if let Some(arnoldi) = arnoldi {
        shoot_krylov(&model, &guess, &opts, arnoldi)
    } else {
        shoot(&model, &guess, &opts)
    }
    .map_err(|e| stopped(&e))?;
    let orbit = orbit_summary_by(
        &model,
        &sol.initial_state,
        (sol.period, 512),
        args.rtol,
        opts.integrator,
    )?;
    let symmetric_orbit = args.symmetric
        || vibroimpact::continuation::is_symmetric_orbit(&model, &sol.initial_state, &opts);
    let doc = periodic_document(
        &model,
        &sol,
        &orbit,
        args.subharmonic,
        symmetric_orbit,
        krylov,
    );
    if let Some(dir) = &args.out {
        write_orbit(dir, &model, &orbit, &doc)?;
    }
    match args.format {
        SummaryFormat::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        SummaryFormat::Table => print!("{}", orbit_text(&model, &sol, &orbit)),
    }
    if sol.converged {
        Ok(())
    } else {
        Err(CliError::new(format!(
            "Newton did not converge: {} (residual history {:?})",
            sol.stop.explanation(),
            sol.residual_history
                .iter()
                .map(|r| format!("{r:.2e}"))
                .collect::<Vec<_>>()
        )))
    }
}

/// Writes `orbit.csv`, `summary.json` and the orbit figures into `dir`.
fn write_orbit(
    dir: &Path,
    model: &Model,
    orbit: &OrbitSummary,
    doc: &serde_json::Value,
) -> Result<(), CliError> {
    ensure_dir(dir)?;
    let n = model.bodies().len();
    write_atomic(
        &dir.join("orbit.csv"),
        history_csv(model, &orbit.times, &orbit.states)?.as_bytes(),
    )?;
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(doc)?.as_bytes(),
    )?;
    let mut fig = Figure::new(
        "Periodic orbit",
        "time over one period  [s]",
        "displacement u  [mm]",
    )
    .legend_at(LegendPosition::Best);
    let mut phase = Figure::new(
        "Periodic orbit in the phase plane",
        "displacement u  [mm]",
        "velocity v  [m/s]",
    )
    .legend_at(LegendPosition::Best);
    for i in 0..n.min(8) {
        let name = &model.bodies()[i].name;
        fig.push(Series::line(
            format!("u_{name}"),
            orbit
                .times
                .iter()
                .enumerate()
                .map(|(j, &t)| (t, 1e3 * orbit.states[j * 2 * n + i])),
        ));
        phase.push(Series::line(
            name.clone(),
            (0..orbit.times.len()).map(|j| {
                (
                    1e3 * orbit.states[j * 2 * n + i],
                    orbit.states[j * 2 * n + n + i],
                )
            }),
        ));
    }
    render(&fig, &dir.join("orbit"))?;
    render(&phase, &dir.join("orbit_phase"))?;
    Ok(())
}

/// The text summary of a shooting result.
fn orbit_text(model: &Model, sol: &PeriodicSolution, orbit: &OrbitSummary) -> String {
    let mut t = format!(
        "{}: period {:.6} s, residual {:.2e} after {} iterations\n",
        if sol.converged {
            "converged"
        } else {
            "NOT CONVERGED"
        },
        sol.period,
        sol.residual_history.last().copied().unwrap_or(f64::NAN),
        sol.residual_history.len() - 1
    );
    t += &format!(
        "{} (largest |multiplier| {:.6})\n",
        if sol.stable() { "stable" } else { "unstable" },
        sol.spectral_radius()
    );
    for m in &sol.multipliers {
        t += &format!(
            "  multiplier {:+.6} {:+.6}i  |{:.6}|\n",
            m.re,
            m.im,
            m.norm()
        );
    }
    for (i, b) in model.bodies().iter().enumerate() {
        t += &format!(
            "  {}: max|u| {:.6e} m, max|v| {:.6e} m/s\n",
            b.name, orbit.max_displacement[i], orbit.max_velocity[i]
        );
    }
    t += &format!("  impacts per period: {}\n", orbit.impacts_per_period());
    t
}

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
    /// forcing: frequency, amplitude).
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
    x_scale: f64,
    x_label: &str,
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
        x_label,
        x_scale,
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
                StudyField::SpecialPoints => "--special-points".to_string(),
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
                println!(
                    "{}: {} points from {} to {} ({:?})",
                    if i == 0 { "branch" } else { "switched branch" },
                    b.points.len(),
                    b.points.first().map_or(f64::NAN, |p| p.parameter),
                    b.points.last().map_or(f64::NAN, |p| p.parameter),
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
        write_branch(dir, &outcome.branch.start_model, b, name, stem, 1.0, name)?;
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
    let read = curves::read_special_points(path, &family.document, &family.parameter)?;
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
            "{} curve from {label}: {} points ({:?}){}{}",
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
        .check(read_document(&args.range.model)?)
        .map_err(|e| study_error(e, args))?;
    if let Some(path) = &args.second.special_points {
        return curves_from_file(args, checked, path, &interrupt);
    }
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
