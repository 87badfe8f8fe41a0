//! `vibroimpact pushover`: the static pushover of one building of a row or
//! pair file ([`vibroimpact::seismic::pushover`]): base shear against roof
//! displacement under the first-mode load pattern, and FEMA P695's V_max,
//! δ_y,eff, δ_u and μ_T; a table, JSON or CSV, with the curve's figure.

use std::path::PathBuf;

use clap::Args;
use vibroimpact::seismic::pushover::{pushover, PushoverOptions};

use crate::error::CliError;
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};
use crate::records;

/// Options of `vibroimpact pushover`.
#[derive(Args, Debug)]
pub struct PushoverArgs {
    /// The row or pair file (docs/earthquakes.md); the building needs
    /// `heights`.
    pair: PathBuf,
    /// The building by name (default: the first; a pair's are `left` and
    /// `right`).
    #[arg(long)]
    building: Option<String>,
    /// The critical storey's drift ratio where the push stops.
    #[arg(long, default_value_t = 0.10)]
    drift_ratio_limit: f64,
    /// Points along the critical storey's drift.
    #[arg(long, default_value_t = 400)]
    points: usize,
    /// FEMA P695's code period T = C_u T_a (s) for δ_y,eff (default: the
    /// building's T1 with its P-Δ).
    #[arg(long)]
    code_period: Option<f64>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Directory for `pushover.json`, `pushover.csv` and the figure
    /// `pushover.svg`/`.png`.
    #[arg(long)]
    out: Option<PathBuf>,
}

/// Runs `vibroimpact pushover`.
pub fn run(args: &PushoverArgs) -> Result<(), CliError> {
    let row = records::row(&args.pair)?;
    let building = match &args.building {
        None => row.buildings.first(),
        Some(name) => row.buildings.iter().find(|b| &b.name == name),
    }
    .ok_or_else(|| {
        let names: Vec<&str> = row.buildings.iter().map(|b| b.name.as_str()).collect();
        CliError::new(format!(
            "--building {:?}: {} has no such building (it has {names:?})",
            args.building.as_deref().unwrap_or(""),
            args.pair.display()
        ))
    })?;
    let opts = PushoverOptions {
        drift_ratio_limit: args.drift_ratio_limit,
        points: args.points,
        code_period: args.code_period,
    };
    let p = pushover(&building.frame, &opts).map_err(|e| {
        // The library names its options in snake case: the CLI's flags.
        let key = e.split([' ', ':']).next().unwrap_or("");
        let option = key.replace('_', "-");
        let named = ["drift-ratio-limit", "points", "code-period"].contains(&option.as_str());
        CliError::new(if named {
            format!("--{option}{}", &e[key.len()..])
        } else {
            format!("{}: {}: {e}", args.pair.display(), building.name)
        })
    })?;
    let doc = p.document(&building.name, &building.frame);
    let csv = curve_csv(&p)?;
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        write_atomic(&dir.join("pushover.csv"), csv.as_bytes())?;
        write_atomic(
            &dir.join("pushover.json"),
            serde_json::to_string_pretty(&doc)?.as_bytes(),
        )?;
        render(&figure(&doc), &dir.join("pushover"))?;
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        Format::Csv => print!("{csv}"),
        Format::Table => println!(
            "{}: critical storey {}{}; V_max {:.6e} N ({:.4} W); T1 {:.4} s; C0 {:.4}; δy,eff {:.6e} m; δu {:.6e} m{}; μT {:.4}",
            building.name,
            p.critical_storey + 1,
            if p.collapsed { " (collapses)" } else { "" },
            p.max_base_shear,
            p.max_base_shear / p.weight,
            p.period,
            p.c0,
            p.yield_displacement,
            p.ultimate_displacement,
            if p.strength_loss { "" } else { " (end of push: no 20 % strength loss)" },
            p.ductility
        ),
    }
    Ok(())
}

/// The curve as CSV: roof displacement, base shear, the storeys' drifts.
fn curve_csv(p: &vibroimpact::seismic::pushover::Pushover) -> Result<String, CliError> {
    let mut out = CsvText::new();
    let storeys = p.drifts.first().map_or(0, Vec::len);
    let mut header = vec![
        "roof_displacement_m".to_string(),
        "base_shear_n".to_string(),
    ];
    header.extend((1..=storeys).map(|i| format!("drift_{i}_m")));
    out.row(header)?;
    for ((u, v), d) in p.roof_displacement.iter().zip(&p.base_shear).zip(&p.drifts) {
        let mut r = vec![u.to_string(), v.to_string()];
        r.extend(d.iter().map(f64::to_string));
        out.row(r)?;
    }
    out.finish()
}

/// Base shear (kN) against roof displacement (mm), with δ_y,eff and δ_u.
fn figure(doc: &serde_json::Value) -> Figure {
    let list = |k: &str| -> Vec<f64> {
        doc[k]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_f64())
            .collect()
    };
    let (u, v) = (list("roof_displacement"), list("base_shear"));
    let top = v.iter().copied().fold(0.0, f64::max) * 1e-3;
    let mut fig = Figure::new(
        format!("Pushover: {}", doc["building"].as_str().unwrap_or("")),
        "roof displacement  [mm]",
        "base shear  [kN]",
    )
    .legend_at(LegendPosition::UpperRight);
    fig.push(Series::line("", u.iter().zip(&v).map(|(u, v)| (1e3 * u, 1e-3 * v))).with_color(0));
    for (key, label, color) in [
        ("yield_displacement", "δy,eff", 1),
        ("ultimate_displacement", "δu", 3),
    ] {
        if let Some(d) = doc[key].as_f64() {
            fig.push(Series::dashed(label, [(1e3 * d, 0.0), (1e3 * d, top)]).with_color(color));
        }
    }
    fig
}
