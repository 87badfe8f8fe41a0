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

use nalgebra::{DMatrix, SymmetricEigen};

use crate::contact::ContactLaw;
use crate::dynamics::ChainDynamics;
use crate::field_error::FieldError;
use crate::integrate::{Method, OdeSystem};
use crate::model::{Accelerogram, BaseExcitation, Body, Contact, ContactPair, Coupling, Model};
use crate::record::Record;
use crate::simulate::{simulate_streaming, Integrator, SimulationOptions};

/// A shear frame: floors from the ground up.
#[derive(Clone, Debug, PartialEq)]
pub struct ShearFrame {
    /// Floor masses (kg), from the first floor up.
    pub masses: Vec<f64>,
    /// Storey stiffnesses (N/m): storey i joins floor i − 1 (the ground for
    /// i = 1) to floor i.
    pub stiffnesses: Vec<f64>,
    /// Rayleigh damping ratio in the first two modes.
    pub damping_ratio: f64,
}

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
    fn pair(key: &'static str, message: String) -> Self {
        PoundingError::Pair {
            file: None,
            line: None,
            key: Some(key),
            message,
        }
    }

    /// A run under `record` failed.
    fn run(record: &Record, message: impl ToString) -> Self {
        PoundingError::Run {
            record: record.source.clone(),
            message: message.to_string(),
        }
    }

    /// The error with the pair file it came from.
    fn in_file(self, source: &str) -> Self {
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

impl ShearFrame {
    /// Checks the frame: as many storeys as floors, masses and stiffnesses
    /// positive and finite, a damping ratio in [0, 1).
    pub fn check(&self, name: &str) -> Result<(), String> {
        if self.masses.is_empty() || self.masses.len() != self.stiffnesses.len() {
            return Err(format!(
                "{name}: {} masses and {} storey stiffnesses; give one of each per floor",
                self.masses.len(),
                self.stiffnesses.len()
            ));
        }
        for (i, (m, k)) in self.masses.iter().zip(&self.stiffnesses).enumerate() {
            if !(m.is_finite() && *m > 0.0 && k.is_finite() && *k > 0.0) {
                return Err(format!(
                    "{name}: floor {}: mass {m} and stiffness {k} must be positive and finite",
                    i + 1
                ));
            }
        }
        if !(self.damping_ratio.is_finite() && (0.0..1.0).contains(&self.damping_ratio)) {
            return Err(format!(
                "{name}: damping ratio {}: give a value in [0, 1)",
                self.damping_ratio
            ));
        }
        Ok(())
    }

    /// The stiffness matrix K (tridiagonal).
    fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.masses.len();
        let k = &self.stiffnesses;
        DMatrix::from_fn(n, n, |r, c| {
            if r == c {
                k[r] + k.get(r + 1).copied().unwrap_or(0.0)
            } else if r + 1 == c {
                -k[c]
            } else if c + 1 == r {
                -k[r]
            } else {
                0.0
            }
        })
    }

    /// The natural circular frequencies (rad/s), lowest first: the
    /// eigenvalues of M^{-1/2} K M^{-1/2}.
    pub fn natural_frequencies(&self) -> Vec<f64> {
        let k = self.stiffness_matrix();
        let s: Vec<f64> = self.masses.iter().map(|m| 1.0 / m.sqrt()).collect();
        let n = s.len();
        let a = DMatrix::from_fn(n, n, |r, c| s[r] * k[(r, c)] * s[c]);
        let mut w: Vec<f64> = SymmetricEigen::new(a)
            .eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt())
            .collect();
        w.sort_by(f64::total_cmp);
        w
    }

    /// The fundamental period T1 (s).
    pub fn period(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.natural_frequencies()[0]
    }

    /// Rayleigh's (α, β) with ζ in modes 1 and 2 (one storey: β = 0, α = 2ζω).
    pub fn rayleigh(&self) -> (f64, f64) {
        let w = self.natural_frequencies();
        let z = self.damping_ratio;
        match w.as_slice() {
            [w1] => (2.0 * z * w1, 0.0),
            [w1, w2, ..] => {
                let alpha = 2.0 * z * w1 * w2 / (w1 + w2);
                (alpha, 2.0 * z / (w1 + w2))
            }
            [] => (0.0, 0.0),
        }
    }
}

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
        for (name, frame) in [("L", &self.left), ("R", &self.right)] {
            let first = bodies.len();
            let (alpha, beta) = frame.rayleigh();
            for (i, (&m, &k)) in frame.masses.iter().zip(&frame.stiffnesses).enumerate() {
                let ground = i == 0;
                bodies.push(Body {
                    name: format!("{name}{}", i + 1),
                    mass: m,
                    stiffness: if ground { k } else { 0.0 },
                    damping: alpha * m + if ground { beta * k } else { 0.0 },
                });
                if !ground {
                    couplings.push(Coupling {
                        a: first + i - 1,
                        b: first + i,
                        stiffness: k,
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
        let base = BaseExcitation::Record(
            Accelerogram::new(record.times.clone(), record.acceleration.clone(), scale)
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
        .map_err(|e| PoundingError::Pair {
            file: None,
            line: None,
            key: None,
            message: e.to_string(),
        })
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
        let opts = self.options(record, run)?;
        let nl = self.left.masses.len();
        let n = model.bodies().len();
        let mut dynamics = ChainDynamics::new(&model, false);
        let (mut y, mut dy) = (vec![0.0; 2 * n], vec![0.0; 2 * n]);
        let mut drift = [vec![0.0f64; nl], vec![0.0f64; n - nl]];
        let mut acceleration = drift.clone();
        let mut displacement = drift.clone();
        let mut closing = vec![f64::NEG_INFINITY; self.floors.len()];
        // Peaks taken as the samples stream by (nothing stored).
        let sim = simulate_streaming(&model, &opts, |t, row| {
            let u = &row[..n];
            for (i, (&x, &v)) in row[..n].iter().zip(&row[n..]).enumerate() {
                (y[2 * i], y[2 * i + 1]) = (x, v);
            }
            dynamics.rhs(t, &y, &mut dy);
            let ag = model.base().at(t);
            for (side, (start, len)) in [(0, nl), (nl, n - nl)].into_iter().enumerate() {
                for i in 0..len {
                    let below = if i == 0 { 0.0 } else { u[start + i - 1] };
                    drift[side][i] = drift[side][i].max((u[start + i] - below).abs());
                    displacement[side][i] = displacement[side][i].max(u[start + i].abs());
                    let a = dy[2 * (start + i) + 1] + ag;
                    acceleration[side][i] = acceleration[side][i].max(a.abs());
                }
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
        Ok(Response {
            drift,
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
            t_end: record.times.last().copied().unwrap_or(0.0),
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

/// One cell of a pounding spectrum: a gap and a period ratio, over the
/// records.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectrumCell {
    /// The gap (m).
    pub gap: f64,
    /// T_left / T_right (the right frame's stiffnesses scaled to it).
    pub period_ratio: f64,
    /// Per record: the largest impact force (N).
    pub impact_force: Vec<f64>,
    /// Per record: the impacts.
    pub impacts: Vec<usize>,
    /// Per record: the largest ratio of a storey drift with pounding to the
    /// same drift of the free frames, over both frames.
    pub drift_amplification: Vec<f64>,
    /// Per record: the gap that avoids contact (m).
    pub required_gap: Vec<f64>,
}

/// The pair with the right frame's stiffnesses scaled so that T_left /
/// T_right = `ratio`.
pub fn with_period_ratio(pair: &PoundingPair, ratio: f64) -> Result<PoundingPair, PoundingError> {
    if !(ratio.is_finite() && ratio > 0.0) {
        return Err(FieldError::new("ratios", ratio, "give positive period ratios").into());
    }
    pair.check()?;
    let factor = (pair.right.period() * ratio / pair.left.period()).powi(2);
    let mut out = pair.clone();
    out.right.stiffnesses.iter_mut().for_each(|k| *k *= factor);
    Ok(out)
}

/// The pounding spectrum: every (gap, period ratio) cell over `records`
/// (each with its scale), in parallel, cells gap-major; each record's run
/// as `run` says. The same numbers at any thread count.
pub fn pounding_spectrum(
    pair: &PoundingPair,
    records: &[(Record, f64)],
    gaps: &[f64],
    ratios: &[f64],
    run: &RunSettings,
) -> Result<Vec<SpectrumCell>, PoundingError> {
    use rayon::prelude::*;
    for (field, empty) in [
        ("records", records.is_empty()),
        ("gaps", gaps.is_empty()),
        ("ratios", ratios.is_empty()),
    ] {
        if empty {
            let message = "a pounding spectrum needs records, gaps and period ratios";
            return Err(FieldError::about(field, message).into());
        }
    }
    if let Some(g) = gaps.iter().find(|g| !(g.is_finite() && **g >= 0.0)) {
        return Err(FieldError::new("gaps", g, "give finite gaps >= 0").into());
    }
    let pairs: Vec<PoundingPair> = ratios
        .iter()
        .map(|&r| with_period_ratio(pair, r))
        .collect::<Result<_, _>>()?;
    let cells: Vec<(usize, usize)> = (0..gaps.len())
        .flat_map(|g| (0..ratios.len()).map(move |r| (g, r)))
        .collect();
    cells
        .par_iter()
        .map(|&(g, r)| {
            let p = PoundingPair {
                gap: gaps[g],
                ..pairs[r].clone()
            };
            let mut cell = SpectrumCell {
                gap: gaps[g],
                period_ratio: ratios[r],
                impact_force: Vec::new(),
                impacts: Vec::new(),
                drift_amplification: Vec::new(),
                required_gap: Vec::new(),
            };
            for (record, scale) in records {
                let res = p.analyse(record, *scale, run)?;
                let amp = (0..2)
                    .flat_map(|side| {
                        let (a, b) = (&res.pounding.drift[side], &res.free.drift[side]);
                        a.iter()
                            .zip(b)
                            .map(|(x, y)| if *y > 0.0 { x / y } else { 1.0 })
                    })
                    .fold(0.0f64, f64::max);
                cell.impact_force.push(res.pounding.peak_impact_force);
                cell.impacts.push(res.pounding.impacts);
                cell.drift_amplification.push(amp);
                cell.required_gap.push(res.required_gap);
            }
            Ok(cell)
        })
        .collect()
}

/// `FROM:TO:N` as N evenly spaced values (N = 1: FROM), the form of the
/// spectrum's gaps and period ratios; `field` names the option.
pub fn value_range(field: &'static str, text: &str) -> Result<Vec<f64>, FieldError> {
    let bad = || FieldError::new(field, text, "give FROM:TO:N, e.g. 0.01:0.1:10");
    let parts: Vec<&str> = text.split(':').collect();
    let [a, b, n] = parts.as_slice() else {
        return Err(bad());
    };
    let a: f64 = a.trim().parse().map_err(|_| bad())?;
    let b: f64 = b.trim().parse().map_err(|_| bad())?;
    let n: usize = n.trim().parse().map_err(|_| bad())?;
    if n == 0 || !a.is_finite() || !b.is_finite() || (n > 1 && a == b) {
        return Err(bad());
    }
    Ok((0..n)
        .map(|i| {
            if n == 1 {
                a
            } else {
                a + (b - a) * i as f64 / (n - 1) as f64
            }
        })
        .collect())
}

/// The empirical q-quantile (0 ≤ q ≤ 1) of `values` with linear
/// interpolation between order statistics (NaN for none).
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let x = q.clamp(0.0, 1.0) * (v.len() - 1) as f64;
    let (i, f) = (x.floor() as usize, x - x.floor());
    if i + 1 < v.len() {
        v[i] * (1.0 - f) + v[i + 1] * f
    } else {
        v[i]
    }
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct FrameSpec {
    masses: Vec<f64>,
    stiffnesses: Vec<f64>,
    damping_ratio: f64,
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

#[path = "pounding_documents.rs"]
pub mod documents;

#[cfg(test)]
#[path = "pounding_tests.rs"]
mod tests;
