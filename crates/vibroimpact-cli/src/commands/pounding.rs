//! `vibroimpact pounding`: a row of buildings (a pair of shear frames, or
//! K buildings, fixed or isolated) side by side under recorded
//! ground motions ([`vibroimpact::seismic::pounding`]): per record the response
//! with and without pounding, the gap that avoids contact and the code
//! rules; with `--gaps` and `--ratios` the pounding spectrum over an
//! ensemble, with `--moat-gaps` the moat-gap study of isolated buildings
//! (median and 16/84 % quantiles). The study is the library's
//! [`Study`].

use std::path::PathBuf;

use clap::Args;
use serde_json::Value;
use vibroimpact::seismic::pounding::{
    documents, quantile, value_range, MoatCell, Outcome, Row, RunSettings, SpectrumCell,
    StoreyLoop, Study, GRAVITY,
};

use crate::args::RowRunArgs;

use crate::error::{option_error, pounding_error, CliError};
use crate::format::{CsvText, Format};
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Series};
use crate::records;

/// Options of `vibroimpact pounding`.
#[derive(Args, Debug)]
pub struct PoundingArgs {
    /// The row (TOML: `[[building]]` entries, or a pair's `[left]` and
    /// `[right]` frames with `gap`, `floors`, `law`; see
    /// docs/earthquakes.md).
    pair: PathBuf,
    /// Records (AT2, two columns or CSV), one run each.
    #[arg(required = true)]
    records: Vec<PathBuf>,
    /// Scale factor applied to every record.
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    #[command(flatten)]
    run: RowRunArgs,
    /// Also the frames apart (`free`), the gap that avoids contact and the
    /// code rules' gaps; `false`: the pair with its contacts only (half the
    /// work).
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    free: bool,
    /// Pounding spectrum: gaps FROM:TO:N (m), with --ratios.
    #[arg(long, requires = "ratios")]
    gaps: Option<String>,
    /// Pounding spectrum: period ratios T_left/T_right FROM:TO:N, with
    /// --gaps.
    #[arg(long, requires = "gaps")]
    ratios: Option<String>,
    /// Moat-gap study of isolated buildings: moat gaps FROM:TO:N (m); per
    /// gap, over the records, the superstructures' peak drift and floor
    /// acceleration, the isolators' displacement and the moat impacts,
    /// and the same without contacts.
    #[arg(long, conflicts_with = "gaps")]
    moat_gaps: Option<String>,
    /// Output folder for pounding.json and, for the runs, runs.csv (a row
    /// per record, building and storey; with hysteretic storeys, the
    /// loops of each record's run, loops-RECORD-BUILDING.svg/.png; for a
    /// spectrum, spectrum.csv and the figure spectrum.svg/.png; for a
    /// moat-gap study, moat.csv and the figures moat-drift and
    /// moat-acceleration .svg/.png).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Format on standard output.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// The pounding spectrum's figure: the median peak impact force against
/// the gap, one line per period ratio.
fn spectrum_figure(cells: &[SpectrumCell]) -> Figure {
    let mut fig = Figure::new(
        "Pounding spectrum: median peak impact force",
        "gap  [m]",
        "peak impact force  [MN]",
    )
    .legend_at(LegendPosition::Best);
    let mut ratios: Vec<f64> = cells.iter().map(|c| c.period_ratio).collect();
    ratios.sort_by(f64::total_cmp);
    ratios.dedup();
    for (k, r) in ratios.iter().enumerate() {
        let pts: Vec<(f64, f64)> = cells
            .iter()
            .filter(|c| c.period_ratio == *r)
            .map(|c| (c.gap, 1e-6 * quantile(&c.impact_force, 0.5)))
            .collect();
        fig.push(Series::line(format!("T_L/T_R = {r:.3}"), pts).with_color(k % 7));
    }
    fig
}

fn spectrum_csv(cells: &[SpectrumCell]) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row([
        "gap",
        "period_ratio",
        "impact_force_median",
        "impact_force_p16",
        "impact_force_p84",
        "drift_amplification_median",
        "drift_amplification_p84",
        "required_gap_median",
    ])?;
    for c in cells {
        w.row([
            format!("{:e}", c.gap),
            format!("{:e}", c.period_ratio),
            format!("{:e}", quantile(&c.impact_force, 0.5)),
            format!("{:e}", quantile(&c.impact_force, 0.16)),
            format!("{:e}", quantile(&c.impact_force, 0.84)),
            format!("{:e}", quantile(&c.drift_amplification, 0.5)),
            format!("{:e}", quantile(&c.drift_amplification, 0.84)),
            format!("{:e}", quantile(&c.required_gap, 0.5)),
        ])?;
    }
    w.finish()
}

/// The runs' peaks as CSV, a row per record, building and storey (from the
/// study's document): peak and residual drift, peak absolute floor
/// acceleration and displacement with pounding, and the peak drift of the
/// building apart (empty with `--free false`).
fn runs_csv(doc: &Value) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row([
        "record",
        "building",
        "storey",
        "peak_drift_m",
        "residual_drift_m",
        "peak_floor_acceleration_m_s2",
        "peak_displacement_m",
        "free_peak_drift_m",
    ])?;
    let cell = |v: &Value| v.as_f64().map_or(String::new(), |x| format!("{x:e}"));
    let names: Vec<&str> = doc["row"]["buildings"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|b| b["name"].as_str())
        .collect();
    for r in doc["runs"].as_array().into_iter().flatten() {
        let (p, f) = (&r["pounding"], &r["free"]);
        for name in &names {
            let drifts = p["peak_drift"][name].as_array().map_or(0, Vec::len);
            for i in 0..drifts {
                w.row([
                    r["record"]["source"].as_str().unwrap_or("").to_string(),
                    name.to_string(),
                    (i + 1).to_string(),
                    cell(&p["peak_drift"][name][i]),
                    cell(&p["residual_drift"][name][i]),
                    cell(&p["peak_floor_acceleration"][name][i]),
                    cell(&p["peak_displacement"][name][i]),
                    cell(&f["peak_drift"][name][i]),
                ])?;
            }
        }
    }
    w.finish()
}

/// The hysteresis loops of one building's storeys (and bearings) in one
/// record's run: force against drift.
fn loops_figure(building: &str, loops: &[&StoreyLoop]) -> Figure {
    let mut fig = Figure::new(
        format!("Hysteresis loops: {building}"),
        "drift  [mm]",
        "force  [MN]",
    )
    .legend_at(LegendPosition::Best);
    for (k, l) in loops.iter().enumerate() {
        let label = match l.storey {
            Some(i) => format!("storey {}", i + 1),
            None => "bearings".to_string(),
        };
        let pts = l
            .drift
            .iter()
            .zip(&l.force)
            .map(|(d, f)| (1e3 * d, 1e-6 * f));
        fig.push(Series::line(label, pts).with_color(k % 7));
    }
    fig
}

/// What a moat-gap figure shows.
#[derive(Clone, Copy)]
enum MoatQuantity {
    /// The superstructures' peak storey drift.
    Drift,
    /// Their peak absolute floor acceleration.
    Acceleration,
}

/// A moat-gap figure: the isolated superstructures' peak drift or floor
/// acceleration against the moat gap, median and 16/84 % over the
/// records, and the median without contacts.
fn moat_figure(cells: &[MoatCell], quantity: MoatQuantity) -> Figure {
    let (title, y_label, unit, pick): (_, _, f64, fn(&MoatCell) -> &Vec<f64>) = match quantity {
        MoatQuantity::Drift => (
            "Isolated building and its moat wall: peak storey drift",
            "peak storey drift  [mm]",
            1e3,
            |c| &c.drift,
        ),
        MoatQuantity::Acceleration => (
            "Isolated building and its moat wall: peak floor acceleration",
            "peak floor acceleration  [m/s2]",
            1.0,
            |c| &c.acceleration,
        ),
    };
    let mut fig = Figure::new(title, "moat gap  [m]", y_label).legend_at(LegendPosition::Best);
    let walls: Vec<&MoatCell> = cells.iter().filter(|c| c.gap.is_some()).collect();
    let curve = |q: f64| -> Vec<(f64, f64)> {
        walls
            .iter()
            .map(|c| (c.gap.unwrap_or(0.0), unit * quantile(pick(c), q)))
            .collect()
    };
    fig.push(Series::line("median, with the wall", curve(0.5)).with_color(0));
    fig.push(Series::dashed("16 / 84 %", curve(0.16)).with_color(0));
    fig.push(Series::dashed("", curve(0.84)).with_color(0));
    if let (Some(free), Some(first), Some(last)) = (
        cells.iter().find(|c| c.gap.is_none()),
        walls.first(),
        walls.last(),
    ) {
        let m = unit * quantile(pick(free), 0.5);
        let ends = [(first.gap.unwrap_or(0.0), m), (last.gap.unwrap_or(0.0), m)];
        fig.push(Series::line("median, no wall", ends).with_color(3));
    }
    fig
}

fn moat_csv(cells: &[MoatCell]) -> Result<String, CliError> {
    let mut w = CsvText::new();
    w.row([
        "moat_gap",
        "drift_median",
        "drift_p16",
        "drift_p84",
        "acceleration_median",
        "acceleration_p16",
        "acceleration_p84",
        "isolator_median",
        "isolator_p84",
        "moat_force_median",
        "moat_force_p84",
        "moat_impacts_median",
        "beyond_capacity",
    ])?;
    for c in cells {
        let q = |v: &[f64], p: f64| format!("{:e}", quantile(v, p));
        let impacts: Vec<f64> = c.moat_impacts.iter().map(|&i| i as f64).collect();
        w.row([
            c.gap.map_or("none".to_string(), |g| format!("{g:e}")),
            q(&c.drift, 0.5),
            q(&c.drift, 0.16),
            q(&c.drift, 0.84),
            q(&c.acceleration, 0.5),
            q(&c.acceleration, 0.16),
            q(&c.acceleration, 0.84),
            q(&c.isolator, 0.5),
            q(&c.isolator, 0.84),
            q(&c.moat_force, 0.5),
            q(&c.moat_force, 0.84),
            q(&impacts, 0.5),
            c.beyond_capacity.iter().filter(|b| **b).count().to_string(),
        ])?;
    }
    w.finish()
}

/// Runs `vibroimpact pounding`.
pub fn run(args: &PoundingArgs) -> Result<(), CliError> {
    let units = records::units(args.run.units.as_deref())?;
    if !args.scale.is_finite() {
        return Err(CliError::new(format!(
            "--scale {}: give a finite scale",
            args.scale
        )));
    }
    let run = args.run.settings()?;
    let row: Row = records::row(&args.pair)?;
    let runs = args
        .records
        .iter()
        .map(|path| Ok((records::read(path, units)?, args.scale)))
        .collect::<Result<Vec<_>, CliError>>()?;
    let range = |field, text: &String| value_range(field, text).map_err(|e| option_error(&e));
    let study = match (&args.gaps, &args.ratios, &args.moat_gaps) {
        (Some(g), Some(r), _) => Study::Spectrum {
            gaps: range("gaps", g)?,
            ratios: range("ratios", r)?,
        },
        (_, _, Some(g)) => Study::Moat {
            gaps: range("moat_gaps", g)?,
        },
        _ => Study::Runs { free: args.free },
    };
    let run = RunSettings {
        // (The runs' loops are drawn where figures are written.)
        loops: args.out.is_some() && matches!(study, Study::Runs { .. }),
        ..run
    };
    crate::progress::announce_long_as(
        study.estimate(&row, &runs, &run).map_err(pounding_error)?,
        "Ctrl-C stops it (nothing is written)",
    );
    let outcome = study.run(&row, &runs, &run).map_err(pounding_error)?;
    let doc = documents::study_document(&row, &runs, &outcome, &run);
    let (csv, name) = match &outcome {
        Outcome::Spectrum(cells) => (Some(spectrum_csv(cells)?), "spectrum"),
        Outcome::Moat(cells) => (Some(moat_csv(cells)?), "moat"),
        Outcome::Runs { .. } => (Some(runs_csv(&doc)?), "runs"),
    };
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        match &outcome {
            Outcome::Spectrum(cells) => render(&spectrum_figure(cells), &dir.join("spectrum"))?,
            Outcome::Moat(cells) => {
                render(
                    &moat_figure(cells, MoatQuantity::Drift),
                    &dir.join("moat-drift"),
                )?;
                render(
                    &moat_figure(cells, MoatQuantity::Acceleration),
                    &dir.join("moat-acceleration"),
                )?;
            }
            Outcome::Runs { loops, .. } => {
                for (r, loops) in loops.iter().enumerate() {
                    for (k, b) in row.buildings.iter().enumerate() {
                        let mine: Vec<&StoreyLoop> =
                            loops.iter().filter(|l| l.building == k).collect();
                        if !mine.is_empty() {
                            // The building's name as a file name: only
                            // letters, digits, '-' and '_'.
                            let safe: String = b
                                .name
                                .chars()
                                .map(|c| {
                                    if c.is_ascii_alphanumeric() || c == '-' {
                                        c
                                    } else {
                                        '_'
                                    }
                                })
                                .collect();
                            let name = format!("loops-{}-{safe}", r + 1);
                            render(&loops_figure(&b.name, &mine), &dir.join(name))?;
                        }
                    }
                }
            }
        }
    }
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        write_atomic(
            &dir.join("pounding.json"),
            serde_json::to_string_pretty(&doc)?.as_bytes(),
        )?;
        if let Some(c) = &csv {
            write_atomic(&dir.join(format!("{name}.csv")), c.as_bytes())?;
        }
    }
    match args.format {
        Format::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        Format::Csv => print!("{}", csv.unwrap_or_default()),
        Format::Table => print_table(&doc),
    }
    Ok(())
}

fn print_table(doc: &Value) {
    let row = &doc["row"];
    for b in row["buildings"].as_array().into_iter().flatten() {
        println!(
            "{}: T1 {:.4} s, {} floors{}",
            b["name"].as_str().unwrap_or("?"),
            b["period"].as_f64().unwrap_or(f64::NAN),
            b["floors"],
            if b["isolated"] == true {
                ", isolated"
            } else {
                ""
            }
        );
    }
    for n in row["notes"].as_array().into_iter().flatten() {
        println!("note: {}", n.as_str().unwrap_or(""));
    }
    for j in row["joints"].as_array().into_iter().flatten() {
        println!(
            "joint {}–{}: gap {} m at floors {}",
            j["between"][0].as_str().unwrap_or("?"),
            j["between"][1].as_str().unwrap_or("?"),
            j["gap"],
            j["floors"]
        );
    }
    for r in doc["runs"].as_array().into_iter().flatten() {
        println!(
            "{}: {} impacts, peak force {:.4e} N",
            r["record"]["source"].as_str().unwrap_or("?"),
            r["pounding"]["impacts"],
            r["pounding"]["peak_impact_force"]
                .as_f64()
                .unwrap_or(f64::NAN),
        );
        let p = &r["pounding"];
        let largest = |v: &Value| {
            v.as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_f64)
                .fold(f64::NAN, f64::max)
        };
        for (name, drifts) in p["peak_drift"].as_object().into_iter().flatten() {
            let ratio = largest(&p["peak_drift_ratio"][name]);
            let ratio = if ratio.is_nan() {
                String::new()
            } else {
                format!(" (ratio {:.3} %)", 100.0 * ratio)
            };
            println!(
                "  {name}: peak drift {:.4e} m{ratio}, peak floor acceleration {:.3} g",
                largest(drifts),
                largest(&p["peak_floor_acceleration"][name]) / GRAVITY,
            );
        }
        for (what, key) in [("", "pounding"), (" without the contacts", "free")] {
            if let Some(n) = r[key]["collapse"]["note"].as_str() {
                println!("  collapse{what}: {n}");
            }
        }
        for j in r["pounding"]["joint_impacts"]
            .as_array()
            .into_iter()
            .flatten()
        {
            println!(
                "  joint {}–{}: {} impacts, peak force {:.4e} N",
                j["between"][0].as_str().unwrap_or("?"),
                j["between"][1].as_str().unwrap_or("?"),
                j["impacts"],
                j["peak_impact_force"].as_f64().unwrap_or(f64::NAN),
            );
        }
        for j in r["joints"].as_array().into_iter().flatten() {
            println!(
                "  joint {}–{}: required gap {:.4e} m (ABS {:.4e}, SRSS {:.4e}, DDC {:.4e})",
                j["between"][0].as_str().unwrap_or("?"),
                j["between"][1].as_str().unwrap_or("?"),
                j["required_gap"].as_f64().unwrap_or(f64::NAN),
                j["code_gaps"]["absolute_sum"].as_f64().unwrap_or(f64::NAN),
                j["code_gaps"]["srss"].as_f64().unwrap_or(f64::NAN),
                j["code_gaps"]["double_difference"]
                    .as_f64()
                    .unwrap_or(f64::NAN),
            );
        }
        let isolators = r["pounding"]["isolators"].as_object();
        for (name, i) in isolators.into_iter().flatten() {
            println!(
                "  {name} isolators: peak {:.4e} m{}, {} moat impacts, peak moat force {:.4e} N",
                i["peak_displacement"].as_f64().unwrap_or(f64::NAN),
                if i["beyond_capacity"] == true {
                    " (BEYOND CAPACITY)"
                } else {
                    ""
                },
                i["moat_impacts"],
                i["moat_peak_force"].as_f64().unwrap_or(f64::NAN),
            );
        }
    }
    if let Some(cells) = doc["moat_cells"].as_array() {
        println!(
            "{:>10} {:>14} {:>16} {:>14} {:>14} {:>10}",
            "moat gap", "drift [m]", "floor acc [m/s2]", "isolator [m]", "moat F [N]", "capacity"
        );
        for c in cells {
            let median = |key: &str| c[key]["median"].as_f64().unwrap_or(f64::NAN);
            let gap = c["gap"]
                .as_f64()
                .map_or("free".to_string(), |g| format!("{g:.4}"));
            println!(
                "{gap:>10} {:>14.4e} {:>16.4e} {:>14.4e} {:>14.4e} {:>10}",
                median("peak_drift"),
                median("peak_floor_acceleration"),
                median("isolator_displacement"),
                median("moat_peak_force"),
                c["beyond_capacity"],
            );
        }
        println!("(medians over the records; capacity: records beyond an isolator's capacity)");
    }
    if let Some(cells) = doc["cells"].as_array() {
        println!(
            "{:>10} {:>8} {:>14} {:>12}",
            "gap [m]", "T_L/T_R", "median F [N]", "median amp"
        );
        for c in cells {
            println!(
                "{:>10.4} {:>8.3} {:>14.4e} {:>12.4}",
                c["gap"].as_f64().unwrap_or(f64::NAN),
                c["period_ratio"].as_f64().unwrap_or(f64::NAN),
                c["peak_impact_force"]["median"]
                    .as_f64()
                    .unwrap_or(f64::NAN),
                c["drift_amplification"]["median"]
                    .as_f64()
                    .unwrap_or(f64::NAN),
            );
        }
    }
}
