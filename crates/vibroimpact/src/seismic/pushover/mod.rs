//! The static pushover of a shear frame (docs/earthquakes.md, FEMA P695
//! §6.3): lateral loads in proportion to the floors' masses times the
//! fundamental mode shape, raised monotonically until a storey collapses
//! or reaches the drift-ratio limit; base shear against roof displacement,
//! the overstrength's V_max, the effective yield and ultimate roof
//! displacements and the period-based ductility μ_T.
//!
//! In a shear frame the storey shears are statics alone: under the load
//! factor λ, storey i carries V_i = λ S_i with S_i the pattern's sum from
//! floor i up, and resists R_i(d) = F_i(d) − (P_i/h_i) d, its law's
//! monotonic force less its P-Δ shear. So each storey is solved by itself.
//! The curve follows the critical storey, the first to reach its peak
//! resistance or its drift limit as λ grows (the weakest in λ): its drift is
//! the parameter, λ = R_c(d_c)/S_c, which carries the curve past the peak
//! where it softens; the other storeys load along their own monotonic
//! curves to λ, and unload elastically (slope k_i − P_i/h_i) when λ falls
//! below the largest they carried.
//!
//! Files: `mod.rs` (the pushover and its document), `tests.rs` (the
//! closed forms).

use crate::model::hysteresis::{under_drift, StoreyLaw};
use crate::model::record::STANDARD_GRAVITY;
use crate::seismic::pounding::ShearFrame;

/// Relative tolerance of a Bouc–Wen storey's monotonic curve.
const CURVE_RTOL: f64 = 1e-10;

/// What the pushover is asked.
#[derive(Clone, Debug, PartialEq)]
pub struct PushoverOptions {
    /// The critical storey's drift-ratio limit where the push stops
    /// (default 0.10: beyond any frame's collapse drift in FEMA P695's
    /// archetypes).
    pub drift_ratio_limit: f64,
    /// Points along the critical storey's drift (default 400).
    pub points: usize,
    /// The code period T = C_u T_a of FEMA P695 eq. (6-7) (s); None: the
    /// frame's fundamental period T1 (with its P-Δ).
    pub code_period: Option<f64>,
}

impl Default for PushoverOptions {
    fn default() -> Self {
        Self {
            drift_ratio_limit: 0.10,
            points: 400,
            code_period: None,
        }
    }
}

/// A pushover curve and what FEMA P695 §6.3 reads from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Pushover {
    /// The lateral load pattern m_x φ_x, summing to 1 (floor order).
    pub pattern: Vec<f64>,
    /// Roof displacement at each point (m).
    pub roof_displacement: Vec<f64>,
    /// Base shear at each point (N).
    pub base_shear: Vec<f64>,
    /// Storey drifts at each point (m; point-major, storey order).
    pub drifts: Vec<Vec<f64>>,
    /// The critical storey (from 0).
    pub critical_storey: usize,
    /// Whether the critical storey lost all its resistance (a collapse
    /// under its gravity loads) before the drift-ratio limit.
    pub collapsed: bool,
    /// The largest base shear V_max (N).
    pub max_base_shear: f64,
    /// The seismic weight W = Σ m g (N).
    pub weight: f64,
    /// The fundamental period T1 with P-Δ (s).
    pub period: f64,
    /// C0 of FEMA P695 eq. (6-8): φ_roof Σ m φ / Σ m φ².
    pub c0: f64,
    /// δ_y,eff = C0 (V_max/W) (g/4π²) max(T, T1)² (m), eq. (6-7).
    pub yield_displacement: f64,
    /// δ_u (m): the roof displacement where the base shear has fallen to
    /// 0.8 V_max past the peak, else at the end of the push.
    pub ultimate_displacement: f64,
    /// Whether δ_u is the 20 % strength loss (false: the end of the push,
    /// a lower bound).
    pub strength_loss: bool,
    /// μ_T = δ_u/δ_y,eff, eq. (6-6).
    pub ductility: f64,
}

/// One storey as the pushover sees it.
struct Storey {
    law: StoreyLaw,
    /// P-Δ stiffness P/h (N/m).
    geometric: f64,
    /// Its share S_i of the load pattern.
    share: f64,
    /// Its drift limit (m).
    limit: f64,
}

impl Storey {
    /// R(d) = F(d) − (P/h) d along the monotonic push from rest.
    fn resistance(&self, d: f64) -> Result<f64, String> {
        let f = under_drift(&self.law, &[d], CURVE_RTOL)
            .map_err(|e| format!("the storey's monotonic curve: {e}"))?;
        Ok(f[0].0 - self.geometric * d)
    }

    /// The drift on its monotonic curve where R = `r`, within `[0, top]`
    /// (R rising there), by bisection to the last bits.
    fn drift_at(&self, r: f64, top: f64) -> Result<f64, String> {
        let (mut lo, mut hi) = (0.0, top);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if self.resistance(mid)? < r {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        Ok(0.5 * (lo + hi))
    }
}

/// The peak of `f` over `[0, top]` on a grid of `n` pieces refined by golden
/// section around the best: (where, value). `f` rises from 0 (a storey's
/// resistance, stable at zero drift), so a best at 0 means the grid is too
/// coarse for the law (a push far past its collapse, or few points): the
/// first piece is searched again, down to where the rise shows.
fn peak(f: impl Fn(f64) -> Result<f64, String>, top: f64, n: usize) -> Result<(f64, f64), String> {
    let mut top = top;
    let (mut best, mut at) = ((0.0, f(0.0)?), 0);
    for _ in 0..1100 {
        for j in 1..=n {
            let d = top * j as f64 / n as f64;
            let v = f(d)?;
            if v > best.1 {
                best = (d, v);
                at = j;
            }
        }
        if at > 0 || top / n as f64 <= f64::MIN_POSITIVE {
            break;
        }
        top /= n as f64;
    }
    if at == n || at == 0 {
        return Ok(best);
    }
    let (a, b) = (
        top * (at - 1) as f64 / n as f64,
        top * (at + 1) as f64 / n as f64,
    );
    let mut failure = None;
    let (v, d) = crate::numeric::golden_max(
        |d| {
            f(d).unwrap_or_else(|e| {
                failure = Some(e);
                f64::NAN
            })
        },
        a,
        b,
    );
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(if v > best.1 { (d, v) } else { best })
}

/// Storey `i`'s tangent stiffness past the drift |`d`| on its monotonic
/// curve, P-Δ included (N/m): negative where the storey softens (a
/// forward difference of 1e-6 |d|).
pub fn storey_tangent(frame: &ShearFrame, i: usize, d: f64) -> Result<f64, String> {
    let laws = frame.laws()?;
    let s = Storey {
        law: laws[i],
        geometric: frame.geometric_stiffnesses()[i],
        share: 1.0,
        limit: f64::INFINITY,
    };
    let (d, h) = (d.abs(), 1e-6 * d.abs().max(f64::MIN_POSITIVE));
    Ok((s.resistance(d + h)? - s.resistance(d)?) / h)
}

/// The most points a push takes (found by the option fuzzer: 2^40 points
/// ran for hours).
pub const MAX_POINTS: usize = 100_000;

/// The pushover of `frame` (it needs the storeys' heights); errors name
/// the option or storey.
pub fn pushover(frame: &ShearFrame, opts: &PushoverOptions) -> Result<Pushover, String> {
    frame.check("frame")?;
    if frame.heights.is_empty() {
        return Err(
            "heights: the pushover needs the storeys' heights (m) for its drift limit".into(),
        );
    }
    if !(opts.drift_ratio_limit.is_finite()
        && opts.drift_ratio_limit > 0.0
        && opts.drift_ratio_limit <= 1.0)
    {
        return Err(format!(
            "drift_ratio_limit = {}: give a drift ratio in (0, 1] (past 1 a storey has moved more than its height, where the shear building's P-Δ means nothing)",
            opts.drift_ratio_limit
        ));
    }
    if !(2..=MAX_POINTS).contains(&opts.points) {
        return Err(format!(
            "points = {}: give 2 to {MAX_POINTS} (each point solves every storey; 1e5 take about a second)",
            opts.points
        ));
    }
    if let Some(t) = opts.code_period {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("code_period = {t}: give a positive period (s)"));
        }
    }
    let n = frame.masses.len();
    let phi = frame.first_mode();
    let raw: Vec<f64> = frame.masses.iter().zip(&phi).map(|(m, p)| m * p).collect();
    let total: f64 = raw.iter().sum();
    let pattern: Vec<f64> = raw.iter().map(|p| p / total).collect();
    let laws = frame.laws()?;
    let geometric = frame.geometric_stiffnesses();
    let storeys: Vec<Storey> = (0..n)
        .map(|i| Storey {
            law: laws[i],
            geometric: geometric[i],
            share: pattern[i..].iter().sum(),
            limit: opts.drift_ratio_limit * frame.heights[i],
        })
        .collect();
    // Each storey's largest load factor, and the drift where it peaks.
    let mut peaks = Vec::with_capacity(n);
    for (i, s) in storeys.iter().enumerate() {
        let (d, r) = peak(|d| s.resistance(d), s.limit, opts.points)
            .map_err(|e| format!("storey {}: {e}", i + 1))?;
        peaks.push((d, r / s.share));
    }
    let c = (0..n)
        .min_by(|&a, &b| peaks[a].1.total_cmp(&peaks[b].1))
        .unwrap_or(0);
    let crit = &storeys[c];
    // The other storeys: the largest λ each has carried and its drift then.
    let mut carried = vec![(0.0f64, 0.0f64); n];
    let (mut roof, mut shear, mut drifts) = (Vec::new(), Vec::new(), Vec::new());
    let mut collapsed = false;
    // The critical storey's drifts: the grid, and its peak.
    let mut grid: Vec<f64> = (0..=opts.points)
        .map(|j| crit.limit * j as f64 / opts.points as f64)
        .collect();
    if peaks[c].0 > 0.0 && peaks[c].0 < crit.limit {
        grid.push(peaks[c].0);
        grid.sort_by(f64::total_cmp);
        grid.dedup();
    }
    for j in 0..grid.len() {
        let mut dc = grid[j];
        let mut r = crit
            .resistance(dc)
            .map_err(|e| format!("storey {}: {e}", c + 1))?;
        if r < 0.0 {
            // Past its collapse: the drift where its resistance vanishes,
            // between the last point and this one.
            let (mut lo, mut hi) = (grid[j - 1], dc);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                if crit
                    .resistance(mid)
                    .map_err(|e| format!("storey {}: {e}", c + 1))?
                    > 0.0
                {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            (dc, r) = (0.5 * (lo + hi), 0.0);
            collapsed = true;
        }
        let lambda = r / crit.share;
        let mut d = vec![0.0; n];
        d[c] = dc;
        for (i, s) in storeys.iter().enumerate().filter(|(i, _)| *i != c) {
            let (top, d_top) = carried[i];
            d[i] = if lambda >= top {
                let x = s
                    .drift_at(lambda * s.share, peaks[i].0.max(f64::MIN_POSITIVE))
                    .map_err(|e| format!("storey {}: {e}", i + 1))?;
                carried[i] = (lambda, x);
                x
            } else {
                d_top - (top - lambda) * s.share / (s.law.initial_stiffness() - s.geometric)
            };
        }
        roof.push(d.iter().sum());
        shear.push(lambda);
        drifts.push(d);
        if collapsed {
            break;
        }
    }
    let weight = frame.masses.iter().sum::<f64>() * STANDARD_GRAVITY;
    let max_base_shear = shear.iter().copied().fold(0.0, f64::max);
    let period = frame.period();
    let t = opts.code_period.unwrap_or(period).max(period);
    let (sum_m_phi, sum_m_phi2) = frame
        .masses
        .iter()
        .zip(&phi)
        .fold((0.0, 0.0), |(a, b), (m, p)| (a + m * p, b + m * p * p));
    let c0 = phi[n - 1] * sum_m_phi / sum_m_phi2;
    let yield_displacement = c0 * max_base_shear / weight * STANDARD_GRAVITY
        / (4.0 * std::f64::consts::PI.powi(2))
        * t
        * t;
    if !(yield_displacement.is_finite() && yield_displacement > 0.0) {
        return Err(format!(
            "code_period = {t}: δ_y,eff = C0 (V_max/W) (g/4π²) T² = {yield_displacement:e} m is not a displacement; give the code period T = C_u T_a (s)"
        ));
    }
    let (ultimate_displacement, strength_loss) = ultimate(&roof, &shear, max_base_shear);
    Ok(Pushover {
        pattern,
        roof_displacement: roof,
        base_shear: shear,
        drifts,
        critical_storey: c,
        collapsed,
        max_base_shear,
        weight,
        period,
        c0,
        yield_displacement,
        ultimate_displacement,
        strength_loss,
        ductility: ultimate_displacement / yield_displacement,
    })
}

/// δ_u: the roof displacement where the base shear first falls to 0.8
/// V_max after its peak (linear between points), else the last point's;
/// and whether it fell.
fn ultimate(roof: &[f64], shear: &[f64], v_max: f64) -> (f64, bool) {
    let top = shear.iter().position(|&v| v == v_max).unwrap_or(0);
    let level = 0.8 * v_max;
    for j in top + 1..shear.len() {
        if shear[j] <= level {
            let w = (shear[j - 1] - level) / (shear[j - 1] - shear[j]);
            return (roof[j - 1] + w * (roof[j] - roof[j - 1]), true);
        }
    }
    (roof.last().copied().unwrap_or(0.0), false)
}

impl Pushover {
    /// The pushover as a document (every face prints this): the curve
    /// (`roof_displacement`, `base_shear`, `drifts` per point), the pattern,
    /// the critical storey (from 1), whether it collapsed, and FEMA P695's
    /// quantities with their `units`.
    pub fn document(&self, building: &str, frame: &ShearFrame) -> serde_json::Value {
        let height: f64 = frame.heights.iter().sum();
        serde_json::json!({
            "building": building,
            "pattern": self.pattern,
            "roof_displacement": self.roof_displacement,
            "roof_drift_ratio": self.roof_displacement.iter().map(|u| u / height).collect::<Vec<_>>(),
            "base_shear": self.base_shear,
            "drifts": self.drifts,
            "critical_storey": self.critical_storey + 1,
            "collapsed": self.collapsed,
            "max_base_shear": self.max_base_shear,
            "weight": self.weight,
            "max_base_shear_over_weight": self.max_base_shear / self.weight,
            "period": self.period,
            "c0": self.c0,
            "yield_displacement": self.yield_displacement,
            "ultimate_displacement": self.ultimate_displacement,
            "strength_loss": self.strength_loss,
            "ductility": self.ductility,
            "units": {
                "roof_displacement": "m", "base_shear": "N", "drifts": "m",
                "max_base_shear": "N", "weight": "N", "period": "s",
                "yield_displacement": "m", "ultimate_displacement": "m",
            },
        })
    }
}

#[cfg(test)]
mod tests;
