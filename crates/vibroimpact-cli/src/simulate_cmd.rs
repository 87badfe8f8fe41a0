//! `vibroimpact simulate`: time history and impact log of a model file.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use vibroimpact::integrate::Method;
use vibroimpact::model::Model;
use vibroimpact::simulate::{simulate, Simulation, SimulationOptions};

use crate::error::CliError;
use crate::format::{csv_text, Format};
use crate::model_io::read_model;
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Marker, Series};
use vibroimpact::model_file::LoadedModel;
use vibroimpact::results::{simulation_summary, SimulationSummary};

/// Integration method on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodName {
    /// Explicit 8th-order Dormand–Prince (DOP853): impacts, free flight.
    Dop853,
    /// Implicit Rosenbrock (RODAS): bodies pressed together for long times.
    Rodas,
    /// DOP853, switching to RODAS when its stiffness test fires.
    Auto,
}

impl MethodName {
    /// The library's method.
    pub fn method(self) -> Method {
        match self {
            MethodName::Dop853 => Method::Dop853,
            MethodName::Rodas => Method::Rodas,
            MethodName::Auto => Method::Auto,
        }
    }
}

/// Options of `vibroimpact simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Model file (TOML, see docs/model.md).
    model: PathBuf,
    /// Simulated time (s).
    #[arg(long, conflicts_with = "periods", required_unless_present = "periods")]
    duration: Option<f64>,
    /// Simulated time in forcing periods 2π/Ω.
    #[arg(long)]
    periods: Option<f64>,
    /// Relative tolerance (default: the model's [simulation] rtol, else 1e-8).
    #[arg(long)]
    rtol: Option<f64>,
    /// Absolute tolerance in m and m/s (default: [simulation] atol, else rtol × 1e-4).
    #[arg(long)]
    atol: Option<f64>,
    /// Output folder for the time history, impact log, summary and plots;
    /// without it only the summary is printed.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Summary format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Time-history sampling interval (s); default: 1/100 forcing period, or duration/2000.
    #[arg(long)]
    output_step: Option<f64>,
    /// Body of the phase portrait (default: the first).
    #[arg(long)]
    body: Option<String>,
    /// Integrate the energy audit and report it.
    #[arg(long)]
    energy: bool,
    /// Integration method.
    #[arg(long, value_enum, default_value_t = MethodName::Dop853)]
    method: MethodName,
    /// Force level F_on (N) that delimits impacts of the exponential law
    /// (default: [simulation] impact_force_threshold, else 1e-3 N).
    #[arg(long)]
    impact_force_threshold: Option<f64>,
}

/// Simulation options from the command line and the model file.
fn options(args: &SimulateArgs, loaded: &LoadedModel) -> Result<SimulationOptions, CliError> {
    let model = &loaded.model;
    let t_end = match (args.duration, args.periods) {
        (Some(d), _) => d,
        (None, Some(p)) => {
            let w = model.forcing_frequency().ok_or_else(|| {
                CliError::new(
                    "--periods needs a periodic excitation with one frequency; use --duration",
                )
            })?;
            p * 2.0 * std::f64::consts::PI / w
        }
        (None, None) => return Err(CliError::new("give --duration or --periods")),
    };
    let rtol = args.rtol.or(loaded.simulation.rtol).unwrap_or(1e-8);
    let output_step = args.out.as_ref().map(|_| {
        args.output_step
            .unwrap_or_else(|| match model.forcing_frequency() {
                Some(w) => 2.0 * std::f64::consts::PI / w / 100.0,
                None => t_end / 2000.0,
            })
    });
    Ok(SimulationOptions {
        t_end,
        rtol,
        atol: args.atol.or(loaded.simulation.atol).unwrap_or(rtol * 1e-4),
        output_step,
        impact_force_threshold: args
            .impact_force_threshold
            .or(loaded.simulation.impact_force_threshold)
            .unwrap_or(1e-3),
        energy: args.energy,
        method: args.method.method(),
        ..SimulationOptions::default()
    })
}

/// CSV of sampled states: `t, u_<body>…, v_<body>…` (rows of `states` are
/// `[u.., v..]` at `times`).
pub fn history_csv(model: &Model, times: &[f64], states: &[f64]) -> Result<String, CliError> {
    let n = model.bodies().len();
    let mut columns: Vec<String> = vec!["t".into()];
    columns.extend(model.bodies().iter().map(|b| format!("u_{}", b.name)));
    columns.extend(model.bodies().iter().map(|b| format!("v_{}", b.name)));
    let rows: Vec<Vec<Option<f64>>> = times
        .iter()
        .enumerate()
        .map(|(j, &t)| {
            std::iter::once(Some(t))
                .chain(states[j * 2 * n..(j + 1) * 2 * n].iter().map(|&x| Some(x)))
                .collect()
        })
        .collect();
    let cols: Vec<&str> = columns.iter().map(String::as_str).collect();
    csv_text(&cols, &rows)
}

/// Writes the time history, impact log, summary and plots into `dir`.
pub fn write_outputs(
    dir: &Path,
    model: &Model,
    sim: &Simulation,
    summary: &SimulationSummary,
    phase_body: usize,
) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(
        &dir.join("history.csv"),
        history_csv(model, &sim.times, &sim.states)?.as_bytes(),
    )?;
    let mut log = String::from("start_time,end_time,pair,impact_velocity,rebound_velocity,restitution,peak_force,duration\n");
    for i in &sim.impacts {
        let f = |x: f64| {
            if x.is_finite() {
                format!("{x:e}")
            } else {
                String::new()
            }
        };
        log.push_str(&format!(
            "{},{},{},{},{},{},{},{}\n",
            f(i.start_time),
            f(i.end_time),
            model.contact_name(i.contact),
            f(i.impact_velocity),
            f(i.rebound_velocity),
            f(i.restitution()),
            f(i.peak_force),
            f(i.duration())
        ));
    }
    write_atomic(&dir.join("impacts.csv"), log.as_bytes())?;
    write_atomic(
        &dir.join("summary.json"),
        serde_json::to_string_pretty(summary)?.as_bytes(),
    )?;
    plot_history(dir, model, sim, phase_body)
}

/// Displacement, phase-portrait and impact-velocity figures.
pub fn plot_history(
    dir: &Path,
    model: &Model,
    sim: &Simulation,
    phase_body: usize,
) -> Result<(), CliError> {
    let n = model.bodies().len();
    let shown: Vec<usize> = if n <= 8 {
        (0..n).collect()
    } else {
        (0..8).map(|j| j * (n - 1) / 7).collect()
    };
    let mut fig = Figure::new("Displacements", "time t  [s]", "displacement u  [mm]")
        .legend_at(LegendPosition::Best);
    for &i in &shown {
        fig.push(Series::line(
            format!("u_{}", model.bodies()[i].name),
            sim.times
                .iter()
                .enumerate()
                .map(|(j, &t)| (t, 1e3 * sim.states[j * 2 * n + i])),
        ));
    }
    render(&fig, &dir.join("displacements"))?;
    let b = phase_body;
    let fig = Figure::new(
        format!("Phase portrait of {}", model.bodies()[b].name),
        "displacement u  [mm]",
        "velocity v  [m/s]",
    )
    .legend_at(LegendPosition::None)
    .with_series(Series::line(
        "",
        (0..sim.times.len()).map(|j| {
            (
                1e3 * sim.states[j * 2 * n + b],
                sim.states[j * 2 * n + n + b],
            )
        }),
    ));
    render(&fig, &dir.join("phase_portrait"))?;
    let mut fig = Figure::new("Impacts", "start time  [s]", "impact velocity  [m/s]")
        .legend_at(LegendPosition::Best);
    let contacts = model.contacts().len();
    let groups: Vec<usize> = if contacts <= 6 {
        (0..contacts).collect()
    } else {
        Vec::new()
    };
    for &k in &groups {
        let pts: Vec<(f64, f64)> = sim
            .impacts
            .iter()
            .filter(|i| i.contact == k)
            .map(|i| (i.start_time, i.impact_velocity))
            .collect();
        if !pts.is_empty() {
            fig.push(Series::markers(model.contact_name(k), pts, Marker::Circle));
        }
    }
    if groups.is_empty() {
        fig.push(Series::markers(
            "all contacts",
            sim.impacts
                .iter()
                .map(|i| (i.start_time, i.impact_velocity)),
            Marker::Circle,
        ));
    }
    render(&fig, &dir.join("impact_velocities"))?;
    Ok(())
}

/// Human-readable summary.
pub fn summary_text(s: &SimulationSummary) -> String {
    let mut t = format!(
        "{}: t = {:.6} s, {} impacts, {} steps ({} rejected), {} rhs evaluations, {} contact evaluations\n",
        if s.completed { "completed" } else { "STOPPED" },
        s.final_time,
        s.impact_count,
        s.steps,
        s.rejected_steps,
        s.rhs_evaluations,
        s.contact_evaluations
    );
    for c in &s.impacts_per_contact {
        t.push_str(&format!("  {:<16} {} impacts\n", c.contact, c.impacts));
    }
    if let Some(e) = &s.energy {
        t.push_str(&format!(
            "energy: input {:.6e} J, dampers {:.6e} J, contacts {:.6e} J, mechanical {:.6e} J, balance residual {:.2e} J\n",
            e.input_work, e.damping_dissipation, e.contact_dissipation, e.mechanical, e.residual
        ));
    }
    if let Some(err) = &s.error {
        t.push_str(&format!("error: {err}\n"));
    }
    t
}

/// Runs `vibroimpact simulate`.
pub fn run(args: &SimulateArgs) -> Result<(), CliError> {
    let loaded = read_model(&args.model)?;
    let opts = options(args, &loaded)?;
    let model = &loaded.model;
    let phase_body = match &args.body {
        None => 0,
        Some(name) => model
            .bodies()
            .iter()
            .position(|b| &b.name == name)
            .ok_or_else(|| CliError::new(format!("--body {name}: no such body")))?,
    };
    let sim = simulate(model, &opts).map_err(|e| CliError::new(e.to_string()))?;
    let s = simulation_summary(model, &sim);
    if let Some(dir) = &args.out {
        write_outputs(dir, model, &sim, &s, phase_body)?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&s)?),
        _ => print!("{}", summary_text(&s)),
    }
    match &sim.error {
        None => Ok(()),
        Some(e) => Err(CliError::new(format!(
            "integration failed at t = {:.9} s (results up to there are kept{}): {e}",
            sim.final_time,
            if args.out.is_some() {
                " in the output folder"
            } else {
                ""
            }
        ))),
    }
}
