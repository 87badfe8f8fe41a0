//! Gauges: quantities of the motion other than a body's own |u| and |v|
//! whose exact extrema (and window means) are located on the dense output
//! with the [`Extrema`](super::Extrema): a storey's drift, a joint's
//! closing, a floor's absolute acceleration.

use crate::integrate::events::EventLocator;

/// A quantity of the motion watched over the extrema window.
#[derive(Clone, Debug, PartialEq)]
pub enum Gauge {
    /// u_left − u_right (m; None: the ground, from which displacements are
    /// measured): a storey's drift, a joint's closing. Its interior extrema
    /// lie where v_left − v_right changes sign. With `mean_from`, also its
    /// time mean from then to the window's end (a residual drift).
    Separation {
        /// The body whose displacement counts positive.
        left: Option<usize>,
        /// The body whose displacement counts negative.
        right: Option<usize>,
        /// Start of the mean's window (s), if a mean is wanted.
        mean_from: Option<f64>,
    },
    /// A body's absolute acceleration: its acceleration relative to the
    /// ground plus the ground's (m/s²). Its interior extrema lie where its
    /// rate (the jerk, a central difference on the dense output) changes
    /// sign.
    AbsoluteAcceleration {
        /// The body.
        body: usize,
    },
}

impl Gauge {
    /// The bodies the gauge reads.
    pub(super) fn sides(&self) -> [Option<usize>; 2] {
        match *self {
            Self::Separation { left, right, .. } => [left, right],
            Self::AbsoluteAcceleration { body } => [Some(body), None],
        }
    }

    /// Start of the mean's window, if any.
    fn mean_from(&self) -> Option<f64> {
        match *self {
            Self::Separation { mean_from, .. } => mean_from,
            Self::AbsoluteAcceleration { .. } => None,
        }
    }

    /// Why the gauge cannot be read on a model of `bodies` bodies, if so.
    pub(super) fn check(&self, bodies: usize) -> Result<(), String> {
        let sides = self.sides();
        if let Some(i) = sides.iter().flatten().find(|&&i| i >= bodies) {
            return Err(format!("gauge {self:?}: body {i} of {bodies}"));
        }
        if let Self::Separation {
            left: None,
            right: None,
            ..
        } = self
        {
            return Err("a separation gauge needs a body on one side".into());
        }
        if let Some(m) = self.mean_from() {
            if !m.is_finite() {
                return Err(format!("gauge {self:?}: a mean from {m}"));
            }
        }
        Ok(())
    }
}

/// What a gauge read over the window: its least and largest value, and its
/// mean over the mean's window if asked.
#[derive(Clone, Debug, PartialEq)]
pub struct GaugeReading {
    /// Least value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// The time mean over `[mean_from, window end]` (None: not asked, or the
    /// run ended before the mean's window opened).
    pub mean: Option<f64>,
}

impl GaugeReading {
    /// max(|min|, |max|): the peak magnitude.
    pub fn peak(&self) -> f64 {
        self.min.abs().max(self.max.abs())
    }
}

/// Gauss–Legendre nodes and weights on [−1, 1], 4 points: exact for the
/// 7th-degree dense output of DOP853.
const GAUSS4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

/// A gauge's reading in progress.
#[derive(Clone, Debug)]
pub(super) struct GaugeScan {
    pub(super) gauge: Gauge,
    min: f64,
    max: f64,
    /// ∫ of the gauge over the part of the mean's window scanned.
    integral: f64,
    covered: f64,
}

impl GaugeScan {
    /// Nothing read yet.
    pub(super) fn new(gauge: Gauge) -> Self {
        Self {
            gauge,
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            integral: 0.0,
            covered: 0.0,
        }
    }

    /// Notes a value.
    pub(super) fn note(&mut self, x: f64) {
        self.min = self.min.min(x);
        self.max = self.max.max(x);
    }

    /// The reading (min = max = 0 where nothing was scanned).
    pub(super) fn reading(&self) -> GaugeReading {
        let read = self.min <= self.max;
        GaugeReading {
            min: if read { self.min } else { 0.0 },
            max: if read { self.max } else { 0.0 },
            mean: (self.covered > 0.0).then(|| self.integral / self.covered),
        }
    }

    /// Scans `[a, b]`, a piece of motion on which `at(t)` gives the gauge
    /// and its rate: the ends, an interior extremum where the rate changes
    /// sign (Brent on the rate), and the mean's part by Gauss–Legendre.
    pub(super) fn scan(&mut self, a: f64, b: f64, mut at: impl FnMut(f64) -> (f64, f64)) {
        let (xa, ra) = at(a);
        let (xb, rb) = at(b);
        self.note(xa);
        self.note(xb);
        if ra * rb < 0.0 {
            if let Ok(t) = EventLocator::FINE.locate(|t| at(t).1, (a, ra), (b, rb)) {
                self.note(at(t).0);
            }
        }
        if let Some(from) = self.gauge.mean_from() {
            let lo = a.max(from);
            if lo < b {
                let (mid, half) = (0.5 * (lo + b), 0.5 * (b - lo));
                self.integral += GAUSS4
                    .iter()
                    .map(|&(x, w)| w * half * at(mid + half * x).0)
                    .sum::<f64>();
                self.covered += b - lo;
            }
        }
    }
}
