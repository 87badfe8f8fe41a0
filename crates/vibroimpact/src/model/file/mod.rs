//! Model files: the TOML schema of `docs/model.md` and its translation into
//! a [`Model`]. The text comes from the caller (the library reads no
//! files); an accelerogram named by file is handed in by a loader the caller
//! supplies. Every error names the source, the line and the key.
//!
//! Files: `mod.rs` (the schema and reading), `build.rs` (the tables of a
//! parsed file made a [`Model`]), `tests.rs` (the schema's checks).
//!
//! A [`ModelDocument`] is the parsed file. It builds the [`Model`]
//! ([`ModelDocument::build`]), sets a numeric key to a new value without
//! re-reading any text (see [`crate::model::parameter`]) and writes itself back as
//! TOML with any record inlined ([`ModelDocument::to_toml`]), so that a
//! model travels between processes without its files.

use serde::{Deserialize, Serialize};
use toml::Spanned;

use crate::contact::{ContactLaw, ForceForm};
use crate::model::record::{Record, RecordMetadata};
use crate::model::{
    Accelerogram, BaseExcitation, Body, Contact, ContactPair, Coupling, HarmonicForce, Model,
};

/// A model-file error: one line naming the source, the line and the key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ModelFileError(pub String);

/// A contact law as written in a model file (`law = "..."` selects it).
#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum LawSpec {
    /// `F = (a + b ṡ) exp(α s)`.
    Exponential {
        /// a/b (m/s); or give `b`.
        a_over_b: Option<f64>,
        /// b (N s/m).
        b: Option<f64>,
        /// α (1/m).
        alpha: f64,
        /// a (N), default 1.
        a: Option<f64>,
        /// Force form.
        form: Option<ForceForm>,
    },
    /// `k s^n`.
    Hertz {
        /// k.
        stiffness: f64,
        /// n, default 1.5.
        exponent: Option<f64>,
    },
    /// `k s + c ṡ`.
    KelvinVoigt {
        /// k.
        stiffness: f64,
        /// c.
        damping: f64,
        /// Force form.
        form: Option<ForceForm>,
    },
    /// `k s^n (1 + χ ṡ)`.
    HuntCrossley {
        /// k.
        stiffness: f64,
        /// n, default 1.5.
        exponent: Option<f64>,
        /// χ (s/m).
        chi: f64,
        /// Force form.
        form: Option<ForceForm>,
    },
    /// `k s^n (1 + 3(1-e²)/4 ṡ/v₀)`.
    LankaraniNikravesh {
        /// k.
        stiffness: f64,
        /// n, default 1.5.
        exponent: Option<f64>,
        /// e.
        restitution: f64,
        /// Floor of v₀ (m/s), default 1e-3.
        min_impact_velocity: Option<f64>,
        /// Force form.
        form: Option<ForceForm>,
    },
}

impl LawSpec {
    /// Builds the law.
    pub fn build(&self) -> Result<ContactLaw, String> {
        let r = match *self {
            LawSpec::Exponential {
                a_over_b,
                b,
                alpha,
                a,
                form,
            } => {
                let a = a.unwrap_or(1.0);
                let form = form.unwrap_or_default();
                match (a_over_b, b) {
                    (Some(q), None) => ContactLaw::exponential_from_ratio(q, alpha, a, form),
                    (None, Some(b)) => ContactLaw::exponential(a, b, alpha, form),
                    _ => {
                        return Err("exponential law: give exactly one of `a_over_b` and `b`".into())
                    }
                }
            }
            LawSpec::Hertz {
                stiffness,
                exponent,
            } => ContactLaw::hertz(stiffness, exponent.unwrap_or(1.5)),
            LawSpec::KelvinVoigt {
                stiffness,
                damping,
                form,
            } => ContactLaw::kelvin_voigt(stiffness, damping, form.unwrap_or_default()),
            LawSpec::HuntCrossley {
                stiffness,
                exponent,
                chi,
                form,
            } => ContactLaw::hunt_crossley(
                stiffness,
                exponent.unwrap_or(1.5),
                chi,
                form.unwrap_or_default(),
            ),
            LawSpec::LankaraniNikravesh {
                stiffness,
                exponent,
                restitution,
                min_impact_velocity,
                form,
            } => ContactLaw::lankarani_nikravesh(
                stiffness,
                exponent.unwrap_or(1.5),
                restitution,
                min_impact_velocity.unwrap_or(1e-3),
                form.unwrap_or_default(),
            ),
        };
        r.map_err(|e| e.to_string())
    }
}

/// Spring and damper to the frame: `stiffness`/`natural_frequency`,
/// `damping`/`damping_ratio`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Support {
    pub(crate) stiffness: Option<f64>,
    pub(crate) natural_frequency: Option<f64>,
    pub(crate) damping: Option<f64>,
    pub(crate) damping_ratio: Option<f64>,
}

impl Support {
    fn resolve(&self, mass: f64) -> Result<(f64, f64), String> {
        let k = match (self.stiffness, self.natural_frequency) {
            (Some(_), Some(_)) => {
                return Err("give `stiffness` or `natural_frequency`, not both".into())
            }
            (Some(k), None) => k,
            (None, Some(w)) => {
                if !(w >= 0.0 && w.is_finite()) {
                    return Err(format!("natural_frequency = {w}: must be finite and >= 0"));
                }
                let k = mass * w * w;
                if !k.is_finite() {
                    return Err(format!(
                        "mass = {mass:e} with natural_frequency = {w}: the stiffness m ω² overflows double precision; give a mass below {:.2e} kg",
                        f64::MAX / (w * w)
                    ));
                }
                k
            }
            (None, None) => 0.0,
        };
        let c = match (self.damping, self.damping_ratio) {
            (Some(_), Some(_)) => return Err("give `damping` or `damping_ratio`, not both".into()),
            (Some(c), None) => c,
            (None, Some(z)) => {
                if !(z >= 0.0 && z.is_finite()) {
                    return Err(format!("damping_ratio = {z}: must be finite and >= 0"));
                }
                if k == 0.0 && z > 0.0 {
                    return Err("damping_ratio needs a stiffness (or natural_frequency) > 0".into());
                }
                // √k √m where k m overflows (the damping itself may not).
                let c = match (k * mass).sqrt() {
                    c if c.is_finite() => 2.0 * z * c,
                    _ => 2.0 * z * k.sqrt() * mass.sqrt(),
                };
                if !c.is_finite() {
                    return Err(format!(
                        "mass = {mass:e}, damping_ratio = {z}: the damping 2ζ√(km) overflows double precision; give a smaller mass or damping ratio"
                    ));
                }
                c
            }
            (None, None) => 0.0,
        };
        Ok((k, c))
    }
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct RowSpec {
    pub(crate) count: usize,
    pub(crate) mass: f64,
    pub(crate) stiffness: Option<f64>,
    pub(crate) natural_frequency: Option<f64>,
    pub(crate) damping: Option<f64>,
    pub(crate) damping_ratio: Option<f64>,
    pub(crate) clearance: f64,
    pub(crate) contact: LawSpec,
    /// "both" (default), "left", "right" or "none".
    pub(crate) walls: Option<String>,
    /// Spring–damper between neighbours.
    pub(crate) coupling: Option<CouplingSpec>,
    /// "soft" (default) or "rigid", for every contact of the row.
    pub(crate) impacts: Option<String>,
    /// A rigid impact's Newton coefficient in place of the law's e(U).
    pub(crate) restitution: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct CouplingSpec {
    pub(crate) stiffness: Option<f64>,
    pub(crate) damping: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct BodySpec {
    pub(crate) name: String,
    pub(crate) mass: f64,
    pub(crate) stiffness: Option<f64>,
    pub(crate) natural_frequency: Option<f64>,
    pub(crate) damping: Option<f64>,
    pub(crate) damping_ratio: Option<f64>,
    pub(crate) initial_displacement: Option<f64>,
    pub(crate) initial_velocity: Option<f64>,
}

/// `between = ["left", "right"]`: exactly two names (a list of three is
/// an error, not silently cut to two).
fn two_names<'de, D: serde::Deserializer<'de>>(d: D) -> Result<[String; 2], D::Error> {
    let names = Vec::<String>::deserialize(d)?;
    <[String; 2]>::try_from(names).map_err(|names| {
        serde::de::Error::custom(format!(
            "`between` needs exactly two names (a body or \"wall\" each), got {}: {names:?}",
            names.len()
        ))
    })
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct SpringSpec {
    #[serde(deserialize_with = "two_names")]
    pub(crate) between: [String; 2],
    pub(crate) stiffness: Option<f64>,
    pub(crate) damping: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct ContactSpec {
    #[serde(deserialize_with = "two_names")]
    pub(crate) between: [String; 2],
    pub(crate) clearance: f64,
    pub(crate) law: LawSpec,
    /// "soft" (default) or "rigid".
    pub(crate) impacts: Option<String>,
    /// A rigid impact's Newton coefficient in place of the law's e(U).
    pub(crate) restitution: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub(crate) enum ExcitationSpec {
    None,
    HarmonicBase {
        amplitude: f64,
        frequency: f64,
        phase: Option<f64>,
    },
    Accelerogram {
        file: Option<String>,
        /// Units of the file's accelerations (g, m/s2, gal); its header's
        /// for an AT2 file; m/s² for a CSV file without.
        units: Option<String>,
        time: Option<Vec<f64>>,
        acceleration: Option<Vec<f64>>,
        scale: Option<f64>,
    },
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct ForceSpec {
    pub(crate) body: String,
    pub(crate) amplitude: f64,
    pub(crate) frequency: f64,
    pub(crate) phase: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct InitialSpec {
    pub(crate) displacement: Option<InitialValues>,
    pub(crate) velocity: Option<InitialValues>,
}

/// `[initial]` values: one per body in order, or by body name (the others
/// at 0), e.g. `velocity = { p1 = 1.0 }` for a struck row.
#[derive(Serialize, Debug, Clone)]
#[serde(untagged)]
pub(crate) enum InitialValues {
    /// One value per body.
    List(Vec<f64>),
    /// Values of named bodies.
    Named(std::collections::BTreeMap<String, f64>),
}

/// An array or a table, read directly (an untagged enum would buffer the
/// table, which the TOML reader refuses for a `[initial.velocity]` header).
impl<'de> Deserialize<'de> for InitialValues {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Values;
        impl<'de> serde::de::Visitor<'de> for Values {
            type Value = InitialValues;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "an array of numbers (one per body) or a table of body names and numbers",
                )
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> Result<Self::Value, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<f64>()? {
                    v.push(x);
                }
                Ok(InitialValues::List(v))
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(
                self,
                mut map: A,
            ) -> Result<Self::Value, A::Error> {
                let mut m = std::collections::BTreeMap::new();
                while let Some((k, x)) = map.next_entry::<String, f64>()? {
                    m.insert(k, x);
                }
                Ok(InitialValues::Named(m))
            }
        }
        d.deserialize_any(Values)
    }
}

impl InitialValues {
    /// The values in body order; `names` are the bodies' names. Errors name
    /// an unknown body.
    fn resolve(&self, names: &[&str], what: &str) -> Result<Vec<f64>, String> {
        match self {
            InitialValues::List(v) => Ok(v.clone()),
            InitialValues::Named(map) => {
                let mut v = vec![0.0; names.len()];
                for (name, value) in map {
                    let i = names
                        .iter()
                        .position(|n| n == name)
                        .ok_or_else(|| format!("[initial] {what}: no body named {name:?}"))?;
                    v[i] = *value;
                }
                Ok(v)
            }
        }
    }
}

/// Optional simulation settings stored with the model.
#[derive(Serialize, Deserialize, Debug, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Impact force threshold F_on (N).
    pub impact_force_threshold: Option<f64>,
    /// The size of the motion (m) that periodic orbits and continuation
    /// measure the state in: the shooting's scaled norm and absolute
    /// tolerance, the continuation's arclength (default 1e-3: millimetre
    /// motion, the seed's rows).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displacement_scale: Option<f64>,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
#[serde(deny_unknown_fields)]
pub(crate) struct ModelFile {
    /// Gravity along the row (m/s², toward −u), a top-level key.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) gravity: Option<Spanned<f64>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) row: Option<Spanned<RowSpec>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) body: Vec<Spanned<BodySpec>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) spring: Vec<Spanned<SpringSpec>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) contact: Vec<Spanned<ContactSpec>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) excitation: Option<Spanned<ExcitationSpec>>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) force: Vec<Spanned<ForceSpec>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) initial: Option<Spanned<InitialSpec>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub(crate) simulation: Option<SimulationSpec>,
}

/// A model built from a document, with the document's simulation settings.
#[derive(Clone, Debug)]
pub struct LoadedModel {
    /// The model.
    pub model: Model,
    /// `[simulation]` settings.
    pub simulation: SimulationSpec,
    /// The accelerogram's record and scale, if the excitation is one.
    pub record: Option<RecordMetadata>,
}

/// The caller's loader of accelerogram files: `(file, units)` to samples
/// in m/s².
pub type RecordLoader<'a> = dyn FnMut(&str, Option<&str>) -> Result<Record, ModelFileError> + 'a;

/// A parsed model file.
#[derive(Clone, Debug)]
pub struct ModelDocument {
    pub(crate) file: ModelFile,
    /// Byte offset of the start of every line of the text (for line numbers).
    line_starts: Vec<usize>,
    source: String,
    record: Option<Record>,
}

/// Errors located in the document: `label:line: message`.
struct Ctx<'a> {
    label: &'a str,
    line_starts: &'a [usize],
}

impl Ctx<'_> {
    fn err_at(&self, span: std::ops::Range<usize>, msg: impl std::fmt::Display) -> ModelFileError {
        let line = self.line_starts.partition_point(|&s| s <= span.start);
        ModelFileError(format!("{}:{line}: {msg}", self.label))
    }

    fn plain(&self, msg: impl std::fmt::Display) -> ModelFileError {
        ModelFileError(format!("{}: {msg}", self.label))
    }
}

impl ModelDocument {
    /// Parses model text. `source` names it in messages; `load_record` is
    /// called with the `file` and `units` of an `accelerogram` excitation and
    /// returns its samples in m/s² (e.g. [`load_accelerogram`] of the
    /// file's text).
    pub fn parse(
        text: &str,
        source: &str,
        load_record: &mut RecordLoader<'_>,
    ) -> Result<Self, ModelFileError> {
        let line_starts: Vec<usize> = std::iter::once(0)
            .chain(text.match_indices('\n').map(|(i, _)| i + 1))
            .collect();
        let cx = Ctx {
            label: source,
            line_starts: &line_starts,
        };
        // A control character says plainly what is wrong (TOML's own parser
        // only reports what it expected instead).
        if let Some((at, c)) = text
            .char_indices()
            .find(|&(_, c)| c.is_control() && !matches!(c, '\t' | '\n' | '\r'))
        {
            return Err(cx.err_at(
                at..at + c.len_utf8(),
                format!(
                    "control character U+{:04X}: a model file is text (TOML allows no control characters but tab)",
                    u32::from(c)
                ),
            ));
        }
        let file: ModelFile = toml::from_str(text).map_err(|e| {
            let msg = e.message().trim().replace('\n', " ");
            match e.span() {
                // The line as written names the key (the TOML text of a
                // Python dict has no lines of the user's own).
                Some(span) => {
                    let start = text[..span.start.min(text.len())]
                        .rfind('\n')
                        .map_or(0, |i| i + 1);
                    let line = text[start..].lines().next().unwrap_or("").trim();
                    // The table the line sits in: the nearest header above.
                    let table = text[..start]
                        .lines()
                        .rev()
                        .map(str::trim)
                        .find(|l| l.starts_with('['))
                        .map(header_name);
                    match line.split_once('=') {
                        Some((key, _)) if !key.trim().is_empty() && !key.contains('[') => {
                            let key = match table {
                                Some(t) => format!("{t}.{}", key.trim()),
                                None => key.trim().to_string(),
                            };
                            cx.err_at(span, format!("key `{key}`: {msg}"))
                        }
                        _ => cx.err_at(span, msg),
                    }
                }
                None => cx.plain(msg),
            }
        })?;
        let record = match file.excitation.as_ref().map(|e| (e.span(), e.get_ref())) {
            Some((
                span,
                ExcitationSpec::Accelerogram {
                    file: f,
                    units,
                    time,
                    acceleration,
                    ..
                },
            )) => Some(match (f, time, acceleration) {
                (Some(f), None, None) => load_record(f, units.as_deref())?,
                (None, Some(_), Some(_)) if units.is_some() => {
                    return Err(cx.err_at(
                        span,
                        "[excitation] accelerogram: `units` is for a `file`; inline `acceleration` is in m/s²",
                    ))
                }
                (None, Some(t), Some(a)) if t.len() != a.len() => {
                    return Err(cx.err_at(
                        span,
                        format!(
                            "[excitation] accelerogram: `time` has {} values, `acceleration` {}",
                            t.len(),
                            a.len()
                        ),
                    ))
                }
                (None, Some(t), Some(a)) => {
                    Record::from_samples(&format!("{source} [excitation]"), t.clone(), a)
                        .map_err(|m| cx.err_at(span, format!("[excitation] accelerogram: {m}")))?
                }
                _ => return Err(cx.err_at(
                    span,
                    "[excitation] accelerogram: give `file`, or `time` and `acceleration` arrays",
                )),
            }),
            _ => None,
        };
        let doc = Self {
            file,
            line_starts,
            source: source.to_string(),
            record,
        };
        doc.build()?;
        Ok(doc)
    }

    /// Reads the model file `path` and any accelerogram file it names
    /// (relative to its folder) through `read`, the caller's file reader
    /// (e.g. `std::fs::read_to_string`): the library itself reads nothing.
    pub fn read(
        path: &std::path::Path,
        read: &dyn Fn(&std::path::Path) -> std::io::Result<String>,
    ) -> Result<Self, ModelFileError> {
        let text = read(path)
            .map_err(|e| ModelFileError(format!("{}: cannot read: {e}", path.display())))?;
        let dir = path.parent().unwrap_or_else(|| std::path::Path::new("."));
        let mut load = |file: &str, units: Option<&str>| -> Result<Record, ModelFileError> {
            let record = dir.join(file);
            let source = record.display().to_string();
            let text = read(&record).map_err(|e| {
                ModelFileError(format!("{source}: cannot read the accelerogram: {e}"))
            })?;
            load_accelerogram(&text, &source, units)
        };
        Self::parse(&text, &path.display().to_string(), &mut load)
    }

    /// Parses model text that refers to no accelerogram file.
    pub fn from_toml(text: &str, source: &str) -> Result<Self, ModelFileError> {
        Self::parse(text, source, &mut |f, _| {
            Err(ModelFileError(format!(
                "{source}: accelerogram file `{f}`: no files can be read here; give the samples inline (`time` and `acceleration` arrays)"
            )))
        })
    }

    /// The source named in messages.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Its `[simulation]` settings (as written; checked when built).
    pub fn simulation(&self) -> SimulationSpec {
        self.file.simulation.clone().unwrap_or_default()
    }

    /// Builds the model.
    pub fn build(&self) -> Result<LoadedModel, ModelFileError> {
        self.build_labelled(&self.source)
    }

    /// The document as TOML text, any accelerogram inlined as `time` and
    /// `acceleration` arrays: [`ModelDocument::from_toml`] of it gives the
    /// same model.
    pub fn to_toml(&self) -> String {
        let mut file = self.file.clone();
        if let (Some(e), Some(r)) = (file.excitation.as_mut(), &self.record) {
            if let ExcitationSpec::Accelerogram {
                file: f,
                units,
                time,
                acceleration,
                ..
            } = e.get_mut()
            {
                *f = None;
                *units = None;
                *time = Some(r.times.clone());
                *acceleration = Some(r.acceleration.clone());
            }
        }
        // Initial values by body name are written one per body (TOML would
        // write them under an `[initial.velocity]` header, which its reader
        // refuses inside `[initial]`).
        if let Some(init) = file.initial.as_mut() {
            let spec = init.get_mut();
            let named = |v: &Option<InitialValues>| matches!(v, Some(InitialValues::Named(_)));
            if named(&spec.displacement) || named(&spec.velocity) {
                if let Ok(loaded) = self.build() {
                    let m = &loaded.model;
                    spec.displacement =
                        Some(InitialValues::List(m.initial_displacement().to_vec()));
                    spec.velocity = Some(InitialValues::List(m.initial_velocity().to_vec()));
                }
            }
        }
        // Serialising plain data (numbers, strings, arrays, tables) cannot fail.
        toml::to_string(&file).unwrap_or_default()
    }
}

/// The largest input file (model, record, measurements) the CLI and the
/// Python package read (1 GiB): larger ones are refused before reading
/// rather than exhausting memory. (The library itself reads no files.)
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// The record (m/s²) of an accelerogram file's text: a record in any form
/// of [`crate::model::record`] (AT2, two columns) when it is an AT2 file or
/// `units` are given, else a two-column CSV in m/s²
/// ([`parse_accelerogram_csv`]).
pub fn load_accelerogram(
    text: &str,
    source: &str,
    units: Option<&str>,
) -> Result<Record, ModelFileError> {
    let units = units
        .map(crate::model::record::Units::parse)
        .transpose()
        .map_err(|e| ModelFileError(format!("{source}: [excitation] {e}")))?;
    if units.is_some() || crate::model::record::is_at2(text, source) {
        crate::model::record::parse_record(text, source, units)
            .map_err(|e| ModelFileError(e.to_string()))
    } else {
        parse_accelerogram_csv(text, source)
    }
}

/// Parses a two-column accelerogram CSV (time s, acceleration m/s²); a
/// header row and `#` comment lines are allowed. `source` names the text in
/// messages, which give its line.
pub fn parse_accelerogram_csv(text: &str, source: &str) -> Result<Record, ModelFileError> {
    let err = |msg: String| Err(ModelFileError(msg));
    let mut times = Vec::new();
    let mut values = Vec::new();
    let mut header_seen = false;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = l.split(',').map(str::trim).collect();
        let parsed: Option<(f64, f64)> = match cells.as_slice() {
            [t, a] => t.parse().ok().zip(a.parse().ok()),
            _ => {
                return err(format!(
                    "{source}:{line_no}: expected two columns (time, acceleration), found {}",
                    cells.len()
                ))
            }
        };
        match parsed {
            Some((t, a)) if t.is_finite() && a.is_finite() => {
                if let Some(&last) = times.last() {
                    if t <= last {
                        return err(format!("{source}:{line_no}: time {t} is not after the previous {last} (times must increase)"));
                    }
                }
                times.push(t);
                values.push(a);
            }
            Some(_) => return err(format!("{source}:{line_no}: values must be finite")),
            None if !header_seen && times.is_empty() => header_seen = true,
            None => return err(format!("{source}:{line_no}: `{l}` is not two numbers")),
        }
    }
    Record::from_samples(source, times, &values).map_err(|e| ModelFileError(e.to_string()))
}

mod build;

/// The table a header line names: `[row]  # comment` is `row`,
/// `[[body]]` is `body` (what follows the closing bracket is not the
/// name: every shipped example comments its headers).
fn header_name(line: &str) -> &str {
    let inner = line.trim_start_matches('[');
    inner.split(']').next().unwrap_or(inner).trim()
}

#[cfg(test)]
mod tests;
