//! What drives a model besides its initial state: the base's motion
//! (harmonic or a recorded accelerogram), harmonic forces on bodies, and
//! gravity along a vertical row.

use super::*;
use std::sync::Arc;

/// A base accelerogram: samples (t_k, a_k), linear interpolation, times a
/// scale factor; zero before the first and after the last sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Accelerogram {
    /// The samples, shared by its clones (a run copies its model's base
    /// into its dynamics: a record of 3,000 samples cost 0.1 ms a copy,
    /// most of it in page faults, issue 37's OpenSees benchmark).
    times: Arc<[f64]>,
    values: Arc<[f64]>,
    scale: f64,
    /// Samples per second at the median spacing: the first guess of a
    /// sample's segment (exact for a uniform record).
    rate: f64,
    /// Per segment k (samples k − 1, k): the scaled acceleration at its
    /// start and its slope, so that a value costs no division (the
    /// integrator asks a dozen a step: 25 % of a frame's run with the
    /// division, issue 37's OpenSees benchmark).
    lines: Arc<[[f64; 2]]>,
}

/// How far [`Accelerogram::at`] walks from its first guess before it falls
/// back to bisection (a record whose spacing varies a lot).
const SEGMENT_WALK: usize = 4;

/// How many of a record's spacings its rate's median is taken from at
/// most (the median of all 3,000 of a far-field record took a fifth of a
/// building row's model set-up).
const SPACINGS_FOR_RATE: usize = 64;

impl Accelerogram {
    /// From strictly increasing times and accelerations (m/s²). Errors name
    /// the first offending sample (0-based).
    pub fn new(times: Vec<f64>, values: Vec<f64>, scale: f64) -> Result<Self, ModelError> {
        if times.len() != values.len() || times.len() < 2 {
            return Err(ModelError::new(
                ModelErrorKind::Missing,
                "excitation.acceleration",
                "accelerogram: needs at least two (time, acceleration) samples",
            ));
        }
        // (The usual record passes both checks in one sweep without a
        // branch a sample; the first offending one is sought only if not.)
        let finite = times
            .iter()
            .chain(&values)
            .fold(true, |ok, x| ok & x.is_finite());
        let increasing = times.windows(2).fold(true, |ok, w| ok & (w[0] < w[1]));
        if !(finite && increasing) {
            for (k, (t, a)) in times.iter().zip(&values).enumerate() {
                if !t.is_finite() || !a.is_finite() {
                    return Err(ModelError::new(
                        ModelErrorKind::InvalidValue,
                        "excitation.acceleration",
                        format!("accelerogram: sample {k} is not finite"),
                    ));
                }
                if k > 0 && *t <= times[k - 1] {
                    return Err(ModelError::new(
                        ModelErrorKind::Order,
                        "excitation.time",
                        format!(
                            "accelerogram: time is not increasing at sample {k} (t = {t} after {})",
                            times[k - 1]
                        ),
                    ));
                }
            }
        }
        if !scale.is_finite() {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                "excitation.scale",
                "accelerogram: scale must be finite",
            ));
        }
        // The median spacing (of at most 64 spread over the record: only
        // the guess depends on it): a record with a tail sample appended (a
        // pounding run's ramp to rest) keeps its own rate, and the guess
        // stays exact; the average would send every guess to bisection.
        let gaps = times.len() - 1;
        let stride = gaps.div_ceil(SPACINGS_FOR_RATE).max(1);
        let mut spacings: Vec<f64> = (0..gaps)
            .step_by(stride)
            .map(|k| times[k + 1] - times[k])
            .collect();
        let middle = spacings.len() / 2;
        let rate = 1.0 / *spacings.select_nth_unstable_by(middle, f64::total_cmp).1;
        let lines = Self::lines(&times, &values, scale);
        Ok(Self {
            times: times.into(),
            values: values.into(),
            scale,
            rate,
            lines,
        })
    }

    /// The segment `k` (samples `k - 1`, `k`) holding `t` inside the
    /// record: the first `k` with `t < t_k`, or the last segment at the
    /// record's end. Guessed from the average spacing and corrected by a
    /// short walk (a uniform record: no walk), so that the integrator's
    /// dozen evaluations per step do not each bisect the record; the
    /// segment is exactly the bisection's.
    pub(super) fn segment(&self, t: f64) -> usize {
        let n = self.times.len();
        let mut k = (((t - self.times[0]) * self.rate) as usize + 1).clamp(1, n - 1);
        for _ in 0..SEGMENT_WALK {
            if self.times[k - 1] > t {
                k -= 1;
            } else if t >= self.times[k] && k < n - 1 {
                k += 1;
            } else {
                return k;
            }
        }
        self.times.partition_point(|&x| x <= t).clamp(1, n - 1)
    }

    /// Each segment's scaled start value and slope (index 0 unused).
    fn lines(times: &[f64], values: &[f64], scale: f64) -> Arc<[[f64; 2]]> {
        std::iter::once([0.0, 0.0])
            .chain(times.windows(2).zip(values.windows(2)).map(|(t, v)| {
                let slope = (v[1] - v[0]) / (t[1] - t[0]);
                [scale * v[0], scale * slope]
            }))
            .collect()
    }

    /// Scaled acceleration at time t (m/s²).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        let n = self.times.len();
        if t < self.times[0] || t > self.times[n - 1] {
            return 0.0;
        }
        let k = self.segment(t);
        let [a0, slope] = self.lines[k];
        // At a segment's end the next value exactly, as the samples say.
        if t == self.times[k] {
            return self.scale * self.values[k];
        }
        a0 + slope * (t - self.times[k - 1])
    }

    /// [`Accelerogram::at`] (the same value) from the segment `hint` or
    /// the next when one holds `t` (its end included), else found; the
    /// segment is kept in `hint`. A run's steps end on the samples, so
    /// that its evaluations move one segment a step.
    #[inline]
    pub fn at_from(&self, t: f64, hint: &mut usize) -> f64 {
        let n = self.times.len();
        for k in [*hint, *hint + 1] {
            if k >= 1 && k < n && self.times[k - 1] <= t && t <= self.times[k] {
                *hint = k;
                if t == self.times[k] {
                    return self.scale * self.values[k];
                }
                let [a0, slope] = self.lines[k];
                return a0 + slope * (t - self.times[k - 1]);
            }
        }
        if t < self.times[0] || t > self.times[n - 1] {
            return 0.0;
        }
        *hint = self.segment(t);
        self.at(t)
    }

    /// The scaled acceleration on the segment that holds `t` inside it:
    /// its value at `t` and its slope; zero before the first sample and
    /// after the last (where the record is zero).
    pub fn line_at(&self, t: f64) -> (f64, f64) {
        let n = self.times.len();
        if !(t > self.times[0] && t < self.times[n - 1]) {
            return (0.0, 0.0);
        }
        let k = self.segment(t);
        let [a0, slope] = self.lines[k];
        (a0 + slope * (t - self.times[k - 1]), slope)
    }

    /// Sample times (the interpolant's breakpoints).
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The scale factor.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Largest |scaled acceleration|.
    pub fn peak(&self) -> f64 {
        self.values.iter().fold(0.0f64, |m, a| m.max(a.abs())) * self.scale.abs()
    }
}

/// Base (frame) acceleration z̈(t).
#[derive(Clone, Debug, PartialEq, Default)]
pub enum BaseExcitation {
    /// No base motion.
    #[default]
    None,
    /// `A sin(Ω t + φ)`.
    Harmonic {
        /// A (m/s²).
        amplitude: f64,
        /// Ω (rad/s) > 0.
        frequency: f64,
        /// φ (rad).
        phase: f64,
    },
    /// A recorded accelerogram.
    Record(Accelerogram),
}

impl BaseExcitation {
    /// z̈(t) (m/s²).
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        match self {
            BaseExcitation::None => 0.0,
            BaseExcitation::Harmonic {
                amplitude,
                frequency,
                phase,
            } => amplitude * (frequency * t + phase).sin(),
            BaseExcitation::Record(r) => r.at(t),
        }
    }

    /// [`BaseExcitation::at`], a record's segment looked up from `hint`
    /// ([`Accelerogram::at_from`]).
    #[inline]
    pub fn at_from(&self, t: f64, hint: &mut usize) -> f64 {
        match self {
            BaseExcitation::Record(r) => r.at_from(t, hint),
            _ => self.at(t),
        }
    }

    /// z̈ on the line that holds `t` inside it, and its slope: a record's
    /// segment ([`Accelerogram::line_at`]); none's zero; a harmonic's
    /// tangent.
    pub fn line_at(&self, t: f64) -> (f64, f64) {
        match self {
            BaseExcitation::None => (0.0, 0.0),
            BaseExcitation::Harmonic {
                amplitude,
                frequency,
                phase,
            } => {
                let (s, c) = (frequency * t + phase).sin_cos();
                (amplitude * s, amplitude * frequency * c)
            }
            BaseExcitation::Record(r) => r.line_at(t),
        }
    }

    /// The largest |z̈| (m/s²).
    pub fn peak(&self) -> f64 {
        match self {
            BaseExcitation::None => 0.0,
            BaseExcitation::Harmonic { amplitude, .. } => amplitude.abs(),
            BaseExcitation::Record(r) => r.peak(),
        }
    }
}

/// A harmonic force `P sin(Ω t + φ)` on one body.
#[derive(Clone, Debug, PartialEq)]
pub struct HarmonicForce {
    /// Body index.
    pub body: usize,
    /// P (N).
    pub amplitude: f64,
    /// Ω (rad/s) > 0.
    pub frequency: f64,
    /// φ (rad).
    pub phase: f64,
}

impl Model {
    /// Gravity along the row (m/s²): every body feels the steady force
    /// −m g (a vertical row, u up: a ball on a vibrating table, an impact
    /// damper); 0 for a horizontal row.
    pub fn gravity(&self) -> f64 {
        self.gravity
    }

    /// The model with gravity `g` (m/s², finite) along the row. It breaks
    /// the mirror symmetry of a row; the local integrator does not take
    /// it (auto picks the global one).
    pub fn with_gravity(mut self, g: f64) -> Result<Self, ModelError> {
        if !g.is_finite() {
            return Err(ModelError::new(
                ModelErrorKind::InvalidValue,
                "gravity",
                format!("gravity = {g}: must be finite (m/s², toward -u)"),
            ));
        }
        self.gravity = g;
        Ok(self)
    }
}
