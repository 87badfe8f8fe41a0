//! The pounding pair file (docs/earthquakes.md) and the errors of a
//! pounding study: the file's line and key, a setting's field, a run's
//! record.

use super::{PoundingPair, ShearFrame};
use crate::field_error::FieldError;
use crate::hysteresis::StoreySpec;
use crate::record::Record;

/// Why a pounding study cannot run or did not finish.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PoundingError {
    /// The pair refused: the pair file where it came from one, the line
    /// where known, the key at fault where known (`left`, `right`, `gap`,
    /// `floors`, `law`), and what is wrong.
    #[error("{}", pair_text(file.as_deref(), *line, message))]
    Pair {
        /// The pair file.
        file: Option<String>,
        /// The line in it.
        line: Option<usize>,
        /// The key at fault.
        key: Option<&'static str>,
        /// What is wrong (naming the frame and floor).
        message: String,
    },
    /// A setting of the study refused, by its field (`sample`, `ratios`,
    /// `gaps`, `records`).
    #[error(transparent)]
    Field(#[from] FieldError),
    /// A run under a record failed: the record and why.
    #[error("{record}: {message}")]
    Run {
        /// The record's source.
        record: String,
        /// Why.
        message: String,
    },
}

/// `FILE:LINE: message`, `FILE: message` or the message.
fn pair_text(file: Option<&str>, line: Option<usize>, message: &str) -> String {
    match (file, line) {
        (Some(f), Some(l)) => format!("{f}:{l}: {message}"),
        (Some(f), None) => format!("{f}: {message}"),
        _ => message.to_string(),
    }
}

impl PoundingError {
    /// The pair refused at `key`.
    pub(super) fn pair(key: &'static str, message: String) -> Self {
        PoundingError::Pair {
            file: None,
            line: None,
            key: Some(key),
            message,
        }
    }

    /// A run under `record` failed.
    pub(super) fn run(record: &Record, message: impl ToString) -> Self {
        PoundingError::Run {
            record: record.source.clone(),
            message: message.to_string(),
        }
    }

    /// The error with the pair file it came from.
    pub(super) fn in_file(self, source: &str) -> Self {
        match self {
            PoundingError::Pair {
                line, key, message, ..
            } => PoundingError::Pair {
                file: Some(source.to_string()),
                line,
                key,
                message,
            },
            other => other,
        }
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    masses: Vec<f64>,
    stiffnesses: Vec<f64>,
    damping_ratio: f64,
    #[serde(default)]
    storeys: Vec<StoreySpec>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct PairSpec {
    left: FrameSpec,
    right: FrameSpec,
    gap: f64,
    floors: Vec<usize>,
    law: crate::model_file::LawSpec,
}

/// A pair from TOML text: `[left]` and `[right]` (`masses`, `stiffnesses`,
/// `damping_ratio`), `gap`, `floors` and `law` (a contact law as in model
/// files); messages name `source` and the line.
pub fn parse_pair(text: &str, source: &str) -> Result<PoundingPair, PoundingError> {
    let spec: PairSpec = toml::from_str(text).map_err(|e| PoundingError::Pair {
        file: Some(source.to_string()),
        line: e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1),
        key: None,
        message: e.message().trim().to_string(),
    })?;
    let frame = |f: FrameSpec| ShearFrame {
        masses: f.masses,
        stiffnesses: f.stiffnesses,
        damping_ratio: f.damping_ratio,
        storeys: f.storeys,
    };
    let pair = PoundingPair {
        left: frame(spec.left),
        right: frame(spec.right),
        gap: spec.gap,
        floors: spec.floors,
        law: spec
            .law
            .build()
            .map_err(|e| PoundingError::pair("law", format!("law: {e}")).in_file(source))?,
    };
    pair.check().map_err(|e| e.in_file(source))?;
    Ok(pair)
}
