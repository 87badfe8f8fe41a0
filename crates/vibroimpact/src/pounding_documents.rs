//! The documents of a pounding study, one shape for every face (the CLI's
//! JSON is the schema; Python returns the same fields and nesting): the
//! pair, each record's run with and without pounding, and the pounding
//! spectrum over gaps × period ratios.

use serde_json::{json, Value};

use super::{quantile, PoundingPair, PoundingResult, Response, SpectrumCell};
use crate::record::Record;

/// The pair: both frames' fundamental periods, the gap and the pounding
/// floors.
pub fn pair_document(pair: &PoundingPair) -> Value {
    json!({
        "left_period": pair.left.period(),
        "right_period": pair.right.period(),
        "gap": pair.gap,
        "floors": pair.floors,
    })
}

/// One response's peaks: drifts, residual drifts, floor accelerations and
/// displacements per floor of each frame (`left`, `right`), the peak
/// impact force, the impact count and the closing velocities.
pub fn response_document(r: &Response) -> Value {
    json!({
        "peak_drift": { "left": r.drift[0], "right": r.drift[1] },
        "residual_drift": { "left": r.residual_drift[0], "right": r.residual_drift[1] },
        "peak_floor_acceleration": { "left": r.acceleration[0], "right": r.acceleration[1] },
        "peak_displacement": { "left": r.displacement[0], "right": r.displacement[1] },
        "peak_impact_force": r.peak_impact_force,
        "impacts": r.impacts,
        "closing": r.closing,
    })
}

/// Per floor, `a / b` (1 where `b` is 0).
fn ratio(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter()
        .zip(b)
        .map(|(x, y)| if *y > 0.0 { x / y } else { 1.0 })
        .collect()
}

/// One record's run: the record, the response with pounding and without
/// it (`free`), the amplification of drifts and floor accelerations by
/// pounding, the gap that avoids contact and the code rules' gaps.
pub fn run_document(record: &Record, scale: f64, res: &PoundingResult) -> Value {
    let (p, f) = (&res.pounding, &res.free);
    json!({
        "record": record.metadata(scale),
        "pounding": response_document(p),
        "free": response_document(f),
        "amplification": {
            "drift": { "left": ratio(&p.drift[0], &f.drift[0]),
                       "right": ratio(&p.drift[1], &f.drift[1]) },
            "floor_acceleration": { "left": ratio(&p.acceleration[0], &f.acceleration[0]),
                                    "right": ratio(&p.acceleration[1], &f.acceleration[1]) },
        },
        "required_gap": res.required_gap,
        "code_gaps": {
            "absolute_sum": res.code_gaps.absolute_sum,
            "srss": res.code_gaps.srss,
            "double_difference": res.code_gaps.double_difference,
            "correlation": res.code_gaps.correlation,
        },
    })
}

/// One record's run with the contacts only (no free response, no gaps):
/// the record and the response with pounding.
pub fn pounding_only_document(record: &Record, scale: f64, r: &Response) -> Value {
    json!({ "record": record.metadata(scale), "pounding": response_document(r) })
}

/// Median and 16/84 % quantiles of a list, with the list.
fn stats(v: &[f64]) -> Value {
    json!({ "median": quantile(v, 0.5), "p16": quantile(v, 0.16), "p84": quantile(v, 0.84), "values": v })
}

/// A cell of the pounding spectrum: its gap and period ratio, and over the
/// records the peak impact force, impact count, drift amplification and
/// required gap.
pub fn cell_document(c: &SpectrumCell) -> Value {
    let impacts: Vec<f64> = c.impacts.iter().map(|&i| i as f64).collect();
    json!({
        "gap": c.gap,
        "period_ratio": c.period_ratio,
        "peak_impact_force": stats(&c.impact_force),
        "impacts": stats(&impacts),
        "drift_amplification": stats(&c.drift_amplification),
        "required_gap": stats(&c.required_gap),
    })
}

/// The study's document: the pair with its runs, or (with `cells`) the
/// pounding spectrum over the records.
pub fn study_document(
    pair: &PoundingPair,
    records: &[(Record, f64)],
    runs: Option<Vec<Value>>,
    cells: Option<&[SpectrumCell]>,
) -> Value {
    let mut doc = json!({ "pair": pair_document(pair) });
    if let Some(runs) = runs {
        doc["runs"] = Value::Array(runs);
    }
    if let Some(cells) = cells {
        doc["records"] = records.iter().map(|(r, s)| json!(r.metadata(*s))).collect();
        doc["cells"] = cells.iter().map(cell_document).collect();
    }
    doc
}
