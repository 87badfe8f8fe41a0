//! Fujita's closed-form impact relations for the exponential law
//! (seed eqs. 8–18; docs/theory.md §2).
//!
//! Relative motion: `μ ẍ = -(a + b ẋ) exp(α x)`, `x(0) = -X`, `ẋ(0) = U`.
//! With `y = ẋ`, `dy/dx = -(a + b y) exp(α x) / (μ y)` integrates to the phase
//! trajectory (seed eq. 8, written for a general reduced mass μ):
//!
//! ```text
//! (1/α) e^{αx} + (μ/b) [y - (a/b) ln(a + b y)] = const.
//! ```
//!
//! Rebound at the same distance `x = -X` with `y = -eU` gives e(V) with
//! `V = U/(a/b)` (eqs. 9–10), independent of μ, a, α and X (the `e^{-αX}`
//! terms cancel exactly). Dropping `e^{-αX}` (X ≫ 1/α), the force
//! `F = (a + b y) e^{αx}` along the trajectory is, with `w = y/(a/b)` and
//! `f = F / (μ α (a/b)²)` (eq. 14), `f(w) = (1 + w)[V - w + ln((1+w)/(1+V))]`
//! (eq. 15), maximal where `2w* = ln((1+w*)/(1+V)) + V` (eq. 17):
//! `f_max = w*(1 + w*)` (eq. 16).
//!
//! ## Numerics
//! The seed's fixed-point iterations (eqs. 11, 18) are kept for reference
//! ([`restitution_fixed_point`], [`peak_velocity_fixed_point`]) but converge
//! slowly for small V (contraction factor `1 - eV`). The production solvers
//! rewrite the equations without cancellation and use safeguarded Newton:
//!
//! - Restitution. With `p = V(e + 1)`, eq. (10) is `p = (1 + V)(1 - e^{-p})`,
//!   i.e. `G(p) = (e^{-p} - 1 + p) - V(1 - e^{-p}) = 0` with the trivial root
//!   `p = 0` (the impact point itself, `e = -1`) excluded by the bracket
//!   `[p_l, min(2V, 1+V)]`, where `p_l = 4V / (1 + sqrt(1 + 4V/3))` follows
//!   from `1 + p/2 ≤ p/(1 - e^{-p}) ≤ 1 + p/2 + p²/12`. Both terms of G are
//!   evaluated to full relative precision, so e is accurate to a few ulps for
//!   V from 1e-300 to 1e300; `e = (p - V)/V` for V < 1 and
//!   `e = (1 - (1 + V) e^{-p})/V` for V ≥ 1 avoid the last cancellation.
//! - Peak force. With `δ = w - V`, `u = δ/(1 + V)`, eq. (17) reads
//!   `k(w) = w + δV/(1+V) + (u - ln(1+u)) = 0` on `(0, V)`, all terms O(V²)
//!   for small V (no cancellation).

use super::{positive, ImpactError, TwoBodies};
use crate::contact::{ContactLaw, LawKind};
use crate::numeric::{
    exp_neg_minus_one_plus, ln_x_minus_log1p, newton_bracketed_from, x_minus_log1p,
};

const XTOL: f64 = 4.0 * f64::EPSILON;
const MAX_ITER: usize = 200;

/// Dimensionless impact velocity `V = U / (a/b)`, seed eq. (9).
pub fn dimensionless_velocity(impact_velocity: f64, a_over_b: f64) -> f64 {
    impact_velocity / a_over_b
}

/// Coefficient of restitution `e(V)`, the non-trivial root of seed eq. (10):
/// `e = 1/V - (1 + 1/V) exp(-V(e + 1))`.
///
/// Full double precision for every finite `V > 0` (see the module notes).
pub fn restitution(v: f64) -> Result<f64, ImpactError> {
    positive("V", v)?;
    let g = |p: f64| {
        let em = (-p).exp_m1(); // e^{-p} - 1
        let value = exp_neg_minus_one_plus(p) + v * em;
        let slope = -em - v * (-p).exp();
        (value, slope)
    };
    let p_lower = 4.0 * v / (1.0 + (1.0 + 4.0 * v / 3.0).sqrt());
    let bound = p_lower.max((1.0 + v) * -(-p_lower).exp_m1());
    let (lo, hi) = (0.999 * bound, 1.001 * (2.0 * v).min(1.0 + v));
    // Newton from the lower bound, which is within a few per cent of the root.
    let p = newton_bracketed_from(g, lo, hi, bound, XTOL, MAX_ITER).map_err(|source| {
        ImpactError::Solver {
            what: "restitution, seed eq. (10)",
            source,
        }
    })?;
    Ok(if v < 1.0 {
        (p - v) / v
    } else {
        (1.0 - (1.0 + v) * (-p).exp()) / v
    })
}

/// Result of one of the seed's fixed-point iterations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedPoint {
    /// The converged value.
    pub value: f64,
    /// Iterations used.
    pub iterations: usize,
}

/// The seed's fixed-point iteration for e(V), eq. (11): `e₀ = 1`,
/// `e_{i+1} = 1/V - (1 + 1/V) exp(-V(e_i + 1))`, stopped when
/// `|e_{i+1} - e_i| <= tol`. Kept as the seed's method and as an independent
/// check; it is slow for small V and loses digits to cancellation there.
pub fn restitution_fixed_point(
    v: f64,
    tol: f64,
    max_iter: usize,
) -> Result<FixedPoint, ImpactError> {
    positive("V", v)?;
    let mut e = 1.0;
    for i in 1..=max_iter {
        let next = 1.0 / v - (1.0 + 1.0 / v) * (-v * (e + 1.0)).exp();
        if (next - e).abs() <= tol {
            return Ok(FixedPoint {
                value: next,
                iterations: i,
            });
        }
        e = next;
    }
    Err(ImpactError::FixedPointNoConvergence {
        what: "restitution, seed eq. (11)",
        v,
        iterations: max_iter,
    })
}

/// `de/dV` at a root `e = e(V)` of seed eq. (10), by implicit
/// differentiation: `de/dV = -(1 + e)(e - 1/(1 + V)) / (e V)`.
pub fn restitution_derivative(v: f64, e: f64) -> f64 {
    -(1.0 + e) * (e - 1.0 / (1.0 + v)) / (e * v)
}

/// Dimensionless force along the trajectory, seed eq. (15):
/// `f(w) = (1 + w)[V - w + ln((1 + w)/(1 + V))]`, for `-1 < w <= V`.
pub fn dimensionless_force(v: f64, w: f64) -> f64 {
    let delta = w - v;
    let u = delta / (1.0 + v);
    (1.0 + w) * (-delta * v / (1.0 + v) - x_minus_log1p(u))
}

/// Dimensionless velocity `w*` at the peak force, the root in `(0, V)` of
/// seed eq. (17): `2w* = ln((1 + w*)/(1 + V)) + V`.
pub fn peak_velocity(v: f64) -> Result<f64, ImpactError> {
    positive("V", v)?;
    let k = |w: f64| {
        let delta = w - v;
        let u = delta / (1.0 + v);
        (
            w + delta * v / (1.0 + v) + x_minus_log1p(u),
            (1.0 + 2.0 * w) / (1.0 + w),
        )
    };
    // The guess w ≈ V²/(2(1 + V)) has the limits of eq. (17) for small V
    // (w* → V²/2) and large V (w* → V/2).
    let guess = v * v / (2.0 * (1.0 + v));
    newton_bracketed_from(k, 0.0, v, guess, XTOL, MAX_ITER).map_err(|source| ImpactError::Solver {
        what: "peak-force velocity, seed eq. (17)",
        source,
    })
}

/// The seed's iteration for w*, eq. (18): `w₀ = V`,
/// `2 w_{i+1} = ln((1 + w_i)/(1 + V)) + V`, stopped at `|Δw| <= tol`.
pub fn peak_velocity_fixed_point(
    v: f64,
    tol: f64,
    max_iter: usize,
) -> Result<FixedPoint, ImpactError> {
    positive("V", v)?;
    let mut w = v;
    for i in 1..=max_iter {
        let next = 0.5 * (((1.0 + w) / (1.0 + v)).ln() + v);
        if (next - w).abs() <= tol {
            return Ok(FixedPoint {
                value: next,
                iterations: i,
            });
        }
        w = next;
    }
    Err(ImpactError::FixedPointNoConvergence {
        what: "peak-force velocity, seed eq. (18)",
        v,
        iterations: max_iter,
    })
}

/// Dimensionless peak force `f_max = w*(1 + w*)`, seed eq. (16) with w* from
/// eq. (17). `F_max = f_max μ α (a/b)²` (eq. 14).
pub fn peak_force_dimensionless(v: f64) -> Result<f64, ImpactError> {
    let w = peak_velocity(v)?;
    Ok(w * (1.0 + w))
}

/// `d f_max / dV = V (1 + w*)/(1 + V)` (implicit differentiation of eqs. 16–17).
pub fn peak_force_dimensionless_derivative(v: f64, w_star: f64) -> f64 {
    v * (1.0 + w_star) / (1.0 + v)
}

/// Closed-form description of one impact (all SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedFormImpact {
    /// Impact velocity U (m/s).
    pub impact_velocity: f64,
    /// Dimensionless impact velocity V (eq. 9).
    pub v: f64,
    /// Coefficient of restitution e (eq. 10).
    pub restitution: f64,
    /// Rebound velocity e U (m/s), the separation speed.
    pub rebound_velocity: f64,
    /// Dimensionless velocity at the peak force w* (eq. 17).
    pub peak_velocity_dimensionless: f64,
    /// Dimensionless peak force f_max (eq. 16).
    pub peak_force_dimensionless: f64,
    /// Peak force F_max (N), eq. (14).
    pub peak_force: f64,
    /// Peak accelerations F_max/m1 and F_max/m2 (m/s²); 0 for a wall.
    pub peak_acceleration: [f64; 2],
    /// Maximum of the approach coordinate s (m) in the limit of a start far
    /// away (X → ∞), from eq. (12) at y = 0.
    pub max_penetration: f64,
}

/// The exponential law acting between two given bodies: the seed's relations
/// in SI units.
///
/// The published and the non-negative form of the law give the same impact:
/// along a two-body trajectory `a + b ẋ >= a(1 - eV) > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExponentialImpact {
    bodies: TwoBodies,
    a: f64,
    b: f64,
    alpha: f64,
}

impl ExponentialImpact {
    /// From an exponential [`ContactLaw`] and the two bodies.
    pub fn new(law: &ContactLaw, bodies: TwoBodies) -> Result<Self, ImpactError> {
        match *law.kind() {
            LawKind::Exponential { a, b, alpha } => Ok(Self { bodies, a, b, alpha }),
            _ => Err(ImpactError::Unsupported(format!(
                "the closed form exists only for the exponential law, not for {}; use direct integration",
                law.name()
            ))),
        }
    }

    /// The bodies.
    pub fn bodies(&self) -> &TwoBodies {
        &self.bodies
    }

    /// a/b (m/s).
    pub fn a_over_b(&self) -> f64 {
        self.a / self.b
    }

    /// Force scale `μ α (a/b)²` (N) of seed eq. (14): `F = f μ α (a/b)²`.
    pub fn force_scale(&self) -> f64 {
        let q = self.a_over_b();
        self.bodies.reduced_mass() * self.alpha * q * q
    }

    /// Scale `K = μ α (a/b) / b` of `e^{αx}` along the trajectory (eq. 12):
    /// `e^{αx} = e^{-αX} + K [V - w + ln((1 + w)/(1 + V))]`.
    fn penetration_scale(&self) -> f64 {
        self.bodies.reduced_mass() * self.alpha * self.a_over_b() / self.b
    }

    /// All closed-form quantities of an impact at velocity `U > 0` (m/s).
    pub fn impact(&self, impact_velocity: f64) -> Result<ClosedFormImpact, ImpactError> {
        positive("impact velocity", impact_velocity)?;
        let v = dimensionless_velocity(impact_velocity, self.a_over_b());
        let e = restitution(v)?;
        let w = peak_velocity(v)?;
        let f = w * (1.0 + w);
        let peak_force = f * self.force_scale();
        let max_penetration = (self.penetration_scale().ln() + ln_x_minus_log1p(v)) / self.alpha;
        if !max_penetration.is_finite() || !peak_force.is_finite() {
            // 1/α or the force scale beyond double precision (α = 5e-324
            // 1/m gave a penetration of -inf, silently).
            return Err(ImpactError::InvalidParameter {
                name: "alpha",
                value: self.alpha,
                requirement: "the impact's peak force or penetration (ln(...)/alpha) leaves double precision: give alpha within about 1e-290 to 1e290 1/m, with masses and a/b of ordinary size",
            });
        }
        Ok(ClosedFormImpact {
            impact_velocity,
            v,
            restitution: e,
            rebound_velocity: e * impact_velocity,
            peak_velocity_dimensionless: w,
            peak_force_dimensionless: f,
            peak_force,
            peak_acceleration: self.bodies.accelerations(peak_force),
            max_penetration,
        })
    }

    /// Phase trajectory of seed eq. (8): the approach coordinate `x` (m) at
    /// relative velocity `y` (m/s) for an impact that starts at `x = -X`
    /// (`start_distance = X > 0`) with velocity `U`. Returns `None` where the
    /// trajectory does not reach `y` (outside `[-eU, U]`).
    pub fn trajectory_position(
        &self,
        impact_velocity: f64,
        start_distance: f64,
        y: f64,
    ) -> Option<f64> {
        let q = self.a_over_b();
        let v = impact_velocity / q;
        let w = y / q;
        if !(w > -1.0 && w <= v) {
            return None;
        }
        let delta = w - v;
        let u = delta / (1.0 + v);
        let g = -delta * v / (1.0 + v) - x_minus_log1p(u);
        let arg = (-self.alpha * start_distance).exp() + self.penetration_scale() * g;
        (arg > 0.0).then(|| arg.ln() / self.alpha)
    }

    /// `points` samples `(x, y)` of the phase trajectory (eq. 8) from the
    /// approach `y = U` through the maximum penetration to the rebound
    /// `y = -eU`, both ends at `x = -X`.
    pub fn trajectory(
        &self,
        impact_velocity: f64,
        start_distance: f64,
        points: usize,
    ) -> Result<Vec<(f64, f64)>, ImpactError> {
        positive("impact velocity", impact_velocity)?;
        positive("start distance", start_distance)?;
        let e = restitution(impact_velocity / self.a_over_b())?;
        let (y_hi, y_lo) = (impact_velocity, -e * impact_velocity);
        let n = points.max(2);
        Ok((0..n)
            .filter_map(|i| {
                let y = y_hi + (y_lo - y_hi) * i as f64 / (n - 1) as f64;
                self.trajectory_position(impact_velocity, start_distance, y)
                    .map(|x| (x, y))
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The same six roots to 20 digits (mpmath, 40-digit arithmetic:
    /// `findroot(e - 1/V + (1 + 1/V) exp(-V(e + 1)))`, and likewise eq. 17).
    #[allow(clippy::excessive_precision)] // the digits as computed, for the record
    const HIGH_PRECISION: [(f64, f64, f64); 6] = [
        (0.01, 0.993_377_454_398_767_363_27, 4.967_038_032_356_94e-5),
        (0.1, 0.937_475_579_949_905_060_52, 4.700_800_310_782_12e-3),
        (0.5, 0.748_434_931_597_434_158_12, 9.887_695_555_122_9e-2),
        (1.0, 0.593_624_260_040_040_092_32, 3.503_687_391_316_42e-1),
        (2.0, 0.410_719_686_061_039_446_7, 1.244_789_499_221_08),
        (10.0, 0.099_981_624_752_943_886_879, 26.463_558_108_714_6),
    ];

    #[test]
    fn reproduces_theory_table() {
        for crate::model::reference::R1Row {
            v,
            e: e_ref,
            f_max: f_ref,
        } in crate::model::reference::R1_TABLE
        {
            let e = restitution(v).unwrap();
            // docs/theory.md prints 12 decimals, but its V = 0.01 entry is rounded
            // at the 10th (exact: 0.99337745439877): allow 1.5e-12 there.
            let tol = if v == 0.01 { 1.5e-12 } else { 1e-12 };
            assert!((e - e_ref).abs() < tol, "e({v}) = {e:.15} vs {e_ref}");
            let f = peak_force_dimensionless(v).unwrap();
            assert!(
                (f - f_ref).abs() < 1e-9 * f_ref,
                "f_max({v}) = {f:.12e} vs {f_ref:e}"
            );
        }
        for (v, e_ref, f_ref) in HIGH_PRECISION {
            let e = restitution(v).unwrap();
            assert!(
                (e - e_ref).abs() <= 8.0 * f64::EPSILON,
                "e({v}) = {e:.17} vs {e_ref}"
            );
            let f = peak_force_dimensionless(v).unwrap();
            assert!(
                (f - f_ref).abs() < 1e-14 * f_ref,
                "f_max({v}) = {f:.15e} vs {f_ref:e}"
            );
        }
    }

    /// The root satisfies eq. (10) itself to rounding, over V in 1e-6..1e3.
    #[test]
    fn restitution_satisfies_eq10_in_full_range() {
        let mut v = 1e-6;
        while v <= 1e3 {
            let e = restitution(v).unwrap();
            assert!(e > 0.0 && e < 1.0 && e * v <= 1.0, "V={v}: e={e}");
            // Residual in the p-form, relative to its terms.
            let p = v * (e + 1.0);
            let lhs = p;
            let rhs = (1.0 + v) * -(-p).exp_m1();
            assert!(
                (lhs - rhs).abs() <= 8.0 * f64::EPSILON * lhs,
                "V={v}: {lhs} vs {rhs}"
            );
            v *= 1.37;
        }
    }

    /// Small-V asymptote e = 1 - 2V/3 + 4V²/9 + O(V³).
    #[test]
    fn small_v_asymptote() {
        for v in [1e-6, 1e-5, 1e-4, 1e-3] {
            let e = restitution(v).unwrap();
            let series = 1.0 - 2.0 * v / 3.0 + 4.0 * v * v / 9.0;
            assert!(
                (e - series).abs() <= v * v * v + 4e-16,
                "V={v}: {e} vs {series}"
            );
            assert!(((1.0 - e) / v - 2.0 / 3.0).abs() <= v, "slope at V={v}");
        }
        // f_max ~ V²/2 for small V.
        for v in [1e-6, 1e-4] {
            let f = peak_force_dimensionless(v).unwrap();
            assert!(
                (f / (v * v / 2.0) - 1.0).abs() < 2.0 * v,
                "f_max({v}) = {f}"
            );
        }
    }

    /// Large V: e ~ 1/V.
    #[test]
    fn large_v_asymptote() {
        let v = 1e3;
        let e = restitution(v).unwrap();
        assert!((e * v - 1.0).abs() < 1e-12);
    }

    /// Newton agrees with the seed's own iterations (eqs. 11 and 18) where
    /// those converge.
    #[test]
    fn newton_matches_seed_fixed_point_iterations() {
        for v in [0.05, 0.3, 1.0, 3.0, 20.0] {
            let fp = restitution_fixed_point(v, 1e-15, 1_000_000).unwrap();
            assert!(
                (fp.value - restitution(v).unwrap()).abs() < 1e-13,
                "e at V={v}"
            );
            let wp = peak_velocity_fixed_point(v, 1e-16, 10_000).unwrap();
            assert!(
                (wp.value - peak_velocity(v).unwrap()).abs() < 1e-13 * v,
                "w* at V={v}"
            );
        }
        // The seed's iteration is slow for small V: it needs ~1/V iterations.
        let slow = restitution_fixed_point(1e-3, 1e-13, 1_000_000).unwrap();
        assert!(slow.iterations > 1000, "{} iterations", slow.iterations);
        assert!(matches!(
            restitution_fixed_point(1e-4, 1e-15, 100),
            Err(ImpactError::FixedPointNoConvergence { .. })
        ));
    }

    /// The analytic derivatives agree with central differences.
    #[test]
    fn derivatives_match_finite_differences() {
        for v in [1e-3, 0.1, 1.0, 10.0] {
            let h = 1e-6 * v;
            let e = restitution(v).unwrap();
            let fd = (restitution(v + h).unwrap() - restitution(v - h).unwrap()) / (2.0 * h);
            assert!((restitution_derivative(v, e) - fd).abs() < 1e-6 * fd.abs().max(1e-3));
            let w = peak_velocity(v).unwrap();
            let fd = (peak_force_dimensionless(v + h).unwrap()
                - peak_force_dimensionless(v - h).unwrap())
                / (2.0 * h);
            assert!((peak_force_dimensionless_derivative(v, w) - fd).abs() < 1e-6 * fd);
        }
    }

    /// f(w) of eq. (15) peaks at w* with value f_max (eq. 16).
    #[test]
    fn eq15_peaks_at_w_star() {
        for v in [0.01, 1.0, 10.0] {
            let w = peak_velocity(v).unwrap();
            let f = dimensionless_force(v, w);
            assert!((f - peak_force_dimensionless(v).unwrap()).abs() < 1e-13 * f);
            for dw in [-1e-3, 1e-3] {
                assert!(dimensionless_force(v, w + dw * v) < f);
            }
            // At w = V the force vanishes (X → ∞).
            assert!(dimensionless_force(v, v).abs() < 1e-15);
        }
    }

    /// The trajectory (eq. 8) passes through x = -X at y = U and y = -eU, and
    /// reaches the maximum penetration at y = 0.
    #[test]
    fn trajectory_endpoints_and_peak() {
        let law = crate::model::reference::seed_law();
        let imp = ExponentialImpact::new(&law, crate::model::reference::seed_bodies()).unwrap();
        let u = 0.3;
        let x_start = 3e-5;
        let c = imp.impact(u).unwrap();
        let x0 = imp.trajectory_position(u, x_start, u).unwrap();
        assert!((x0 + x_start).abs() < 1e-15);
        let x1 = imp
            .trajectory_position(u, x_start, -c.rebound_velocity)
            .unwrap();
        assert!((x1 + x_start).abs() < 1e-12, "rebound end at {x1}");
        let xm = imp.trajectory_position(u, x_start, 0.0).unwrap();
        // Far start (e^{-αX} negligible): the maximum is the closed form's.
        let xm_far = imp.trajectory_position(u, 1.0, 0.0).unwrap();
        assert!((xm_far - c.max_penetration).abs() < 1e-15);
        assert!(xm > xm_far);
        let pts = imp.trajectory(u, x_start, 101).unwrap();
        assert!(pts.iter().all(|&(x, _)| x <= xm + 1e-15));
        // Peak force from eq. (14) with μ = m/2 (the seed's equal masses).
        let q: f64 = 1.2;
        assert!(
            (c.peak_force - c.peak_force_dimensionless * 0.227 / 2.0 * 1.3e5 * q * q).abs()
                < 1e-9 * c.peak_force
        );
    }

    #[test]
    fn invalid_input_is_rejected() {
        assert!(restitution(0.0).is_err());
        assert!(restitution(-1.0).is_err());
        assert!(restitution(f64::NAN).is_err());
        assert!(peak_velocity(f64::INFINITY).is_err());
        let hertz = ContactLaw::hertz(1e9, 1.5).unwrap();
        assert!(ExponentialImpact::new(&hertz, TwoBodies::new(1.0, 1.0).unwrap()).is_err());
    }
}
