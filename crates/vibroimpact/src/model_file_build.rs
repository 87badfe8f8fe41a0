//! Building a [`Model`] from a parsed model file: every table of the
//! schema checked and translated, each error naming the source, the line
//! and the key.

use super::*;

impl ModelDocument {
    /// Builds the model, naming it `label` in messages.
    pub(crate) fn build_labelled(&self, label: &str) -> Result<LoadedModel, ModelFileError> {
        let cx = Ctx {
            label,
            line_starts: &self.line_starts,
        };
        let file = &self.file;
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
            (None, true) => return Err(cx.plain("no bodies: add a [row] table or [[body]] tables")),
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
                let mut seen = std::collections::HashSet::new();
                for (i, b) in file.body.iter().enumerate() {
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
                    let (k, c) = support.resolve(spec.mass).map_err(|m| {
                        cx.err_at(span.clone(), format!("[[body]] {}: {m}", spec.name))
                    })?;
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
        let index: std::collections::HashMap<&str, usize> = bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), i))
            .collect();
        let find = |name: &str| index.get(name).copied();
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
            let side = |n: &str| -> Result<Option<usize>, ModelFileError> {
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
                    ExcitationSpec::Accelerogram { scale, .. } => {
                        let record = self.record.as_ref().ok_or_else(|| {
                            cx.err_at(span.clone(), "[excitation] accelerogram: no record loaded")
                        })?;
                        let scale = scale.unwrap_or(1.0);
                        // The samples' errors belong to the record, the
                        // scale's to the model file's [excitation].
                        BaseExcitation::Record(
                            Accelerogram::new(
                                record.times.clone(),
                                record.acceleration.clone(),
                                scale,
                            )
                            .map_err(|e| match e.key.as_str() {
                                "excitation.scale" => cx.err_at(
                                    span.clone(),
                                    format!("[excitation] scale = {scale}: must be finite"),
                                ),
                                _ => ModelFileError(format!("{}: {e}", record.source)),
                            })?,
                        )
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
                    b.get_ref().initial_displacement.is_some()
                        || b.get_ref().initial_velocity.is_some()
                })
            {
                return Err(cx.err_at(
                    span,
                    "give the initial state either in [initial] or in the [[body]] tables, not both",
                ));
            }
            let spec = init.get_ref();
            let names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
            let resolve = |values: &Option<InitialValues>, what: &str| match values {
                Some(v) => v
                    .resolve(&names, what)
                    .map_err(|e| cx.err_at(span.clone(), e)),
                None => Ok(Vec::new()),
            };
            init_u = resolve(&spec.displacement, "displacement")?;
            init_v = resolve(&spec.velocity, "velocity")?;
        }
        let model = Model::new(bodies, couplings, contacts, base, forces, init_u, init_v)
            .map_err(|e| cx.plain(e))?;
        let simulation = file.simulation.clone().unwrap_or_default();
        for (key, value) in [
            ("rtol", simulation.rtol),
            ("atol", simulation.atol),
            ("impact_force_threshold", simulation.impact_force_threshold),
        ] {
            if let Some(v) = value.filter(|v| !(*v > 0.0 && v.is_finite())) {
                return Err(cx.plain(format!("[simulation] {key} = {v}: must be finite and > 0")));
            }
        }
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
}
