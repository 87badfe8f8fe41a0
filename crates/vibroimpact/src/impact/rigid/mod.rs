//! Impacts in the rigid limit (docs/theory.md §12): an instantaneous jump
//! of the relative velocity from `U` to `−e(U) U`, with the coefficient of
//! restitution the pair's soft law gives.
//!
//! - The exponential law: seed eq. (10), `e(V)` with `V = U/(a/b)` and no
//!   α in it, so its soft impact tends to this map as α → ∞ at fixed a/b.
//! - Hunt–Crossley, `k s^n (1 + χ ṡ)`: in the variables `s = L ξ`,
//!   `t = (L/U) τ` with `L^{n+1} = (n+1) μ U²/(2k)` the impact is
//!   `ξ'' = −(2/(n+1)) ξ^n (1 + χU ξ')`, so `e`, the peak force over
//!   `k L^n` and the duration over `L/U` are functions of `x = χU` alone
//!   (for each n), tabulated once by direct integration; below `x = 1e-6`,
//!   `e = 1 − (2/3) x` (the first-order energy loss, `(2/3) μ χ U³`),
//!   above `x = 100`, `e = 1/x` (the rebound speed tends to `1/χ`, where the
//!   force vanishes).
//! - Lankarani–Nikravesh is Hunt–Crossley with `χ = 3(1 − e₀²)/(4 v₀)`,
//!   `v₀ = max(U, v_min)`: a constant `e` above `v_min`.
//! - Kelvin–Voigt is linear: `e`, the peak force over `U` and the duration
//!   do not depend on `U` (one integration); Hertz is elastic, `e = 1`.
//! - A Newton coefficient given directly replaces the law's.
//!
//! The impulse follows from momentum, `P = μ (1 + e) U`, and the energy
//! lost is `½ μ U² (1 − e²)` exactly. The soft law's peak force and
//! duration come with each impact as estimates (what the soft contact
//! would have shown).
//!
//! Files: `mod.rs` (the laws' e(U) and the map), `tests.rs` (against
//! direct integration and closed forms).

use std::sync::{Arc, Mutex};

use super::closed_form::{
    dimensionless_velocity, restitution, restitution_derivative, ExponentialImpact,
};
use super::direct::{integrate_impact, DirectImpact, DirectOptions};
use super::table::Table;
use super::{positive, ImpactError, TwoBodies};
use crate::contact::{ContactLaw, ForceForm, LawKind};

/// `x = χU` (or V for the exponential law) below which the first-order
/// expansion holds, and above which the damped laws' `e = 1/x` holds, to
/// about 1e-12.
const TABLE_RANGE: (f64, f64) = (1e-6, 1e2);
/// Pieces of the tables over ln x (each of degree 16).
const TABLE_PIECES: usize = 16;

/// One contact pair's impacts in the rigid limit.
#[derive(Clone, Debug)]
pub struct RigidLaw {
    mu: f64,
    shape: Shape,
}

#[derive(Clone, Debug)]
enum Shape {
    /// Seed eq. (10) and the closed-form peak force; the duration tabulated
    /// in V (its unit `1/(α a/b)`: μ only shifts the impact in s).
    Seed(Seed),
    /// Hunt–Crossley and Lankarani–Nikravesh: functions of x = χ(U) U.
    Damped {
        law: ContactLaw,
        k: f64,
        n: f64,
        /// χ, or for Lankarani–Nikravesh `3(1 − e₀²)/4` and v_min.
        chi: Chi,
        table: Arc<Table<3>>,
    },
    /// Kelvin–Voigt: e, the peak force per unit U and the duration.
    Linear {
        e: f64,
        peak_per_velocity: f64,
        duration: f64,
    },
    /// Hertz: e = 1, the peak force k L^n, the duration `tau L/U`.
    Elastic { k: f64, n: f64, tau: f64 },
    /// A coefficient given directly (the soft law's estimates kept).
    Newton { e: f64, soft: Box<Shape> },
}

#[derive(Clone, Copy, Debug)]
enum Chi {
    Fixed(f64),
    Lankarani { c: f64, v_min: f64 },
}

impl Chi {
    /// x = χ(U) U and dx/dU.
    fn x(self, u: f64) -> (f64, f64) {
        match self {
            Chi::Fixed(chi) => (chi * u, chi),
            Chi::Lankarani { c, v_min } if u < v_min => (c * u / v_min, c / v_min),
            Chi::Lankarani { c, .. } => (c, 0.0),
        }
    }
}

/// One impact in the rigid limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidImpact {
    /// Approach velocity U (m/s).
    pub impact_velocity: f64,
    /// Coefficient of restitution e(U).
    pub restitution: f64,
    /// de/dU (s/m), for the saltation of a velocity-dependent law.
    pub restitution_slope: f64,
    /// Separation velocity e U (m/s).
    pub rebound_velocity: f64,
    /// Impulse P = μ (1 + e) U (N s), pushing the bodies apart.
    pub impulse: f64,
    /// Energy lost, ½ μ U² (1 − e²) (J).
    pub energy_lost: f64,
    /// The soft law's peak force (N), an estimate.
    pub peak_force: f64,
    /// The soft law's contact duration (s), an estimate.
    pub duration: f64,
}

impl RigidLaw {
    /// The rigid limit of `law` between bodies of reduced mass `mu`, or a
    /// Newton coefficient `restitution` in (0, 1] in place of the law's.
    pub fn new(law: &ContactLaw, mu: f64, restitution: Option<f64>) -> Result<Self, ImpactError> {
        positive("reduced mass", mu)?;
        let soft = match *law.kind() {
            LawKind::Exponential { a, b, alpha } => Shape::Seed(Seed {
                law: *law,
                closed: ExponentialImpact::new(law, TwoBodies::against_wall(mu)?)?,
                a_over_b: a / b,
                alpha,
                table: table(Tabled::Exponential)?,
            }),
            LawKind::HuntCrossley { k, n, chi } if chi > 0.0 => Shape::Damped {
                law: *law,
                k,
                n,
                chi: Chi::Fixed(chi),
                table: table(Tabled::Damped(n))?,
            },
            LawKind::LankaraniNikravesh {
                k,
                n,
                restitution,
                min_impact_velocity,
            } => Shape::Damped {
                law: *law,
                k,
                n,
                chi: Chi::Lankarani {
                    c: 0.75 * (1.0 - restitution * restitution),
                    v_min: min_impact_velocity,
                },
                table: table(Tabled::Damped(n))?,
            },
            LawKind::Hertz { k, n } | LawKind::HuntCrossley { k, n, .. } => {
                let r = unit_impact(&ContactLaw::hertz(k, n).map_err(unsupported)?, mu)?;
                let l = law.length_scale(mu, 1.0);
                Shape::Elastic {
                    k,
                    n,
                    tau: r.contact_duration / l,
                }
            }
            LawKind::KelvinVoigt { k, c } => {
                let zeta = c / (2.0 * (k * mu).sqrt());
                if law.form() == ForceForm::Published && zeta >= 1.0 {
                    return Err(ImpactError::Unsupported(format!(
                        "kelvin-voigt with damping ratio c/(2 sqrt(k mu)) = {zeta} >= 1 never separates (e = 0): a rigid impact cannot stand for it; keep the soft law, or give a restitution"
                    )));
                }
                let r = unit_impact(law, mu)?;
                Shape::Linear {
                    e: r.restitution,
                    peak_per_velocity: r.peak_force,
                    duration: r.contact_duration,
                }
            }
        };
        let shape = match restitution {
            None => soft,
            Some(e) if e > 0.0 && e <= 1.0 => Shape::Newton {
                e,
                soft: Box::new(soft),
            },
            Some(e) => return Err(ImpactError::InvalidParameter {
                name: "restitution",
                value: e,
                requirement:
                    "must lie in (0, 1] (e = 0 keeps the bodies together: that needs the soft law)",
            }),
        };
        if let Shape::Linear { e, .. } = shape {
            if e <= 0.0 {
                return Err(ImpactError::Unsupported(
                    "this kelvin-voigt contact gives e = 0 (the bodies do not separate): keep the soft law, or give a restitution".into(),
                ));
            }
        }
        Ok(Self { mu, shape })
    }

    /// The reduced mass μ (kg).
    pub fn reduced_mass(&self) -> f64 {
        self.mu
    }

    /// What judging an impact at approach velocity `u > 0` (m/s) reads:
    /// its estimated duration (s) and rebound velocity (m/s), as
    /// [`RigidLaw::impact`] has them (for the seed's law without solving
    /// for the peak force).
    pub fn judging(&self, u: f64) -> Result<(f64, f64), ImpactError> {
        positive("impact velocity", u)?;
        let (e, duration) = self.shape.judging(self.mu, u)?;
        Ok((duration, e * u))
    }

    /// The impact at approach velocity `u > 0` (m/s).
    pub fn impact(&self, u: f64) -> Result<RigidImpact, ImpactError> {
        self.impact_with(u, true)
    }

    /// The impact at `u > 0` as a period map takes it: the jump, de/dU and
    /// the estimated duration, the same bits as [`impact`](Self::impact)'s;
    /// the peak force, which only an impact log reads, left NaN where it
    /// is a root of its own (the seed's law, also under a Newton
    /// coefficient).
    pub fn jump(&self, u: f64) -> Result<RigidImpact, ImpactError> {
        self.impact_with(u, false)
    }

    /// [`impact`](Self::impact), its peak force solved or not (`peak`).
    fn impact_with(&self, u: f64, peak: bool) -> Result<RigidImpact, ImpactError> {
        positive("impact velocity", u)?;
        let (e, slope, peak_force, duration) = self.shape.at(self.mu, u, peak)?;
        Ok(RigidImpact {
            impact_velocity: u,
            restitution: e,
            restitution_slope: slope,
            rebound_velocity: e * u,
            impulse: self.mu * (1.0 + e) * u,
            energy_lost: 0.5 * self.mu * u * u * (1.0 - e) * (1.0 + e),
            peak_force,
            duration,
        })
    }
}

impl Shape {
    /// (e, de/dU, peak force, duration) at U; without `peak`, the seed's
    /// law's peak force not solved (NaN).
    fn at(&self, mu: f64, u: f64, peak: bool) -> Result<(f64, f64, f64, f64), ImpactError> {
        Ok(match self {
            Shape::Seed(seed) => {
                // (The closed form's e(V) is the same root: solved once;
                // without the peak, e(V) alone.)
                let (v, e, peak_force) = if peak {
                    let closed = seed.closed.impact(u)?;
                    (closed.v, closed.restitution, closed.peak_force)
                } else {
                    let v = dimensionless_velocity(u, seed.closed.a_over_b());
                    (v, restitution(v)?, f64::NAN)
                };
                let duration = seed.duration(mu, (u, v))?;
                let slope = restitution_derivative(v, e) / seed.a_over_b;
                (e, slope, peak_force, duration)
            }
            Shape::Damped {
                law,
                k,
                n,
                chi,
                table,
            } => {
                let (x, dx) = chi.x(u);
                let l = ((n + 1.0) * mu * u * u / (2.0 * k)).powf(1.0 / (n + 1.0));
                let scale = (k * l.powf(*n), l / u);
                let (lo, hi) = TABLE_RANGE;
                let (e, de) = if x < lo {
                    // Second order matched to the table's end (its value
                    // there carries the integration's 1e-13).
                    let c = (table.value(0, lo.ln()) - 1.0 + 2.0 / 3.0 * lo) / (lo * lo);
                    (1.0 - 2.0 / 3.0 * x + c * x * x, -2.0 / 3.0 + 2.0 * c * x)
                } else if x > hi {
                    (1.0 / x, -1.0 / (x * x))
                } else {
                    let (e, de_dq) = table.at(0, x.ln());
                    (e, de_dq / x)
                };
                let q = x.clamp(lo, hi).ln();
                let (peak, tau) = if x > hi {
                    let r = direct(law, mu, u)?;
                    (r.peak_force, r.contact_duration)
                } else {
                    let peak = table.value(1, q).exp();
                    let tau = table.value(2, q).exp();
                    (peak * scale.0, tau * scale.1)
                };
                (e, de * dx, peak, tau)
            }
            Shape::Linear {
                e,
                peak_per_velocity,
                duration,
            } => (*e, 0.0, peak_per_velocity * u, *duration),
            Shape::Elastic { k, n, tau } => {
                let l = ((n + 1.0) * mu * u * u / (2.0 * k)).powf(1.0 / (n + 1.0));
                (1.0, 0.0, k * l.powf(*n), tau * l / u)
            }
            Shape::Newton { e, soft } => {
                let (_, _, peak, tau) = soft.at(mu, u, peak)?;
                (*e, 0.0, peak, tau)
            }
        })
    }

    /// (e, duration) at U, as [`Shape::at`] has them: for the seed's law
    /// without the peak force's root.
    fn judging(&self, mu: f64, u: f64) -> Result<(f64, f64), ImpactError> {
        match self {
            Shape::Seed(seed) => {
                let v = dimensionless_velocity(u, seed.closed.a_over_b());
                Ok((restitution(v)?, seed.duration(mu, (u, v))?))
            }
            Shape::Newton { e, soft } => Ok((*e, soft.judging(mu, u)?.1)),
            _ => {
                let (e, _, _, duration) = self.at(mu, u, true)?;
                Ok((e, duration))
            }
        }
    }
}

/// The seed's law in its rigid limit ([`Shape::Seed`]).
#[derive(Clone, Debug)]
struct Seed {
    law: ContactLaw,
    closed: ExponentialImpact,
    a_over_b: f64,
    alpha: f64,
    table: Arc<Table<3>>,
}

impl Seed {
    /// The duration at U (V = U/(a/b)): its table's, or the law's
    /// integrated beyond the table.
    fn duration(&self, mu: f64, (u, v): (f64, f64)) -> Result<f64, ImpactError> {
        Ok(if self.table.contains(v.ln()) {
            self.table.value(2, v.ln()).exp() / (self.alpha * self.a_over_b)
        } else {
            direct(&self.law, mu, u)?.contact_duration
        })
    }
}

fn unsupported(e: impl std::fmt::Display) -> ImpactError {
    ImpactError::Unsupported(e.to_string())
}

/// The law's impact against a wall with mass `mu` at `u`.
fn direct(law: &ContactLaw, mu: f64, u: f64) -> Result<DirectImpact, ImpactError> {
    integrate_impact(law, TwoBodies::against_wall(mu)?, u, &DIRECT)
}

/// The integrations behind the tables and constants: near double
/// precision (e to about 1e-13).
const DIRECT: DirectOptions = DirectOptions {
    rtol: 1e-14,
    duration_level: None,
    max_steps: 1_000_000,
};

/// The impact at U = 1 m/s.
fn unit_impact(law: &ContactLaw, mu: f64) -> Result<DirectImpact, ImpactError> {
    direct(law, mu, 1.0)
}

/// The tabulated families.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Tabled {
    /// The exponential law (a = b = α = μ = 1): e, ln peak force, ln
    /// duration, in ln V.
    Exponential,
    /// Hunt–Crossley of exponent n: e, ln(peak force / (k L^n)),
    /// ln(duration U/L), in ln χU.
    Damped(f64),
}

/// A family's key: its kind and exponent's bits.
type Key = (u8, u64);

/// The tables built so far: each family once per process.
static TABLES: Mutex<Vec<(Key, Arc<Table<3>>)>> = Mutex::new(Vec::new());

/// The table of `family` over ln x, built on first use.
fn table(family: Tabled) -> Result<Arc<Table<3>>, ImpactError> {
    let key = match family {
        Tabled::Exponential => (0, 0),
        Tabled::Damped(n) => (1, n.to_bits()),
    };
    let mut tables = TABLES.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, t)) = tables.iter().find(|(k, _)| *k == key) {
        return Ok(t.clone());
    }
    let (lo, hi) = TABLE_RANGE;
    let built = Arc::new(Table::new((lo.ln(), hi.ln()), TABLE_PIECES, |q| {
        let x = q.exp();
        Ok::<_, ImpactError>(match family {
            Tabled::Exponential => {
                // a = b = α = 1, μ = 1: V = U, the time unit 1.
                let law = ContactLaw::exponential(1.0, 1.0, 1.0, ForceForm::Published)
                    .map_err(unsupported)?;
                let r = direct(&law, 1.0, x)?;
                [r.restitution, r.peak_force.ln(), r.contact_duration.ln()]
            }
            Tabled::Damped(n) => {
                // k = μ = χ = 1: x = U, L^{n+1} = (n+1) U²/2.
                let law = ContactLaw::hunt_crossley(1.0, n, 1.0, ForceForm::Published)
                    .map_err(unsupported)?;
                let r = direct(&law, 1.0, x)?;
                let l = ((n + 1.0) * x * x / 2.0).powf(1.0 / (n + 1.0));
                [
                    r.restitution,
                    (r.peak_force / l.powf(n)).ln(),
                    (r.contact_duration * x / l).ln(),
                ]
            }
        })
    })?);
    tables.push((key, built.clone()));
    Ok(built)
}

#[cfg(test)]
mod tests;
