//! The documents of a pounding study, one shape for every face (the CLI's
//! JSON is the schema; Python returns the same fields and nesting): the
//! row, each record's run with and without pounding (per building keyed by
//! its name, per joint in order), and the pounding spectrum over gaps ×
//! period ratios.

use serde_json::{json, Map, Value};

use super::{
    quantile, MoatCell, Outcome, PoundingResult, Response, Row, RunSettings, SpectrumCell,
};
use crate::model::hysteresis::StoreyLaw;
use crate::model::record::Record;

/// The row: each building's name, fundamental period, floors, whether it
/// is isolated and its Rayleigh damping (ratio, α, β, on the initial
/// stiffness in the fixed-base modes 1 and 2); each joint's two
/// buildings, gap and pounding floors; the row's notes ([`Row::notes`]).
pub fn row_document(row: &Row) -> Value {
    let buildings: Vec<Value> = row
        .buildings
        .iter()
        .map(|b| {
            let (alpha, beta) = b.frame.rayleigh();
            json!({
                "name": b.name,
                "period": b.period(),
                "floors": b.floors(),
                "isolated": b.isolation.is_some(),
                "rayleigh": {
                    "ratio": b.frame.damping_ratio,
                    "alpha": alpha,
                    "beta": beta,
                    "basis": "initial stiffness, fixed-base modes 1 and 2",
                },
            })
        })
        .collect();
    let joints: Vec<Value> = row
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            json!({
                "between": [row.buildings[j].name, row.buildings[j + 1].name],
                "gap": joint.gap,
                "floors": joint.floors,
            })
        })
        .collect();
    json!({ "buildings": buildings, "joints": joints, "notes": row.notes() })
}

/// `{name: value}` over the row's buildings.
fn by_building<T: serde::Serialize>(row: &Row, values: impl IntoIterator<Item = T>) -> Value {
    let map: Map<String, Value> = row
        .buildings
        .iter()
        .zip(values)
        .map(|(b, v)| (b.name.clone(), json!(v)))
        .collect();
    Value::Object(map)
}

/// The yield drift of a law (None for an elastic one).
fn yield_drift(law: &StoreyLaw) -> Option<f64> {
    match law {
        StoreyLaw::Elastic { .. } => None,
        StoreyLaw::Bilinear(b) => Some(b.yield_drift),
        StoreyLaw::BoucWen(w) => Some(w.yield_drift),
        StoreyLaw::Imk(m) => Some(m.yield_drift),
    }
}

/// One response's peaks per building (keyed by name): drifts, residual
/// drifts, ductility demands (peak over yield drift; null for an elastic
/// storey), hysteretic energies, floor accelerations and displacements;
/// the isolators' response (isolated buildings); the peak impact force
/// and impact count between buildings, each joint's closings, per joint
/// its impacts and peak impact force (`joint_impacts`), and where a storey
/// moved more than its height, the `collapse` that stopped the run (null
/// for a run to its end).
pub fn response_document(row: &Row, r: &Response) -> Value {
    let ductility = row.buildings.iter().zip(&r.drift).map(|(b, drift)| {
        let laws = b.frame.laws().unwrap_or_default();
        drift
            .iter()
            .zip(laws.iter().map(yield_drift).chain(std::iter::repeat(None)))
            .map(|(d, uy)| uy.map(|uy| d / uy))
            .collect::<Vec<_>>()
    });
    let ratios = |d: &[Vec<f64>]| {
        let per: Vec<Option<Vec<f64>>> = row
            .buildings
            .iter()
            .zip(d)
            .map(|(b, d)| b.frame.drift_ratios(d))
            .collect();
        by_building(row, per)
    };
    let mut doc = json!({
        "peak_drift": by_building(row, &r.drift),
        "peak_drift_ratio": ratios(&r.drift),
        "residual_drift": by_building(row, &r.residual_drift),
        "residual_drift_ratio": ratios(&r.residual_drift),
        "ductility": by_building(row, ductility),
        "hysteretic_energy": by_building(row, &r.hysteretic_energy),
        "peak_floor_acceleration": by_building(row, &r.acceleration),
        "peak_displacement": by_building(row, &r.displacement),
        "peak_impact_force": r.peak_impact_force,
        "impacts": r.impacts,
        "closing": r.closing,
        "collapse": r.collapse.map(|c| json!({
            "building": row.buildings[c.building].name,
            "storey": c.storey + 1,
            "time": c.time,
            "note": format!(
                "storey {} of {} moved more than its height by t = {:.4} s: the building has collapsed, the run stopped there, and its peaks are those up to then",
                c.storey + 1, row.buildings[c.building].name, c.time
            ),
        })),
        "joint_impacts": r.joint_impacts.iter().enumerate().map(|(j, &(n, f))| json!({
            "between": [row.buildings[j].name, row.buildings[j + 1].name],
            "impacts": n,
            "peak_impact_force": f,
        })).collect::<Vec<_>>(),
    });
    let isolators: Map<String, Value> = row
        .buildings
        .iter()
        .zip(&r.isolators)
        .filter_map(|(b, i)| {
            let (i, iso) = (i.as_ref()?, b.isolation.as_ref()?);
            Some((
                b.name.clone(),
                json!({
                    "peak_displacement": i.peak_displacement,
                    "residual_displacement": i.residual_displacement,
                    "hysteretic_energy": i.hysteretic_energy,
                    "capacity": iso.capacity,
                    "beyond_capacity": i.beyond_capacity,
                    "moat_impacts": i.moat_impacts,
                    "moat_peak_force": i.moat_peak_force,
                }),
            ))
        })
        .collect();
    if !isolators.is_empty() {
        doc["isolators"] = Value::Object(isolators);
    }
    doc
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
/// pounding per building, and per joint the gap that avoids contact and
/// the code rules' gaps.
pub fn run_document(row: &Row, record: &Record, scale: f64, res: &PoundingResult) -> Value {
    let (p, f) = (&res.pounding, &res.free);
    let amp = |a: &[Vec<f64>], b: &[Vec<f64>]| {
        by_building(row, a.iter().zip(b).map(|(x, y)| ratio(x, y)))
    };
    let joints: Vec<Value> = res
        .joints
        .iter()
        .enumerate()
        .map(|(j, g)| {
            json!({
                "between": [row.buildings[j].name, row.buildings[j + 1].name],
                "required_gap": g.required_gap,
                "code_gaps": {
                    "absolute_sum": g.code_gaps.absolute_sum,
                    "srss": g.code_gaps.srss,
                    "double_difference": g.code_gaps.double_difference,
                    "correlation": g.code_gaps.correlation,
                },
            })
        })
        .collect();
    json!({
        "record": record.metadata(scale),
        "pounding": response_document(row, p),
        "free": response_document(row, f),
        "amplification": {
            "drift": amp(&p.drift, &f.drift),
            "floor_acceleration": amp(&p.acceleration, &f.acceleration),
        },
        "joints": joints,
    })
}

/// One record's run with the contacts only (no free response, no gaps):
/// the record and the response with pounding.
pub fn pounding_only_document(row: &Row, record: &Record, scale: f64, r: &Response) -> Value {
    json!({ "record": record.metadata(scale), "pounding": response_document(row, r) })
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

/// A cell of the moat-gap study: its gap (null: without contacts) and over
/// the records the isolated superstructures' peak drift and floor
/// acceleration, the isolators' displacement, the moat force and impacts
/// (median, 16/84 % and the values), and how many records passed an
/// isolator's capacity.
pub fn moat_cell_document(c: &MoatCell) -> Value {
    let impacts: Vec<f64> = c.moat_impacts.iter().map(|&i| i as f64).collect();
    json!({
        "gap": c.gap,
        "peak_drift": stats(&c.drift),
        "peak_floor_acceleration": stats(&c.acceleration),
        "isolator_displacement": stats(&c.isolator),
        "moat_peak_force": stats(&c.moat_force),
        "moat_impacts": stats(&impacts),
        "beyond_capacity": c.beyond_capacity.iter().filter(|b| **b).count(),
    })
}

/// How the runs were computed: the sampling step, the tolerance, the
/// method and the integrator.
pub fn settings_document(run: &RunSettings) -> Value {
    json!({
        "sample": run.sample,
        "rtol": run.rtol,
        "method": run.method.name(),
        "integrator": run.integrator.name(),
    })
}

/// The units of every quantity of the seismic documents.
pub fn units_document() -> Value {
    json!({
        "drift": "m",
        "drift_ratio": "m/m",
        "displacement": "m",
        "floor_acceleration": "m/s2",
        "force": "N",
        "energy": "J",
        "period": "s",
        "gap": "m",
        "spectral_acceleration": "m/s2",
    })
}

/// The study's document: the row, the settings and units, and its runs,
/// or (with the records) the cells of the pounding spectrum or of the
/// moat-gap study.
pub fn study_document(
    row: &Row,
    records: &[(Record, f64)],
    outcome: &Outcome,
    run: &RunSettings,
) -> Value {
    let mut doc = json!({
        "row": row_document(row),
        "settings": settings_document(run),
        "units": units_document(),
    });
    let metadata = || -> Value { records.iter().map(|(r, s)| json!(r.metadata(*s))).collect() };
    match outcome {
        Outcome::Runs { documents, .. } => doc["runs"] = Value::Array(documents.clone()),
        Outcome::Spectrum(cells) => {
            doc["records"] = metadata();
            doc["cells"] = cells.iter().map(cell_document).collect();
        }
        Outcome::Moat(cells) => {
            doc["records"] = metadata();
            doc["moat_cells"] = cells.iter().map(moat_cell_document).collect();
        }
    }
    doc
}
