//! `vibroimpact simulate`: time history and impact log of a model file.

use std::path::{Path, PathBuf};

use clap::Args;
use vibroimpact::model::Model;
use vibroimpact::simulate::{estimate_work, simulate_streaming, Simulation, SimulationOptions};

use crate::args::{ImpactArgs, IntegratorName, MethodName};
use crate::error::CliError;
use crate::format::{history_header, number, CsvText, SummaryFormat};
use crate::model_io::read_document;
use crate::output::{commit_temp, temp_path, Pending};
use crate::output::{ensure_dir, write_atomic, OutputError};
use crate::plot::{render, Figure, LegendPosition, Marker, Series};
use vibroimpact::model::file::LoadedModel;
use vibroimpact::results::{simulation_summary, Provenance, SimulationSummary};

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
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    format: SummaryFormat,
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
    /// `auto` (local from 16 groups of bodies up); `global`: every body
    /// integrated at every step; `local`: exact
    /// motion between contacts, only bodies in touch integrated.
    #[arg(long, value_enum, default_value_t = IntegratorName::Auto)]
    integrator: IntegratorName,
    /// Force level F_on (N) that delimits impacts of the exponential law
    /// (default: [simulation] impact_force_threshold, else 1e-3 N).
    #[arg(long)]
    impact_force_threshold: Option<f64>,
    #[command(flatten)]
    impacts: ImpactArgs,
}

/// Simulation options from the command line and the model file.
fn options(args: &SimulateArgs, loaded: &LoadedModel) -> Result<SimulationOptions, CliError> {
    let model = &loaded.model;
    let positive = |flag: &str, v: f64| {
        if v > 0.0 && v.is_finite() {
            Ok(v)
        } else {
            Err(CliError::new(format!(
                "{flag} {v}: give a positive, finite {}",
                if flag == "--periods" {
                    "number of forcing periods"
                } else {
                    "time (s)"
                }
            )))
        }
    };
    let t_end = match (args.duration, args.periods) {
        (Some(d), _) => positive("--duration", d)?,
        (None, Some(p)) => {
            positive("--periods", p)?;
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
        integrator: args.integrator.integrator(),
        ..SimulationOptions::default()
    })
}

/// The impact log as CSV (quoted where a pair name needs it).
fn impact_log_csv(model: &Model, sim: &Simulation) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row([
        "start_time",
        "end_time",
        "pair",
        "impact_velocity",
        "rebound_velocity",
        "restitution",
        "peak_force",
        "duration",
        "impacts",
        "impulse",
        "energy_lost",
    ])?;
    let f = |x: f64| {
        if x.is_finite() {
            format!("{x:e}")
        } else {
            String::new()
        }
    };
    // A rigid impact's peak force and duration are the soft law's
    // estimates (docs/theory.md §12); its impulse and loss are exact.
    for i in &sim.impacts {
        let (duration, kind, impulse, lost) = match &i.rigid {
            Some(r) => (r.duration, "rigid", r.impulse, r.energy_lost),
            None => (i.duration(), "soft", f64::NAN, f64::NAN),
        };
        w.row([
            f(i.start_time),
            f(i.end_time),
            model.contact_name(i.contact),
            f(i.impact_velocity),
            f(i.rebound_velocity),
            f(i.restitution()),
            f(i.peak_force),
            f(duration),
            kind.to_string(),
            f(impulse),
            f(lost),
        ])?;
    }
    w.finish()
}

/// Writes the impact log, summary and plots into `dir` (the time history
/// is streamed there by [`HistoryFile`] while the simulation runs).
pub fn write_outputs(
    dir: &Path,
    model: &Model,
    sim: &Simulation,
    summary: &SimulationSummary,
    phase_body: usize,
) -> Result<(), CliError> {
    ensure_dir(dir)?;
    write_atomic(
        &dir.join("impacts.csv"),
        impact_log_csv(model, sim)?.as_bytes(),
    )?;
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
    // A row of 10⁶ printed 10⁶ + 1 lines here: the busiest contacts,
    // the rest counted (every one is in the JSON summary).
    let n = s.impacts_per_contact.len();
    if n <= SHOWN_CONTACTS {
        for c in &s.impacts_per_contact {
            t.push_str(&format!("  {:<16} {} impacts\n", c.contact, c.impacts));
        }
    } else {
        let mut busiest: Vec<_> = s.impacts_per_contact.iter().enumerate().collect();
        busiest.sort_by(|a, b| b.1.impacts.cmp(&a.1.impacts).then(a.0.cmp(&b.0)));
        busiest.truncate(SHOWN_CONTACTS);
        busiest.sort_by_key(|(i, _)| *i);
        for (_, c) in busiest {
            t.push_str(&format!("  {:<16} {} impacts\n", c.contact, c.impacts));
        }
        let silent = s
            .impacts_per_contact
            .iter()
            .filter(|c| c.impacts == 0)
            .count();
        t.push_str(&format!(
            "  ... {} more contacts not shown ({silent} of all {n} without impacts; every one in --format json)\n",
            n - SHOWN_CONTACTS
        ));
    }
    if let Some(l) = &s.local {
        t.push_str(&format!(
            "local integrator: {} bodies integrated (at most {} at once, in at most {} sets), {} set changes, {} contact checks\n",
            l.bodies_integrated, l.largest_set, l.most_sets, l.set_changes, l.contact_checks
        ));
    }
    if let Some(r) = &s.record {
        t.push_str(&format!(
            "record: {} ({} samples, {}, {:.3} s, PGA {:.4} m/s2 as read) x {}\n",
            r.source,
            r.samples,
            r.dt.map_or("non-uniform step".to_string(), |dt| format!("dt {dt} s")),
            r.duration,
            r.pga,
            r.scale
        ));
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
    let document = read_document(&args.model)?;
    let mut loaded = document.build()?;
    loaded.model = args.impacts.apply(loaded.model)?;
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
    let interrupt = crate::interrupt::on_ctrl_c();
    let opts = SimulationOptions {
        interrupt: Some(interrupt.clone()),
        ..opts
    };
    crate::progress::announce_long(estimate_work(model, &opts));
    let mut history = match &args.out {
        Some(dir) => {
            ensure_dir(dir)?;
            Some(HistoryFile::create(&dir.join("history.csv"), model, &opts)?)
        }
        None => None,
    };
    let run = simulate_streaming(model, &opts, |t, state| {
        history.as_mut().is_none_or(|h| h.sample(t, state))
    });
    let mut sim = match run {
        Ok(sim) => sim,
        // Refused before any step (`--output-step 0`): no file is left.
        Err(e) => {
            if let Some(h) = history {
                h.discard();
            }
            return Err(e.into());
        }
    };
    let mut s = simulation_summary(model, &sim);
    s.record = loaded.record.clone();
    s.provenance = Some(Provenance::new(&document, &opts));
    if let (Some(dir), Some(history)) = (&args.out, history) {
        (sim.times, sim.states) = history.finish()?;
        write_outputs(dir, model, &sim, &s, phase_body)?;
    }
    match args.format {
        SummaryFormat::Json => println!("{}", serde_json::to_string_pretty(&s)?),
        _ => print!("{}", summary_text(&s)),
    }
    if interrupt.requested() {
        return Err(CliError::new(format!(
            "interrupted (Ctrl-C) at t = {:.9} s: the results up to there are kept{}",
            sim.final_time,
            if args.out.is_some() {
                " in the output folder"
            } else {
                ""
            }
        )));
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

/// Contacts listed in the table summary: the busiest, in model order.
const SHOWN_CONTACTS: usize = 20;

/// Points of the history kept for the figures (every k-th sample).
const PLOTTED_SAMPLES: f64 = 20_000.0;

/// `history.csv` written while the simulation runs: rows go through a
/// buffered CSV writer into a temporary sibling, renamed when complete; the
/// figures get every k-th sample (at most about 20 000).
struct HistoryFile {
    path: PathBuf,
    tmp: PathBuf,
    _pending: Pending,
    writer: csv::Writer<std::io::BufWriter<std::fs::File>>,
    error: Option<std::io::Error>,
    every: usize,
    count: usize,
    /// The next sample kept for the figures.
    next_kept: usize,
    times: Vec<f64>,
    states: Vec<f64>,
    row: Vec<String>,
}

impl HistoryFile {
    /// Opens the temporary file and writes the header.
    fn create(path: &Path, model: &Model, opts: &SimulationOptions) -> Result<Self, CliError> {
        let tmp = temp_path(path);
        let pending = Pending::new(&tmp);
        let fail = |e: std::io::Error| OutputError {
            path: path.to_path_buf(),
            source: e,
        };
        let file = std::fs::File::create(&tmp).map_err(fail)?;
        let mut writer = csv::Writer::from_writer(std::io::BufWriter::new(file));
        let header = history_header(model);
        writer.write_record(&header).map_err(|e| fail(e.into()))?;
        let samples = opts.output_step.map_or(1.0, |dt| opts.t_end / dt + 1.0);
        Ok(Self {
            path: path.to_path_buf(),
            tmp,
            _pending: pending,
            writer,
            error: None,
            every: (samples / PLOTTED_SAMPLES).ceil().max(1.0) as usize,
            count: 0,
            next_kept: 0,
            times: Vec::new(),
            states: Vec::new(),
            row: Vec::with_capacity(header.len()),
        })
    }

    /// Writes one sample; false (stop the simulation) once writing failed.
    fn sample(&mut self, t: f64, state: &[f64]) -> bool {
        self.row.clear();
        self.row.push(number(Some(t)));
        self.row.extend(state.iter().map(|&x| number(Some(x))));
        if let Err(e) = self.writer.write_record(&self.row) {
            self.error = Some(e.into());
            return false;
        }
        if self.count == self.next_kept {
            self.times.push(t);
            self.states.extend_from_slice(state);
            self.next_kept += self.every;
        }
        self.count += 1;
        true
    }

    /// Removes the temporary file (a run refused before its first step).
    fn discard(self) {
        drop(self.writer);
        let _ = std::fs::remove_file(&self.tmp);
    }

    /// Flushes and renames the file into place; returns the samples kept
    /// for the figures. On a write error the temporary file is removed and
    /// the error names the file.
    fn finish(self) -> Result<(Vec<f64>, Vec<f64>), CliError> {
        let fail = |source: std::io::Error| {
            let _ = std::fs::remove_file(&self.tmp);
            CliError::from(OutputError {
                path: self.path.clone(),
                source,
            })
        };
        if let Some(e) = self.error {
            return Err(fail(e));
        }
        let file = self
            .writer
            .into_inner()
            .map_err(|e| fail(e.into_error()))?
            .into_inner()
            .map_err(|e| fail(e.into_error()))?;
        file.sync_all().map_err(fail)?;
        commit_temp(&self.tmp, &self.path)?;
        Ok((self.times, self.states))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The history file streams every sample to disk but keeps at most
    /// about 20 000 for the figures, whatever the length of the run.
    #[test]
    fn history_file_streams_and_keeps_a_bounded_sample() {
        let dir = std::env::temp_dir().join(format!("vi-history-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let model = vibroimpact::model::reference::r2(2, 1e-3, 7.0).unwrap();
        let opts = SimulationOptions {
            t_end: 1e6,
            output_step: Some(1.0),
            ..SimulationOptions::default()
        };
        let path = dir.join("history.csv");
        let mut h = HistoryFile::create(&path, &model, &opts).unwrap();
        assert_eq!(h.every, 51);
        let n: usize = 100_000;
        for k in 0..n {
            assert!(h.sample(k as f64, &[0.5, -0.5, 1.0, -1.0]));
        }
        assert!(!path.exists(), "only the temporary file while running");
        let (times, states) = h.finish().unwrap();
        assert_eq!(times.len(), n.div_ceil(51));
        assert_eq!(states.len(), 4 * times.len());
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.lines().count(), n + 1);
        assert_eq!(text.lines().next().unwrap(), "t,u_p1,u_p2,v_p1,v_p2");
        assert_eq!(text.lines().nth(2).unwrap(), "1e0,5e-1,-5e-1,1e0,-1e0");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
