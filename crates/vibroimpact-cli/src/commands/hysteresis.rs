//! `vibroimpact hysteresis`: a storey law ([`vibroimpact::model::hysteresis`])
//! under a cyclic drift protocol or a drift history from a file: its loop
//! (force and dissipated energy at every drift) as JSON, CSV or a table,
//! with a figure of the loop.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use vibroimpact::model::hysteresis::{
    cyclic_protocol, parse_drifts, seconds_per_drift, under_drift, LawError, StoreyLaw, StoreySpec,
};
use vibroimpact::results::{hysteresis_document, hysteresis_summary};
use vibroimpact::simulate::LONG_RUN;

use crate::error::CliError;
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};

/// The storey laws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LawName {
    /// F = k d.
    Elastic,
    /// Bilinear with kinematic hardening (OpenSees Steel01 without
    /// isotropic hardening).
    Bilinear,
    /// Bouc–Wen with optional degradation (OpenSees BoucWen).
    BoucWen,
    /// The modified Ibarra–Medina–Krawinkler storey (OpenSees IMKBilin,
    /// symmetric) with cyclic deterioration.
    Imk,
}

/// Options of `vibroimpact hysteresis`.
#[derive(Args, Debug)]
pub struct HysteresisArgs {
    /// The law.
    #[arg(long, value_enum, default_value_t = LawName::Bilinear)]
    law: LawName,
    /// Elastic stiffness k (N/m).
    #[arg(long)]
    stiffness: f64,
    /// Yield drift u_y (m); bilinear and Bouc–Wen.
    #[arg(long)]
    yield_drift: Option<f64>,
    /// Post-yield stiffness over the elastic one, in [0, 1).
    #[arg(long, default_value_t = 0.05)]
    post_yield_ratio: f64,
    /// Bouc–Wen exponent n (≥ 1; large: sharp yield).
    #[arg(long, default_value_t = 2.0)]
    exponent: f64,
    /// Bouc–Wen β.
    #[arg(long, default_value_t = 0.5)]
    beta: f64,
    /// Bouc–Wen γ.
    #[arg(long, default_value_t = 0.5)]
    gamma: f64,
    /// Bouc–Wen δ_A (1/J): A = 1 − δ_A e with e the hysteretic work.
    #[arg(long, default_value_t = 0.0)]
    degradation_a: f64,
    /// Bouc–Wen δ_ν (1/J), strength degradation.
    #[arg(long, default_value_t = 0.0)]
    degradation_nu: f64,
    /// Bouc–Wen δ_η (1/J), stiffness degradation.
    #[arg(long, default_value_t = 0.0)]
    degradation_eta: f64,
    /// IMK: the capping strength over the yield strength (≥ 1).
    #[arg(long)]
    cap_ratio: Option<f64>,
    /// IMK: the plastic drift from yield to the cap (m).
    #[arg(long)]
    plastic_drift: Option<f64>,
    /// IMK: the drift from the cap to zero force (m).
    #[arg(long)]
    post_capping_drift: Option<f64>,
    /// IMK: the residual strength over the yield strength, in [0, 1].
    #[arg(long)]
    residual_ratio: Option<f64>,
    /// IMK: the ultimate drift (m, total).
    #[arg(long)]
    ultimate_drift: Option<f64>,
    /// IMK: λ_S (m), strength deterioration (none if not given).
    #[arg(long)]
    lambda_s: Option<f64>,
    /// IMK: λ_C (m), cap deterioration (none if not given).
    #[arg(long)]
    lambda_c: Option<f64>,
    /// IMK: λ_K (m), unloading-stiffness deterioration (none if not given).
    #[arg(long)]
    lambda_k: Option<f64>,
    /// IMK: c_S.
    #[arg(long, default_value_t = 1.0)]
    c_s: f64,
    /// IMK: c_C.
    #[arg(long, default_value_t = 1.0)]
    c_c: f64,
    /// IMK: c_K.
    #[arg(long, default_value_t = 1.0)]
    c_k: f64,
    /// Drift amplitudes of the cyclic protocol (m), comma separated, each
    /// held for --cycles sine cycles.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    amplitudes: Vec<f64>,
    /// Cycles at each amplitude.
    #[arg(long, default_value_t = 2)]
    cycles: usize,
    /// Samples a cycle (a multiple of 4).
    #[arg(long, default_value_t = 200)]
    points: usize,
    /// A drift history instead of the protocol: a file of drifts (m), one a
    /// line (a header line and `#` comments are skipped); linear between
    /// them, from rest.
    #[arg(long)]
    drift: Option<PathBuf>,
    /// Relative tolerance of Bouc–Wen's integration along the drift.
    #[arg(long, default_value_t = 1e-10)]
    rtol: f64,
    /// Output folder: hysteresis.csv, hysteresis.json and the loop figure.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

impl HysteresisArgs {
    /// The law's spec from the options.
    fn spec(&self) -> Result<StoreySpec, CliError> {
        let uy = || {
            self.yield_drift
                .ok_or_else(|| CliError::new("--yield-drift: give the yield drift (m)"))
        };
        Ok(match self.law {
            LawName::Elastic if self.yield_drift.is_some() => {
                return Err(CliError::new(
                    "--yield-drift: an elastic storey has no yield drift (give --law bilinear or bouc-wen)",
                ))
            }
            LawName::Elastic => StoreySpec::Elastic {},
            LawName::Bilinear => StoreySpec::Bilinear {
                yield_drift: uy()?,
                post_yield_ratio: self.post_yield_ratio,
            },
            LawName::BoucWen => StoreySpec::BoucWen {
                yield_drift: uy()?,
                post_yield_ratio: self.post_yield_ratio,
                exponent: Some(self.exponent),
                beta: Some(self.beta),
                gamma: Some(self.gamma),
                degradation_a: Some(self.degradation_a),
                degradation_nu: Some(self.degradation_nu),
                degradation_eta: Some(self.degradation_eta),
            },
            LawName::Imk => StoreySpec::imk(
                self.yield_drift,
                [
                    self.cap_ratio,
                    self.plastic_drift,
                    self.post_capping_drift,
                    self.residual_ratio,
                    self.ultimate_drift,
                ],
                [self.lambda_s, self.lambda_c, self.lambda_k],
                [self.c_s, self.c_c, self.c_k],
            )
            .map_err(|key| {
                CliError::new(format!("--{}: give it for --law imk", key.replace('_', "-")))
            })?,
        })
    }
}

/// A law error in the command line's words.
fn law_error(e: LawError) -> CliError {
    CliError::new(format!(
        "--{} {}: {}",
        e.key.replace(['_', '.'], "-"),
        e.value,
        e.message
    ))
}

/// The drifts of a file ([`parse_drifts`]); errors name the file and line.
fn read_drifts(path: &Path) -> Result<Vec<f64>, CliError> {
    let name = path.display().to_string();
    let text = crate::input::read_text(path).map_err(|e| CliError::new(format!("{name}: {e}")))?;
    parse_drifts(&text, &name).map_err(|e| CliError::new(e.to_string()))
}

/// Runs `vibroimpact hysteresis`.
pub fn run(args: &HysteresisArgs) -> Result<(), CliError> {
    let law = args.spec()?.law(args.stiffness).map_err(law_error)?;
    if !(args.rtol.is_finite() && args.rtol > 0.0) {
        return Err(CliError::new(format!(
            "--rtol {}: must be finite and > 0",
            args.rtol
        )));
    }
    let drifts = match (&args.drift, args.amplitudes.is_empty()) {
        (Some(path), true) => read_drifts(path)?,
        (None, false) => {
            cyclic_protocol(&args.amplitudes, args.cycles, args.points).map_err(law_error)?
        }
        (Some(_), false) => {
            return Err(CliError::new(
                "--drift: give --drift or --amplitudes, not both",
            ))
        }
        (None, true) => {
            return Err(CliError::new(
                "--amplitudes: give the protocol's drift amplitudes (m), or --drift FILE",
            ))
        }
    };
    // The JSON document holds a row object per sample (about 1.5 kB):
    // refused where it would not fit, announced where it takes long.
    let samples = drifts.len() as f64;
    let document = args.out.is_some() || args.format == Format::Json;
    if document && samples * DOCUMENT_BYTES_PER_SAMPLE > MAX_DOCUMENT_BYTES {
        return Err(CliError::new(format!(
            "{} drift samples: the JSON document (--format json, --out) would hold about {:.0} GB; give fewer samples (--points, --cycles) or --format table or csv",
            drifts.len(),
            samples * DOCUMENT_BYTES_PER_SAMPLE / 1e9
        )));
    }
    let seconds = samples
        * (seconds_per_drift(&law)
            + if document {
                DOCUMENT_SECONDS_PER_SAMPLE
            } else {
                0.0
            });
    if seconds > LONG_RUN {
        eprintln!(
            "note: a long run: {} drift samples, about {seconds:.0} s on one core; Ctrl-C quits (nothing is written)",
            drifts.len()
        );
    }
    let rows = under_drift(&law, &drifts, args.rtol)?;
    if !document {
        return print_summary(&law, &drifts, &rows, args.format);
    }
    let doc = hysteresis_document(&law, &drifts, &rows);
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        write_atomic(&dir.join("hysteresis.csv"), csv(&drifts, &rows)?.as_bytes())?;
        write_atomic(
            &dir.join("hysteresis.json"),
            serde_json::to_string_pretty(&doc)?.as_bytes(),
        )?;
        let mut fig = Figure::new("Hysteresis loop", "drift  [mm]", "force  [kN]")
            .legend_at(LegendPosition::None);
        fig.push(Series::line(
            "",
            drifts.iter().zip(&rows).map(|(d, r)| (1e3 * d, 1e-3 * r.0)),
        ));
        render(&fig, &dir.join("hysteresis"))?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        Format::Csv => print!("{}", csv(&drifts, &rows)?),
        Format::Table => print_table(&doc, drifts.len()),
    }
    Ok(())
}

/// Bytes and seconds per sample of the JSON document (measured: 1.5 GB
/// and 1.6 s for 1e6 samples), and the most it may hold.
const DOCUMENT_BYTES_PER_SAMPLE: f64 = 1.5e3;
const DOCUMENT_SECONDS_PER_SAMPLE: f64 = 1.6e-6;
const MAX_DOCUMENT_BYTES: f64 = 8e9;

/// The table or CSV without the JSON document (a row object per sample
/// is not needed to print them).
fn print_summary(
    law: &StoreyLaw,
    drifts: &[f64],
    rows: &[(f64, f64)],
    format: Format,
) -> Result<(), CliError> {
    match format {
        Format::Csv => print!("{}", csv(drifts, rows)?),
        _ => print_table(&hysteresis_summary(law, rows), drifts.len()),
    }
    Ok(())
}

/// The one-line table of a summary or document over `samples` drifts.
fn print_table(doc: &serde_json::Value, samples: usize) {
    println!(
        "{}: {samples} drifts, peak force {:.6e} N, dissipated {:.6e} J",
        doc["law"]["law"].as_str().unwrap_or(""),
        doc["peak_force"].as_f64().unwrap_or(f64::NAN),
        doc["total_dissipated"].as_f64().unwrap_or(f64::NAN),
    );
}

fn csv(drifts: &[f64], rows: &[(f64, f64)]) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row(["drift", "force", "dissipated"])?;
    for (d, (f, e)) in drifts.iter().zip(rows) {
        w.row([format!("{d:e}"), format!("{f:e}"), format!("{e:e}")])?;
    }
    w.finish()
}
