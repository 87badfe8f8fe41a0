//! `vibroimpact identify`: a/b and α of the exponential law from measured
//! impacts (seed §3).

use std::path::PathBuf;

use clap::Args;
use vibroimpact::identify::Estimate;
pub use vibroimpact::identify::Identification;
use vibroimpact::impact::TwoBodies;

use crate::args::parse_mass2;
use crate::error::CliError;
use crate::format::SummaryFormat;
use crate::measurements::Measurements;

/// Options of `vibroimpact identify`.
#[derive(Args, Debug)]
pub struct IdentifyArgs {
    /// CSV with columns `impact_velocity` (m/s) and `restitution`.
    #[arg(long)]
    restitution: Option<PathBuf>,
    /// CSV with columns `impact_velocity` (m/s) and `peak_acceleration`
    /// (m/s², of body 1: peak force / mass1).
    #[arg(long)]
    acceleration: Option<PathBuf>,
    /// Mass of body 1 (kg).
    #[arg(long, default_value_t = 0.227)]
    mass1: f64,
    /// Mass of body 2 (kg), or `wall`.
    #[arg(long, default_value = "0.227")]
    mass2: String,
    /// Hold a/b at this value (m/s) and fit alpha only.
    #[arg(long)]
    a_over_b: Option<f64>,
    /// Fit a/b and alpha jointly from both data sets (default: a/b from the
    /// restitution data, then alpha given a/b, as in the seed).
    #[arg(long)]
    joint: bool,
    /// Output format (table or json).
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    format: SummaryFormat,
}

/// Runs `vibroimpact identify`.
pub fn run(args: &IdentifyArgs) -> Result<(), CliError> {
    if args.restitution.is_none() && args.acceleration.is_none() {
        return Err(CliError::new(
            "nothing to identify: give --restitution and/or --acceleration",
        ));
    }
    if let Some(q) = args.a_over_b {
        if !(q > 0.0 && q.is_finite()) {
            return Err(CliError::new(format!("--a-over-b {q}: must be > 0")));
        }
    }
    let bodies = TwoBodies::new(args.mass1, parse_mass2(&args.mass2)?)?;
    let data = Measurements::read(args.restitution.as_deref(), args.acceleration.as_deref())?;
    let result = data.identify(bodies, args.a_over_b, args.joint)?;
    match args.format {
        SummaryFormat::Json => println!("{}", serde_json::to_string_pretty(&result)?),
        _ => print!("{}", table_text(&result)),
    }
    Ok(())
}

/// Human-readable summary of an identification.
pub fn table_text(r: &Identification) -> String {
    let mut s = format!("method: {}\n", r.method);
    let est = |name: &str, unit: &str, e: &Option<Estimate>| match e {
        Some(e) if e.std_error > 0.0 => format!(
            "{name:<9} = {:.6e} ± {:.2e} {unit} ({:.2}%)\n",
            e.value,
            e.std_error,
            100.0 * e.std_error / e.value
        ),
        Some(e) => format!("{name:<9} = {:.6e} {unit} (given)\n", e.value),
        None => String::new(),
    };
    s += &est("a/b", "m/s", &r.a_over_b);
    s += &est("alpha", "1/m", &r.alpha);
    if let Some(f) = &r.restitution_fit {
        s += &format!(
            "restitution fit: {} points, residual std {:.3e}\n",
            f.residuals.len(),
            f.residual_std
        );
    }
    if let Some(f) = &r.acceleration_fit {
        s += &format!(
            "acceleration fit: {} points, residual std of ln A {:.3e} ({:.1}%)\n",
            f.acceleration_residuals.len(),
            f.acceleration_residual_std,
            100.0 * f.acceleration_residual_std
        );
        if f.correlation != 0.0 {
            s += &format!("correlation(ln a/b, ln alpha) = {:.3}\n", f.correlation);
        }
    }
    s
}
