//! `vibroimpact spectrum`: the elastic response spectra of a recorded
//! ground motion ([`vibroimpact::seismic::spectrum`]) as JSON, CSV or a table, with
//! a figure of the pseudo-acceleration.

use std::path::PathBuf;

use clap::Args;
use vibroimpact::results::spectrum_document;
use vibroimpact::seismic::spectrum::{periods, response_spectrum, SpectralPoint};

use crate::error::{option_error, CliError};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};
use crate::records;

/// Options of `vibroimpact spectrum`.
#[derive(Args, Debug)]
pub struct SpectrumArgs {
    /// The record: a PEER NGA `.AT2` file, two columns (time s,
    /// acceleration; header lines are skipped) or CSV.
    record: PathBuf,
    /// Units of the record's accelerations: g, m/s2 or gal (cm/s²); needed
    /// when its header does not state them.
    #[arg(long)]
    units: Option<String>,
    /// Scale factor applied to the record.
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// Damping ratio of the oscillators.
    #[arg(long, default_value_t = 0.05)]
    damping: f64,
    /// Periods FROM:TO:N, with a `log` suffix for logarithmic spacing (s).
    #[arg(long, default_value = "0.05:5:100log")]
    periods: String,
    /// Output folder for spectrum.json, spectrum.csv and the figure.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// `FROM:TO:N[log]`.
fn parse_periods(text: &str) -> Result<Vec<f64>, CliError> {
    let bad = || {
        CliError::new(format!(
            "--periods {text}: give FROM:TO:N with an optional `log` suffix, e.g. 0.05:5:100log"
        ))
    };
    let (body, log) = match text.strip_suffix("log") {
        Some(b) => (b, true),
        None => (text, false),
    };
    let parts: Vec<&str> = body.split(':').collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad());
    };
    let (a, b, n) = (
        a.parse::<f64>().map_err(|_| bad())?,
        b.parse::<f64>().map_err(|_| bad())?,
        n.parse::<usize>().map_err(|_| bad())?,
    );
    periods(a, b, n, log).map_err(|e| CliError::new(format!("--periods {text}: {e}")))
}

fn csv(rows: &[SpectralPoint]) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row([
        "period",
        "pseudo_acceleration",
        "pseudo_velocity",
        "displacement",
    ])?;
    for p in rows {
        w.row([
            format!("{:e}", p.period),
            format!("{:e}", p.pseudo_acceleration),
            format!("{:e}", p.pseudo_velocity),
            format!("{:e}", p.displacement),
        ])?;
    }
    w.finish()
}

/// Runs `vibroimpact spectrum`.
pub fn run(args: &SpectrumArgs) -> Result<(), CliError> {
    let units = records::units(args.units.as_deref())?;
    let periods = parse_periods(&args.periods)?;
    let record = records::read(&args.record, units)?;
    let rows = response_spectrum(&record, args.scale, args.damping, &periods)
        .map_err(|e| option_error(&e))?;
    let doc = spectrum_document(&record, args.scale, args.damping, &rows);
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        write_atomic(&dir.join("spectrum.csv"), csv(&rows)?.as_bytes())?;
        write_atomic(
            &dir.join("spectrum.json"),
            serde_json::to_string_pretty(&doc)?.as_bytes(),
        )?;
        let mut fig = Figure::new(
            format!("Pseudo-acceleration spectrum, ζ = {}", args.damping),
            "period T  [s]",
            "PSA  [m/s²]",
        )
        .log_x()
        .legend_at(LegendPosition::None);
        fig.push(Series::line(
            "",
            rows.iter().map(|p| (p.period, p.pseudo_acceleration)),
        ));
        render(&fig, &dir.join("spectrum"))?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        Format::Csv => print!("{}", csv(&rows)?),
        Format::Table => {
            println!(
                "{}: {} samples, dt {}, PGA {:.4} m/s² ({} in the file), damping {}",
                record.source,
                record.times.len(),
                record.dt.map_or("variable".into(), |d| format!("{d} s")),
                record.pga() * args.scale,
                record.units.name(),
                args.damping
            );
            println!(
                "{:>10} {:>14} {:>14} {:>14}",
                "T [s]", "PSA [m/s2]", "PSV [m/s]", "SD [m]"
            );
            for p in &rows {
                println!(
                    "{:>10.4} {:>14.6e} {:>14.6e} {:>14.6e}",
                    p.period, p.pseudo_acceleration, p.pseudo_velocity, p.displacement
                );
            }
        }
    }
    Ok(())
}
