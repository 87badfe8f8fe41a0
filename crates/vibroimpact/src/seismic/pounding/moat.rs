//! The moat-gap study of isolated buildings (docs/earthquakes.md): the row
//! under an ensemble of records with every moat at each of a list of
//! gaps, and once without contacts; per gap, over the records, the peak
//! drift and floor acceleration of the superstructures of the buildings
//! with a moat, their isolators' displacement and the moat impacts.

use super::{PoundingError, Response, Row, RunSettings};
use crate::field_error::FieldError;
use crate::model::record::Record;

/// The study at one moat gap (or without the wall: `gap` None), over the
/// records (one value per record, in order).
#[derive(Clone, Debug, PartialEq)]
pub struct MoatCell {
    /// The moat gap (m), or None for the buildings without contacts.
    pub gap: Option<f64>,
    /// The largest storey drift of the superstructures of the buildings
    /// with a moat wall (m).
    pub drift: Vec<f64>,
    /// Their largest absolute floor acceleration (m/s²).
    pub acceleration: Vec<f64>,
    /// Their isolators' largest displacement (m).
    pub isolator: Vec<f64>,
    /// The largest moat impact force (N; 0 without impacts).
    pub moat_force: Vec<f64>,
    /// The moat impacts.
    pub moat_impacts: Vec<usize>,
    /// Whether an isolator passed its stated capacity.
    pub beyond_capacity: Vec<bool>,
}

/// The study: every gap of `gaps` (and, first, the row without contacts)
/// under every record of `records` (each with its scale), in parallel;
/// the same numbers at any thread count. Needs an isolated building with
/// a moat wall; joints between buildings keep their gaps.
pub fn moat_study(
    row: &Row,
    records: &[(Record, f64)],
    gaps: &[f64],
    run: &RunSettings,
) -> Result<Vec<MoatCell>, PoundingError> {
    use rayon::prelude::*;
    row.check()?;
    let moats: Vec<usize> = (0..row.buildings.len())
        .filter(|&k| {
            row.buildings[k]
                .isolation
                .as_ref()
                .is_some_and(|i| i.moat.is_some())
        })
        .collect();
    if moats.is_empty() {
        let message = "a moat-gap study needs an isolated building with a moat wall";
        return Err(FieldError::about("moat_gaps", message).into());
    }
    if records.is_empty() || gaps.is_empty() {
        let message = "a moat-gap study needs records and gaps";
        return Err(FieldError::about("moat_gaps", message).into());
    }
    if let Some(g) = gaps.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
        return Err(FieldError::new("moat_gaps", g, "give finite gaps >= 0").into());
    }
    let cases: Vec<Option<f64>> = std::iter::once(None)
        .chain(gaps.iter().map(|&g| Some(g)))
        .collect();
    let jobs: Vec<(usize, usize)> = (0..cases.len())
        .flat_map(|c| (0..records.len()).map(move |r| (c, r)))
        .collect();
    let responses: Vec<Response> = jobs
        .par_iter()
        .map(|&(c, r)| {
            let (record, scale) = &records[r];
            let mut row = row.clone();
            if let Some(g) = cases[c] {
                for &k in &moats {
                    if let Some(m) = row.buildings[k]
                        .isolation
                        .as_mut()
                        .and_then(|i| i.moat.as_mut())
                    {
                        m.gap = g;
                    }
                }
            }
            row.respond(record, *scale, cases[c].is_some(), run)
        })
        .collect::<Result<_, _>>()?;
    Ok(cases
        .iter()
        .enumerate()
        .map(|(c, &gap)| {
            let mut cell = MoatCell {
                gap,
                drift: Vec::new(),
                acceleration: Vec::new(),
                isolator: Vec::new(),
                moat_force: Vec::new(),
                moat_impacts: Vec::new(),
                beyond_capacity: Vec::new(),
            };
            for res in &responses[c * records.len()..(c + 1) * records.len()] {
                let most = |v: &[Vec<f64>]| {
                    moats
                        .iter()
                        .flat_map(|&k| v[k].iter().copied())
                        .fold(0.0f64, f64::max)
                };
                let isolators = moats.iter().filter_map(|&k| res.isolators[k]);
                cell.drift.push(most(&res.drift));
                cell.acceleration.push(most(&res.acceleration));
                cell.isolator.push(
                    isolators
                        .clone()
                        .fold(0.0, |m, i| m.max(i.peak_displacement)),
                );
                cell.moat_force
                    .push(isolators.clone().fold(0.0, |m, i| m.max(i.moat_peak_force)));
                cell.moat_impacts
                    .push(isolators.clone().map(|i| i.moat_impacts).sum());
                cell.beyond_capacity
                    .push(isolators.clone().any(|i| i.beyond_capacity));
            }
            cell
        })
        .collect())
}
