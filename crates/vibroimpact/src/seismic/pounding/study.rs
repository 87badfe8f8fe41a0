//! A whole pounding study as every face runs it (the CLI's `pounding`,
//! Python's `pounding`): per record the runs, or the pounding spectrum of
//! a pair, or the moat-gap study of isolated buildings.

use serde_json::Value;

use super::{
    documents, moat_study, pounding_spectrum, MoatCell, PoundingError, Row, RunSettings,
    SpectrumCell, StoreyLoop,
};
use crate::model::record::Record;
use crate::simulate::WorkEstimate;

/// Which study.
#[derive(Clone, Debug, PartialEq)]
pub enum Study {
    /// Each record run with the contacts, and apart when `free`.
    Runs {
        /// Also the buildings apart, the joints' required and code gaps.
        free: bool,
    },
    /// The pounding spectrum of a pair over gaps × period ratios.
    Spectrum {
        /// Gaps (m).
        gaps: Vec<f64>,
        /// Period ratios T_left/T_right.
        ratios: Vec<f64>,
    },
    /// The moat-gap study of isolated buildings.
    Moat {
        /// Moat gaps (m).
        gaps: Vec<f64>,
    },
}

/// What a study gives.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// Per record.
    Runs {
        /// Its document ([`documents::run_document`] or
        /// [`documents::pounding_only_document`]).
        documents: Vec<Value>,
        /// The hysteresis loops of its run with the contacts.
        loops: Vec<Vec<StoreyLoop>>,
    },
    /// The pounding spectrum's cells.
    Spectrum(Vec<SpectrumCell>),
    /// The moat-gap study's cells (the first without contacts).
    Moat(Vec<MoatCell>),
}

impl Study {
    /// The study's work, estimated before it starts: each record's run
    /// with the contacts, times the runs the study makes of it (apart
    /// too; per spectrum or moat cell). None where a run's checks refuse
    /// it (the study itself says why).
    pub fn estimate(
        &self,
        row: &Row,
        records: &[(Record, f64)],
        run: &RunSettings,
    ) -> Result<Option<WorkEstimate>, PoundingError> {
        let runs = match self {
            Study::Runs { free } => 1.0 + f64::from(u8::from(*free)),
            Study::Spectrum { gaps, ratios } => (gaps.len() * ratios.len()) as f64,
            Study::Moat { gaps } => 1.0 + gaps.len() as f64,
        };
        let mut total: Option<WorkEstimate> = None;
        for (r, s) in records {
            let Some(one) = row.estimate(r, *s, true, run)? else {
                return Ok(None);
            };
            let one = one.times(runs);
            total = Some(total.map_or(one, |t| t.then(one)));
        }
        Ok(total)
    }

    /// Runs the study of `row` under `records` (each with its scale).
    pub fn run(
        &self,
        row: &Row,
        records: &[(Record, f64)],
        run: &RunSettings,
    ) -> Result<Outcome, PoundingError> {
        Ok(match self {
            Study::Runs { free } => {
                let mut documents = Vec::with_capacity(records.len());
                let mut loops = Vec::with_capacity(records.len());
                for (r, s) in records {
                    let (doc, pounding) = if *free {
                        let res = row.analyse(r, *s, run)?;
                        (documents::run_document(row, r, *s, &res), res.pounding)
                    } else {
                        let res = row.respond(r, *s, true, run)?;
                        (documents::pounding_only_document(row, r, *s, &res), res)
                    };
                    documents.push(doc);
                    loops.push(pounding.loops);
                }
                Outcome::Runs { documents, loops }
            }
            Study::Spectrum { gaps, ratios } => {
                Outcome::Spectrum(pounding_spectrum(row, records, gaps, ratios, run)?)
            }
            Study::Moat { gaps } => Outcome::Moat(moat_study(row, records, gaps, run)?),
        })
    }
}
