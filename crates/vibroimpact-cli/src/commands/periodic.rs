//! `vibroimpact periodic`: one periodic solution by shooting, with its
//! Floquet multipliers and the orbit over its period (the library's
//! [`OrbitStudy`]).

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::continuation::{Guess, OrbitStudy, StudyError, StudyField};
use vibroimpact::integrate::Interrupt;
use vibroimpact::model::Model;
use vibroimpact::periodic::{OrbitSummary, PeriodicSolution, ShootingOptions};
use vibroimpact::results::periodic_document;

use crate::args::{ImpactArgs, IntegratorName, LinearAlgebra};
use crate::error::CliError;
use crate::format::{history_csv, SummaryFormat};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};

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
    #[command(flatten)]
    impacts: ImpactArgs,
    /// Look for a mirror-symmetric orbit (u_i(t + nT/2) = -u_{N+1-i}(t)) with
    /// the half map S P_{nT/2}: half the integration per Newton step; needs
    /// a mirror-symmetric model and an odd --subharmonic.
    #[arg(long)]
    symmetric: bool,
    /// Integrator of the period map: `local` carries the state (and the
    /// monodromy matrix, or the record its products replay) by the exact
    /// motion between contacts. The `simulate` guess is simulated by
    /// `auto`'s integrator either way, so both shoot from the same start.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    integrator: IntegratorName,
    /// Output format.
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    format: SummaryFormat,
    /// Output folder: orbit.csv, summary.json, orbit figures.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// The start guess of `--guess`: `simulate`, `homotopy` or a JSON file
/// with `initial_state`.
fn read_guess(spec: &str) -> Result<Guess, CliError> {
    match spec {
        "simulate" => return Ok(Guess::Simulate),
        "homotopy" => return Ok(Guess::Homotopy),
        _ => {}
    }
    let path = Path::new(spec);
    if !path.exists() {
        // A keyword's typo (`homotpy`) is not a missing file.
        return Err(CliError::new(format!(
            "--guess {spec}: neither `simulate`, `homotopy` nor an existing JSON file with `initial_state`"
        )));
    }
    let text = crate::input::read_text(path)
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
    Ok(Guess::State(state))
}

/// A study error in the command line's words: the option first.
fn study_error(e: StudyError, args: &PeriodicArgs, interrupt: &Interrupt) -> CliError {
    if interrupt.requested() {
        return interrupted();
    }
    match e {
        StudyError::Invalid { field, message } => {
            let option = match field {
                StudyField::Subharmonic => format!("--subharmonic {}", args.subharmonic),
                StudyField::Arnoldi => format!("--arnoldi {}", args.linear.arnoldi),
                StudyField::Guess => format!("--guess {}", args.guess),
                StudyField::Symmetric => "--symmetric".to_string(),
                other => format!("--{}", other.name().replace('_', "-")),
            };
            CliError::new(format!("{option}: {message}"))
        }
        StudyError::Field(f) => crate::error::option_error(&f),
        other => CliError::new(other.to_string()),
    }
}

/// The error of a run stopped by Ctrl-C.
fn interrupted() -> CliError {
    CliError::new("interrupted (Ctrl-C): no periodic solution was written")
}

/// Runs `vibroimpact periodic`.
pub fn run_periodic(args: &PeriodicArgs) -> Result<(), CliError> {
    let interrupt = crate::interrupt::on_ctrl_c();
    let study = OrbitStudy {
        guess: read_guess(&args.guess)?,
        guess_periods: args.guess_periods,
        linear: args.linear.linear(),
        arnoldi: args.linear.arnoldi,
        options: ShootingOptions {
            subharmonic: args.subharmonic,
            rtol: args.rtol,
            tol: args.tol,
            symmetric: args.symmetric,
            interrupt: Some(interrupt.clone()),
            integrator: args.integrator.integrator(),
            ..ShootingOptions::default()
        },
    };
    let spell = |e| study_error(e, args, &interrupt);
    let checked = study
        .check(args.impacts.read(&args.model)?)
        .map_err(spell)?;
    crate::progress::announce_long(checked.work());
    let (model, krylov) = (checked.model.clone(), checked.krylov.is_some());
    let out = checked.run().map_err(spell)?;
    // A Ctrl-C after the last point the run checked (its summary, or a
    // Newton that ended unconverged): still nothing is written.
    if interrupt.requested() {
        return Err(interrupted());
    }
    let (sol, orbit) = (&out.solution, &out.orbit);
    let doc = periodic_document(&model, sol, orbit, args.subharmonic, out.symmetric, krylov);
    if let Some(dir) = &args.out {
        write_orbit(dir, &model, orbit, &doc)?;
    }
    match args.format {
        SummaryFormat::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        SummaryFormat::Table => print!("{}", orbit_text(&model, sol, orbit)),
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
