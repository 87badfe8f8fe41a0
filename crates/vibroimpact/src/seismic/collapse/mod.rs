//! Collapse assessment in the FEMA P695 way (docs/earthquakes.md,
//! "Collapse"): per record an incremental dynamic analysis of a row of
//! buildings, its scale raised until the row collapses, the collapse
//! bracketed by bisection; then the median collapse scale over the
//! records, censored records (no collapse up to the largest scale) never
//! folded in.
//!
//! Files: `mod.rs` (IDA per record, the median, margins), `fragility.rs`
//! (the lognormal fragility by maximum likelihood), `study.rs` (the study
//! every face runs and its documents), `tests.rs` (the checks).
//!
//! A run collapses when a storey drift passes the drift limit (the run
//! stops there), when an isolator passes its stated capacity (if the
//! criterion says so), or when it does not converge (a step size that
//! underflows, the step limit: non-convergence counts as collapse, as FEMA
//! P695 has it; an explicit method's stiffness or a run without progress
//! depend on the method and stay errors). The scales follow a geometric
//! hunt from `first` by `growth` up to `max_scale` (down by `growth` from
//! `first` if that collapses already); between the last scale survived and
//! the first that collapsed, bisection (geometric midpoints) until their
//! ratio is within `1 + tolerance`. The collapse scale is the bracket's
//! upper end.
//!
//! The intensity of FEMA P695 is the record set's median spectral
//! acceleration S_T at the period: a record set scaled as one by a factor
//! c has intensity c S_T, so the median collapse intensity is Ŝ_CT =
//! median(cᵢ) S_T. The faces compute S_T (the response spectra of the
//! records as given, normalized as the set requires) and the margins.

use crate::model::record::Record;
use crate::seismic::pounding::{PoundingError, Row, RunSettings, Stop};
use crate::seismic::pushover::storey_tangent;

/// The storey drift at which a run counts as a collapse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DriftLimit {
    /// A storey drift (m), every storey.
    Drift(f64),
    /// A storey drift ratio: each storey's height times it (every building
    /// needs heights). FEMA P695 practice caps sidesway at a drift ratio
    /// beyond the collapse of its archetypes: [`DriftLimit::FEMA`].
    Ratio(f64),
}

impl DriftLimit {
    /// The default: a drift ratio of 0.10.
    pub const FEMA: Self = Self::Ratio(0.10);
}

/// When a run counts as a collapse.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Criterion {
    /// The storey drift limit.
    pub drift: DriftLimit,
    /// Whether an isolator displacement past its stated capacity is a
    /// collapse.
    pub capacity: bool,
    /// Whether the row's contacts (pounding, moat walls) are in (the
    /// fragility "with pounding"), or left out ("without").
    pub contacts: bool,
}

/// The scales an IDA visits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdaSettings {
    /// The first scale.
    pub first: f64,
    /// The hunt's growth factor (> 1).
    pub growth: f64,
    /// The largest scale run: a record still standing there is censored.
    pub max_scale: f64,
    /// The bracket's relative width at which bisection stops.
    pub tolerance: f64,
}

impl Default for IdaSettings {
    /// From 0.25 by 1.5 up to 20, bracketed to 2 %.
    fn default() -> Self {
        Self {
            first: 0.25,
            growth: 1.5,
            max_scale: 20.0,
            tolerance: 0.02,
        }
    }
}

/// What one run of an IDA found.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// Standing at the end.
    Standing,
    /// A storey drift passed the limit on a rising curve (the storey
    /// still stiffened as it drifted).
    Drift {
        /// The building.
        building: String,
        /// The storey (1-based).
        storey: usize,
        /// Its peak drift, exact on the dense output (m).
        drift: f64,
        /// The sample at which the run stopped past the limit (s); None
        /// where the limit was passed only between samples (the run then
        /// went on to its end).
        time: Option<f64>,
    },
    /// Dynamic instability: a storey drift passed the limit where the
    /// storey's tangent stiffness with P-Δ (its monotonic curve's) was
    /// negative, so nothing stopped it drifting (sidesway).
    Instability {
        /// The building.
        building: String,
        /// The storey (1-based).
        storey: usize,
        /// Its peak drift, exact on the dense output (m).
        drift: f64,
        /// The sample at which the run stopped past the limit (s); None
        /// where only the dense output saw it pass.
        time: Option<f64>,
    },
    /// An isolator passed its capacity.
    Capacity {
        /// The building.
        building: String,
        /// The isolator's peak displacement (m).
        displacement: f64,
    },
    /// The run failed to integrate.
    Diverged {
        /// Why.
        message: String,
    },
}

impl Verdict {
    /// Whether it is a collapse.
    pub fn collapsed(&self) -> bool {
        !matches!(self, Verdict::Standing)
    }
}

/// One run of an IDA.
#[derive(Clone, Debug, PartialEq)]
pub struct IdaPoint {
    /// The scale.
    pub scale: f64,
    /// The largest storey drift over the buildings (m; up to the stop, or
    /// up to where a run that did not converge ended).
    pub max_drift: f64,
    /// The largest storey drift ratio (None: a building has no heights).
    pub max_drift_ratio: Option<f64>,
    /// The verdict.
    pub verdict: Verdict,
}

/// One record's IDA.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordIda {
    /// The record's source.
    pub source: String,
    /// The runs in the order made.
    pub points: Vec<IdaPoint>,
    /// The largest scale survived below the collapse (the bracket's lower
    /// end; the largest scale run if censored).
    pub survived: f64,
    /// The collapse scale (the bracket's upper end), or None: no collapse
    /// up to `survived`.
    pub collapse: Option<f64>,
}

impl IdaSettings {
    /// Refuses a first scale or limit not positive and finite, a growth
    /// ≤ 1, a tolerance outside (0, 1), a largest scale below the first.
    pub fn check(&self) -> Result<(), PoundingError> {
        use crate::field_error::FieldError;
        let bad = |field, v: f64, m| Err(FieldError::new(field, v, m).into());
        if !(self.first.is_finite() && self.first > 0.0) {
            return bad("first", self.first, "give a positive scale");
        }
        if !(self.growth.is_finite() && self.growth > 1.0) {
            return bad("growth", self.growth, "give a factor > 1");
        }
        if !(self.max_scale.is_finite() && self.max_scale >= self.first) {
            return bad("max_scale", self.max_scale, "give a scale >= first");
        }
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return bad("tolerance", self.tolerance, "give a value in (0, 1)");
        }
        Ok(())
    }
}

impl Criterion {
    /// Refuses a drift limit that is not positive and finite, and a drift
    /// ratio above 1.
    pub fn check(&self) -> Result<(), PoundingError> {
        let (key, v, m) = match self.drift {
            DriftLimit::Drift(d) => ("drift_limit", d, "give a positive storey drift (m)"),
            DriftLimit::Ratio(r) => (
                "drift_ratio_limit",
                r,
                "give a drift ratio in (0, 1] (a storey past its height has collapsed whatever the limit)",
            ),
        };
        let ratio_above_one = matches!(self.drift, DriftLimit::Ratio(r) if r > 1.0);
        if v.is_finite() && v > 0.0 && !ratio_above_one {
            Ok(())
        } else {
            Err(crate::field_error::FieldError::new(key, v, m).into())
        }
    }

    /// Every storey's drift limit (m) per building; a ratio needs every
    /// building's heights.
    pub fn limits(&self, row: &Row) -> Result<Vec<Vec<f64>>, PoundingError> {
        row.buildings
            .iter()
            .map(|b| match self.drift {
                DriftLimit::Drift(d) => Ok(vec![d; b.floors()]),
                DriftLimit::Ratio(r) if b.frame.heights.is_empty() => {
                    Err(crate::field_error::FieldError::new(
                        "drift_ratio_limit",
                        r,
                        format!("building {:?} has no storey heights: give its heights, or a drift limit in metres", b.name),
                    )
                    .into())
                }
                DriftLimit::Ratio(r) => Ok(b.frame.heights.iter().map(|h| r * h).collect()),
            })
            .collect()
    }

    /// One run of `row` under `record` × `scale`.
    fn run(
        &self,
        row: &Row,
        record: &Record,
        scale: f64,
        run: &RunSettings,
    ) -> Result<IdaPoint, PoundingError> {
        let limits = self.limits(row)?;
        let (r, stop) = row.respond_until(record, scale, self.contacts, run, Some(&limits))?;
        // The storey nearest its limit (drift over limit), and the largest
        // drift and drift ratio.
        let (mut worst, mut max_drift, mut max_ratio) = ((0.0f64, 0, 0), 0.0f64, Some(0.0f64));
        for (k, drifts) in r.drift.iter().enumerate() {
            let heights = &row.buildings[k].frame.heights;
            if heights.is_empty() {
                max_ratio = None;
            }
            for (i, &d) in drifts.iter().enumerate() {
                if d / limits[k][i] > worst.0 {
                    worst = (d / limits[k][i], k, i);
                }
                max_drift = max_drift.max(d);
                max_ratio = max_ratio.map(|m| m.max(d / heights.get(i).copied().unwrap_or(1.0)));
            }
        }
        let (passed, k, i) = worst;
        let drift = r
            .drift
            .get(k)
            .and_then(|d| d.get(i))
            .copied()
            .unwrap_or(0.0);
        let name = |k: usize| row.buildings[k].name.clone();
        let past = |time| -> Result<Verdict, PoundingError> {
            let tangent = storey_tangent(&row.buildings[k].frame, i, drift)
                .map_err(|m| PoundingError::pair("storeys", m))?;
            let (building, storey) = (name(k), i + 1);
            Ok(if tangent < 0.0 {
                Verdict::Instability {
                    building,
                    storey,
                    drift,
                    time,
                }
            } else {
                Verdict::Drift {
                    building,
                    storey,
                    drift,
                    time,
                }
            })
        };
        let beyond = r
            .isolators
            .iter()
            .enumerate()
            .find_map(|(k, i)| i.filter(|i| i.beyond_capacity).map(|i| (k, i)));
        let verdict = match (stop, beyond) {
            (Stop::Diverged { message }, _) => Verdict::Diverged { message },
            (Stop::Limit { time }, _) => past(Some(time))?,
            (Stop::End, _) if passed > 1.0 => past(None)?,
            (Stop::End, Some((k, i))) if self.capacity => Verdict::Capacity {
                building: name(k),
                displacement: i.peak_displacement,
            },
            _ => Verdict::Standing,
        };
        Ok(IdaPoint {
            scale,
            max_drift,
            max_drift_ratio: max_ratio,
            verdict,
        })
    }
}

/// The IDA of `row` under `record`: the hunt, then bisection of the
/// collapse bracket (module notes). Errors other than a run that fails to
/// integrate (a collapse) stop it.
pub fn record_ida(
    row: &Row,
    record: &Record,
    criterion: &Criterion,
    ida: &IdaSettings,
    run: &RunSettings,
) -> Result<RecordIda, PoundingError> {
    criterion.check()?;
    ida.check()?;
    row.check()?;
    let mut points = Vec::new();
    let mut survived = 0.0;
    let mut scale = ida.first;
    let mut collapse = None;
    loop {
        let p = criterion.run(row, record, scale, run)?;
        let fell = p.verdict.collapsed();
        points.push(p);
        if fell {
            collapse = Some(scale);
            break;
        }
        survived = scale;
        if scale >= ida.max_scale {
            break;
        }
        scale = (scale * ida.growth).min(ida.max_scale);
    }
    if let Some(mut high) = collapse {
        let mut low = survived;
        // The first scale collapsed: down by the growth factor until a
        // scale stands (a model that falls at every scale down to 1e-6 of
        // the first is an error, not a collapse intensity).
        while low == 0.0 {
            let scale = high / ida.growth;
            if scale < 1e-6 * ida.first {
                return Err(PoundingError::Run {
                    record: record.source.clone(),
                    message: format!(
                        "collapses at every scale down to {high:e}: check the model and the drift limit"
                    ),
                });
            }
            let p = criterion.run(row, record, scale, run)?;
            let fell = p.verdict.collapsed();
            points.push(p);
            if fell {
                high = scale;
            } else {
                low = scale;
            }
        }
        while high / low > 1.0 + ida.tolerance {
            let mid = (low * high).sqrt();
            let p = criterion.run(row, record, mid, run)?;
            if p.verdict.collapsed() {
                high = mid;
            } else {
                low = mid;
            }
            points.push(p);
        }
        survived = low;
        collapse = Some(high);
    }
    Ok(RecordIda {
        source: record.source.clone(),
        points,
        survived,
        collapse,
    })
}

/// The median collapse scale over the records' IDAs: a censored record
/// (no collapse up to its largest scale) counts as standing above every
/// collapse, never as a value. None when the median falls among the
/// censored records (more than half of them, or the middle pair reaches
/// one).
pub fn median_collapse(records: &[RecordIda]) -> Option<f64> {
    let n = records.len();
    if n == 0 {
        return None;
    }
    let mut scales: Vec<f64> = records
        .iter()
        .map(|r| r.collapse.unwrap_or(f64::INFINITY))
        .collect();
    scales.sort_by(f64::total_cmp);
    let m = if n % 2 == 1 {
        scales[n / 2]
    } else {
        0.5 * (scales[n / 2 - 1] + scales[n / 2])
    };
    m.is_finite().then_some(m)
}

mod fragility;
pub use fragility::{fragility, Fragility, FragilityError};
mod study;
pub use study::{
    check_margins, fit_fragility, record_document, study_document, summary_document, CollapseStudy,
    RecordCollapse,
};

#[cfg(test)]
mod tests;
