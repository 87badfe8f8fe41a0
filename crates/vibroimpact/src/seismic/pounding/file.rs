//! The pounding row file, or the pair file (docs/earthquakes.md) and the errors of a
//! pounding study: the file's line and key, a setting's field, a run's
//! record.

use super::{Bearing, Building, Gravity, Isolation, Joint, Moat, Row, ShearFrame, Wall};
use crate::contact::ContactLaw;
use crate::field_error::FieldError;
use crate::model::file::LawSpec;
use crate::model::hysteresis::StoreySpec;
use crate::model::record::Record;
use crate::model::Impacts;

/// Why a pounding study cannot run or did not finish.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PoundingError {
    /// The pair refused: the pair file where it came from one, the line
    /// where known, the key at fault where known (`left`, `right`,
    /// `building`, `name`, `joint`, `gap`, `floors`, `law`), and what is
    /// wrong.
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
    /// A run under a record did not integrate to its end (a step that
    /// failed, the step limit): the record, its scale and why. A collapse
    /// study counts it as a collapse.
    #[error("{record} x {scale}: {message}")]
    Diverged {
        /// The record's source.
        record: String,
        /// Its scale.
        scale: f64,
        /// Why.
        message: String,
    },
    /// The study was asked to stop (Ctrl-C): no result.
    #[error("interrupted: the study stopped before its end, no result")]
    Interrupted,
    /// A run under a record could not start or failed: the record and why.
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
    /// The row refused at `key`.
    pub(crate) fn pair(key: &'static str, message: String) -> Self {
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
struct MoatSpec {
    gap: f64,
    law: LawSpec,
    wall: Option<Wall>,
    impacts: Option<String>,
    restitution: Option<f64>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct IsolationSpec {
    mass: f64,
    bearing: Bearing,
    #[serde(default)]
    damping: f64,
    capacity: Option<f64>,
    moat: Option<MoatSpec>,
}

/// A building's table: its frame (and isolation); in a row file also its
/// name and, from the second on, the joint to the building on its left.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BuildingSpec {
    name: Option<String>,
    masses: Vec<f64>,
    stiffnesses: Vec<f64>,
    damping_ratio: f64,
    #[serde(default)]
    storeys: Vec<StoreySpec>,
    #[serde(default)]
    heights: Vec<f64>,
    #[serde(default)]
    p_delta: bool,
    #[serde(default)]
    leaning_loads: Vec<f64>,
    isolation: Option<IsolationSpec>,
    gap: Option<f64>,
    floors: Option<Vec<usize>>,
    law: Option<LawSpec>,
}

impl BuildingSpec {
    /// Whether it gives a joint's key (`gap`, `floors`, `law`).
    fn has_joint(&self) -> bool {
        self.gap.is_some() || self.floors.is_some() || self.law.is_some()
    }
}

/// A pair file (`[left]`, `[right]`, one joint) or a row file
/// (`[[building]]` entries, `law` the joints' law unless a building gives
/// its own).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RowSpec {
    left: Option<BuildingSpec>,
    right: Option<BuildingSpec>,
    gap: Option<f64>,
    floors: Option<Vec<usize>>,
    law: Option<LawSpec>,
    #[serde(default)]
    building: Vec<BuildingSpec>,
}

/// A contact law, the error naming `key`.
fn law(spec: &LawSpec, key: &'static str, what: &str) -> Result<ContactLaw, PoundingError> {
    spec.build()
        .map_err(|e| PoundingError::pair(key, format!("{what}{key}: {e}")))
}

/// The building `name` of a building's table; `what` names it in errors.
fn building(name: String, f: BuildingSpec, what: &str) -> Result<Building, PoundingError> {
    let isolation = f
        .isolation
        .map(|i| {
            let moat = i
                .moat
                .map(|m| {
                    let impacts = match (&m.impacts, m.restitution) {
                        (None, None) => Ok(Impacts::Soft),
                        (name, e) => Impacts::parse(name.as_deref().unwrap_or("soft"), e),
                    }
                    .map_err(|e| {
                        PoundingError::pair("impacts", format!("{what}: isolation: moat.{e}"))
                    })?;
                    Ok::<_, PoundingError>(Moat {
                        gap: m.gap,
                        law: law(&m.law, "law", &format!("{what}: isolation: moat."))?,
                        wall: m.wall,
                        impacts,
                    })
                })
                .transpose()?;
            Ok::<_, PoundingError>(Isolation {
                mass: i.mass,
                bearing: i.bearing,
                damping: i.damping,
                capacity: i.capacity,
                moat,
            })
        })
        .transpose()?;
    Ok(Building {
        name,
        frame: ShearFrame {
            masses: f.masses,
            stiffnesses: f.stiffnesses,
            damping_ratio: f.damping_ratio,
            storeys: f.storeys,
            heights: f.heights,
            gravity: Gravity {
                p_delta: f.p_delta,
                leaning_loads: f.leaning_loads,
            },
        },
        isolation,
    })
}

/// A row from the TOML text of a pair file (`[left]` and `[right]`
/// frames, `gap`, `floors`, `law`) or a row file (`[[building]]` entries
/// with `name`, the frame's keys, an optional `isolation` table, and from
/// the second on `gap` and `floors` to the building on the left; `law` at
/// the top or per building). Messages name `source`, the line where TOML
/// knows it, and the building and key.
pub fn parse_row(text: &str, source: &str) -> Result<Row, PoundingError> {
    let spec: RowSpec = toml::from_str(text).map_err(|e| PoundingError::Pair {
        file: Some(source.to_string()),
        line: e
            .span()
            .map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1),
        key: None,
        message: e.message().trim().to_string(),
    })?;
    let row = row_of(spec).map_err(|e| e.in_file(source))?;
    row.check().map_err(|e| e.in_file(source))?;
    Ok(row)
}

/// The row a file spec describes, in either form.
fn row_of(spec: RowSpec) -> Result<Row, PoundingError> {
    let missing = |key: &'static str, message: &str| Err(PoundingError::pair(key, message.into()));
    if spec.building.is_empty() {
        let (Some(left), Some(right)) = (spec.left, spec.right) else {
            return missing(
                "building",
                "give [left] and [right] frames, or [[building]] entries",
            );
        };
        let (Some(gap), Some(floors), Some(l)) = (spec.gap, spec.floors, spec.law) else {
            return missing("gap", "a pair needs gap, floors and law");
        };
        if let Some((side, _)) = [("left", &left), ("right", &right)]
            .into_iter()
            .find(|(_, f)| f.name.is_some() || f.has_joint())
        {
            return missing(
                "building",
                &format!("{side} frame: name, gap, floors and law belong to [[building]] entries; a pair file gives gap, floors and law at the top"),
            );
        }
        return Ok(Row {
            buildings: vec![
                building("left".into(), left, "left frame")?,
                building("right".into(), right, "right frame")?,
            ],
            joints: vec![Joint {
                gap,
                floors,
                law: law(&l, "law", "")?,
            }],
        });
    }
    if spec.left.is_some() || spec.right.is_some() || spec.gap.is_some() || spec.floors.is_some() {
        return missing(
            "building",
            "[[building]] entries: give each joint's gap and floors in the building to its right, not [left]/[right], gap or floors at the top",
        );
    }
    let mut buildings = Vec::new();
    let mut joints = Vec::new();
    for (k, b) in spec.building.into_iter().enumerate() {
        let name = b.name.clone().unwrap_or_else(|| format!("B{}", k + 1));
        if name.trim().is_empty() {
            return missing(
                "name",
                &format!(
                    "building {}: the name is empty (results are keyed by it)",
                    k + 1
                ),
            );
        }
        let what = format!("building {name}");
        if k == 0 {
            if b.has_joint() {
                return missing(
                    "building",
                    &format!("{what}: the first building has no joint to its left: give gap, floors and law from the second on"),
                );
            }
        } else {
            let (Some(gap), Some(floors)) = (b.gap, b.floors.clone()) else {
                return missing(
                    "gap",
                    &format!("{what}: give gap and floors (the joint to the building on its left)"),
                );
            };
            let Some(l) = b.law.as_ref().or(spec.law.as_ref()) else {
                return missing(
                    "law",
                    &format!("{what}: give law (or a law at the top for every joint)"),
                );
            };
            joints.push(Joint {
                gap,
                floors,
                law: law(l, "law", &format!("{what}: "))?,
            });
        }
        buildings.push(building(name, b, &what)?);
    }
    Ok(Row { buildings, joints })
}
