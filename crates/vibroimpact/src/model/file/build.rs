//! Building a [`Model`] from a parsed model file: every table of the
//! schema checked and translated, one function per table, each error
//! naming the source, the line and the key.

use crate::model::Impacts;
use std::collections::HashMap;

use super::*;

/// What the body tables give: the bodies, the springs and contacts of a
/// `[row]`, and the initial state of `[[body]]` tables.
#[derive(Default)]
struct BodyTables {
    bodies: Vec<Body>,
    couplings: Vec<Coupling>,
    contacts: Vec<Contact>,
    init_u: Vec<f64>,
    init_v: Vec<f64>,
}

/// The bodies by name, for the tables that refer to them.
struct Names<'a> {
    index: HashMap<&'a str, usize>,
    bodies: &'a [Body],
}

impl<'a> Names<'a> {
    fn new(bodies: &'a [Body]) -> Self {
        Self {
            index: bodies
                .iter()
                .enumerate()
                .map(|(i, b)| (b.name.as_str(), i))
                .collect(),
            bodies,
        }
    }

    fn find(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// The first ten names, for messages.
    fn list(&self) -> String {
        self.bodies
            .iter()
            .map(|b| b.name.as_str())
            .take(10)
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// `v` if finite, else why (named `key`).
fn physical(v: f64, key: &str) -> Result<f64, String> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{key} = {v}: must be finite"))
    }
}

impl ModelDocument {
    /// Builds the model, naming it `label` in messages.
    pub(crate) fn build_labelled(&self, label: &str) -> Result<LoadedModel, ModelFileError> {
        let cx = Ctx {
            label,
            line_starts: &self.line_starts,
        };
        let file = &self.file;
        let mut tables = match (&file.row, file.body.is_empty()) {
            (Some(_), false) => {
                let span = file.body[0].span();
                return Err(cx.err_at(span, "give either [row] or [[body]] tables, not both"));
            }
            (None, true) => return Err(cx.plain("no bodies: add a [row] table or [[body]] tables")),
            (Some(row), true) => row_table(&cx, row)?,
            (None, false) => body_tables(&cx, &file.body)?,
        };
        let names = Names::new(&tables.bodies);
        let row_contacts = tables.contacts.len();
        let springs = spring_tables(&cx, &file.spring, &names)?;
        let contacts = contact_tables(&cx, &file.contact, &names)?;
        let base = self.excitation_table(&cx)?;
        let forces = force_tables(&cx, &file.force, &names)?;
        if let Some(init) = &file.initial {
            (tables.init_u, tables.init_v) = initial_table(&cx, file, init, &names)?;
        }
        tables.couplings.extend(springs);
        tables.contacts.extend(contacts);
        let model = Model::new(
            tables.bodies,
            tables.couplings,
            tables.contacts,
            base,
            forces,
            tables.init_u,
            tables.init_v,
        )
        .map_err(|e| cx.plain(e))?;
        let model = impacts_keys(&cx, file, row_contacts, model)?;
        let model = match &file.gravity {
            Some(g) => model
                .with_gravity(*g.get_ref())
                .map_err(|e| cx.err_at(g.span(), e.to_string()))?,
            None => model,
        };
        let simulation = simulation_table(&cx, file)?;
        let record = match (&self.record, model.base()) {
            (Some(r), BaseExcitation::Record(a)) => Some(r.metadata(a.scale())),
            _ => None,
        };
        Ok(LoadedModel {
            model,
            simulation,
            record,
        })
    }

    /// `[excitation]`: none, a harmonic base acceleration or the loaded
    /// record, scaled.
    fn excitation_table(&self, cx: &Ctx<'_>) -> Result<BaseExcitation, ModelFileError> {
        let Some(e) = &self.file.excitation else {
            return Ok(BaseExcitation::None);
        };
        let span = e.span();
        match e.get_ref() {
            ExcitationSpec::None => Ok(BaseExcitation::None),
            ExcitationSpec::HarmonicBase {
                amplitude,
                frequency,
                phase,
            } => {
                if !(*frequency > 0.0 && frequency.is_finite()) {
                    return Err(cx.err_at(
                        span,
                        format!(
                            "[excitation] frequency = {frequency}: must be finite and > 0 (rad/s)"
                        ),
                    ));
                }
                physical(*amplitude, "amplitude")
                    .map_err(|m| cx.err_at(span.clone(), format!("[excitation] {m}")))?;
                Ok(BaseExcitation::Harmonic {
                    amplitude: *amplitude,
                    frequency: *frequency,
                    phase: phase.unwrap_or(0.0),
                })
            }
            ExcitationSpec::Accelerogram { scale, .. } => {
                let record = self.record.as_ref().ok_or_else(|| {
                    cx.err_at(span.clone(), "[excitation] accelerogram: no record loaded")
                })?;
                let scale = scale.unwrap_or(1.0);
                // The samples' errors belong to the record, the scale's to
                // the model file's [excitation].
                let a = Accelerogram::new(record.times.clone(), record.acceleration.clone(), scale)
                    .map_err(|e| match e.key.as_str() {
                        "excitation.scale" => cx.err_at(
                            span.clone(),
                            format!("[excitation] scale = {scale}: must be finite"),
                        ),
                        _ => ModelFileError(format!("{}: {e}", record.source)),
                    })?;
                Ok(BaseExcitation::Record(a))
            }
        }
    }
}

/// `[row]`: N equal bodies between walls, with their contacts and an
/// optional coupling between neighbours.
fn row_table(cx: &Ctx<'_>, row: &Spanned<RowSpec>) -> Result<BodyTables, ModelFileError> {
    let span = row.span();
    let r = row.get_ref();
    let at = |m: String| cx.err_at(span.clone(), format!("[row] {m}"));
    if r.count == 0 || r.count > 1_000_000 {
        return Err(at(format!(
            "count = {}: must be from 1 to 1000000",
            r.count
        )));
    }
    if !(r.mass > 0.0 && r.mass.is_finite()) {
        return Err(at(format!("mass = {}: must be finite and > 0", r.mass)));
    }
    let support = Support {
        stiffness: r.stiffness,
        natural_frequency: r.natural_frequency,
        damping: r.damping,
        damping_ratio: r.damping_ratio,
    };
    let (k, c) = support.resolve(r.mass).map_err(at)?;
    let law = r.contact.build().map_err(|m| at(format!("contact: {m}")))?;
    let walls = match r.walls.as_deref().unwrap_or("both") {
        "both" => (true, true),
        "left" => (true, false),
        "right" => (false, true),
        "none" => (false, false),
        w => {
            return Err(at(format!(
                "walls = \"{w}\": must be both, left, right or none"
            )))
        }
    };
    physical(r.clearance, "clearance").map_err(at)?;
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
    .map_err(|e| at(e.to_string()))?;
    let couplings = match &r.coupling {
        None => Vec::new(),
        Some(cp) => (0..r.count.saturating_sub(1))
            .map(|i| Coupling {
                a: i,
                b: i + 1,
                stiffness: cp.stiffness.unwrap_or(0.0),
                damping: cp.damping.unwrap_or(0.0),
            })
            .collect(),
    };
    Ok(BodyTables {
        bodies: row_model.bodies().to_vec(),
        couplings,
        contacts: row_model.contacts().to_vec(),
        ..BodyTables::default()
    })
}

/// `[[body]]` tables: named bodies with their supports and initial states.
fn body_tables(cx: &Ctx<'_>, tables: &[Spanned<BodySpec>]) -> Result<BodyTables, ModelFileError> {
    let mut out = BodyTables::default();
    let mut seen = std::collections::HashSet::new();
    for (i, b) in tables.iter().enumerate() {
        let span = b.span();
        let spec = b.get_ref();
        if !seen.insert(spec.name.as_str()) || spec.name == "wall" {
            return Err(cx.err_at(
                span,
                format!(
                    "[[body]] #{}: name `{}` is used twice or reserved",
                    i + 1,
                    spec.name
                ),
            ));
        }
        let at = |m: String| cx.err_at(span.clone(), format!("[[body]] {}: {m}", spec.name));
        if !(spec.mass > 0.0 && spec.mass.is_finite()) {
            return Err(at(format!("mass = {}: must be finite and > 0", spec.mass)));
        }
        let support = Support {
            stiffness: spec.stiffness,
            natural_frequency: spec.natural_frequency,
            damping: spec.damping,
            damping_ratio: spec.damping_ratio,
        };
        let (k, c) = support.resolve(spec.mass).map_err(at)?;
        out.bodies.push(Body {
            name: spec.name.clone(),
            mass: spec.mass,
            stiffness: k,
            damping: c,
        });
        out.init_u.push(spec.initial_displacement.unwrap_or(0.0));
        out.init_v.push(spec.initial_velocity.unwrap_or(0.0));
    }
    Ok(out)
}

/// `[[spring]]` tables: springs and dashpots between two named bodies.
fn spring_tables(
    cx: &Ctx<'_>,
    tables: &[Spanned<SpringSpec>],
    names: &Names<'_>,
) -> Result<Vec<Coupling>, ModelFileError> {
    tables
        .iter()
        .map(|s| {
            let span = s.span();
            let spec = s.get_ref();
            let idx: Vec<usize> = spec
                .between
                .iter()
                .map(|n| {
                    names.find(n).ok_or_else(|| {
                        cx.err_at(
                            span.clone(),
                            format!("[[spring]]: unknown body `{n}` (bodies: {})", names.list()),
                        )
                    })
                })
                .collect::<Result<_, _>>()?;
            Ok(Coupling {
                a: idx[0],
                b: idx[1],
                stiffness: spec.stiffness.unwrap_or(0.0),
                damping: spec.damping.unwrap_or(0.0),
            })
        })
        .collect()
}

/// `[[contact]]` tables: a law and a clearance between two bodies, or a
/// body and a wall.
fn contact_tables(
    cx: &Ctx<'_>,
    tables: &[Spanned<ContactSpec>],
    names: &Names<'_>,
) -> Result<Vec<Contact>, ModelFileError> {
    tables.iter().map(|c| contact_table(cx, c, names)).collect()
}

/// One `[[contact]]` table.
fn contact_table(
    cx: &Ctx<'_>,
    c: &Spanned<ContactSpec>,
    names: &Names<'_>,
) -> Result<Contact, ModelFileError> {
    let span = c.span();
    let spec = c.get_ref();
    let [left, right] = [&spec.between[0], &spec.between[1]];
    let law = spec
        .law
        .build()
        .map_err(|m| cx.err_at(span.clone(), format!("[[contact]] {left}|{right}: {m}")))?;
    let side = |n: &str| -> Result<Option<usize>, ModelFileError> {
        if n == "wall" {
            return Ok(None);
        }
        names.find(n).map(Some).ok_or_else(|| {
            cx.err_at(
                span.clone(),
                format!(
                    "[[contact]]: unknown body `{n}` (bodies: {}; or `wall`)",
                    names.list()
                ),
            )
        })
    };
    let pair = match (side(left)?, side(right)?) {
        (None, None) => return Err(cx.err_at(span, "[[contact]]: between two walls")),
        (None, Some(r)) => ContactPair::LeftWall { body: r },
        (Some(l), None) => ContactPair::RightWall { body: l },
        (Some(l), Some(r)) if l == r => {
            return Err(cx.err_at(
                span,
                format!("[[contact]] between = [\"{left}\", \"{right}\"]: a body cannot strike itself; name two different bodies, or a body and `wall`"),
            ));
        }
        (Some(l), Some(r)) if l > r => {
            return Err(cx.err_at(
                span,
                format!("[[contact]] between = [\"{left}\", \"{right}\"]: give the left body first (bodies are in order along the line)"),
            ));
        }
        (Some(l), Some(r)) => ContactPair::Bodies { left: l, right: r },
    };
    if !(spec.clearance >= 0.0 && spec.clearance.is_finite()) {
        return Err(cx.err_at(
            span,
            format!(
                "[[contact]] {left}|{right}: clearance = {}: must be finite and >= 0",
                spec.clearance
            ),
        ));
    }
    Ok(Contact {
        pair,
        clearance: spec.clearance,
        law,
    })
}

/// The `impacts` and `restitution` keys of `[row]` (its contacts, the
/// first `row_contacts`) and of each `[[contact]]`, set on the model.
fn impacts_keys(
    cx: &Ctx<'_>,
    file: &ModelFile,
    row_contacts: usize,
    mut model: Model,
) -> Result<Model, ModelFileError> {
    let row = file.row.iter().flat_map(|r| {
        let spec = r.get_ref();
        (0..row_contacts).map(move |k| {
            (
                k,
                r.span(),
                "[row]".to_string(),
                &spec.impacts,
                spec.restitution,
            )
        })
    });
    let tables = file.contact.iter().enumerate().map(|(i, c)| {
        let spec = c.get_ref();
        let at = format!("[[contact]] {}|{}", spec.between[0], spec.between[1]);
        (
            row_contacts + i,
            c.span(),
            at,
            &spec.impacts,
            spec.restitution,
        )
    });
    for (k, span, at, name, restitution) in row.chain(tables) {
        if name.is_none() && restitution.is_none() {
            continue;
        }
        let impacts = Impacts::parse(name.as_deref().unwrap_or("soft"), restitution)
            .map_err(|m| cx.err_at(span.clone(), format!("{at} {m}")))?;
        model = model
            .with_impacts(k, impacts)
            .map_err(|e| cx.err_at(span, format!("{at} impacts = \"rigid\": {}", e.message)))?;
    }
    Ok(model)
}

/// `[[force]]` tables: harmonic forces on named bodies.
fn force_tables(
    cx: &Ctx<'_>,
    tables: &[Spanned<ForceSpec>],
    names: &Names<'_>,
) -> Result<Vec<HarmonicForce>, ModelFileError> {
    tables
        .iter()
        .map(|f| {
            let spec = f.get_ref();
            let body = names.find(&spec.body).ok_or_else(|| {
                cx.err_at(f.span(), format!("[[force]]: unknown body `{}`", spec.body))
            })?;
            Ok(HarmonicForce {
                body,
                amplitude: spec.amplitude,
                frequency: spec.frequency,
                phase: spec.phase.unwrap_or(0.0),
            })
        })
        .collect()
}

/// `[initial]`: the initial displacements and velocities (not with
/// initial values in `[[body]]` tables).
fn initial_table(
    cx: &Ctx<'_>,
    file: &ModelFile,
    init: &Spanned<InitialSpec>,
    names: &Names<'_>,
) -> Result<(Vec<f64>, Vec<f64>), ModelFileError> {
    let span = init.span();
    if file.body.iter().any(|b| {
        b.get_ref().initial_displacement.is_some() || b.get_ref().initial_velocity.is_some()
    }) {
        return Err(cx.err_at(
            span,
            "give the initial state either in [initial] or in the [[body]] tables, not both",
        ));
    }
    let spec = init.get_ref();
    let names: Vec<&str> = names.bodies.iter().map(|b| b.name.as_str()).collect();
    let resolve = |values: &Option<InitialValues>, what: &str| match values {
        Some(v) => v
            .resolve(&names, what)
            .map_err(|e| cx.err_at(span.clone(), e)),
        None => Ok(Vec::new()),
    };
    Ok((
        resolve(&spec.displacement, "displacement")?,
        resolve(&spec.velocity, "velocity")?,
    ))
}

/// `[simulation]`: tolerances and the impact threshold, each finite and
/// positive where given.
fn simulation_table(cx: &Ctx<'_>, file: &ModelFile) -> Result<SimulationSpec, ModelFileError> {
    let simulation = file.simulation.clone().unwrap_or_default();
    for (key, value) in [
        ("rtol", simulation.rtol),
        ("atol", simulation.atol),
        ("impact_force_threshold", simulation.impact_force_threshold),
        ("displacement_scale", simulation.displacement_scale),
    ] {
        if let Some(v) = value.filter(|v| !(*v > 0.0 && v.is_finite())) {
            return Err(cx.plain(format!("[simulation] {key} = {v}: must be finite and > 0")));
        }
    }
    if let Some(rtol) = simulation.rtol {
        crate::field_error::FieldError::tolerance("rtol", rtol)
            .map_err(|e| cx.plain(format!("[simulation] {e}")))?;
    }
    Ok(simulation)
}
