//! The documents of results that every face of the library shows: the
//! CLI's JSON output and the Python package's result objects carry the same
//! fields, made here once.

use rayon::prelude::*;
use serde::Serialize;
use serde_json::{json, Value};

use crate::contact::{ContactLaw, LawKind};
use crate::continuation::{
    Branch, BranchSpecialPoints, ContinueOutcome, Curves, SpecialKind, SpecialPoint,
};
use crate::impact::closed_form::ExponentialImpact;
use crate::impact::direct::{integrate_impact, DirectOptions};
use crate::impact::{ImpactError, TwoBodies};
use crate::model::file::ModelDocument;
use crate::model::parameter::ModelParameter;
use crate::model::{Impacts, Model};
use crate::periodic::{OrbitSummary, PeriodicSolution};
use crate::simulate::Simulation;

/// JSON description of a contact law: name, form and parameters.
pub fn law_document(law: &ContactLaw) -> serde_json::Value {
    let params = match *law.kind() {
        LawKind::Exponential { a, b, alpha } => {
            serde_json::json!({"a": a, "b": b, "a_over_b": a / b, "alpha": alpha})
        }
        LawKind::Hertz { k, n } => serde_json::json!({"stiffness": k, "exponent": n}),
        LawKind::KelvinVoigt { k, c } => serde_json::json!({"stiffness": k, "damping": c}),
        LawKind::HuntCrossley { k, n, chi } => {
            serde_json::json!({"stiffness": k, "exponent": n, "chi": chi})
        }
        LawKind::LankaraniNikravesh {
            k,
            n,
            restitution,
            min_impact_velocity,
        } => serde_json::json!({"stiffness": k, "exponent": n, "restitution": restitution,
            "min_impact_velocity": min_impact_velocity}),
    };
    serde_json::json!({"law": law.name(), "form": law.form().name(), "parameters": params})
}

/// How impacts are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ImpactMethod {
    /// Fujita's closed form (exponential law only).
    ClosedForm,
    /// Direct integration of the relative motion (any law).
    Integrate,
}

impl ImpactMethod {
    /// The name used in outputs.
    pub fn name(self) -> &'static str {
        match self {
            ImpactMethod::ClosedForm => "closed-form",
            ImpactMethod::Integrate => "integrate",
        }
    }
}

/// Impact relations at one impact velocity.
#[derive(Serialize, Debug)]
pub struct ImpactRow {
    /// U (m/s).
    pub impact_velocity: f64,
    /// V = U/(a/b), exponential law only.
    pub v: Option<f64>,
    /// e.
    pub restitution: f64,
    /// e U (m/s).
    pub rebound_velocity: f64,
    /// f_max = F_max / (μ α (a/b)²), exponential law only.
    pub peak_force_dimensionless: Option<f64>,
    /// F_max (N).
    pub peak_force: f64,
    /// F_max/m1 (m/s²).
    pub peak_acceleration1: f64,
    /// F_max/m2 (m/s²), 0 for a wall.
    pub peak_acceleration2: f64,
    /// Maximum approach coordinate (m).
    pub max_penetration: f64,
    /// Contact duration (s), integrate only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_duration: Option<f64>,
}

impl ImpactRow {
    /// The values in the order of [`IMPACT_COLUMNS`].
    pub fn values(&self) -> [Option<f64>; 10] {
        [
            Some(self.impact_velocity),
            self.v,
            Some(self.restitution),
            Some(self.rebound_velocity),
            self.peak_force_dimensionless,
            Some(self.peak_force),
            Some(self.peak_acceleration1),
            Some(self.peak_acceleration2),
            Some(self.max_penetration),
            self.contact_duration,
        ]
    }
}

/// Column names of an [`ImpactRow`].
pub const IMPACT_COLUMNS: [&str; 10] = [
    "impact_velocity",
    "v",
    "restitution",
    "rebound_velocity",
    "peak_force_dimensionless",
    "peak_force",
    "peak_acceleration1",
    "peak_acceleration2",
    "max_penetration",
    "contact_duration",
];

/// The impact relations of one law between two bodies, velocity by
/// velocity: Fujita's closed form (exponential law only) or direct
/// integration.
#[derive(Clone, Debug)]
pub struct ImpactRelations<'a> {
    law: &'a ContactLaw,
    bodies: TwoBodies,
    method: ImpactMethod,
    opts: DirectOptions,
    closed: Option<ExponentialImpact>,
}

impl<'a> ImpactRelations<'a> {
    /// The relations by `method`; the closed form needs the exponential law.
    pub fn new(
        law: &'a ContactLaw,
        bodies: TwoBodies,
        method: ImpactMethod,
        opts: &DirectOptions,
    ) -> Result<Self, ImpactError> {
        let closed = match law.kind() {
            LawKind::Exponential { .. } => Some(ExponentialImpact::new(law, bodies)?),
            _ => None,
        };
        if method == ImpactMethod::ClosedForm && closed.is_none() {
            return Err(ImpactError::Unsupported(format!(
                "method closed-form exists only for the exponential law, not for {}; use method integrate",
                law.name()
            )));
        }
        Ok(Self {
            law,
            bodies,
            method,
            opts: *opts,
            closed,
        })
    }

    /// The row at impact velocity `u` (m/s).
    pub fn row(&self, u: f64) -> Result<ImpactRow, ImpactError> {
        Ok(match (self.method, &self.closed) {
            (ImpactMethod::ClosedForm, Some(cf)) => {
                let c = cf.impact(u)?;
                ImpactRow {
                    impact_velocity: u,
                    v: Some(c.v),
                    restitution: c.restitution,
                    rebound_velocity: c.rebound_velocity,
                    peak_force_dimensionless: Some(c.peak_force_dimensionless),
                    peak_force: c.peak_force,
                    peak_acceleration1: c.peak_acceleration[0],
                    peak_acceleration2: c.peak_acceleration[1],
                    max_penetration: c.max_penetration,
                    contact_duration: None,
                }
            }
            _ => {
                let d = integrate_impact(self.law, self.bodies, u, &self.opts)?;
                let closed = self.closed.as_ref();
                ImpactRow {
                    impact_velocity: u,
                    v: closed.map(|cf| u / cf.a_over_b()),
                    restitution: d.restitution,
                    rebound_velocity: d.rebound_velocity,
                    peak_force_dimensionless: closed.map(|cf| d.peak_force / cf.force_scale()),
                    peak_force: d.peak_force,
                    peak_acceleration1: d.peak_acceleration[0],
                    peak_acceleration2: d.peak_acceleration[1],
                    max_penetration: d.max_penetration,
                    contact_duration: Some(d.contact_duration),
                }
            }
        })
    }
}

/// The impact relations at every velocity, in parallel on rayon's pool; the
/// first error in velocity order is reported, so the outcome does not depend
/// on the thread count.
pub fn impact_rows(
    law: &ContactLaw,
    bodies: TwoBodies,
    velocities: &[f64],
    method: ImpactMethod,
    opts: &DirectOptions,
) -> Result<Vec<ImpactRow>, ImpactError> {
    let relations = ImpactRelations::new(law, bodies, method, opts)?;
    let rows: Vec<Result<ImpactRow, ImpactError>> =
        velocities.par_iter().map(|&u| relations.row(u)).collect();
    rows.into_iter().collect()
}

/// The document of `vibroimpact impact`: method, contact law, masses and
/// one row per velocity.
pub fn impact_document(
    law: &ContactLaw,
    bodies: TwoBodies,
    method: ImpactMethod,
    rows: &[ImpactRow],
) -> Value {
    json!({
        "method": method.name(),
        "contact_law": law_document(law),
        "mass1": bodies.m1(),
        "mass2": if bodies.m2().is_infinite() { json!("wall") } else { json!(bodies.m2()) },
        "reduced_mass": bodies.reduced_mass(),
        "rows": rows,
    })
}

/// Impacts of one contact per period (periodic orbits).
#[derive(Serialize, Debug)]
struct ContactImpactsDocument {
    contact: String,
    count: usize,
    impact_velocities: Vec<f64>,
    peak_forces: Vec<f64>,
}

/// The document of a periodic solution (`vibroimpact periodic`).
/// `symmetric_orbit`: whether the orbit is mirror-symmetric; `krylov`:
/// whether it was found matrix-free.
pub fn periodic_document(
    model: &Model,
    sol: &PeriodicSolution,
    orbit: &OrbitSummary,
    subharmonic: u32,
    symmetric_orbit: bool,
    krylov: bool,
) -> Value {
    let impacts: Vec<ContactImpactsDocument> = orbit
        .impacts
        .iter()
        .map(|c| ContactImpactsDocument {
            contact: model.contact_name(c.contact),
            count: c.impact_velocities.len(),
            impact_velocities: c.impact_velocities.clone(),
            peak_forces: c.peak_forces.clone(),
        })
        .collect();
    json!({
        "converged": sol.converged,
        "newton_stop": sol.stop.name(),
        "method": if krylov { "newton-krylov (dominant multipliers by Arnoldi)" } else { "newton (dense monodromy)" },
        "period": sol.period,
        "subharmonic": subharmonic,
        "initial_state": sol.initial_state,
        "residual_history": sol.residual_history,
        "floquet_multipliers": sol.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
        "spectral_radius": sol.spectral_radius(),
        "stable": sol.stable(),
        "symmetric_orbit": symmetric_orbit,
        "max_displacement": orbit.max_displacement,
        "max_velocity": orbit.max_velocity,
        "impacts_per_period": orbit.impacts_per_period(),
        "impacts": impacts,
    })
}

/// The document of a branch (`points`, `special_points`), as `vibroimpact
/// continue` prints it.
pub fn branch_document(branch: &Branch, model: &Model, name: &str) -> Value {
    json!({
        "parameter_name": name,
        "subharmonic": branch.subharmonic,
        "symmetric": branch.symmetric,
        "stop": branch.stop.name(),
        "stop_detail": branch.stop.detail(),
        "contacts": (0..model.contacts().len()).map(|k| model.contact_name(k)).collect::<Vec<_>>(),
        "points": branch.points.iter().map(|p| json!({
            "parameter": p.parameter,
            "max_displacement": p.max_displacement,
            "max_velocity": p.max_velocity,
            "impacts_per_period": p.impacts_per_period,
            "stable": p.stable,
            "spectral_radius": p.spectral_radius(),
            "floquet_multipliers": p.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
            "initial_state": p.state,
            "label": p.label,
        })).collect::<Vec<_>>(),
        "special_points": branch.special.iter().map(|s| json!({
            "kind": s.kind.name(),
            "label": s.label,
            "parameter": s.parameter,
            "symmetry_breaking": s.symmetry_breaking,
            "floquet_multipliers": s.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
            "initial_state": s.state,
            "max_displacement": s.max_displacement,
            "after_point": s.after_point,
        })).collect::<Vec<_>>(),
    })
}

/// A branch document that cannot be read back (what is missing or wrong).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct BranchDocumentError(pub String);

/// Reads back the special points of a [`branch_document`] of `document`
/// (its `parameter_name` must be the key of `first`).
pub fn branch_special_points(
    doc: &Value,
    document: &ModelDocument,
    first: &ModelParameter,
) -> Result<BranchSpecialPoints, BranchDocumentError> {
    let at = |what: String| BranchDocumentError(what);
    let name = doc["parameter_name"]
        .as_str()
        .ok_or_else(|| at("no `parameter_name`".into()))?;
    let key = document.parameter(name).map(|p| p.key).ok();
    if key.as_ref() != Some(&first.key) {
        return Err(at(format!(
            "a branch in `{name}`, not in the parameter {}",
            first.name
        )));
    }
    let symmetric = doc["symmetric"]
        .as_bool()
        .ok_or_else(|| at("no `symmetric`".into()))?;
    let subharmonic = doc["subharmonic"]
        .as_u64()
        .and_then(|n| u32::try_from(n).ok())
        .filter(|&n| n >= 1)
        .ok_or_else(|| at("no `subharmonic` (a whole number ≥ 1)".into()))?;
    let list = doc["special_points"]
        .as_array()
        .ok_or_else(|| at("no `special_points` list".into()))?;
    let mut special = Vec::new();
    for (k, s) in list.iter().enumerate() {
        let field = |f: &str| at(format!("special_points[{k}]: no valid `{f}`"));
        let kind = SpecialKind::ALL
            .into_iter()
            .find(|kind| s["kind"].as_str() == Some(kind.name()))
            .ok_or_else(|| field("kind"))?;
        let state: Vec<f64> = s["initial_state"]
            .as_array()
            .ok_or_else(|| field("initial_state"))?
            .iter()
            .map(|v| v.as_f64().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| field("initial_state"))?;
        // A branch of another model (the docs' example once chained the
        // row of three into the row of two): said here, by size.
        if let Ok(model) = document.build() {
            let d = 2 * model.model.bodies().len();
            if state.len() != d {
                return Err(at(format!(
                    "special_points[{k}]: a state of {} values, a branch of a model with {} bodies; {} has {} ({d} values): give a branch.json of this model",
                    state.len(),
                    state.len() / 2,
                    document.source(),
                    d / 2
                )));
            }
        }
        special.push(SpecialPoint {
            kind,
            label: s["label"]
                .as_str()
                .ok_or_else(|| field("label"))?
                .to_string(),
            parameter: s["parameter"]
                .as_f64()
                .filter(|v| v.is_finite())
                .ok_or_else(|| field("parameter"))?,
            state,
            max_displacement: Vec::new(),
            multipliers: Vec::new(),
            tangent: Vec::new(),
            after_point: 0,
            symmetry_breaking: s["symmetry_breaking"]
                .as_bool()
                .ok_or_else(|| field("symmetry_breaking"))?,
        });
    }
    Ok(BranchSpecialPoints {
        special,
        symmetric,
        subharmonic,
    })
}

/// A storey law's name and parameters, defaults resolved.
pub fn storey_law_document(law: &crate::model::hysteresis::StoreyLaw) -> Value {
    use crate::model::hysteresis::StoreyLaw;
    match law {
        StoreyLaw::Elastic { stiffness } => json!({"law": "elastic", "stiffness": stiffness}),
        StoreyLaw::Bilinear(b) => json!({
            "law": "bilinear",
            "stiffness": b.stiffness,
            "yield_drift": b.yield_drift,
            "post_yield_ratio": b.post_yield_ratio,
        }),
        StoreyLaw::BoucWen(w) => json!({
            "law": "bouc-wen",
            "stiffness": w.stiffness,
            "yield_drift": w.yield_drift,
            "post_yield_ratio": w.post_yield_ratio,
            "exponent": w.exponent,
            "beta": w.beta,
            "gamma": w.gamma,
            "degradation_a": w.degradation.a,
            "degradation_nu": w.degradation.nu,
            "degradation_eta": w.degradation.eta,
        }),
        StoreyLaw::Imk(m) => json!({
            "law": "imk",
            "stiffness": m.stiffness,
            "yield_drift": m.yield_drift,
            "cap_ratio": m.cap_ratio,
            "plastic_drift": m.plastic_drift,
            "post_capping_drift": m.post_capping_drift,
            "residual_ratio": m.residual_ratio,
            "ultimate_drift": m.ultimate_drift,
            "lambda_s": finite(m.lambda[0]),
            "lambda_c": finite(m.lambda[1]),
            "lambda_k": finite(m.lambda[2]),
            "c_s": m.exponent[0],
            "c_c": m.exponent[1],
            "c_k": m.exponent[2],
        }),
    }
}

/// A value, or null where it is infinite (an IMK λ without deterioration).
fn finite(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// The `hysteresis` summary: the law, the units, the peak force and the
/// energy dissipated over `rows` (force, dissipated so far) — the
/// document without its rows.
pub fn hysteresis_summary(law: &crate::model::hysteresis::StoreyLaw, rows: &[(f64, f64)]) -> Value {
    json!({
        "law": storey_law_document(law),
        "units": { "drift": "m", "force": "N", "dissipated": "J" },
        "peak_force": rows.iter().fold(0.0f64, |m, r| m.max(r.0.abs())),
        "total_dissipated": rows.last().map_or(0.0, |r| r.1),
    })
}

/// The `hysteresis` document: [`hysteresis_summary`] and a row per drift
/// (drift, force, dissipated so far).
pub fn hysteresis_document(
    law: &crate::model::hysteresis::StoreyLaw,
    drifts: &[f64],
    rows: &[(f64, f64)],
) -> Value {
    let mut doc = hysteresis_summary(law, rows);
    doc["rows"] = drifts
        .iter()
        .zip(rows)
        .map(|(d, (f, e))| json!({ "drift": d, "force": f, "dissipated": e }))
        .collect();
    doc
}

/// The `spectrum` document: the record (scaled by `scale`), the damping,
/// how the peaks are taken, the units and a row per period.
pub fn spectrum_document(
    record: &crate::model::record::Record,
    scale: f64,
    damping: f64,
    rows: &[crate::seismic::spectrum::SpectralPoint],
) -> Value {
    json!({
        "record": record.metadata(scale),
        "damping": damping,
        "peaks": "over the record's time steps",
        "units": { "period": "s", "pseudo_acceleration": "m/s2", "pseudo_velocity": "m/s", "displacement": "m" },
        "rows": rows.iter().map(|p| json!({
            "period": p.period,
            "pseudo_acceleration": p.pseudo_acceleration,
            "pseudo_velocity": p.pseudo_velocity,
            "displacement": p.displacement,
        })).collect::<Vec<_>>(),
    })
}

/// The `continue` document: the branch's ([`branch_document`]) with
/// `switched_branch` when the switch succeeded and, with curves, their
/// `curves` and `curves_skipped` ([`curves_document`]).
pub fn continue_document(outcome: &ContinueOutcome) -> Value {
    let (model, name) = (&outcome.branch.start_model, &outcome.parameter);
    let mut doc = branch_document(&outcome.branch.branch, model, name);
    if let Some(Ok(b)) = &outcome.branch.switched {
        doc["switched_branch"] = branch_document(b, model, name);
    }
    if let Some((c, q)) = &outcome.curves {
        let c = curves_document(c, name, q);
        doc["curves"] = c["curves"].clone();
        doc["curves_skipped"] = c["skipped"].clone();
    }
    doc
}

/// The `curves` document: each curve with its kind, start label, stop,
/// points (both parameters `p` and `q` by name, max |u| per body,
/// multipliers) and its codimension-two points (kind, index in `points`,
/// both parameters), and the special points skipped with the reason.
pub fn curves_document(curves: &Curves, p: &str, q: &str) -> Value {
    let list: Vec<Value> = curves
        .followed
        .iter()
        .map(|(label, c)| {
            json!({
                "kind": c.kind.name(),
                "from": label,
                "stop": c.stop,
                "special": c.special.iter().map(|sp| {
                    let pt = &c.points[sp.point];
                    json!({ "kind": sp.kind.name(), "point": sp.point, p: pt.p, q: pt.q })
                }).collect::<Vec<_>>(),
                "points": c.points.iter().map(|pt| json!({
                    p: pt.p,
                    q: pt.q,
                    "max_displacement": pt.max_displacement,
                    "floquet_multipliers": pt.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
                    "initial_state": pt.state,
                })).collect::<Vec<_>>(),
            })
        })
        .collect();
    let skipped: Vec<Value> = curves
        .skipped
        .iter()
        .map(|(label, why)| json!({ "from": label, "reason": why }))
        .collect();
    json!({ "parameter": p, "parameter2": q, "curves": list, "skipped": skipped })
}

/// The summary of a simulation (JSON).
#[derive(Serialize, Debug)]
pub struct SimulationSummary {
    /// Whether the simulation reached the end time.
    pub completed: bool,
    /// The integration error that stopped it, if any.
    pub error: Option<String>,
    /// Time reached (s).
    pub final_time: f64,
    /// Final displacements in body order (m).
    pub final_displacement: Vec<f64>,
    /// Final velocities in body order (m/s).
    pub final_velocity: Vec<f64>,
    /// Number of logged impacts.
    pub impact_count: usize,
    /// Impacts per contact, in contact order.
    pub impacts_per_contact: Vec<ContactCount>,
    /// Right-hand side evaluations.
    pub rhs_evaluations: u64,
    /// Accepted steps.
    pub steps: u64,
    /// Rejected steps.
    pub rejected_steps: u64,
    /// Contact-law evaluations (far contacts are skipped).
    pub contact_evaluations: u64,
    /// The contact laws and their force forms (and rigid impacts, where
    /// a contact's are: docs/theory.md §12).
    pub contact_laws: Vec<String>,
    /// `global` or `local` (docs/theory.md §10).
    pub integrator: &'static str,
    /// Rigid contacts' soft episodes (docs/theory.md §12): where the rigid
    /// idealisation broke and the contact's law was integrated.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub soft_episodes: Vec<EpisodeSummary>,
    /// The local integrator's work: bound checks of contacts between
    /// exactly moving bodies, changes of the integrated set, its largest
    /// size and the number of bodies ever integrated.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub local: Option<LocalSummary>,
    /// Energy audit (J), with --energy.
    pub energy: Option<EnergySummary>,
    /// The recorded ground motion, when the excitation is one (set by the
    /// caller from [`crate::model::file::LoadedModel::record`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub record: Option<crate::model::record::RecordMetadata>,
    /// What produced it (set by the caller: [`Provenance::new`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

/// What produced a result: the program's version, the integration's
/// settings and a digest of the model, so that a result file says how to
/// reproduce it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Provenance {
    /// vibroimpact's version.
    pub version: &'static str,
    /// The integration method asked for (`auto` switches between DOP853
    /// and RODAS as the run needs).
    pub method: &'static str,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance (m and m/s).
    pub atol: f64,
    /// The integrator asked for (`auto`, `global`, `local`).
    pub integrator: &'static str,
    /// SHA-256 (hex) of the model's canonical text
    /// ([`ModelDocument::to_toml`]: comments and layout aside, an
    /// accelerogram inlined): the same model, the same digest, from a
    /// file or from Python.
    pub model_sha256: String,
}

impl Provenance {
    /// The provenance of a run of `document` with `opts`.
    pub fn new(document: &ModelDocument, opts: &crate::simulate::SimulationOptions) -> Self {
        use sha2::{Digest, Sha256};
        let hash = Sha256::digest(document.to_toml().as_bytes());
        Self {
            version: env!("CARGO_PKG_VERSION"),
            method: opts.method.name(),
            rtol: opts.rtol,
            atol: opts.atol,
            integrator: opts.integrator.name(),
            model_sha256: hash.iter().map(|b| format!("{b:02x}")).collect(),
        }
    }
}

/// Impacts of one contact.
#[derive(Serialize, Debug)]
pub struct ContactCount {
    /// Contact name, e.g. `p1|p2`.
    pub contact: String,
    /// Number of impacts.
    pub impacts: usize,
}

/// The local integrator's work.
#[derive(Serialize, Debug)]
pub struct LocalSummary {
    /// Bound checks of contacts between exactly moving bodies.
    pub contact_checks: u64,
    /// Changes of the integrated set.
    pub set_changes: u64,
    /// Most bodies integrated at once.
    pub largest_set: usize,
    /// Most sets integrated side by side at once (clusters that no contact
    /// joins, each with its own stepper).
    pub most_sets: usize,
    /// Bodies integrated at some time (the others moved exactly
    /// throughout and were never evaluated).
    pub bodies_integrated: usize,
}

/// Energy audit (J).
#[derive(Serialize, Debug)]
pub struct EnergySummary {
    /// Mechanical energy at the start.
    pub initial: f64,
    /// Mechanical energy at the end.
    pub mechanical: f64,
    /// Work of the excitation.
    pub input_work: f64,
    /// Dissipated in dampers.
    pub damping_dissipation: f64,
    /// Dissipated in contacts.
    pub contact_dissipation: f64,
    /// Dissipated by hysteretic storeys (present where the model has them).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hysteretic_dissipation: Option<f64>,
    /// E + D_c + D_k + D_h - W - E0.
    pub residual: f64,
}

/// One soft episode of a rigid contact, for the summaries.
#[derive(Clone, Debug, Serialize)]
pub struct EpisodeSummary {
    /// The contact's name.
    pub contact: String,
    /// Start (s).
    pub start_time: f64,
    /// End (s): the bodies separated; None if still in contact at the end.
    pub end_time: Option<f64>,
    /// Why its law took over.
    pub reason: String,
}

/// Builds the summary of a simulation.
pub fn simulation_summary(model: &Model, sim: &Simulation) -> SimulationSummary {
    let mut counts = vec![0usize; model.contacts().len()];
    for i in &sim.impacts {
        counts[i.contact] += 1;
    }
    let mut laws: Vec<String> = model
        .contacts()
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let law = format!("{} ({})", c.law.name(), c.law.form().name());
            match model.impacts(k) {
                Impacts::Soft => law,
                Impacts::Rigid { restitution: None } => {
                    format!("{law}, rigid impacts with its e(U)")
                }
                Impacts::Rigid {
                    restitution: Some(e),
                } => format!("{law}, rigid impacts with e = {e}"),
            }
        })
        .collect();
    laws.dedup();
    SimulationSummary {
        completed: sim.error.is_none(),
        error: sim.error.as_ref().map(ToString::to_string),
        final_time: sim.final_time,
        final_displacement: sim.final_displacement.clone(),
        final_velocity: sim.final_velocity.clone(),
        impact_count: sim.impacts.len(),
        impacts_per_contact: counts
            .iter()
            .enumerate()
            .map(|(k, &n)| ContactCount {
                contact: model.contact_name(k),
                impacts: n,
            })
            .collect(),
        rhs_evaluations: sim.stats.rhs_evaluations,
        steps: sim.stats.steps,
        rejected_steps: sim.stats.rejected_steps,
        contact_evaluations: sim.contact_evaluations,
        contact_laws: laws,
        soft_episodes: sim
            .soft_episodes
            .iter()
            .map(|e| EpisodeSummary {
                contact: model.contact_name(e.contact),
                start_time: e.start_time,
                end_time: (!e.end_time.is_nan()).then_some(e.end_time),
                reason: e.reason.describe(model),
            })
            .collect(),
        integrator: if sim.local.is_some() {
            "local"
        } else {
            "global"
        },
        local: sim.local.as_ref().map(|l| LocalSummary {
            contact_checks: l.contact_checks,
            set_changes: l.set_changes,
            largest_set: l.largest_set,
            most_sets: l.most_sets,
            bodies_integrated: l.bodies_integrated(),
        }),
        energy: sim.energy.map(|e| EnergySummary {
            initial: e.initial,
            mechanical: e.mechanical,
            input_work: e.input_work,
            damping_dissipation: e.damping_dissipation,
            contact_dissipation: e.contact_dissipation,
            hysteretic_dissipation: (!model.storeys().is_empty())
                .then_some(e.hysteretic_dissipation),
            residual: e.residual(),
        }),
        record: None,
        provenance: None,
    }
}
