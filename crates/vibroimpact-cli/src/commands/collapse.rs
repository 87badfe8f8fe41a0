//! `vibroimpact collapse`: the FEMA P695 collapse study of a row of
//! buildings ([`vibroimpact::seismic::collapse`]): per record an IDA to collapse
//! (drift limit, isolator capacity, non-convergence), bracketed by
//! bisection; the median collapse scale and intensity Ŝ_CT, and with the
//! tables' values given, CMR and ACMR. Records in parallel; the same
//! numbers at any thread count.

use std::path::PathBuf;

use clap::Args;
use rayon::prelude::*;
use serde_json::Value;
use vibroimpact::seismic::collapse::{
    check_margins, record_document, study_document, summary_document, CollapseStudy, Criterion,
    DriftLimit, IdaSettings,
};
use vibroimpact::simulate::WorkEstimate;

use crate::args::RowRunArgs;
use crate::error::{option_error, pounding_error, CliError};
use crate::format::SummaryFormat;
use crate::output::{ensure_dir, write_atomic};
use crate::plot::{render, Figure, LegendPosition, Marker, Series};
use crate::records;

/// Options of `vibroimpact collapse`.
#[derive(Args, Debug)]
pub struct CollapseArgs {
    /// The row (or pair) file (docs/earthquakes.md).
    pair: PathBuf,
    /// Records (AT2, two columns or CSV), normalized as the record set
    /// asks (FEMA P695: by PGV); one IDA each.
    #[arg(required = true)]
    records: Vec<PathBuf>,
    /// The storey drift at collapse (m), every storey; instead of
    /// --drift-ratio-limit.
    #[arg(long, conflicts_with = "drift_ratio_limit")]
    drift_limit: Option<f64>,
    /// The storey drift ratio at collapse, each storey's height times it
    /// (the buildings need `heights`); the default 0.10 is FEMA P695
    /// practice's cap on sidesway, beyond its archetypes' collapse.
    #[arg(long)]
    drift_ratio_limit: Option<f64>,
    /// The period T (s) of the intensity S_T (the records' median spectral
    /// acceleration there, as FEMA P695's S_NRT: their geometric mean).
    #[arg(long)]
    period: Option<f64>,
    /// The damping ratio of that spectral acceleration.
    #[arg(long, default_value_t = 0.05)]
    damping: f64,
    /// The first scale of every IDA.
    #[arg(long, default_value_t = 0.25)]
    first: f64,
    /// The hunt's growth factor.
    #[arg(long, default_value_t = 1.5)]
    growth: f64,
    /// The largest scale: a record standing there is censored ("no
    /// collapse up to scale X").
    #[arg(long, default_value_t = 20.0)]
    max_scale: f64,
    /// The collapse bracket's relative width.
    #[arg(long, default_value_t = 0.02)]
    tolerance: f64,
    /// With the row's contacts (pounding, moat walls), or without them.
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    contacts: bool,
    /// An isolator past its stated capacity collapses.
    #[arg(long, default_value_t = true, action = clap::ArgAction::Set)]
    capacity: bool,
    /// S_MT of FEMA P695 in g (from its tables): gives CMR = Ŝ_CT / S_MT.
    #[arg(long, requires = "period")]
    smt: Option<f64>,
    /// SSF of FEMA P695 (from its tables): gives ACMR = SSF · CMR.
    #[arg(long, requires = "smt")]
    ssf: Option<f64>,
    #[command(flatten)]
    run: RowRunArgs,
    /// Output folder for collapse.json, the IDA figure ida.svg/.png and the
    /// fragility figure fragility.svg/.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Format on standard output.
    #[arg(long, value_enum, default_value_t = SummaryFormat::Table)]
    format: SummaryFormat,
}

/// The IDA curves (Vamvatsikos–Cornell): per record the largest storey
/// drift ratio (the drift where the limit is in metres) against the
/// intensity, Sa(T1) in g where the study has a period (the record's
/// spectral acceleration times the scale), else the scale; the collapses
/// marked by their mode; the limit as a line.
fn ida_figure(doc: &Value) -> Figure {
    let in_g = doc["period"].as_f64().is_some();
    let criterion = &doc["criterion"];
    let (limit, key, x_label) = match criterion["drift_ratio_limit"].as_f64() {
        Some(r) => (r, "max_drift_ratio", "largest storey drift ratio"),
        None => (
            criterion["drift_limit"].as_f64().unwrap_or(f64::NAN),
            "max_drift",
            "largest storey drift  [m]",
        ),
    };
    let y_label = match doc["period"].as_f64() {
        Some(t) => format!("Sa(T1 = {t} s)  [g]"),
        None => "scale".to_string(),
    };
    let mut fig = Figure::new("Incremental dynamic analysis", x_label, y_label)
        .legend_at(LegendPosition::LowerRight);
    let modes = [
        ("drift", "collapse: drift limit", Marker::Triangle),
        (
            "instability",
            "collapse: dynamic instability",
            Marker::Diamond,
        ),
        ("capacity", "collapse: isolator capacity", Marker::Square),
        ("diverged", "collapse: numerical failure", Marker::Circle),
    ];
    let mut fallen: Vec<Vec<(f64, f64)>> = vec![Vec::new(); modes.len()];
    let mut top = 0.0f64;
    for r in doc["records"].as_array().into_iter().flatten() {
        let per_scale = if in_g {
            r["sa"].as_f64().unwrap_or(f64::NAN)
        } else {
            1.0
        };
        let mut pts: Vec<(f64, f64)> = r["runs"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|p| {
                let (s, d) = (p["scale"].as_f64()? * per_scale, p[key].as_f64()?);
                top = top.max(s);
                let kind = &p["verdict"]["kind"];
                if let Some(m) = modes.iter().position(|(k, _, _)| kind == k) {
                    fallen[m].push((d.min(limit), s));
                }
                Some((d.min(limit), s))
            })
            .collect();
        pts.sort_by(|a, b| a.1.total_cmp(&b.1));
        fig.push(Series::line("", pts).with_color(0));
    }
    for ((_, label, marker), pts) in modes.iter().zip(fallen) {
        if !pts.is_empty() {
            fig.push(Series::markers(*label, pts, *marker).with_color(3));
        }
    }
    fig.push(Series::dashed("drift limit", [(limit, 0.0), (limit, top)]).with_color(1));
    fig
}

/// The collapse fragility: the lognormal fit of the summary (θ, β, by
/// maximum likelihood with the censored records' survival) as a curve
/// against the empirical collapse fractions (the i-th smallest collapse
/// intensity at i / N, N every record, censored ones included), the
/// intensity S_T in g (the set's Sa(T) times the collapse scale, as Ŝ_CT)
/// where the study has a period, else the scale.
/// None where the summary determines no fit (its note says why).
fn fragility_figure(doc: &Value) -> Option<Figure> {
    let fit = &doc["summary"]["fragility"];
    let (theta, beta) = (fit["median"].as_f64()?, fit["dispersion"].as_f64()?);
    let per = doc["summary"]["s_t"].as_f64().unwrap_or(1.0);
    let records = doc["records"].as_array()?;
    let mut fell: Vec<f64> = records
        .iter()
        .filter_map(|r| Some(r["collapse"].as_f64()? * per))
        .collect();
    fell.sort_by(f64::total_cmp);
    let n = records.len() as f64;
    let top = 1.2
        * fell
            .last()
            .copied()
            .unwrap_or(theta)
            .max(theta * (2.0 * beta).exp());
    let model = vibroimpact::seismic::collapse::Fragility {
        median: theta,
        dispersion: beta,
        records: records.len(),
        censored: 0,
    };
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|i| top * i as f64 / 200.0)
        .map(|s| (s, model.probability(s)))
        .collect();
    let x_label = match doc["period"].as_f64() {
        Some(t) => format!("S_T = the set's Sa(T = {t} s) at collapse  [g]"),
        None => "scale".to_string(),
    };
    let mut fig = Figure::new("Collapse fragility", x_label, "probability of collapse")
        .legend_at(LegendPosition::LowerRight)
        .y_range(0.0, 1.0);
    fig.push(
        Series::line(
            format!("lognormal fit: θ = {theta:.4}, β = {beta:.3}"),
            curve,
        )
        .with_color(0),
    );
    let empirical = fell
        .iter()
        .enumerate()
        .map(|(i, s)| (*s, (i + 1) as f64 / n));
    fig.push(
        Series::markers("collapsed records (fraction)", empirical, Marker::Circle).with_color(3),
    );
    fig.push(Series::dashed("median θ", [(theta, 0.0), (theta, 0.5)]).with_color(1));
    Some(fig)
}

/// Runs `vibroimpact collapse`.
pub fn run(args: &CollapseArgs) -> Result<(), CliError> {
    let units = records::units(args.run.units.as_deref())?;
    let row = records::row(&args.pair)?;
    let study = CollapseStudy {
        criterion: Criterion {
            drift: match (args.drift_limit, args.drift_ratio_limit) {
                (Some(d), _) => DriftLimit::Drift(d),
                (None, Some(r)) => DriftLimit::Ratio(r),
                (None, None) => DriftLimit::FEMA,
            },
            capacity: args.capacity,
            contacts: args.contacts,
        },
        ida: IdaSettings {
            first: args.first,
            growth: args.growth,
            max_scale: args.max_scale,
            tolerance: args.tolerance,
        },
        run: args.run.settings()?,
        period: args.period,
        damping: args.damping,
    };
    study.check().map_err(pounding_error)?;
    check_margins(args.smt, args.ssf).map_err(|e| option_error(&e))?;
    let recs = args
        .records
        .iter()
        .map(|p| records::read(p, units))
        .collect::<Result<Vec<_>, _>>()?;
    let estimates = recs
        .iter()
        .map(|r| study.estimate(&row, r))
        .collect::<Result<Option<Vec<_>>, _>>()
        .map_err(pounding_error)?;
    crate::progress::announce_long_as(
        estimates.and_then(|w| w.into_iter().reduce(WorkEstimate::then)),
        "Ctrl-C stops it (nothing is written)",
    );
    let parts = recs
        .par_iter()
        .map(|r| study.record(&row, r))
        .collect::<Result<Vec<_>, _>>()
        .map_err(pounding_error)?;
    let doc = study_document(
        &row,
        &study,
        parts.iter().map(record_document).collect(),
        summary_document(&parts, args.smt, args.ssf),
    );
    if let Some(dir) = &args.out {
        ensure_dir(dir)?;
        write_atomic(
            &dir.join("collapse.json"),
            serde_json::to_string_pretty(&doc)?.as_bytes(),
        )?;
        render(&ida_figure(&doc), &dir.join("ida"))?;
        match fragility_figure(&doc) {
            Some(fig) => render(&fig, &dir.join("fragility"))?,
            None => eprintln!(
                "note: no fragility figure ({})",
                doc["summary"]["fragility_note"]
                    .as_str()
                    .unwrap_or("no fit")
            ),
        }
    }
    match args.format {
        SummaryFormat::Json => println!("{}", serde_json::to_string_pretty(&doc)?),
        SummaryFormat::Table => print_table(&doc),
    }
    Ok(())
}

fn print_table(doc: &Value) {
    for r in doc["records"].as_array().into_iter().flatten() {
        let runs = r["runs"].as_array().map_or(0, Vec::len);
        match r["collapse"].as_f64() {
            Some(c) => println!(
                "{}: collapse ({}) between scales {:.4} and {:.4} ({runs} runs)",
                r["source"].as_str().unwrap_or("?"),
                r["collapse_mode"].as_str().unwrap_or("?"),
                r["survived"].as_f64().unwrap_or(f64::NAN),
                c
            ),
            None => println!(
                "{}: {} ({runs} runs)",
                r["source"].as_str().unwrap_or("?"),
                r["note"].as_str().unwrap_or("")
            ),
        }
    }
    let s = &doc["summary"];
    let num = |k: &str| s[k].as_f64().map_or("-".to_string(), |v| format!("{v:.4}"));
    println!(
        "{} of {} records collapsed; median collapse scale {}; S_T {} g; S_CT {} g; CMR {}; ACMR {}",
        s["collapsed"],
        s["records"],
        num("median_collapse_scale"),
        num("s_t"),
        num("s_ct"),
        num("cmr"),
        num("acmr")
    );
    match (s["fragility"].is_object(), s["fragility_note"].as_str()) {
        (true, _) => println!(
            "fragility (lognormal, maximum likelihood): median {} {}, dispersion {:.4}",
            s["fragility"]["median"]
                .as_f64()
                .map_or("-".into(), |v| format!("{v:.4}")),
            if doc["period"].is_null() {
                "(scale)"
            } else {
                "g"
            },
            s["fragility"]["dispersion"].as_f64().unwrap_or(f64::NAN)
        ),
        (false, Some(n)) => println!("{n}"),
        _ => {}
    }
    if let Some(n) = s["note"].as_str() {
        println!("note: {n}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    /// Sa(T1) in g on the intensity axis where the study has a period (the
    /// record's Sa × the scale / g), the scale without one; the drift
    /// ratio on the other where the limit is a ratio, else the drift; a
    /// collapse marked by its mode.
    #[test]
    fn the_ida_is_drawn_in_sa_of_t1_with_collapses_by_mode() {
        let run = |scale: f64, kind: &str| json!({"scale": scale, "max_drift": 0.01 * scale, "max_drift_ratio": 0.003 * scale, "verdict": {"kind": kind}});
        let record = json!({"sa": 2.0, "runs": [run(0.5, "standing"), run(1.0, "capacity"), run(1.2, "instability")]});
        let metres = json!({"drift_limit": 0.05, "drift_ratio_limit": null});
        let fig =
            ida_figure(&json!({"period": 1.0, "criterion": metres, "records": [record.clone()]}));
        assert_eq!(fig.y_label, "Sa(T1 = 1 s)  [g]");
        assert_eq!(fig.x_label, "largest storey drift  [m]");
        assert_eq!(
            fig.series[0].points,
            vec![(0.005, 1.0), (0.01, 2.0), (0.012, 2.4)]
        );
        let marked: Vec<_> = fig.series[1..]
            .iter()
            .filter_map(|s| s.label.as_deref())
            .collect();
        assert_eq!(
            marked[..2],
            [
                "collapse: dynamic instability",
                "collapse: isolator capacity"
            ]
        );
        let ratio = json!({"drift_limit": null, "drift_ratio_limit": 0.1});
        let bare = ida_figure(&json!({"period": null, "criterion": ratio, "records": [record]}));
        assert_eq!(bare.y_label, "scale");
        assert_eq!(bare.x_label, "largest storey drift ratio");
        assert_eq!(
            bare.series[0].points,
            vec![(0.0015, 0.5), (0.003, 1.0), (0.0036, 1.2)]
        );
    }
}
