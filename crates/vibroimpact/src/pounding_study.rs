//! A whole pounding study as every face runs it (the CLI's `pounding`,
//! Python's `pounding`): per record the runs, or the pounding spectrum of
//! a pair, or the moat-gap study of isolated buildings.

use serde_json::Value;

use super::{
    documents, moat_study, pounding_spectrum, MoatCell, PoundingError, Row, RunSettings,
    SpectrumCell,
};
use crate::record::Record;

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
    /// One document per record ([`documents::run_document`] or
    /// [`documents::pounding_only_document`]).
    Runs(Vec<Value>),
    /// The pounding spectrum's cells.
    Spectrum(Vec<SpectrumCell>),
    /// The moat-gap study's cells (the first without contacts).
    Moat(Vec<MoatCell>),
}

impl Study {
    /// Runs the study of `row` under `records` (each with its scale).
    pub fn run(
        &self,
        row: &Row,
        records: &[(Record, f64)],
        run: &RunSettings,
    ) -> Result<Outcome, PoundingError> {
        Ok(match self {
            Study::Runs { free } => Outcome::Runs(
                records
                    .iter()
                    .map(|(r, s)| {
                        if *free {
                            row.analyse(r, *s, run)
                                .map(|res| documents::run_document(row, r, *s, &res))
                        } else {
                            row.respond(r, *s, true, run)
                                .map(|res| documents::pounding_only_document(row, r, *s, &res))
                        }
                    })
                    .collect::<Result<_, _>>()?,
            ),
            Study::Spectrum { gaps, ratios } => {
                Outcome::Spectrum(pounding_spectrum(row, records, gaps, ratios, run)?)
            }
            Study::Moat { gaps } => Outcome::Moat(moat_study(row, records, gaps, run)?),
        })
    }
}
