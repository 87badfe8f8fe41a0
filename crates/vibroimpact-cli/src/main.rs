//! `vibroimpact`: the command-line interface.
//!
//! Without arguments it runs the built-in default study and writes its
//! report (see [`report`]); subcommands expose the library's computations.

/// The allocator: the rigid period maps build and drop a run's small
/// buffers per evaluation (docs/decisions.md D45).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod args;
mod commands;
mod curves;
mod data;
mod error;
mod figures;
mod format;
#[cfg(test)]
mod fuzz_tests;
mod input;
mod interrupt;
mod measurements;
mod model_io;
mod output;
mod plot;
mod progress;
mod records;
mod report;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use commands::{
    basins, branch, chart, collapse, hysteresis, identify, impact, periodic, pounding, pushover,
    simulate, spectrum, sweep,
};

/// Vibrating systems with mutual impacts (after T. Fujita 1977).
#[derive(Parser, Debug)]
#[command(name = "vibroimpact", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Report folder of the default study (run when no subcommand is given).
    #[arg(long, default_value = "vibroimpact-report")]
    out: PathBuf,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Two-body impact relations: restitution, peak force, contact duration.
    #[command(allow_negative_numbers = true)]
    Impact(impact::ImpactArgs),
    /// Identify a/b and alpha of the exponential law from measured impacts.
    #[command(allow_negative_numbers = true)]
    Identify(identify::IdentifyArgs),
    /// Simulate a model file: time history, impact log, summary and plots.
    #[command(allow_negative_numbers = true)]
    Simulate(simulate::SimulateArgs),
    /// Brute-force bifurcation diagram: Poincaré samples against a parameter.
    #[command(allow_negative_numbers = true)]
    Sweep(sweep::SweepArgs),
    /// Brute-force stability chart over two parameters: the attractor's
    /// period, impacts, Lyapunov exponent and coexistence per cell.
    #[command(allow_negative_numbers = true)]
    Chart(chart::ChartArgs),
    /// Basins of attraction: a grid of initial states in a plane of state
    /// space, each run to its attractor.
    #[command(allow_negative_numbers = true)]
    Basins(basins::BasinsArgs),
    /// Elastic response spectra of a ground-motion record (AT2, two
    /// columns, CSV): pseudo-acceleration, pseudo-velocity, displacement.
    #[command(allow_negative_numbers = true)]
    Spectrum(spectrum::SpectrumArgs),
    /// A storey law (elastic, bilinear, Bouc–Wen) under cyclic drift or a
    /// drift history: its hysteresis loop and dissipated energy.
    #[command(allow_negative_numbers = true)]
    Hysteresis(hysteresis::HysteresisArgs),
    /// The static pushover of a building of a row or pair file: base shear
    /// against roof displacement, FEMA P695's overstrength and
    /// period-based ductility μ_T.
    #[command(allow_negative_numbers = true)]
    Pushover(pushover::PushoverArgs),
    /// Pounding of a row of buildings (a pair of frames, K buildings,
    /// isolated ones in their moats) under recorded ground motions:
    /// response with and without pounding, the gap that avoids contact,
    /// code rules, pounding spectra, moat-gap studies.
    #[command(allow_negative_numbers = true)]
    Pounding(pounding::PoundingArgs),
    /// The FEMA P695 collapse study of a row of buildings: per record an
    /// IDA to collapse, the median collapse intensity, CMR and ACMR.
    #[command(allow_negative_numbers = true)]
    Collapse(collapse::CollapseArgs),
    /// Find a periodic solution by shooting, with its Floquet multipliers.
    #[command(allow_negative_numbers = true)]
    Periodic(periodic::PeriodicArgs),
    /// Continue a branch of periodic solutions in a parameter (folds, branch
    /// points, period doublings, torus and grazing points).
    #[command(allow_negative_numbers = true)]
    Continue(branch::ContinueArgs),
    /// Run the default study and write its report (same as no subcommand).
    Report {
        /// Report folder.
        #[arg(long, default_value = "vibroimpact-report")]
        out: PathBuf,
    },
    /// Every subcommand's options as JSON (name, default, whether it takes
    /// a value): what the parity test holds the Python functions to.
    #[command(hide = true)]
    Options,
}

/// The options of every subcommand, from clap's command tree: for each,
/// `positional` names and `options` (`name` without the dashes,
/// `default`, `flag`).
fn options_document() -> serde_json::Value {
    use clap::CommandFactory;
    let cli = Cli::command();
    let commands: serde_json::Map<String, serde_json::Value> = cli
        .get_subcommands()
        .filter(|c| !c.is_hide_set())
        .map(|c| {
            let positional: Vec<&str> = c.get_positionals().map(|a| a.get_id().as_str()).collect();
            let options: Vec<serde_json::Value> = c
                .get_arguments()
                .filter(|a| !a.is_positional())
                .filter_map(|a| {
                    let name = a.get_long()?;
                    let default: Vec<String> = a
                        .get_default_values()
                        .iter()
                        .map(|v| v.to_string_lossy().into_owned())
                        .collect();
                    Some(serde_json::json!({
                        "name": name,
                        "default": (!default.is_empty()).then(|| default.join(",")),
                        "flag": !a.get_action().takes_values(),
                    }))
                })
                .filter(|o| o["name"] != "help" && o["name"] != "version")
                .collect();
            (
                c.get_name().to_string(),
                serde_json::json!({ "positional": positional, "options": options }),
            )
        })
        .collect();
    serde_json::Value::Object(commands)
}

fn main() -> ExitCode {
    // Output into a closed pipe (`vibroimpact … | head`) ends the command
    // quietly, as for other command-line tools, instead of a panic.
    #[cfg(unix)]
    // SAFETY: restoring the default action of SIGPIPE before any thread
    // starts; no handler of ours is replaced.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    let result = match &cli.command {
        Some(Command::Impact(args)) => impact::run(args),
        Some(Command::Identify(args)) => identify::run(args),
        Some(Command::Simulate(args)) => simulate::run(args),
        Some(Command::Periodic(args)) => periodic::run_periodic(args),
        Some(Command::Continue(args)) => branch::run_continue(args),
        Some(Command::Sweep(args)) => sweep::run(args),
        Some(Command::Chart(args)) => chart::run(args),
        Some(Command::Basins(args)) => basins::run(args),
        Some(Command::Spectrum(args)) => spectrum::run(args),
        Some(Command::Hysteresis(args)) => hysteresis::run(args),
        Some(Command::Pushover(args)) => pushover::run(args),
        Some(Command::Pounding(args)) => pounding::run(args),
        Some(Command::Collapse(args)) => collapse::run(args),
        Some(Command::Report { out }) => report::run(out),
        Some(Command::Options) => {
            println!("{:#}", options_document());
            Ok(())
        }
        None => report::run(&cli.out),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
