//! `vibroimpact impact`: two-body impact relations over a set of impact
//! velocities, closed form (exponential law) or by direct integration (any
//! law).

use clap::{Args, ValueEnum};
use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::impact::direct::DirectOptions;
use vibroimpact::impact::TwoBodies;
use vibroimpact::model::reference;
use vibroimpact::results::{impact_document, impact_rows, ImpactMethod, IMPACT_COLUMNS};

use crate::args::parse_mass2;
use crate::error::CliError;
use crate::format::{print_rows, Format};

/// Contact law names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LawName {
    /// Fujita's exponential law (seed eq. 1): --a-over-b, --alpha, --a.
    Exponential,
    /// Hertz k s^n: --stiffness, --exponent (default 1.5).
    Hertz,
    /// Linear spring-dashpot k s + c ṡ: --stiffness, --damping.
    KelvinVoigt,
    /// Hunt–Crossley k s^n (1 + χ ṡ): --stiffness, --exponent, --chi.
    HuntCrossley,
    /// Lankarani–Nikravesh: --stiffness, --exponent, --law-restitution.
    LankaraniNikravesh,
}

/// Force form on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Default)]
pub enum FormName {
    /// The law as published (may pull during fast separation).
    #[default]
    Published,
    /// Clamped at F >= 0.
    NonNegative,
}

/// Contact-law options shared by the commands.
#[derive(Args, Debug, Clone)]
pub struct LawArgs {
    /// Contact law.
    #[arg(long, value_enum, default_value_t = LawName::Exponential)]
    pub law: LawName,
    /// Exponential law: a/b in m/s (default: the seed's 1.2).
    #[arg(long)]
    pub a_over_b: Option<f64>,
    /// Exponential law: alpha in 1/m (default: the seed's 1.3e5).
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Exponential law: a in N (moves the contact point by ln(a)/alpha only).
    #[arg(long, default_value_t = 1.0)]
    pub a: f64,
    /// Power and linear laws: stiffness k (N/m^n).
    #[arg(long)]
    pub stiffness: Option<f64>,
    /// Power laws: exponent n (default 1.5).
    #[arg(long)]
    pub exponent: Option<f64>,
    /// Kelvin–Voigt: damping c (N s/m).
    #[arg(long)]
    pub damping: Option<f64>,
    /// Hunt–Crossley: damping factor chi (s/m).
    #[arg(long)]
    pub chi: Option<f64>,
    /// Lankarani–Nikravesh: target coefficient of restitution.
    #[arg(long)]
    pub law_restitution: Option<f64>,
    /// Lankarani–Nikravesh: floor of the onset velocity (m/s).
    #[arg(long, default_value_t = 1e-3)]
    pub min_impact_velocity: f64,
    /// Force form: published, or clamped at F >= 0.
    #[arg(long, value_enum, default_value_t)]
    pub form: FormName,
}

fn required(value: Option<f64>, flag: &str, law: &str) -> Result<f64, CliError> {
    value.ok_or_else(|| CliError::new(format!("--law {law} needs {flag}")))
}

impl LawArgs {
    /// Builds the contact law, naming any missing or invalid option.
    pub fn build(&self) -> Result<ContactLaw, CliError> {
        let form = match self.form {
            FormName::Published => ForceForm::Published,
            FormName::NonNegative => ForceForm::NonNegative,
        };
        let n = self.exponent.unwrap_or(1.5);
        Ok(match self.law {
            LawName::Exponential => ContactLaw::exponential_from_ratio(
                self.a_over_b.unwrap_or(reference::A_OVER_B),
                self.alpha.unwrap_or(reference::ALPHA),
                self.a,
                form,
            )?,
            LawName::Hertz => {
                ContactLaw::hertz(required(self.stiffness, "--stiffness", "hertz")?, n)?
            }
            LawName::KelvinVoigt => ContactLaw::kelvin_voigt(
                required(self.stiffness, "--stiffness", "kelvin-voigt")?,
                required(self.damping, "--damping", "kelvin-voigt")?,
                form,
            )?,
            LawName::HuntCrossley => ContactLaw::hunt_crossley(
                required(self.stiffness, "--stiffness", "hunt-crossley")?,
                n,
                required(self.chi, "--chi", "hunt-crossley")?,
                form,
            )?,
            LawName::LankaraniNikravesh => ContactLaw::lankarani_nikravesh(
                required(self.stiffness, "--stiffness", "lankarani-nikravesh")?,
                n,
                required(
                    self.law_restitution,
                    "--law-restitution",
                    "lankarani-nikravesh",
                )?,
                self.min_impact_velocity,
                form,
            )?,
        })
    }
}

/// How impacts are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Fujita's closed form (exponential law only).
    ClosedForm,
    /// Direct integration of the relative motion (any law).
    Integrate,
}

impl Method {
    fn method(self) -> ImpactMethod {
        match self {
            Method::ClosedForm => ImpactMethod::ClosedForm,
            Method::Integrate => ImpactMethod::Integrate,
        }
    }
}

/// The most impact velocities of one call (about 1 GB of output rows).
const MAX_VELOCITIES: usize = 10_000_000;

/// Options of `vibroimpact impact`.
#[derive(Args, Debug)]
pub struct ImpactArgs {
    #[command(flatten)]
    law: LawArgs,
    /// Mass of body 1 (kg); default: the seed's 38.1 mm steel ball.
    #[arg(long, default_value_t = 0.227)]
    mass1: f64,
    /// Mass of body 2 (kg), or `wall` (also `inf`) for a rigid wall.
    #[arg(long, default_value = "0.227")]
    mass2: String,
    /// Impact velocities (m/s): `0.01,0.1,1`, or a range `START:STOP:N`,
    /// `START:STOP:Nlog` (log-spaced) or `START:STOP:Nlin`.
    #[arg(long, allow_hyphen_values = true)]
    velocity: String,
    /// closed-form (exponential law) or integrate; default: closed-form for
    /// the exponential law, integrate otherwise.
    #[arg(long, value_enum)]
    method: Option<Method>,
    /// Integration tolerance (for --method integrate).
    #[arg(long, default_value_t = 1e-12)]
    rtol: f64,
    /// Force level (fraction of the peak) delimiting the contact duration;
    /// default 1e-3 for the exponential law, 0 for the others.
    #[arg(long)]
    duration_level: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// Parses a velocity list or range (see [`ImpactArgs`]).
pub fn parse_velocities(spec: &str) -> Result<Vec<f64>, CliError> {
    let bad = |what: String| CliError::new(format!("--velocity {spec}: {what}"));
    let number = |s: &str| -> Result<f64, CliError> {
        s.trim()
            .parse::<f64>()
            .map_err(|_| bad(format!("`{s}` is not a number")))
    };
    let values = if spec.contains(':') {
        let parts: Vec<&str> = spec.split(':').collect();
        if parts.len() != 3 {
            return Err(bad(
                "a range is START:STOP:N, START:STOP:Nlog or START:STOP:Nlin".into(),
            ));
        }
        let (start, stop) = (number(parts[0])?, number(parts[1])?);
        let count_spec = parts[2].trim();
        let (count, log) = if let Some(c) = count_spec.strip_suffix("log") {
            (c, true)
        } else {
            (count_spec.strip_suffix("lin").unwrap_or(count_spec), false)
        };
        let n: usize = count.parse().map_err(|_| {
            bad(format!(
                "`{count_spec}` is not a point count like 200 or 200log"
            ))
        })?;
        if !(2..=MAX_VELOCITIES).contains(&n) {
            return Err(bad(format!(
                "a range needs from 2 to {MAX_VELOCITIES} points"
            )));
        }
        if log && !(start > 0.0 && stop > 0.0) {
            return Err(bad("a log range needs positive ends".into()));
        }
        (0..n)
            .map(|i| {
                let x = i as f64 / (n - 1) as f64;
                if log {
                    (start.ln() + x * (stop.ln() - start.ln())).exp()
                } else {
                    start + x * (stop - start)
                }
            })
            .collect()
    } else {
        spec.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    if let Some(v) = values.iter().find(|v| !(**v > 0.0 && v.is_finite())) {
        return Err(bad(format!("impact velocities must be > 0 (got {v})")));
    }
    Ok(values)
}

/// Runs `vibroimpact impact`.
pub fn run(args: &ImpactArgs) -> Result<(), CliError> {
    let law = args.law.build()?;
    let bodies = TwoBodies::new(args.mass1, parse_mass2(&args.mass2)?)?;
    let velocities = parse_velocities(&args.velocity)?;
    let method = args.method.unwrap_or(if law.has_compact_support() {
        Method::Integrate
    } else {
        Method::ClosedForm
    });
    let opts = DirectOptions {
        rtol: args.rtol,
        duration_level: args.duration_level,
        ..DirectOptions::default()
    };
    if method == Method::ClosedForm && law.has_compact_support() {
        return Err(CliError::new(format!(
            "--method closed-form exists only for the exponential law, not for {}; use --method integrate",
            law.name()
        )));
    }
    let rows = impact_rows(&law, bodies, &velocities, method.method(), &opts)?;
    match args.format {
        Format::Json => {
            let doc = impact_document(&law, bodies, method.method(), &rows);
            println!("{}", serde_json::to_string_pretty(&doc)?);
        }
        format => {
            let ncol = if method == Method::Integrate { 10 } else { 9 };
            let table: Vec<Vec<Option<f64>>> =
                rows.iter().map(|r| r.values()[..ncol].to_vec()).collect();
            print_rows(format, &IMPACT_COLUMNS[..ncol], &table)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_specs() {
        assert_eq!(
            parse_velocities("0.01,0.1,1").unwrap(),
            vec![0.01, 0.1, 1.0]
        );
        let r = parse_velocities("0.001:10:5log").unwrap();
        assert_eq!(r.len(), 5);
        assert!(
            (r[0] - 0.001).abs() < 1e-18
                && (r[4] - 10.0).abs() < 1e-12
                && (r[1] - 0.01).abs() < 1e-15
        );
        assert_eq!(parse_velocities("1:2:3").unwrap(), vec![1.0, 1.5, 2.0]);
        for bad in [
            "", "0.1,x", "0,1", "-1", "1:2", "1:2:1", "0:1:3log", "1:2:3foo",
        ] {
            assert!(parse_velocities(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn mass2_wall() {
        assert!(parse_mass2("wall").unwrap().is_infinite());
        assert_eq!(parse_mass2("0.5").unwrap(), 0.5);
        assert!(parse_mass2("heavy").is_err());
    }
}
