//! Pounding of adjacent structures (docs/earthquakes.md): a row of
//! buildings side by side on the same ground, each separated from the
//! next by a joint (a gap at one or more floors) where they may collide
//! under a recorded ground motion. The two-frame pair is the row of two;
//! one building alone is the row of one (an isolated building against its
//! moat wall). The row becomes a model of the library's kind (floors are
//! bodies on a line, storeys are springs and dampers or hysteretic
//! storeys, each joint's floors are contacts with any of the contact
//! laws), so a pounding run is a simulation like any other.
//!
//! ## Files
//! - `mod.rs` — the [`Row`] and its run;
//! - `file.rs` — the row (or pair) file and its errors;
//! - `frame.rs`, `building.rs` — a shear frame; a building placed in the
//!   row (fixed or isolated, its moat);
//! - `response.rs` — what a run gives back: peaks, collapse, loops, stop;
//! - `peaks.rs` — the peaks of a run, taken as its samples stream by;
//! - `study.rs`, `documents.rs` — the study every face runs, its documents;
//! - `spectrum.rs`, `moat.rs` — pounding spectra; moat-gap studies;
//! - `tests/` — frames, pairs (`mod.rs`) and rows, isolation (`rows.rs`).
//!
//! Each frame has floor masses m_i, storey stiffnesses k_i (storey i joins
//! floor i − 1, or the ground for i = 1, to floor i) and Rayleigh damping
//! C = αM + βK with the ratio ζ in its first two modes (one storey: ζ
//! exactly). In the floors' displacements relative to the ground, C is a
//! damper α m_i from each floor to the ground and a damper β k_i beside
//! each storey spring: exactly the model's body dampers and couplings. A
//! building may stand on an isolation layer with a moat wall
//! ([`Building`]).

use crate::contact::ContactLaw;
use crate::field_error::FieldError;
use crate::integrate::{IntegrationError, Interrupt, Method};
use crate::model::record::Record;
use crate::model::{Accelerogram, BaseExcitation, Contact, ContactPair, Model};
use crate::simulate::{
    estimate_work, simulate_streaming, Integrator, SimulationOptions, WorkEstimate,
};

/// The free-vibration tail after the record for a row with yielding
/// storeys or hysteretic bearings, in fundamental periods of its
/// longest-period building.
pub const TAIL_PERIODS: f64 = 5.0;

/// Buildings side by side, left to right, a joint between each
/// neighbouring two.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The buildings, left to right.
    pub buildings: Vec<Building>,
    /// `joints[j]` between buildings j and j + 1.
    pub joints: Vec<Joint>,
}

/// A joint between two neighbouring buildings.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The gap at rest (m).
    pub gap: f64,
    /// The floors (1-based) at which they may collide, each at most the
    /// lower building's height.
    pub floors: Vec<usize>,
    /// The contact law of every pounding floor.
    pub law: ContactLaw,
}

/// The loosest relative tolerance a seismic run takes: looser controls no
/// error (issue 37's fuzzing: rtol 0.5 gave a yielding frame's peak drift
/// 3 times too large, and under a scale of 5e8 a run that did not end).
pub const MAX_RTOL: f64 = 1e-2;

/// The tightest: below it the error test asks for more than double
/// precision holds.
pub const MIN_RTOL: f64 = 1e-13;

/// How a pounding run is computed.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSettings {
    /// Sampling step of the hysteresis loops (s), and of the storeys'
    /// drift checks where finer than the record's step; peaks, residuals
    /// and impact forces are exact whatever the step.
    pub sample: f64,
    /// Relative tolerance of the integration (the absolute one is
    /// `rtol · 1e-4 · max(smallest gap, 1 mm)`, 1 mm without gaps).
    pub rtol: f64,
    /// Integration method: DOP853, or DOPRI5 for loose tolerances (a
    /// record's samples limit the step; docs/earthquakes.md).
    pub method: Method,
    /// Global, or local: each frame moves exactly between poundings, per
    /// record sample (docs/theory.md §10).
    pub integrator: Integrator,
    /// A stop request (Ctrl-C): every run of the study ends at its next
    /// step with [`PoundingError::Interrupted`].
    pub interrupt: Option<Interrupt>,
    /// Whether a run keeps its hysteretic storeys' loops at the samples
    /// (the CLI's figures): the peaks need none, and a run without them
    /// evaluates no storey force at the samples.
    pub loops: bool,
}

impl RunSettings {
    /// Sampling every `sample` s at tolerance `rtol` with DOP853, global,
    /// without the loops.
    pub fn new(sample: f64, rtol: f64) -> Self {
        Self {
            sample,
            rtol,
            method: Method::Dop853,
            integrator: Integrator::Global,
            interrupt: None,
            loops: false,
        }
    }
}

/// A record's sampling step (s): its mean spacing.
fn record_step(record: &Record) -> f64 {
    let t = &record.times;
    match t.len() {
        0 | 1 => f64::INFINITY,
        n => (t[n - 1] - t[0]) / (n - 1) as f64,
    }
}

/// Der Kiureghian's correlation of two oscillators with frequency ratio r
/// = ω_j/ω_i and damping ζ_i, ζ_j.
pub fn correlation(r: f64, zi: f64, zj: f64) -> f64 {
    let num = 8.0 * (zi * zj).sqrt() * (zi + r * zj) * r.powf(1.5);
    let den = (1.0 - r * r).powi(2)
        + 4.0 * zi * zj * r * (1.0 + r * r)
        + 4.0 * (zi * zi + zj * zj) * r * r;
    // Two undamped oscillators of one frequency move alike: ρ = 1 (the
    // formula is 0/0 there).
    if den == 0.0 {
        1.0
    } else {
        num / den
    }
}

/// A row's model with where each building's bodies, storeys and contacts
/// sit in it.
#[derive(Clone, Debug)]
pub struct RowModel {
    /// The model.
    pub model: Model,
    /// Per building.
    pub placements: Vec<Placement>,
    /// Per joint, its contacts (model indices, one per pounding floor).
    pub joints: Vec<Vec<usize>>,
}

impl Row {
    /// The pair: `left` and `right` frames (fixed) with one joint.
    pub fn pair(
        left: ShearFrame,
        right: ShearFrame,
        gap: f64,
        floors: Vec<usize>,
        law: ContactLaw,
    ) -> Self {
        let building = |name: &str, frame| Building {
            name: name.into(),
            frame,
            isolation: None,
        };
        Self {
            buildings: vec![building("left", left), building("right", right)],
            joints: vec![Joint { gap, floors, law }],
        }
    }

    /// What is legal but worth a word: an isolated building whose bearings'
    /// capacity is below its moat gap (the bearings pass their capacity
    /// before the slab can reach the wall).
    pub fn notes(&self) -> Vec<String> {
        self.buildings
            .iter()
            .filter_map(|b| {
                let iso = b.isolation.as_ref()?;
                let (c, gap) = (iso.capacity?, iso.moat.as_ref()?.gap);
                (c < gap).then(|| {
                    format!(
                        "building {}: the bearings' capacity {c} m is below the moat gap {gap} m: they pass it before the slab can reach the wall",
                        b.name
                    )
                })
            })
            .collect()
    }

    /// Checks the row: at least one building (one alone: an isolated
    /// building and its moat wall), distinct names, each checked; a joint
    /// between each two neighbours with a finite gap ≥ 0 and floors of
    /// both. Errors name the building or joint.
    pub fn check(&self) -> Result<(), PoundingError> {
        let pair = PoundingError::pair;
        if self.buildings.is_empty() {
            return Err(pair("building", "no building: give at least one".into()));
        }
        for (k, b) in self.buildings.iter().enumerate() {
            if self.buildings[..k].iter().any(|o| o.name == b.name) {
                return Err(pair(
                    "name",
                    format!("building name {:?} is used twice", b.name),
                ));
            }
            b.check(&self.what(k)).map_err(|m| pair(self.key(k), m))?;
        }
        if self.joints.len() + 1 != self.buildings.len() {
            return Err(pair(
                "joint",
                format!(
                    "{} joints for {} buildings: give one between each two neighbours",
                    self.joints.len(),
                    self.buildings.len()
                ),
            ));
        }
        for (j, joint) in self.joints.iter().enumerate() {
            let what = self.joint_name(j);
            if !(joint.gap.is_finite() && joint.gap >= 0.0) {
                return Err(pair(
                    "gap",
                    format!("{what}gap {}: give a finite gap >= 0", joint.gap),
                ));
            }
            if joint.floors.is_empty() {
                return Err(pair(
                    "floors",
                    format!("{what}floors: give at least one pounding floor"),
                ));
            }
            let top = self.buildings[j]
                .floors()
                .min(self.buildings[j + 1].floors());
            if let Some(f) = joint
                .floors
                .iter()
                .enumerate()
                .find_map(|(i, f)| joint.floors[..i].contains(f).then_some(f))
            {
                return Err(pair(
                    "floors",
                    format!("{what}floors: floor {f} is given twice"),
                ));
            }
            if let Some(f) = joint.floors.iter().find(|f| **f == 0 || **f > top) {
                return Err(pair(
                    "floors",
                    format!(
                        "{what}floors: floor {f} is not a floor of both buildings (1 to {top})"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Whether this is the two-frame pair of a pair file.
    fn is_pair(&self) -> bool {
        self.buildings.len() == 2
            && self.buildings[0].name == "left"
            && self.buildings[1].name == "right"
    }

    /// Building k in messages: `left frame` in a pair, else `building NAME`.
    fn what(&self, k: usize) -> String {
        if self.is_pair() {
            format!("{} frame", self.buildings[k].name)
        } else {
            format!("building {}", self.buildings[k].name)
        }
    }

    /// Building k's key in errors: `left`/`right` in a pair, else
    /// `building`.
    fn key(&self, k: usize) -> &'static str {
        match (self.is_pair(), k) {
            (true, 0) => "left",
            (true, _) => "right",
            _ => "building",
        }
    }

    /// Joint j in messages: nothing for a pair's one joint, else `joint
    /// A–B: `.
    fn joint_name(&self, j: usize) -> String {
        if self.is_pair() {
            String::new()
        } else {
            format!(
                "joint {}–{}: ",
                self.buildings[j].name,
                self.buildings[j + 1].name
            )
        }
    }

    /// The row as a model under `record` × `scale`: each building's bodies
    /// left to right on one line; a contact per joint floor and the moat
    /// walls if `contacts`.
    pub fn model(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
    ) -> Result<RowModel, PoundingError> {
        self.check()?;
        let mut parts = Parts::default();
        let tags = self.tags();
        let placements = self
            .buildings
            .iter()
            .enumerate()
            .map(|(k, b)| {
                b.place(&tags[k], &mut parts, contacts)
                    .map_err(|m| PoundingError::pair(self.key(k), format!("{}: {m}", self.what(k))))
            })
            .collect::<Result<Vec<_>, _>>()?;
        let joints = self
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                if !contacts {
                    return Vec::new();
                }
                let (a, b) = (&placements[j], &placements[j + 1]);
                joint
                    .floors
                    .iter()
                    .map(|&f| {
                        parts.contacts.push(Contact {
                            pair: ContactPair::Bodies {
                                left: a.first_floor + f - 1,
                                right: b.first_floor + f - 1,
                            },
                            clearance: joint.gap,
                            law: joint.law,
                        });
                        parts.contacts.len() - 1
                    })
                    .collect()
            })
            .collect();
        let (times, acceleration) = self.excitation(record);
        let base = BaseExcitation::Record(
            Accelerogram::new(times, acceleration, scale)
                .map_err(|e| PoundingError::run(record, e))?,
        );
        let model = Model::new(
            parts.bodies,
            parts.couplings,
            parts.contacts,
            base,
            Vec::new(),
            Vec::new(),
            Vec::new(),
        )
        .and_then(|m| m.with_storeys(parts.storeys))
        .and_then(|mut m| {
            // Rigid moat walls (docs/theory.md §12).
            for (b, p) in self.buildings.iter().zip(&placements) {
                let moat = b.isolation.as_ref().and_then(|i| i.moat.as_ref());
                for (&k, moat) in p.moat.iter().zip(std::iter::repeat(moat).flatten()) {
                    m = m.with_impacts(k, moat.impacts)?;
                }
            }
            Ok(m)
        })
        .map_err(|e| PoundingError::Pair {
            file: None,
            line: None,
            key: None,
            message: e.to_string(),
        })?;
        Ok(RowModel {
            model,
            placements,
            joints,
        })
    }

    /// The body-name prefix of each building: `L` and `R` for a pair, else
    /// `B1`, `B2`, … followed by a dot.
    fn tags(&self) -> Vec<String> {
        if self.is_pair() {
            vec!["L".into(), "R".into()]
        } else {
            (1..=self.buildings.len())
                .map(|k| format!("B{k}."))
                .collect()
        }
    }

    /// The ground motion a run takes: the record, and after it, for a row
    /// with yielding storeys or hysteretic bearings, a free-vibration tail
    /// of [`TAIL_PERIODS`] of the longest fundamental period at rest (the
    /// residual drifts are read in its last period).
    fn excitation(&self, record: &Record) -> (Vec<f64>, Vec<f64>) {
        let n = record.times.len() + 2;
        let (mut times, mut acceleration) = (Vec::with_capacity(n), Vec::with_capacity(n));
        times.extend_from_slice(&record.times);
        acceleration.extend_from_slice(&record.acceleration);
        if let Some(tail) = self.tail() {
            let end = times.last().copied().unwrap_or(0.0);
            // One sample step down to rest (within the tail however coarse
            // the record).
            let dt = record.dt.unwrap_or(tail / 1000.0).min(0.5 * tail);
            times.extend([end + dt, end + tail]);
            acceleration.extend([0.0, 0.0]);
        }
        (times, acceleration)
    }

    /// The free-vibration tail's length (s), for a row with yielding
    /// storeys or hysteretic bearings.
    fn tail(&self) -> Option<f64> {
        self.buildings.iter().any(Building::inelastic).then(|| {
            TAIL_PERIODS
                * self
                    .buildings
                    .iter()
                    .map(Building::period)
                    .fold(0.0, f64::max)
        })
    }

    /// The peak response to `record` × `scale` over its duration, with the
    /// contacts or without (`contacts`): drifts, floor accelerations and
    /// displacements sampled as `run` says, impact forces the impact log's
    /// exact peaks. A run that does not converge is
    /// [`PoundingError::Diverged`].
    pub fn respond(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
        run: &RunSettings,
    ) -> Result<Response, PoundingError> {
        match self.respond_until(record, scale, contacts, run, None)? {
            (r, Stop::End | Stop::Limit { .. }) => Ok(r),
            (_, Stop::Diverged { message }) => Err(PoundingError::Diverged {
                record: record.source.clone(),
                scale,
                message,
            }),
        }
    }

    /// The work of one run under `record` × `scale` (with or without the
    /// contacts), estimated before it starts as a simulation's is
    /// ([`estimate_work`]): a long run says so up front. None where the
    /// run's checks refuse it (the run itself says why).
    pub fn estimate(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
        run: &RunSettings,
    ) -> Result<Option<WorkEstimate>, PoundingError> {
        let rm = self.model(record, scale, contacts)?;
        let opts = SimulationOptions {
            storey_forces: run.loops,
            ..self.options(record, run)?
        };
        Ok(estimate_work(&rm.model, &opts))
    }

    /// [`Row::respond`], stopped as soon as a sampled storey drift passes
    /// its limit in `limits` (m, per building and storey, if given), and
    /// kept (not an error) where the run does not
    /// converge: the response up to the stop, and why it stopped. Not
    /// converging is a step size that underflows or the step limit; the
    /// other early ends (an explicit method's stiffness, no progress) depend
    /// on the method, not the structure, and stay errors.
    pub fn respond_until(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
        run: &RunSettings,
        limits: Option<&[Vec<f64>]>,
    ) -> Result<(Response, Stop), PoundingError> {
        let rm = self.model(record, scale, contacts)?;
        let mut opts = SimulationOptions {
            storey_forces: run.loops,
            ..self.options(record, run)?
        };
        let mut peaks = Peaks::new(self, &rm, opts.t_end, run.loops);
        opts.gauges = peaks.gauges();
        opts.extrema_window = Some((0.0, opts.t_end));
        opts.extrema_of_bodies = false;
        // Every storey is checked against its limit (and its height: a
        // storey moved more than its height has collapsed, and a run past
        // it only grows absurd) at least every record sample, whatever
        // the sampling of the loops: the output step is the sample split
        // into `every` parts no longer than the record's step.
        let heights: Vec<Vec<f64>> = self
            .buildings
            .iter()
            .map(|b| {
                let n = b.frame.masses.len();
                (0..n)
                    .map(|i| b.frame.heights.get(i).copied().unwrap_or(f64::INFINITY))
                    .collect()
            })
            .collect();
        let bounds: Vec<Vec<f64>> = match limits {
            Some(l) => l
                .iter()
                .zip(&heights)
                .map(|(l, h)| l.iter().zip(h).map(|(l, h)| l.min(*h)).collect())
                .collect(),
            None => heights.clone(),
        };
        let record_step = record_step(record);
        let every = if run.sample >= opts.t_end {
            // One sample of the loops (at 0), the checks at the record's.
            opts.output_step = Some(record_step.min(opts.t_end));
            u64::MAX
        } else {
            let every = (run.sample / record_step).ceil().max(1.0);
            opts.output_step = Some(run.sample / every);
            every as u64
        };
        let model = &rm.model;
        let drift_limits = peaks.limits(&bounds);
        let (mut passed, mut collapse, mut k) = (None, None, 0u64);
        let sim = simulate_streaming(model, &opts, |t, row| {
            let worst = peaks.check(row, &drift_limits);
            if run.loops && k % every == 0 {
                peaks.sample(row);
            }
            k += 1;
            if let Some((building, storey)) = worst {
                passed = Some(t);
                if bounds[building][storey] == heights[building][storey] {
                    collapse = Some(Collapse {
                        building,
                        storey,
                        time: t,
                    });
                }
            }
            passed.is_none()
        })
        .map_err(|e| PoundingError::run(record, e.0))?;
        let stop = match (&sim.error, passed) {
            (_, Some(time)) if limits.is_some() => Stop::Limit { time },
            (_, Some(_)) => Stop::End,
            (None, None) => Stop::End,
            (Some(e), None) => match e.source {
                IntegrationError::StepSizeUnderflow { .. }
                | IntegrationError::TooManySteps { .. } => Stop::Diverged {
                    message: e.to_string(),
                },
                IntegrationError::Interrupted { .. } => return Err(PoundingError::Interrupted),
                _ => return Err(PoundingError::run(record, e)),
            },
        };
        let mut response = peaks.finish(self, &rm, &sim);
        response.collapse = collapse;
        Ok((response, stop))
    }

    /// The time history of the row with its contacts under `record` ×
    /// `scale`, sampled every `run.sample` seconds: every body's
    /// displacement (the model's body order: building by building, left
    /// to right), the hysteretic storeys' loops and the impact log, with
    /// the model it ran.
    pub fn history(
        &self,
        record: &Record,
        scale: f64,
        run: &RunSettings,
    ) -> Result<History, PoundingError> {
        let rm = self.model(record, scale, true)?;
        let opts = SimulationOptions {
            storey_forces: true,
            ..self.options(record, run)?
        };
        let n = rm.model.bodies().len();
        let mut peaks = Peaks::new(self, &rm, opts.t_end, true);
        let (mut times, mut displacement) = (Vec::new(), Vec::new());
        let model = &rm.model;
        let sim = simulate_streaming(model, &opts, |t, row| {
            times.push(t);
            displacement.extend_from_slice(&row[..n]);
            peaks.sample(row);
            true
        })
        .map_err(|e| PoundingError::run(record, e.0))?;
        if let Some(e) = &sim.error {
            return Err(PoundingError::run(record, e));
        }
        let loops = peaks.finish(self, &rm, &sim).loops;
        Ok(History {
            model: rm,
            times,
            displacement,
            impacts: sim.impacts,
            loops,
        })
    }

    fn options(
        &self,
        record: &Record,
        run: &RunSettings,
    ) -> Result<SimulationOptions, PoundingError> {
        if !(run.sample.is_finite() && run.sample > 0.0) {
            return Err(FieldError::new("sample", run.sample, "give a positive step").into());
        }
        if !(MIN_RTOL..=MAX_RTOL).contains(&run.rtol) {
            let m = "give a relative tolerance in [1e-13, 1e-2]: a looser one controls no error (at 0.5 a yielding frame's peak drift came out 3 times too large, and a run under a large scale did not end), a tighter one is below double precision";
            return Err(FieldError::new("rtol", run.rtol, m).into());
        }
        let moats = self
            .buildings
            .iter()
            .filter_map(|b| b.isolation.as_ref()?.moat.as_ref().map(|m| m.gap));
        let gap = self
            .joints
            .iter()
            .map(|j| j.gap)
            .chain(moats)
            .fold(f64::INFINITY, f64::min);
        Ok(SimulationOptions {
            t_end: record.times.last().copied().unwrap_or(0.0) + self.tail().unwrap_or(0.0),
            rtol: run.rtol,
            // 1 mm where there is no gap (a building alone).
            atol: run.rtol * 1e-4 * if gap.is_finite() { gap.max(1e-3) } else { 1e-3 },
            output_step: Some(run.sample),
            method: run.method,
            integrator: run.integrator,
            interrupt: run.interrupt.clone(),
            ..SimulationOptions::default()
        })
    }

    /// The pounding study of one record: the row with and without its
    /// contacts, and per joint the gap that avoids contact and the code
    /// rules' gaps.
    pub fn analyse(
        &self,
        record: &Record,
        scale: f64,
        run: &RunSettings,
    ) -> Result<PoundingResult, PoundingError> {
        let pounding = self.respond(record, scale, true, run)?;
        let free = self.respond(record, scale, false, run)?;
        let joints = self
            .joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                let required_gap = free.closing[j].iter().fold(0.0f64, |m, c| m.max(*c));
                let peak = |k: usize| {
                    joint
                        .floors
                        .iter()
                        .fold(0.0f64, |m, &f| m.max(free.displacement[k][f - 1]))
                };
                let (ul, ur) = (peak(j), peak(j + 1));
                let (a, b) = (&self.buildings[j], &self.buildings[j + 1]);
                let rho = correlation(
                    b.frequency() / a.frequency(),
                    a.frame.damping_ratio,
                    b.frame.damping_ratio,
                );
                JointGaps {
                    required_gap,
                    code_gaps: CodeGaps {
                        absolute_sum: ul + ur,
                        srss: (ul * ul + ur * ur).sqrt(),
                        // ≥ (u_L − u_R)² ≥ 0 for ρ ≤ 1; the max only guards rounding.
                        double_difference: (ul * ul + ur * ur - 2.0 * rho * ul * ur)
                            .max(0.0)
                            .sqrt(),
                        correlation: rho,
                    },
                }
            })
            .collect();
        Ok(PoundingResult {
            pounding,
            free,
            joints,
        })
    }
}

mod building;
mod file;
mod frame;
mod moat;
mod peaks;
mod response;
mod spectrum;
mod study;

use building::Parts;
pub use building::{Bearing, Building, Isolation, Moat, Placement, Wall, GRAVITY};
pub use file::{parse_row, PoundingError};
pub use frame::{Gravity, ShearFrame};
pub use moat::{moat_study, MoatCell};
use peaks::Peaks;
pub use response::{
    CodeGaps, Collapse, History, IsolatorResponse, JointGaps, PoundingResult, Response, Stop,
    StoreyLoop,
};
pub use spectrum::{pounding_spectrum, quantile, value_range, with_period_ratio, SpectrumCell};
pub use study::{Outcome, Study};

pub mod documents;

#[cfg(test)]
pub(crate) mod tests;
