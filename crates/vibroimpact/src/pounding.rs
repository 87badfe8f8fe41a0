//! Pounding of adjacent structures (docs/earthquakes.md): two shear frames
//! side by side on the same ground, separated by a gap at one or more
//! floors where they may collide under a recorded ground motion. The pair
//! becomes a model of the library's kind (floors are bodies on a line,
//! storeys are springs and dampers, the gap is a contact with any of the
//! contact laws), so a pounding run is a simulation like any other.
//!
//! Each frame has floor masses m_i, storey stiffnesses k_i (storey i joins
//! floor i − 1, or the ground for i = 1, to floor i) and Rayleigh damping
//! C = αM + βK with the ratio ζ in its first two modes (one storey: ζ
//! exactly). In the floors' displacements relative to the ground, C is a
//! damper α m_i from each floor to the ground and a damper β k_i beside
//! each storey spring: exactly the model's body dampers and couplings.

use crate::contact::ContactLaw;
use crate::field_error::FieldError;
use crate::hysteresis::StoreyLaw;
use crate::integrate::Method;
use crate::model::{
    Accelerogram, BaseExcitation, Body, Contact, ContactPair, Coupling, Model, Storey,
};
use crate::record::Record;
use crate::simulate::{simulate_streaming, Integrator, SimulationOptions};

/// The free-vibration tail after the record for a pair with yielding
/// storeys, in fundamental periods of the longer-period frame.
pub const TAIL_PERIODS: f64 = 5.0;

/// Two frames side by side, `left` of `right`, with a gap at some floors.
#[derive(Clone, Debug)]
pub struct PoundingPair {
    /// The frame on the left.
    pub left: ShearFrame,
    /// The frame on the right.
    pub right: ShearFrame,
    /// The gap at rest (m).
    pub gap: f64,
    /// The floors (1-based) at which they may collide, each at most the
    /// lower frame's height.
    pub floors: Vec<usize>,
    /// The contact law of every pounding floor.
    pub law: ContactLaw,
}

/// How a pounding run is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RunSettings {
    /// Sampling step of drifts, floor accelerations and displacements (s);
    /// impact forces are the impact log's exact peaks whatever the step.
    pub sample: f64,
    /// Relative tolerance of the integration (the absolute one is
    /// `rtol · 1e-4 · max(gap, 1 mm)`).
    pub rtol: f64,
    /// Integration method: DOP853, or DOPRI5 for loose tolerances (a
    /// record's samples limit the step; docs/earthquakes.md).
    pub method: Method,
    /// Global, or local: each frame moves exactly between poundings, per
    /// record sample (docs/theory.md §10).
    pub integrator: Integrator,
}

impl RunSettings {
    /// Sampling every `sample` s at tolerance `rtol` with DOP853, global.
    pub fn new(sample: f64, rtol: f64) -> Self {
        Self {
            sample,
            rtol,
            method: Method::Dop853,
            integrator: Integrator::Global,
        }
    }
}

/// The peak response of the two frames to one record.
#[derive(Clone, Debug, PartialEq)]
pub struct Response {
    /// Peak storey drifts max |u_i − u_{i−1}| (m), left then right frame.
    pub drift: [Vec<f64>; 2],
    /// Residual storey drifts (m, signed): the mean drift over each frame's
    /// last fundamental period (of the free-vibration tail that follows the
    /// record for yielding storeys).
    pub residual_drift: [Vec<f64>; 2],
    /// Peak absolute floor accelerations max |ü_i + a_g| over the samples
    /// (m/s²), left then right.
    pub acceleration: [Vec<f64>; 2],
    /// Peak floor displacements relative to the ground (m).
    pub displacement: [Vec<f64>; 2],
    /// Largest impact force (N), 0 without impacts.
    pub peak_impact_force: f64,
    /// Impacts.
    pub impacts: usize,
    /// Per pounding floor, the largest closing max (u_left − u_right) (m).
    pub closing: Vec<f64>,
}

/// One record's pounding study: the pair with and without its contacts.
#[derive(Clone, Debug, PartialEq)]
pub struct PoundingResult {
    /// With the contacts.
    pub pounding: Response,
    /// The frames apart (no contacts).
    pub free: Response,
    /// The smallest gap that avoids contact: the largest closing of the
    /// free frames over the pounding floors (m; 0 if they never close).
    pub required_gap: f64,
    /// The code rules from the free frames' peak displacements u_L, u_R at
    /// the pounding floors (largest over them, m): absolute sum, SRSS, and
    /// the double difference `√(u_L² + u_R² − 2ρ u_L u_R)` with ρ the
    /// correlation of two oscillators of the frames' fundamental periods
    /// and damping (Der Kiureghian's CQC coefficient).
    pub code_gaps: CodeGaps,
}

/// Separation gaps of the code rules (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CodeGaps {
    /// u_L + u_R.
    pub absolute_sum: f64,
    /// √(u_L² + u_R²).
    pub srss: f64,
    /// √(u_L² + u_R² − 2ρ u_L u_R).
    pub double_difference: f64,
    /// ρ.
    pub correlation: f64,
}

/// Der Kiureghian's correlation of two oscillators with frequency ratio r
/// = ω_j/ω_i and damping ζ_i, ζ_j.
pub fn correlation(r: f64, zi: f64, zj: f64) -> f64 {
    let num = 8.0 * (zi * zj).sqrt() * (zi + r * zj) * r.powf(1.5);
    let den = (1.0 - r * r).powi(2)
        + 4.0 * zi * zj * r * (1.0 + r * r)
        + 4.0 * (zi * zi + zj * zj) * r * r;
    num / den
}

impl PoundingPair {
    /// Checks the pair.
    pub fn check(&self) -> Result<(), PoundingError> {
        let pair = PoundingError::pair;
        self.left.check("left frame").map_err(|m| pair("left", m))?;
        self.right
            .check("right frame")
            .map_err(|m| pair("right", m))?;
        if !(self.gap.is_finite() && self.gap >= 0.0) {
            return Err(pair(
                "gap",
                format!("gap {}: give a finite gap >= 0", self.gap),
            ));
        }
        let top = self.left.masses.len().min(self.right.masses.len());
        if self.floors.is_empty() {
            return Err(pair(
                "floors",
                "floors: give at least one pounding floor".into(),
            ));
        }
        if let Some(f) = self.floors.iter().find(|f| **f == 0 || **f > top) {
            return Err(pair(
                "floors",
                format!("floors: floor {f} is not a floor of both frames (1 to {top})"),
            ));
        }
        Ok(())
    }

    /// The pair as a model under `record` × `scale`: the left frame's
    /// floors, then the right frame's, on one line; a contact per pounding
    /// floor if `contacts`.
    pub fn model(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
    ) -> Result<Model, PoundingError> {
        self.check()?;
        let mut bodies = Vec::new();
        let mut couplings = Vec::new();
        let mut storeys = Vec::new();
        for (name, frame) in [("L", &self.left), ("R", &self.right)] {
            let first = bodies.len();
            let (alpha, beta) = frame.rayleigh();
            let laws = frame.laws().map_err(|m| PoundingError::Pair {
                file: None,
                line: None,
                key: Some("storeys"),
                message: m,
            })?;
            for (i, (&m, &k)) in frame.masses.iter().zip(&frame.stiffnesses).enumerate() {
                let ground = i == 0;
                let below = (!ground).then(|| first + i - 1);
                // A yielding storey's spring is its law; its damper (β k on
                // the initial stiffness) stays linear.
                let spring = match laws[i] {
                    StoreyLaw::Elastic { .. } => k,
                    law => {
                        storeys.push(Storey {
                            below,
                            above: first + i,
                            law,
                        });
                        0.0
                    }
                };
                bodies.push(Body {
                    name: format!("{name}{}", i + 1),
                    mass: m,
                    stiffness: if ground { spring } else { 0.0 },
                    damping: alpha * m + if ground { beta * k } else { 0.0 },
                });
                if let Some(a) = below {
                    couplings.push(Coupling {
                        a,
                        b: first + i,
                        stiffness: spring,
                        damping: beta * k,
                    });
                }
            }
        }
        let n_left = self.left.masses.len();
        let contact_list = if contacts {
            self.floors
                .iter()
                .map(|&f| Contact {
                    pair: ContactPair::Bodies {
                        left: f - 1,
                        right: n_left + f - 1,
                    },
                    clearance: self.gap,
                    law: self.law,
                })
                .collect()
        } else {
            Vec::new()
        };
        let (times, acceleration) = self.excitation(record);
        let base = BaseExcitation::Record(
            Accelerogram::new(times, acceleration, scale)
                .map_err(|e| PoundingError::run(record, e))?,
        );
        Model::new(
            bodies,
            couplings,
            contact_list,
            base,
            Vec::new(),
            Vec::new(),
            Vec::new(),
        )
        .and_then(|m| m.with_storeys(storeys))
        .map_err(|e| PoundingError::Pair {
            file: None,
            line: None,
            key: None,
            message: e.to_string(),
        })
    }

    /// The ground motion a run takes: the record, and after it, for a pair
    /// with yielding storeys, a free-vibration tail of [`TAIL_PERIODS`] of
    /// the longer fundamental period at rest (the residual drifts are read
    /// in its last period).
    fn excitation(&self, record: &Record) -> (Vec<f64>, Vec<f64>) {
        let (mut times, mut acceleration) = (record.times.clone(), record.acceleration.clone());
        if let Some(tail) = self.tail() {
            let end = times.last().copied().unwrap_or(0.0);
            let dt = record.dt.unwrap_or(tail / 1000.0);
            times.extend([end + dt, end + tail]);
            acceleration.extend([0.0, 0.0]);
        }
        (times, acceleration)
    }

    /// The free-vibration tail's length (s), for a pair with yielding
    /// storeys.
    fn tail(&self) -> Option<f64> {
        (self.left.inelastic() || self.right.inelastic())
            .then(|| TAIL_PERIODS * self.left.period().max(self.right.period()))
    }

    /// The peak response to `record` × `scale` over its duration, with the
    /// contacts or without (`contacts`): drifts, floor accelerations and
    /// displacements sampled as `run` says, impact forces the impact log's
    /// exact peaks.
    pub fn respond(
        &self,
        record: &Record,
        scale: f64,
        contacts: bool,
        run: &RunSettings,
    ) -> Result<Response, PoundingError> {
        let model = self.model(record, scale, contacts)?;
        let opts = SimulationOptions {
            accelerations: true,
            ..self.options(record, run)?
        };
        let nl = self.left.masses.len();
        let n = model.bodies().len();
        let mut drift = [vec![0.0f64; nl], vec![0.0f64; n - nl]];
        let mut acceleration = drift.clone();
        let mut displacement = drift.clone();
        // The residual drifts: the mean drift over the last fundamental
        // period of each frame (of the free-vibration tail where there is
        // one).
        let windows = [self.left.period(), self.right.period()].map(|p| opts.t_end - p);
        let mut residual = [(vec![0.0f64; nl], 0usize), (vec![0.0f64; n - nl], 0usize)];
        let mut closing = vec![f64::NEG_INFINITY; self.floors.len()];
        // Peaks taken as the samples stream by (nothing stored); a sample
        // is [u.., v.., a..].
        let sim = simulate_streaming(&model, &opts, |t, row| {
            let (u, a) = (&row[..n], &row[2 * n..]);
            let ag = model.base().at(t);
            for (side, (start, len)) in [(0, nl), (nl, n - nl)].into_iter().enumerate() {
                let late = t >= windows[side];
                for i in 0..len {
                    let below = if i == 0 { 0.0 } else { u[start + i - 1] };
                    let d = u[start + i] - below;
                    drift[side][i] = drift[side][i].max(d.abs());
                    displacement[side][i] = displacement[side][i].max(u[start + i].abs());
                    acceleration[side][i] = acceleration[side][i].max((a[start + i] + ag).abs());
                    if late {
                        residual[side].0[i] += d;
                    }
                }
                residual[side].1 += usize::from(late);
            }
            for (c, &f) in self.floors.iter().enumerate() {
                closing[c] = closing[c].max(u[f - 1] - u[nl + f - 1]);
            }
            true
        })
        .map_err(|e| PoundingError::run(record, e.0))?;
        if let Some(e) = &sim.error {
            return Err(PoundingError::run(record, e));
        }
        let residual_drift =
            residual.map(|(sum, count)| sum.iter().map(|s| s / count.max(1) as f64).collect());
        Ok(Response {
            drift,
            residual_drift,
            acceleration,
            displacement,
            peak_impact_force: sim.impacts.iter().fold(0.0, |m, i| m.max(i.peak_force)),
            impacts: sim.impacts.len(),
            closing,
        })
    }

    /// The time history of the pair with its contacts under `record` ×
    /// `scale`: every floor's displacement sampled every `run.sample`
    /// seconds (body order: the left frame's floors, then the right
    /// frame's) and the impact log.
    pub fn history(
        &self,
        record: &Record,
        scale: f64,
        run: &RunSettings,
    ) -> Result<crate::simulate::Simulation, PoundingError> {
        let model = self.model(record, scale, true)?;
        let sim = crate::simulate::simulate(&model, &self.options(record, run)?)
            .map_err(|e| PoundingError::run(record, e.0))?;
        match &sim.error {
            Some(e) => Err(PoundingError::run(record, e)),
            None => Ok(sim),
        }
    }

    fn options(
        &self,
        record: &Record,
        run: &RunSettings,
    ) -> Result<SimulationOptions, PoundingError> {
        if !(run.sample.is_finite() && run.sample > 0.0) {
            return Err(FieldError::new("sample", run.sample, "give a positive step").into());
        }
        Ok(SimulationOptions {
            t_end: record.times.last().copied().unwrap_or(0.0) + self.tail().unwrap_or(0.0),
            rtol: run.rtol,
            atol: run.rtol * 1e-4 * self.gap.max(1e-3),
            output_step: Some(run.sample),
            method: run.method,
            integrator: run.integrator,
            ..SimulationOptions::default()
        })
    }

    /// The pounding study of one record: the pair with and without its
    /// contacts, the gap that avoids contact and the code rules' gaps.
    pub fn analyse(
        &self,
        record: &Record,
        scale: f64,
        run: &RunSettings,
    ) -> Result<PoundingResult, PoundingError> {
        let pounding = self.respond(record, scale, true, run)?;
        let free = self.respond(record, scale, false, run)?;
        let required_gap = free.closing.iter().fold(0.0f64, |m, c| m.max(*c));
        let ul = self
            .floors
            .iter()
            .fold(0.0f64, |m, &f| m.max(free.displacement[0][f - 1]));
        let ur = self
            .floors
            .iter()
            .fold(0.0f64, |m, &f| m.max(free.displacement[1][f - 1]));
        let (wl, wr) = (
            self.left.natural_frequencies()[0],
            self.right.natural_frequencies()[0],
        );
        let rho = correlation(wr / wl, self.left.damping_ratio, self.right.damping_ratio);
        Ok(PoundingResult {
            pounding,
            free,
            required_gap,
            code_gaps: CodeGaps {
                absolute_sum: ul + ur,
                srss: (ul * ul + ur * ur).sqrt(),
                // ≥ (u_L − u_R)² ≥ 0 for ρ ≤ 1; the max only guards rounding.
                double_difference: (ul * ul + ur * ur - 2.0 * rho * ul * ur).max(0.0).sqrt(),
                correlation: rho,
            },
        })
    }
}

#[path = "pounding_file.rs"]
mod file;
#[path = "pounding_frame.rs"]
mod frame;
#[path = "pounding_spectrum.rs"]
mod spectrum;

pub use file::{parse_pair, PoundingError};
pub use frame::ShearFrame;
pub use spectrum::{pounding_spectrum, quantile, value_range, with_period_ratio, SpectrumCell};

#[path = "pounding_documents.rs"]
pub mod documents;

#[cfg(test)]
#[path = "pounding_tests.rs"]
mod tests;
