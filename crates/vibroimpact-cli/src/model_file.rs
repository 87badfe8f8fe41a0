//! Model files (TOML) → [`Model`]. The format is documented in
//! `docs/model.md`; every error names the file, the line and the key.

use std::path::{Path, PathBuf};

use serde::Deserialize;
use toml::Spanned;
use vibroimpact::contact::{ContactLaw, ForceForm};
use vibroimpact::model::{
    Accelerogram, BaseExcitation, Body, Contact, ContactPair, Coupling, HarmonicForce, Model,
};

use crate::error::CliError;

/// A contact law as written in a model file (`law = "..."` selects it).
#[derive(Deserialize, Debug, Clone)]
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
struct Support {
    stiffness: Option<f64>,
    natural_frequency: Option<f64>,
    damping: Option<f64>,
    damping_ratio: Option<f64>,
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
                mass * w * w
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
                2.0 * z * (k * mass).sqrt()
            }
            (None, None) => 0.0,
        };
        Ok((k, c))
    }
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct RowSpec {
    count: usize,
    mass: f64,
    stiffness: Option<f64>,
    natural_frequency: Option<f64>,
    damping: Option<f64>,
    damping_ratio: Option<f64>,
    clearance: f64,
    contact: LawSpec,
    /// "both" (default), "left", "right" or "none".
    walls: Option<String>,
    /// Spring–damper between neighbours.
    coupling: Option<CouplingSpec>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct CouplingSpec {
    stiffness: Option<f64>,
    damping: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct BodySpec {
    name: String,
    mass: f64,
    stiffness: Option<f64>,
    natural_frequency: Option<f64>,
    damping: Option<f64>,
    damping_ratio: Option<f64>,
    initial_displacement: Option<f64>,
    initial_velocity: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct SpringSpec {
    between: [String; 2],
    stiffness: Option<f64>,
    damping: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ContactSpec {
    between: [String; 2],
    clearance: f64,
    law: LawSpec,
}

#[derive(Deserialize, Debug)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
enum ExcitationSpec {
    None,
    HarmonicBase {
        amplitude: f64,
        frequency: f64,
        phase: Option<f64>,
    },
    Accelerogram {
        file: String,
        scale: Option<f64>,
    },
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ForceSpec {
    body: String,
    amplitude: f64,
    frequency: f64,
    phase: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct InitialSpec {
    displacement: Option<Vec<f64>>,
    velocity: Option<Vec<f64>>,
}

/// Optional simulation settings stored with the model.
#[derive(Deserialize, Debug, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Relative tolerance.
    pub rtol: Option<f64>,
    /// Absolute tolerance.
    pub atol: Option<f64>,
    /// Impact force threshold F_on (N).
    pub impact_force_threshold: Option<f64>,
}

#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
struct ModelFile {
    row: Option<Spanned<RowSpec>>,
    #[serde(default)]
    body: Vec<Spanned<BodySpec>>,
    #[serde(default)]
    spring: Vec<Spanned<SpringSpec>>,
    #[serde(default)]
    contact: Vec<Spanned<ContactSpec>>,
    excitation: Option<Spanned<ExcitationSpec>>,
    #[serde(default)]
    force: Vec<Spanned<ForceSpec>>,
    initial: Option<Spanned<InitialSpec>>,
    simulation: Option<SimulationSpec>,
}

/// A model read from a file, with the file's simulation settings.
pub struct LoadedModel {
    /// The model.
    pub model: Model,
    /// `[simulation]` settings.
    pub simulation: SimulationSpec,
}

fn line_of(text: &str, byte: usize) -> usize {
    1 + text.as_bytes()[..byte.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

struct Ctx<'a> {
    source: String,
    text: &'a str,
}

impl Ctx<'_> {
    fn err_at(&self, span: std::ops::Range<usize>, msg: impl std::fmt::Display) -> CliError {
        CliError::new(format!(
            "{}:{}: {msg}",
            self.source,
            line_of(self.text, span.start)
        ))
    }
}

/// Parses a model from TOML text. `source` names the file in messages;
/// `base_dir` resolves relative accelerogram paths.
pub fn parse_model(text: &str, source: &str, base_dir: &Path) -> Result<LoadedModel, CliError> {
    let cx = Ctx {
        source: source.to_string(),
        text,
    };
    let file: ModelFile = toml::from_str(text).map_err(|e| {
        let msg = e.message().trim().replace('\n', " ");
        match e.span() {
            Some(span) => cx.err_at(span, msg),
            None => CliError::new(format!("{source}: {msg}")),
        }
    })?;
    let physical = |v: f64, key: &str| -> Result<f64, String> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(format!("{key} = {v}: must be finite"))
        }
    };
    let mut bodies: Vec<Body> = Vec::new();
    let mut couplings = Vec::new();
    let mut contacts = Vec::new();
    let mut init_u = Vec::new();
    let mut init_v = Vec::new();
    match (&file.row, file.body.is_empty()) {
        (Some(_), false) => {
            let span = file.body[0].span();
            return Err(cx.err_at(span, "give either [row] or [[body]] tables, not both"));
        }
        (None, true) => {
            return Err(CliError::new(format!(
                "{source}: no bodies: add a [row] table or [[body]] tables"
            )))
        }
        (Some(row), true) => {
            let span = row.span();
            let r = row.get_ref();
            if r.count == 0 || r.count > 1_000_000 {
                return Err(cx.err_at(
                    span,
                    format!("[row] count = {}: must be from 1 to 1000000", r.count),
                ));
            }
            if !(r.mass > 0.0 && r.mass.is_finite()) {
                return Err(cx.err_at(
                    span,
                    format!("[row] mass = {}: must be finite and > 0", r.mass),
                ));
            }
            let support = Support {
                stiffness: r.stiffness,
                natural_frequency: r.natural_frequency,
                damping: r.damping,
                damping_ratio: r.damping_ratio,
            };
            let (k, c) = support
                .resolve(r.mass)
                .map_err(|m| cx.err_at(span.clone(), format!("[row] {m}")))?;
            let law = r
                .contact
                .build()
                .map_err(|m| cx.err_at(span.clone(), format!("[row] contact: {m}")))?;
            let walls = match r.walls.as_deref().unwrap_or("both") {
                "both" => (true, true),
                "left" => (true, false),
                "right" => (false, true),
                "none" => (false, false),
                w => {
                    return Err(cx.err_at(
                        span,
                        format!("[row] walls = \"{w}\": must be both, left, right or none"),
                    ))
                }
            };
            physical(r.clearance, "clearance")
                .map_err(|m| cx.err_at(span.clone(), format!("[row] {m}")))?;
            let row_model = Model::row(
                r.count,
                r.mass,
                k,
                c,
                r.clearance,
                law,
                walls,
                BaseExcitation::None,
            )
            .map_err(|e| cx.err_at(span.clone(), format!("[row] {e}")))?;
            bodies = row_model.bodies().to_vec();
            contacts = row_model.contacts().to_vec();
            if let Some(cp) = &r.coupling {
                for i in 0..r.count.saturating_sub(1) {
                    couplings.push(Coupling {
                        a: i,
                        b: i + 1,
                        stiffness: cp.stiffness.unwrap_or(0.0),
                        damping: cp.damping.unwrap_or(0.0),
                    });
                }
            }
        }
        (None, false) => {
            for (i, b) in file.body.iter().enumerate() {
                let span = b.span();
                let spec = b.get_ref();
                if bodies.iter().any(|x| x.name == spec.name) || spec.name == "wall" {
                    return Err(cx.err_at(
                        span,
                        format!(
                            "[[body]] #{}: name `{}` is used twice or reserved",
                            i + 1,
                            spec.name
                        ),
                    ));
                }
                if !(spec.mass > 0.0 && spec.mass.is_finite()) {
                    return Err(cx.err_at(
                        span,
                        format!(
                            "[[body]] {}: mass = {}: must be finite and > 0",
                            spec.name, spec.mass
                        ),
                    ));
                }
                let support = Support {
                    stiffness: spec.stiffness,
                    natural_frequency: spec.natural_frequency,
                    damping: spec.damping,
                    damping_ratio: spec.damping_ratio,
                };
                let (k, c) = support
                    .resolve(spec.mass)
                    .map_err(|m| cx.err_at(span.clone(), format!("[[body]] {}: {m}", spec.name)))?;
                bodies.push(Body {
                    name: spec.name.clone(),
                    mass: spec.mass,
                    stiffness: k,
                    damping: c,
                });
                init_u.push(spec.initial_displacement.unwrap_or(0.0));
                init_v.push(spec.initial_velocity.unwrap_or(0.0));
            }
        }
    }
    let find = |name: &str| bodies.iter().position(|b| b.name == name);
    let names = || {
        bodies
            .iter()
            .map(|b| b.name.as_str())
            .take(10)
            .collect::<Vec<_>>()
            .join(", ")
    };
    for s in &file.spring {
        let span = s.span();
        let spec = s.get_ref();
        let idx: Vec<usize> = spec
            .between
            .iter()
            .map(|n| {
                find(n).ok_or_else(|| {
                    cx.err_at(
                        span.clone(),
                        format!("[[spring]]: unknown body `{n}` (bodies: {})", names()),
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        couplings.push(Coupling {
            a: idx[0],
            b: idx[1],
            stiffness: spec.stiffness.unwrap_or(0.0),
            damping: spec.damping.unwrap_or(0.0),
        });
    }
    for c in &file.contact {
        let span = c.span();
        let spec = c.get_ref();
        let law = spec.law.build().map_err(|m| {
            cx.err_at(
                span.clone(),
                format!("[[contact]] {}|{}: {m}", spec.between[0], spec.between[1]),
            )
        })?;
        let side = |n: &str| -> Result<Option<usize>, CliError> {
            if n == "wall" {
                Ok(None)
            } else {
                find(n).map(Some).ok_or_else(|| {
                    cx.err_at(
                        span.clone(),
                        format!(
                            "[[contact]]: unknown body `{n}` (bodies: {}; or `wall`)",
                            names()
                        ),
                    )
                })
            }
        };
        let pair = match (side(&spec.between[0])?, side(&spec.between[1])?) {
            (None, None) => return Err(cx.err_at(span, "[[contact]]: between two walls")),
            (None, Some(r)) => ContactPair::LeftWall { body: r },
            (Some(l), None) => ContactPair::RightWall { body: l },
            (Some(l), Some(r)) => {
                if l >= r {
                    return Err(cx.err_at(
                        span,
                        format!("[[contact]] between = [\"{}\", \"{}\"]: give the left body first (bodies are in order along the line)", spec.between[0], spec.between[1]),
                    ));
                }
                ContactPair::Bodies { left: l, right: r }
            }
        };
        if !(spec.clearance >= 0.0 && spec.clearance.is_finite()) {
            return Err(cx.err_at(
                span,
                format!(
                    "[[contact]] {}|{}: clearance = {}: must be finite and >= 0",
                    spec.between[0], spec.between[1], spec.clearance
                ),
            ));
        }
        contacts.push(Contact {
            pair,
            clearance: spec.clearance,
            law,
        });
    }
    let base = match &file.excitation {
        None => BaseExcitation::None,
        Some(e) => {
            let span = e.span();
            match e.get_ref() {
                ExcitationSpec::None => BaseExcitation::None,
                ExcitationSpec::HarmonicBase {
                    amplitude,
                    frequency,
                    phase,
                } => {
                    if !(*frequency > 0.0 && frequency.is_finite()) {
                        return Err(cx.err_at(span, format!("[excitation] frequency = {frequency}: must be finite and > 0 (rad/s)")));
                    }
                    physical(*amplitude, "amplitude")
                        .map_err(|m| cx.err_at(span.clone(), format!("[excitation] {m}")))?;
                    BaseExcitation::Harmonic {
                        amplitude: *amplitude,
                        frequency: *frequency,
                        phase: phase.unwrap_or(0.0),
                    }
                }
                ExcitationSpec::Accelerogram { file: f, scale } => {
                    let path = base_dir.join(f);
                    BaseExcitation::Record(read_accelerogram(&path, scale.unwrap_or(1.0))?)
                }
            }
        }
    };
    let mut forces = Vec::new();
    for f in &file.force {
        let span = f.span();
        let spec = f.get_ref();
        let body = find(&spec.body).ok_or_else(|| {
            cx.err_at(
                span.clone(),
                format!("[[force]]: unknown body `{}`", spec.body),
            )
        })?;
        forces.push(HarmonicForce {
            body,
            amplitude: spec.amplitude,
            frequency: spec.frequency,
            phase: spec.phase.unwrap_or(0.0),
        });
    }
    if let Some(init) = &file.initial {
        let span = init.span();
        if !file.body.is_empty()
            && file.body.iter().any(|b| {
                b.get_ref().initial_displacement.is_some() || b.get_ref().initial_velocity.is_some()
            })
        {
            return Err(cx.err_at(
                span,
                "give the initial state either in [initial] or in the [[body]] tables, not both",
            ));
        }
        let spec = init.get_ref();
        init_u = spec.displacement.clone().unwrap_or_default();
        init_v = spec.velocity.clone().unwrap_or_default();
    }
    let model = Model::new(bodies, couplings, contacts, base, forces, init_u, init_v)
        .map_err(|e| CliError::new(format!("{source}: {e}")))?;
    Ok(LoadedModel {
        model,
        simulation: file.simulation.unwrap_or_default(),
    })
}

/// Reads a model file.
pub fn read_model(path: &Path) -> Result<LoadedModel, CliError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::new(format!("{}: cannot read: {e}", path.display())))?;
    let dir = path
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf);
    parse_model(&text, &path.display().to_string(), &dir)
}

/// Reads a two-column accelerogram CSV (time s, acceleration m/s²); a
/// header row and `#` comment lines are allowed.
pub fn read_accelerogram(path: &Path, scale: f64) -> Result<Accelerogram, CliError> {
    let source = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::new(format!("{source}: cannot read the accelerogram: {e}")))?;
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
                return Err(CliError::new(format!(
                    "{source}:{line_no}: expected two columns (time, acceleration), found {}",
                    cells.len()
                )))
            }
        };
        match parsed {
            Some((t, a)) if t.is_finite() && a.is_finite() => {
                if let Some(&last) = times.last() {
                    if t <= last {
                        return Err(CliError::new(format!("{source}:{line_no}: time {t} is not after the previous {last} (times must increase)")));
                    }
                }
                times.push(t);
                values.push(a);
            }
            Some(_) => {
                return Err(CliError::new(format!(
                    "{source}:{line_no}: values must be finite"
                )))
            }
            None if !header_seen && times.is_empty() => header_seen = true,
            None => {
                return Err(CliError::new(format!(
                    "{source}:{line_no}: `{l}` is not two numbers"
                )))
            }
        }
    }
    Accelerogram::new(times, values, scale).map_err(|e| CliError::new(format!("{source}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<LoadedModel, CliError> {
        parse_model(text, "m.toml", Path::new("."))
    }

    const ROW: &str = r#"
[row]
count = 3
mass = 0.227
natural_frequency = 7.41
damping_ratio = 0.013
clearance = 0.001
contact = { law = "exponential", a_over_b = 1.2, alpha = 1.3e5, a = 1.0 }

[excitation]
type = "harmonic-base"
amplitude = 0.05
frequency = 7.0395
"#;

    #[test]
    fn row_form() {
        let m = parse(ROW).unwrap().model;
        assert_eq!(m.bodies().len(), 3);
        assert_eq!(m.contacts().len(), 4);
        assert!((m.bodies()[0].stiffness - 0.227 * 7.41 * 7.41).abs() < 1e-12);
        assert!((m.bodies()[0].damping - 2.0 * 0.013 * 0.227 * 7.41).abs() < 1e-14);
        assert_eq!(m.forcing_frequency(), Some(7.0395));
    }

    #[test]
    fn explicit_form() {
        let text = r#"
[[body]]
name = "a"
mass = 1.0
stiffness = 100.0
[[body]]
name = "b"
mass = 2.0
natural_frequency = 5.0
damping_ratio = 0.02
initial_velocity = 0.1
[[spring]]
between = ["a", "b"]
stiffness = 10.0
[[contact]]
between = ["wall", "a"]
clearance = 0.002
law = { law = "hertz", stiffness = 1e9 }
[[contact]]
between = ["a", "b"]
clearance = 0.001
law = { law = "kelvin-voigt", stiffness = 1e6, damping = 10.0, form = "non-negative" }
[[force]]
body = "b"
amplitude = 1.0
frequency = 3.0
"#;
        let m = parse(text).unwrap().model;
        assert_eq!(m.couplings().len(), 1);
        assert_eq!(m.contact_name(0), "wall|a");
        assert_eq!(m.contacts()[1].law.form(), ForceForm::NonNegative);
        assert_eq!(m.initial_velocity(), &[0.0, 0.1]);
        assert_eq!(m.forcing_frequency(), Some(3.0));
    }

    fn err(text: &str) -> String {
        parse(text).err().expect("should fail").to_string()
    }

    #[test]
    fn errors_name_line_and_key() {
        let e = err(&ROW.replace("mass = 0.227", "mass = 0.227\nmasss = 1"));
        assert!(e.starts_with("m.toml:") && e.contains("masss"), "{e}");
        let e = err(&ROW.replace("clearance = 0.001\n", ""));
        assert!(e.contains("clearance"), "{e}");
        let e = err(&ROW.replace("mass = 0.227", "mass = -1"));
        assert!(e.starts_with("m.toml:2:") && e.contains("mass = -1"), "{e}");
        let e = err(&ROW.replace("alpha = 1.3e5", "alpha = 0"));
        assert!(e.contains("alpha"), "{e}");
        let e = err(&ROW.replace("clearance = 0.001", "clearance = -0.001"));
        assert!(e.contains("clearance"), "{e}");
        let e = err("[[body]]\nname = \"a\"\nmass = 1.0\n[[contact]]\nbetween = [\"a\", \"zz\"]\nclearance = 0.0\nlaw = { law = \"hertz\", stiffness = 1.0 }\n");
        assert!(
            e.starts_with("m.toml:4:") && e.contains("unknown body `zz`"),
            "{e}"
        );
        let e = err("[[body]]\nname = \"a\"\nmass = 1.0\ninitial_displacement = 0.01\n[[contact]]\nbetween = [\"a\", \"wall\"]\nclearance = 0.001\nlaw = { law = \"hertz\", stiffness = 1.0 }\n");
        assert!(e.contains("overlap"), "{e}");
        let e = err(&ROW.replace("type = \"harmonic-base\"", "type = \"quake\""));
        assert!(e.contains("quake"), "{e}");
        let e = err(&ROW.replace("law = \"exponential\"", "law = \"magic\""));
        assert!(e.contains("magic"), "{e}");
    }

    #[test]
    fn accelerogram_files() {
        let dir = std::env::temp_dir().join(format!("vibroimpact-acc-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("ok.csv"), "time,acceleration\n0,0\n0.5,1\n1.0,0\n").unwrap();
        std::fs::write(dir.join("bad.csv"), "0,0\n0.5,1\n0.4,0\n").unwrap();
        let a = read_accelerogram(&dir.join("ok.csv"), 2.0).unwrap();
        assert_eq!(a.at(0.25), 1.0);
        let e = read_accelerogram(&dir.join("bad.csv"), 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bad.csv:3:") && e.contains("increase"), "{e}");
        let text = "[row]\ncount = 1\nmass = 1.0\nstiffness = 1.0\nclearance = 0.01\ncontact = { law = \"hertz\", stiffness = 1e6 }\n[excitation]\ntype = \"accelerogram\"\nfile = \"ok.csv\"\nscale = 0.5\n";
        let m = parse_model(text, "m.toml", &dir).unwrap().model;
        assert!(matches!(m.base(), BaseExcitation::Record(_)));
    }
}
