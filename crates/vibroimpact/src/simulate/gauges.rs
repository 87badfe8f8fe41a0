//! Gauges: quantities of the motion other than a body's own |u| and |v|
//! whose exact extrema (and window means) are located on the dense output
//! with the [`Extrema`](super::Extrema): a storey's drift, a joint's
//! closing, a floor's absolute acceleration.

/// A quantity of the motion watched over the extrema window.
#[derive(Clone, Copy, Debug, PartialEq)]
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

/// Where the cubic Hermite interpolant of a piece, values `xa`, `xb` and
/// rates `ra`, `rb` (of opposite signs) at its ends, is stationary (the
/// root in (a, b) of its quadratic rate), and its value there. The piece is short
/// (an integrator's step, a sixteenth of a period), so the cubic places the
/// extremum to O(h⁴) and the value read there on the motion itself is off
/// the true extremum by the square of that (a relative 1e-10 at a record's
/// 0.01 s and 30 rad/s).
pub(super) fn hermite_stationary(
    (a, b): (f64, f64),
    (xa, ra): (f64, f64),
    (xb, rb): (f64, f64),
) -> (f64, f64) {
    let h = b - a;
    // The rate times h in s = (t − a)/h: q(s) = c2 s² + c1 s + c0, with
    // q(0) = h ra and q(1) = h rb.
    let c2 = 6.0 * (xa - xb) + 3.0 * h * (ra + rb);
    let c1 = 6.0 * (xb - xa) - h * (4.0 * ra + 2.0 * rb);
    let c0 = h * ra;
    // The root in (0, 1), where q changes sign: the stable form of the
    // quadratic formula (a linear q where c2 vanishes), clamped into the
    // bracket against rounding.
    let s = if c2.abs() <= 1e-12 * (c1.abs() + c0.abs()) {
        -c0 / c1
    } else {
        let disc = (c1 * c1 - 4.0 * c2 * c0).max(0.0).sqrt();
        let q = -0.5 * (c1 + disc.copysign(c1));
        let (r1, r2) = (q / c2, if q != 0.0 { c0 / q } else { f64::NAN });
        if (0.0..=1.0).contains(&r1) {
            r1
        } else {
            r2
        }
    };
    let s = if s.is_finite() {
        s.clamp(0.0, 1.0)
    } else {
        0.5
    };
    // The cubic's value there (Hermite basis).
    let (s2, s3) = (s * s, s * s * s);
    let value = (2.0 * s3 - 3.0 * s2 + 1.0) * xa
        + (s3 - 2.0 * s2 + s) * h * ra
        + (-2.0 * s3 + 3.0 * s2) * xb
        + (s3 - s2) * h * rb;
    (a + s * h, value)
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

    /// Notes a value (a NaN passed over, as by `f64::min` and `max`; plain
    /// comparisons, which cost less than their NaN-aware forms).
    #[inline]
    pub(super) fn note(&mut self, x: f64) {
        if x < self.min {
            self.min = x;
        }
        if x > self.max {
            self.max = x;
        }
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
        let ends = (at(a), at(b));
        self.scan_ends((a, b), ends, at);
    }

    /// [`GaugeScan::scan`] with the values and rates at the ends given
    /// (inline: most pieces only note their ends).
    #[inline]
    pub(super) fn scan_ends(
        &mut self,
        (a, b): (f64, f64),
        ends: ((f64, f64), (f64, f64)),
        at: impl FnMut(f64) -> (f64, f64),
    ) {
        self.note(ends.0 .0);
        self.scan_on((a, b), ends, at);
    }

    /// [`GaugeScan::scan_ends`] from the end of the last piece scanned,
    /// noted then.
    #[inline]
    pub(super) fn scan_on(
        &mut self,
        (a, b): (f64, f64),
        ((xa, ra), (xb, rb)): ((f64, f64), (f64, f64)),
        at: impl FnMut(f64) -> (f64, f64),
    ) {
        self.note(xb);
        if ra * rb < 0.0 {
            self.turning((a, b), ((xa, ra), (xb, rb)), at);
        } else if self.gauge.mean_from().is_some_and(|from| from < b) {
            self.mean_part((a, b), at);
        }
    }

    /// [`GaugeScan::scan_ends`] where the rate changes sign between the
    /// ends: the cubic's stationary point, then one secant step on the
    /// rate from the side of the bracket it leaves; skipped where the
    /// cubic's extremum stays a hundredth of the reading's size inside
    /// what was read (the cubic is within about (ωh)⁴/384 of the motion:
    /// 3e-3 even at ωh = 1, and the local integrator's pieces keep ωh
    /// below 0.4). Then the mean's part.
    #[inline(never)]
    fn turning(
        &mut self,
        (a, b): (f64, f64),
        ((xa, ra), (xb, rb)): ((f64, f64), (f64, f64)),
        mut at: impl FnMut(f64) -> (f64, f64),
    ) {
        let (t1, guess) = hermite_stationary((a, b), (xa, ra), (xb, rb));
        let margin = 1e-2 * self.min.abs().max(self.max.abs());
        if guess < self.max - margin && guess > self.min + margin {
            return self.mean_part((a, b), at);
        }
        let (x1, r1) = at(t1);
        self.note(x1);
        let (tc, rc) = if r1 * ra < 0.0 { (a, ra) } else { (b, rb) };
        if r1 != 0.0 && r1 != rc {
            let t2 = t1 - r1 * (t1 - tc) / (r1 - rc);
            if t2 > a && t2 < b {
                self.note(at(t2).0);
            }
        }
        self.mean_part((a, b), at);
    }

    /// The part of `[a, b]` in the mean's window, by Gauss–Legendre.
    fn mean_part(&mut self, (a, b): (f64, f64), mut at: impl FnMut(f64) -> (f64, f64)) {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The cubic through a cubic's values and slopes is the cubic: its
    /// stationary point and value are exact, for a maximum and a minimum,
    /// and for a quadratic (c2 = 0 in the rate's form).
    #[test]
    fn the_hermite_stationary_point_of_a_cubic_is_exact() {
        // x(t) = (t − 0.3)² (t − 2) on [0, 1]: stationary at t = 0.3 (a
        // maximum, x = 0) and t = 1.4667 (outside).
        let x = |t: f64| (t - 0.3) * (t - 0.3) * (t - 2.0);
        let r = |t: f64| 2.0 * (t - 0.3) * (t - 2.0) + (t - 0.3) * (t - 0.3);
        let (t, v) = hermite_stationary((0.0, 1.0), (x(0.0), r(0.0)), (x(1.0), r(1.0)));
        assert!((t - 0.3).abs() < 1e-14 && v.abs() < 1e-14, "{t} {v}");
        // A parabola −(t − 2.5)² on [2, 4]: its maximum at 2.5.
        let (t, v) = hermite_stationary((2.0, 4.0), (-0.25, 1.0), (-2.25, -3.0));
        assert!((t - 2.5).abs() < 1e-14 && v.abs() < 1e-14, "{t} {v}");
        // Its mirror, a minimum.
        let (t, v) = hermite_stationary((2.0, 4.0), (0.25, -1.0), (2.25, 3.0));
        assert!((t - 2.5).abs() < 1e-14 && v.abs() < 1e-14, "{t} {v}");
    }
}
