//! A collapse study as every face runs it: per record its IDA and its
//! spectral acceleration at the period (one task per record for a
//! cluster), then the summary over the records; and their documents (the
//! CLI's JSON is the schema, Python returns the same).

use serde_json::{json, Value};

use super::{
    fragility, median_collapse, record_ida, Criterion, DriftLimit, Fragility, FragilityError,
    IdaSettings, RecordIda, Verdict,
};
use crate::field_error::FieldError;
use crate::model::record::{Record, STANDARD_GRAVITY};
use crate::seismic::pounding::{PoundingError, Row, RunSettings};
use crate::simulate::WorkEstimate;

/// The settings of a collapse study.
#[derive(Clone, Debug, PartialEq)]
pub struct CollapseStudy {
    /// When a run collapses.
    pub criterion: Criterion,
    /// The scales visited.
    pub ida: IdaSettings,
    /// How each run is computed.
    pub run: RunSettings,
    /// The period T of the intensity S_T (s): the records' spectral
    /// acceleration at it, 5 % damped unless `damping` says otherwise.
    pub period: Option<f64>,
    /// The damping ratio of that spectral acceleration.
    pub damping: f64,
}

/// One record's part of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordCollapse {
    /// Its IDA.
    pub ida: RecordIda,
    /// Its pseudo-spectral acceleration at the period, unscaled, in g
    /// (FEMA P695 states S_T, Ŝ_CT and S_MT in g).
    pub sa: Option<f64>,
}

impl CollapseStudy {
    /// Refuses, before any run, a criterion or IDA setting out of range, a
    /// period of the intensity that is not positive and finite, and a
    /// damping ratio outside [0, 1).
    pub fn check(&self) -> Result<(), PoundingError> {
        self.criterion.check()?;
        self.ida.check()?;
        if let Some(t) = self.period {
            if !(t.is_finite() && t > 0.0) {
                let m = "give the positive period (s) of the spectral acceleration";
                return Err(FieldError::new("period", t, m).into());
            }
        }
        if !(0.0..1.0).contains(&self.damping) {
            let m = "give a damping ratio in [0, 1)";
            return Err(FieldError::new("damping", self.damping, m).into());
        }
        Ok(())
    }

    /// The work of one record's IDA, estimated before it starts: its run
    /// at the first scale times the runs the IDA can make (the scales up
    /// to the largest, then the bisection to the tolerance). None where a
    /// run's checks refuse it (the run itself says why).
    pub fn estimate(
        &self,
        row: &Row,
        record: &Record,
    ) -> Result<Option<WorkEstimate>, PoundingError> {
        self.check()?;
        let ida = &self.ida;
        let climbs = ((ida.max_scale / ida.first).ln() / ida.growth.ln()).ceil() + 1.0;
        let halvings = (ida.growth.ln() / (1.0 + ida.tolerance).ln())
            .log2()
            .ceil()
            .max(0.0);
        // (A drift-ratio limit needs the heights: refused here, before any
        // run.)
        self.criterion.limits(row)?;
        let one = row.estimate(record, ida.first, self.criterion.contacts, &self.run)?;
        Ok(one.map(|w| w.times(climbs + halvings)))
    }

    /// One record's IDA and spectral acceleration (the task of one
    /// record).
    pub fn record(&self, row: &Row, record: &Record) -> Result<RecordCollapse, PoundingError> {
        self.check()?;
        let sa = self
            .period
            .map(|t| {
                crate::seismic::spectrum::response_spectrum(record, 1.0, self.damping, &[t])
                    .map(|p| p[0].pseudo_acceleration / STANDARD_GRAVITY)
            })
            .transpose()?;
        let ida = record_ida(row, record, &self.criterion, &self.ida, &self.run)?;
        Ok(RecordCollapse { ida, sa })
    }
}

/// A verdict as a document: `kind` (standing, drift, capacity, diverged)
/// and its details.
fn verdict_document(v: &Verdict) -> Value {
    match v {
        Verdict::Standing => json!({ "kind": "standing" }),
        Verdict::Drift {
            building,
            storey,
            drift,
            time,
        } => {
            json!({ "kind": "drift", "building": building, "storey": storey, "drift": drift, "time": time })
        }
        Verdict::Instability {
            building,
            storey,
            drift,
            time,
        } => {
            json!({ "kind": "instability", "building": building, "storey": storey, "drift": drift, "time": time })
        }
        Verdict::Capacity {
            building,
            displacement,
        } => json!({ "kind": "capacity", "building": building, "displacement": displacement }),
        Verdict::Diverged { message } => json!({ "kind": "diverged", "message": message }),
    }
}

/// One record's document: its source, spectral acceleration, the runs
/// (`scale`, `max_drift`, `verdict`) in the order made, the bracket
/// (`survived`, `collapse`), whether it is censored and, then, the note
/// "no collapse up to scale X".
pub fn record_document(r: &RecordCollapse) -> Value {
    let points: Vec<Value> = r
        .ida
        .points
        .iter()
        .map(|p| json!({ "scale": p.scale, "max_drift": p.max_drift, "max_drift_ratio": p.max_drift_ratio, "verdict": verdict_document(&p.verdict) }))
        .collect();
    // How it collapsed: the verdict of the run at the collapse scale.
    let mode = r.ida.collapse.and_then(|c| {
        let run = r.ida.points.iter().find(|p| p.scale == c)?;
        Some(match run.verdict {
            Verdict::Drift { .. } => "drift limit",
            Verdict::Instability { .. } => "dynamic instability",
            Verdict::Capacity { .. } => "isolator capacity",
            Verdict::Diverged { .. } => "numerical failure",
            Verdict::Standing => return None,
        })
    });
    json!({
        "source": r.ida.source,
        "sa": r.sa,
        "runs": points,
        "survived": r.ida.survived,
        "collapse": r.ida.collapse,
        "collapse_mode": mode,
        "censored": r.ida.collapse.is_none(),
        "note": r.ida.collapse.is_none().then(|| format!("no collapse up to scale {}", r.ida.survived)),
    })
}

/// Refuses an S_MT (g) or SSF that is not positive and finite (a negative
/// S_MT gave a negative CMR): checked before any run.
pub fn check_margins(smt: Option<f64>, ssf: Option<f64>) -> Result<(), FieldError> {
    for (field, v, what) in [
        (
            "smt",
            smt,
            "give the positive MCE spectral acceleration S_MT in g",
        ),
        ("ssf", ssf, "give the positive spectral shape factor"),
    ] {
        if let Some(v) = v.filter(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(FieldError::new(field, v, what));
        }
    }
    Ok(())
}

/// The summary over the records' parts: the median collapse scale (null
/// where censored records leave it undetermined, with a note naming
/// them); with spectral accelerations, the set's median S_T at the period
/// (their geometric mean, as FEMA P695's S_NRT) and the median collapse
/// intensity Ŝ_CT = median scale × S_T, both in g; with
/// `smt` (S_MT, g) the collapse margin ratio CMR = Ŝ_CT / S_MT, and with
/// `ssf` also ACMR = SSF × CMR; the lognormal fragility fitted to the
/// records ([`fit_fragility`]) or, where none is determined, the note why.
pub fn summary_document(records: &[RecordCollapse], smt: Option<f64>, ssf: Option<f64>) -> Value {
    let idas: Vec<RecordIda> = records.iter().map(|r| r.ida.clone()).collect();
    let median = median_collapse(&idas);
    // The set's median as FEMA P695 tabulates it (S_NRT, Table A-3): the
    // geometric mean, the median of the lognormal fit.
    let s_t = set_intensity(records);
    let s_ct = median.zip(s_t).map(|(m, s)| m * s);
    let cmr = s_ct.zip(smt).map(|(c, m)| c / m);
    let censored: Vec<String> = idas
        .iter()
        .filter(|r| r.collapse.is_none())
        .map(|r| format!("{}: no collapse up to scale {}", r.source, r.survived))
        .collect();
    let (fragility, fragility_note) = match fit_fragility(records) {
        Ok(f) => (
            json!({
                "median": f.median,
                "dispersion": f.dispersion,
                "records": f.records,
                "censored": f.censored,
                "intensity": if s_t.is_some() { "s_t" } else { "scale" },
            }),
            Value::Null,
        ),
        Err(e) => (Value::Null, json!(format!("no fragility: {e}"))),
    };
    json!({
        "records": records.len(),
        "collapsed": records.len() - censored.len(),
        "median_collapse_scale": median,
        "s_t": s_t,
        "s_ct": s_ct,
        "smt": smt,
        "cmr": cmr,
        "ssf": ssf,
        "acmr": cmr.zip(ssf).map(|(c, s)| c * s),
        "censored": censored,
        "fragility": fragility,
        "fragility_note": fragility_note,
        "note": median.is_none().then(|| format!(
            "the median collapse scale is not determined: {} of {} records did not collapse; raise the largest scale",
            censored.len(),
            records.len()
        )),
    })
}

/// The lognormal fragility of the records' intensities (module
/// `fragility`): each record's collapse scale, or the largest it survived
/// (censored), times the set's S_T in g where every record has its Sa
/// (the intensity of FEMA P695, whose median is Ŝ_CT), else the scale
/// itself.
pub fn fit_fragility(records: &[RecordCollapse]) -> Result<Fragility, FragilityError> {
    let per = set_intensity(records).unwrap_or(1.0);
    let (values, censored): (Vec<f64>, Vec<bool>) = records
        .iter()
        .map(|r| {
            let scale = r.ida.collapse.unwrap_or(r.ida.survived);
            (scale * per, r.ida.collapse.is_none())
        })
        .unzip();
    fragility(&values, &censored)
}

/// The set's S_T (g): the geometric mean of the records' Sa, as FEMA P695
/// tabulates S_NRT; None unless every record has one.
fn set_intensity(records: &[RecordCollapse]) -> Option<f64> {
    let sas: Option<Vec<f64>> = records.iter().map(|r| r.sa).collect();
    sas.filter(|v| !v.is_empty())
        .map(|v| (v.iter().map(|x| x.ln()).sum::<f64>() / v.len() as f64).exp())
}

/// The units of a study's document: the pounding runs' units, with the
/// spectral accelerations (each record's `sa`, S_T, Ŝ_CT, S_MT) in g, as
/// FEMA P695 states them.
fn units_document() -> Value {
    let mut units = crate::seismic::pounding::documents::units_document();
    units["spectral_acceleration"] = json!("g");
    units
}

/// The study's document: the row, the settings, every record's document
/// ([`record_document`]) and the summary ([`summary_document`]).
pub fn study_document(
    row: &Row,
    study: &CollapseStudy,
    records: Vec<Value>,
    summary: Value,
) -> Value {
    json!({
        "row": crate::seismic::pounding::documents::row_document(row),
        "criterion": {
            "drift_limit": match study.criterion.drift {
                DriftLimit::Drift(d) => json!(d),
                DriftLimit::Ratio(_) => Value::Null,
            },
            "drift_ratio_limit": match study.criterion.drift {
                DriftLimit::Ratio(r) => json!(r),
                DriftLimit::Drift(_) => Value::Null,
            },
            "capacity": study.criterion.capacity,
            "contacts": study.criterion.contacts,
        },
        "ida": {
            "first": study.ida.first,
            "growth": study.ida.growth,
            "max_scale": study.ida.max_scale,
            "tolerance": study.ida.tolerance,
        },
        "period": study.period,
        "damping": study.damping,
        "settings": crate::seismic::pounding::documents::settings_document(&study.run),
        "units": units_document(),
        "records": records,
        "summary": summary,
    })
}
