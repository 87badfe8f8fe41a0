//! Hysteresis of inelastic storeys (docs/theory.md §11): the force across a
//! storey as a function of its drift d and its history, carried by a
//! hysteretic drift z.
//!
//! Files: `mod.rs` (the laws), `imk.rs` (the modified IMK storey),
//! `tests.rs` (loops against closed forms).
//!
//! - Elastic: F = k d.
//! - Bilinear with kinematic hardening (OpenSees `Steel01` without its
//!   isotropic terms): F = k (b d + (1 − b) z), where z follows d while
//!   |z| < u_y and stays at ±u_y while the drift goes on outwards. Between
//!   the switches (yield: |z| reaches u_y; unloading: ḋ changes sign) the
//!   force is linear in d, so the motion between them is exact.
//! - Bouc–Wen (OpenSees `BoucWen`, with its strength and stiffness
//!   degradation): F = k (α d + (1 − α) z) with
//!   ż = ḋ [A − ν (γ + β sgn(ḋ z)) |z / u_y|ⁿ] / η, A = 1 − δ_A e,
//!   ν = 1 + δ_ν e, η = 1 + δ_η e, and e = ∫ (1 − α) k z dd the work of the
//!   hysteretic part. With β + γ = 1 and no degradation z saturates at
//!   ±u_y: u_y is the yield drift. OpenSees' parameters are ours with
//!   β_OS = β / u_yⁿ, γ_OS = γ / u_yⁿ.
//!
//! The dissipated (hysteretic) energy of a storey is the work of its
//! hysteretic part less what it stores, (1 − b) k (∫ z dd − z²/2).

use serde::{Deserialize, Serialize};

use crate::integrate::{integrate_to, IntegrationError, IntegratorOptions, OdeSystem};
use crate::model::record::RecordError;

/// A storey law's setting refused: its key and what is wrong (the caller
/// names the building and storey).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{key} = {value}: {message}")]
pub struct LawError {
    /// The key (`stiffness`, `yield_drift`, `post_yield_ratio`, `exponent`,
    /// `beta`, `gamma`, `degradation_a`, `degradation_nu`,
    /// `degradation_eta`; of a protocol `amplitudes`, `cycles`, `points`).
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// What is wrong.
    pub message: &'static str,
}

/// Bilinear hysteresis with kinematic hardening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bilinear {
    /// Elastic stiffness k (N/m).
    pub stiffness: f64,
    /// Yield drift u_y (m).
    pub yield_drift: f64,
    /// Post-yield stiffness over the elastic one, b ∈ [0, 1).
    pub post_yield_ratio: f64,
}

/// Strength and stiffness degradation of Bouc–Wen with the work e of the
/// hysteretic part (1/J): A = 1 − δ_A e, ν = 1 + δ_ν e, η = 1 + δ_η e.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Degradation {
    /// δ_A.
    pub a: f64,
    /// δ_ν (strength).
    pub nu: f64,
    /// δ_η (stiffness).
    pub eta: f64,
}

/// Bouc–Wen smooth hysteresis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoucWen {
    /// Elastic stiffness k (N/m).
    pub stiffness: f64,
    /// Yield drift u_y (m): where z saturates with β + γ = 1.
    pub yield_drift: f64,
    /// Post-yield stiffness over the elastic one, α ∈ [0, 1).
    pub post_yield_ratio: f64,
    /// The exponent n ≥ 1 (large: sharp yield).
    pub exponent: f64,
    /// β: with γ the loop's shape (β + γ = 1 for z to saturate at u_y;
    /// OpenSees' examples take β = 0.55, γ = 0.45).
    pub beta: f64,
    /// γ.
    pub gamma: f64,
    /// Degradation with the hysteretic work (none by default).
    pub degradation: Degradation,
}

/// A storey's force–drift law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StoreyLaw {
    /// Linear.
    Elastic {
        /// Stiffness k (N/m).
        stiffness: f64,
    },
    /// Bilinear with kinematic hardening.
    Bilinear(Bilinear),
    /// Bouc–Wen.
    BoucWen(BoucWen),
    /// The modified Ibarra–Medina–Krawinkler storey (OpenSees `IMKBilin`):
    /// its memory is an [`imk::ImkState`], not a hysteretic drift.
    Imk(imk::Imk),
}

/// What a storey carries besides its drift: the hysteretic drift z (m)
/// and the work e of its hysteretic part (J).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Hysteretic {
    /// z.
    pub z: f64,
    /// e = ∫ (1 − α) k z dd.
    pub work: f64,
}

/// `Ok` if `v` satisfies `ok`, else the error for `key`.
fn need(key: &'static str, v: f64, ok: bool, message: &'static str) -> Result<(), LawError> {
    if ok && v.is_finite() {
        Ok(())
    } else {
        Err(LawError {
            key,
            value: v,
            message,
        })
    }
}

/// The smallest yield drift (m): below a nanometre a storey switches
/// branch at every step of a run (a fuzzed 5e-324 m hung a pounding run).
pub const MIN_YIELD_DRIFT: f64 = 1e-9;

/// The checks every hysteretic law shares: stiffness positive, yield
/// drift at least [`MIN_YIELD_DRIFT`], post-yield ratio in [0, 1).
fn check_common(k: f64, uy: f64, b: f64) -> Result<(), LawError> {
    need("stiffness", k, k > 0.0, "must be finite and > 0")?;
    need("yield_drift", uy, uy > 0.0, "must be finite and > 0")?;
    need(
        "yield_drift",
        uy,
        uy >= MIN_YIELD_DRIFT,
        "must be at least 1e-9 m (a smaller one switches branch at every step)",
    )?;
    need(
        "post_yield_ratio",
        b,
        (0.0..1.0).contains(&b),
        "must be in [0, 1)",
    )
}

impl Bilinear {
    /// Refuses a stiffness or yield drift ≤ 0 and a post-yield ratio
    /// outside [0, 1).
    pub fn check(&self) -> Result<(), LawError> {
        check_common(self.stiffness, self.yield_drift, self.post_yield_ratio)
    }

    /// The force at drift `d` with hysteretic drift `z`.
    pub fn force(&self, d: f64, z: f64) -> f64 {
        let b = self.post_yield_ratio;
        self.stiffness * (b * d + (1.0 - b) * z)
    }

    /// The state after the drift moves monotonically from `d0` to `d1`:
    /// z follows until it reaches ±u_y, then stays; the work of the
    /// hysteretic part grows by (1 − b) k ∫ z dd. Exact.
    pub fn advance(&self, s: Hysteretic, d0: f64, d1: f64) -> Hysteretic {
        let (uy, kh) = (
            self.yield_drift,
            (1.0 - self.post_yield_ratio) * self.stiffness,
        );
        let step = d1 - d0;
        let bound = uy.copysign(step);
        // The elastic part: z moves with d up to the bound.
        let elastic = if step == 0.0 {
            0.0
        } else {
            ((bound - s.z) / step).clamp(0.0, 1.0) * step
        };
        let z_yield = s.z + elastic;
        let plastic = step - elastic;
        let z = if plastic == 0.0 { z_yield } else { bound };
        Hysteretic {
            z,
            work: s.work + kh * (0.5 * (s.z + z_yield) * elastic + z * plastic),
        }
    }
}

impl BoucWen {
    /// Refuses a stiffness or yield drift ≤ 0, a post-yield ratio outside
    /// [0, 1), an exponent below 1 (|z|ⁿ then has an infinite slope at
    /// z = 0), β + γ ≤ 0 (z unbounded under loading), β < 0 (the tangent on
    /// unloading from saturation, 2β/(β + γ) of the elastic one, turns
    /// negative) and degradation coefficients below 0.
    pub fn check(&self) -> Result<(), LawError> {
        check_common(self.stiffness, self.yield_drift, self.post_yield_ratio)?;
        need(
            "exponent",
            self.exponent,
            self.exponent >= 1.0,
            "must be finite and >= 1",
        )?;
        need("gamma", self.gamma, true, "must be finite")?;
        need(
            "beta",
            self.beta,
            self.beta + self.gamma > 0.0,
            "give beta + gamma > 0 (else z grows without bound under loading)",
        )?;
        need(
            "beta",
            self.beta,
            self.beta >= 0.0,
            "give beta >= 0 (else the tangent turns negative on unloading)",
        )?;
        let dg = &self.degradation;
        need(
            "degradation_a",
            dg.a,
            dg.a >= 0.0,
            "must be finite and >= 0",
        )?;
        need(
            "degradation_nu",
            dg.nu,
            dg.nu >= 0.0,
            "must be finite and >= 0",
        )?;
        need(
            "degradation_eta",
            dg.eta,
            dg.eta >= 0.0,
            "must be finite and >= 0",
        )
    }

    /// The force at drift `d` with hysteretic drift `z`.
    pub fn force(&self, d: f64, z: f64) -> f64 {
        let a = self.post_yield_ratio;
        self.stiffness * (a * d + (1.0 - a) * z)
    }

    /// dz/dd and de/dd in the state `s` with the drift moving in the
    /// direction `sign` (±1).
    pub fn slope(&self, s: Hysteretic, sign: f64) -> (f64, f64) {
        let dg = &self.degradation;
        let a = 1.0 - dg.a * s.work;
        let nu = 1.0 + dg.nu * s.work;
        let eta = 1.0 + dg.eta * s.work;
        let psi = self.gamma + self.beta * if sign * s.z > 0.0 { 1.0 } else { -1.0 };
        let dz = (a - nu * psi * (s.z / self.yield_drift).abs().powf(self.exponent)) / eta;
        (dz, (1.0 - self.post_yield_ratio) * self.stiffness * s.z)
    }

    /// The state after the drift moves monotonically from `d0` to `d1`,
    /// by DOP853 on dz/dd to relative tolerance `rtol`.
    pub fn advance(
        &self,
        s: Hysteretic,
        d0: f64,
        d1: f64,
        rtol: f64,
    ) -> Result<Hysteretic, IntegrationError> {
        if d1 == d0 {
            return Ok(s);
        }
        let mut sys = AlongDrift {
            law: *self,
            sign: (d1 - d0).signum(),
        };
        // In the distance travelled over u_y, with z over u_y and the work
        // over k u_y²: one tolerance for both.
        let (uy, scale) = (self.yield_drift, self.stiffness * self.yield_drift.powi(2));
        let opts = IntegratorOptions {
            rtol,
            atol: rtol,
            ..IntegratorOptions::default()
        };
        let y0 = [s.z / uy, s.work / scale];
        let (y, _) = integrate_to(&mut sys, 0.0, &y0, (d1 - d0).abs() / uy, &opts)?;
        Ok(Hysteretic {
            z: y[0] * uy,
            work: y[1] * scale,
        })
    }
}

/// Bouc–Wen's state along the distance travelled by the drift in one
/// direction.
struct AlongDrift {
    law: BoucWen,
    sign: f64,
}

impl OdeSystem for AlongDrift {
    fn dim(&self) -> usize {
        2
    }
    /// In the scaled variables of [`BoucWen::advance`].
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        let (uy, k) = (self.law.yield_drift, self.law.stiffness);
        let s = Hysteretic {
            z: y[0] * uy,
            work: y[1] * k * uy * uy,
        };
        let (dz, dw) = self.law.slope(s, self.sign);
        dydt[0] = self.sign * dz;
        dydt[1] = self.sign * dw / (k * uy);
    }
}

impl StoreyLaw {
    /// The law's checks.
    pub fn check(&self) -> Result<(), LawError> {
        match self {
            StoreyLaw::Elastic { stiffness } => need(
                "stiffness",
                *stiffness,
                *stiffness > 0.0,
                "must be finite and > 0",
            ),
            StoreyLaw::Bilinear(b) => b.check(),
            StoreyLaw::BoucWen(w) => w.check(),
            StoreyLaw::Imk(m) => m.check(),
        }
    }

    /// The initial (elastic) stiffness, on which Rayleigh damping is based.
    pub fn initial_stiffness(&self) -> f64 {
        match self {
            StoreyLaw::Elastic { stiffness } => *stiffness,
            StoreyLaw::Bilinear(b) => b.stiffness,
            StoreyLaw::BoucWen(w) => w.stiffness,
            StoreyLaw::Imk(m) => m.stiffness,
        }
    }

    /// The force at drift `d` in state `s`.
    ///
    /// An IMK storey's force, stored and dissipated energy come from its
    /// own state ([`imk::Imk::piece_force`]): NaN here.
    pub fn force(&self, d: f64, s: Hysteretic) -> f64 {
        match self {
            StoreyLaw::Elastic { stiffness } => stiffness * d,
            StoreyLaw::Bilinear(b) => b.force(d, s.z),
            StoreyLaw::BoucWen(w) => w.force(d, s.z),
            StoreyLaw::Imk(_) => f64::NAN,
        }
    }

    /// The energy stored at drift `d` in state `s`: ½ b k d² + ½ (1 − b) k z²
    /// (½ k d² for the elastic law). With [`StoreyLaw::dissipated`] it is
    /// the work ∫ F dd done on the storey.
    pub fn stored(&self, d: f64, s: Hysteretic) -> f64 {
        let (k, b) = match self {
            StoreyLaw::Elastic { stiffness } => return 0.5 * stiffness * d * d,
            StoreyLaw::Bilinear(b) => (b.stiffness, b.post_yield_ratio),
            StoreyLaw::BoucWen(w) => (w.stiffness, w.post_yield_ratio),
            StoreyLaw::Imk(_) => return f64::NAN,
        };
        0.5 * k * (b * d * d + (1.0 - b) * s.z * s.z)
    }

    /// The energy dissipated by hysteresis in state `s`: the hysteretic
    /// part's work less what it stores.
    pub fn dissipated(&self, s: Hysteretic) -> f64 {
        let (k, b) = match self {
            StoreyLaw::Elastic { .. } => return 0.0,
            StoreyLaw::Bilinear(b) => (b.stiffness, b.post_yield_ratio),
            StoreyLaw::BoucWen(w) => (w.stiffness, w.post_yield_ratio),
            StoreyLaw::Imk(_) => return f64::NAN,
        };
        s.work - 0.5 * (1.0 - b) * k * s.z * s.z
    }
}

/// A storey under an imposed drift history: the force and the dissipated
/// energy at every drift (the drift moves linearly between them), from
/// rest. Bouc–Wen to relative tolerance `rtol`.
pub fn under_drift(
    law: &StoreyLaw,
    drifts: &[f64],
    rtol: f64,
) -> Result<Vec<(f64, f64)>, IntegrationError> {
    let rows = path(law, drifts, rtol)?;
    // A force or energy past double precision (a drift of 1e300 m on a
    // stiff storey) is refused, never drawn.
    if let Some(k) = rows
        .iter()
        .position(|(f, e)| !(f.is_finite() && e.is_finite()))
    {
        return Err(IntegrationError::InvalidOptions(format!(
            "drift sample {} = {:e} m: the storey's force or energy is not finite there (beyond double precision for this law); give smaller drifts",
            k + 1,
            drifts[k]
        )));
    }
    Ok(rows)
}

/// [`under_drift`]'s rows, unchecked.
fn path(law: &StoreyLaw, drifts: &[f64], rtol: f64) -> Result<Vec<(f64, f64)>, IntegrationError> {
    if let StoreyLaw::Imk(m) = law {
        let mut s = m.rest();
        return Ok(drifts
            .iter()
            .map(|&d| {
                m.advance(&mut s, d);
                (s.force, m.dissipated(&s))
            })
            .collect());
    }
    let mut s = Hysteretic::default();
    let mut out = Vec::with_capacity(drifts.len());
    let mut d0 = 0.0;
    for &d in drifts {
        s = match law {
            StoreyLaw::Elastic { .. } => s,
            StoreyLaw::Bilinear(b) => b.advance(s, d0, d),
            StoreyLaw::BoucWen(w) => w.advance(s, d0, d, rtol)?,
            StoreyLaw::Imk(_) => s,
        };
        out.push((law.force(d, s), law.dissipated(s)));
        d0 = d;
    }
    Ok(out)
}

/// A storey's law as written in a file or given by a face, without its
/// stiffness (the frame's): `law = "elastic" | "bilinear" | "bouc-wen"`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum StoreySpec {
    /// Linear (no other key: a `yield_drift` given to an elastic storey is
    /// refused, not ignored).
    Elastic {},
    /// Bilinear with kinematic hardening.
    Bilinear {
        /// Yield drift u_y (m).
        yield_drift: f64,
        /// b ∈ [0, 1).
        post_yield_ratio: f64,
    },
    /// Bouc–Wen.
    BoucWen {
        /// Yield drift u_y (m).
        yield_drift: f64,
        /// α ∈ [0, 1).
        post_yield_ratio: f64,
        /// n ≥ 1, default 2.
        exponent: Option<f64>,
        /// β, default 0.5.
        beta: Option<f64>,
        /// γ, default 0.5.
        gamma: Option<f64>,
        /// δ_A (1/J), default 0.
        degradation_a: Option<f64>,
        /// δ_ν (1/J), default 0.
        degradation_nu: Option<f64>,
        /// δ_η (1/J), default 0.
        degradation_eta: Option<f64>,
    },
    /// The modified IMK storey (OpenSees `IMKBilin`, symmetric).
    Imk {
        /// Yield drift u_y (m).
        yield_drift: f64,
        /// F_c/F_y ≥ 1.
        cap_ratio: f64,
        /// Plastic drift to the cap d_p (m).
        plastic_drift: f64,
        /// Post-capping drift d_pc (m), cap to zero force.
        post_capping_drift: f64,
        /// F_r/F_y in [0, 1].
        residual_ratio: f64,
        /// Ultimate drift d_u (m).
        ultimate_drift: f64,
        /// λ_S (m), default none (no strength deterioration).
        lambda_s: Option<f64>,
        /// λ_C (m), default none.
        lambda_c: Option<f64>,
        /// λ_K (m), default none.
        lambda_k: Option<f64>,
        /// c_S, default 1.
        c_s: Option<f64>,
        /// c_C, default 1.
        c_c: Option<f64>,
        /// c_K, default 1.
        c_k: Option<f64>,
    },
}

/// The keys an IMK storey needs besides its yield drift, in the order
/// [`StoreySpec::imk`] takes them.
pub const IMK_KEYS: [&str; 5] = [
    "cap_ratio",
    "plastic_drift",
    "post_capping_drift",
    "residual_ratio",
    "ultimate_drift",
];

impl StoreySpec {
    /// An IMK storey's spec from the keys as the faces take them: the yield
    /// drift, the five of [`IMK_KEYS`], λ_S, λ_C, λ_K (None: no such
    /// deterioration) and c_S, c_C, c_K. Err: the first key missing.
    pub fn imk(
        yield_drift: Option<f64>,
        keys: [Option<f64>; 5],
        lambda: [Option<f64>; 3],
        c: [f64; 3],
    ) -> Result<Self, &'static str> {
        let yield_drift = yield_drift.ok_or("yield_drift")?;
        let mut v = [0.0; 5];
        for (k, key) in IMK_KEYS.iter().enumerate() {
            v[k] = keys[k].ok_or(*key)?;
        }
        Ok(StoreySpec::Imk {
            yield_drift,
            cap_ratio: v[0],
            plastic_drift: v[1],
            post_capping_drift: v[2],
            residual_ratio: v[3],
            ultimate_drift: v[4],
            lambda_s: lambda[0],
            lambda_c: lambda[1],
            lambda_k: lambda[2],
            c_s: Some(c[0]),
            c_c: Some(c[1]),
            c_k: Some(c[2]),
        })
    }

    /// The law with the storey's elastic `stiffness`, checked.
    pub fn law(&self, stiffness: f64) -> Result<StoreyLaw, LawError> {
        let law = match *self {
            StoreySpec::Elastic {} => StoreyLaw::Elastic { stiffness },
            StoreySpec::Bilinear {
                yield_drift,
                post_yield_ratio,
            } => StoreyLaw::Bilinear(Bilinear {
                stiffness,
                yield_drift,
                post_yield_ratio,
            }),
            StoreySpec::BoucWen {
                yield_drift,
                post_yield_ratio,
                exponent,
                beta,
                gamma,
                degradation_a,
                degradation_nu,
                degradation_eta,
            } => StoreyLaw::BoucWen(BoucWen {
                stiffness,
                yield_drift,
                post_yield_ratio,
                exponent: exponent.unwrap_or(2.0),
                beta: beta.unwrap_or(0.5),
                gamma: gamma.unwrap_or(0.5),
                degradation: Degradation {
                    a: degradation_a.unwrap_or(0.0),
                    nu: degradation_nu.unwrap_or(0.0),
                    eta: degradation_eta.unwrap_or(0.0),
                },
            }),
            StoreySpec::Imk {
                yield_drift,
                cap_ratio,
                plastic_drift,
                post_capping_drift,
                residual_ratio,
                ultimate_drift,
                lambda_s,
                lambda_c,
                lambda_k,
                c_s,
                c_c,
                c_k,
            } => StoreyLaw::Imk(imk::Imk {
                stiffness,
                yield_drift,
                cap_ratio,
                plastic_drift,
                post_capping_drift,
                residual_ratio,
                ultimate_drift,
                lambda: [lambda_s, lambda_c, lambda_k].map(|l| l.unwrap_or(f64::INFINITY)),
                exponent: [c_s, c_c, c_k].map(|c| c.unwrap_or(1.0)),
            }),
        };
        law.check()?;
        Ok(law)
    }
}

/// A drift history from text (`source` names it in errors): one drift a
/// line (m), blank lines and `#` comments skipped, text before the first
/// number a header; a line that starts with a number is data, never taken
/// for a header; every drift finite, at least one.
pub fn parse_drifts(text: &str, source: &str) -> Result<Vec<f64>, RecordError> {
    let mut drifts = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        match l.parse::<f64>() {
            Ok(d) if d.is_finite() => drifts.push(d),
            Ok(_) => {
                return Err(RecordError::at(
                    source,
                    i + 1,
                    format!("`{l}` is not finite"),
                ))
            }
            Err(_) if drifts.is_empty() && !starts_with_number(l) => continue,
            Err(_) => {
                let hint = if starts_with_number(l) {
                    " (one drift a line)"
                } else {
                    ""
                };
                return Err(RecordError::at(
                    source,
                    i + 1,
                    format!("`{l}` is not a drift{hint}"),
                ));
            }
        }
    }
    if drifts.is_empty() {
        return Err(RecordError::whole(source, "no drifts"));
    }
    Ok(drifts)
}

/// Whether the first field of `line` (split at whitespace, `,` or `;`)
/// reads as a number: then the line is data, not a header.
fn starts_with_number(line: &str) -> bool {
    line.split(|c: char| c.is_whitespace() || c == ',' || c == ';')
        .next()
        .is_some_and(|f| f.parse::<f64>().is_ok())
}

/// Seconds per drift sample of [`under_drift`] (measured: Bouc–Wen
/// integrated between samples 3 µs, the piecewise-linear laws 0.2 µs).
pub fn seconds_per_drift(law: &StoreyLaw) -> f64 {
    match law {
        StoreyLaw::BoucWen(_) => 3e-6,
        _ => 0.2e-6,
    }
}

/// The most samples a cyclic protocol may have (800 MB of drifts).
pub const MAX_PROTOCOL_SAMPLES: f64 = 1e8;

/// A cyclic drift protocol: `cycles` sine cycles at each amplitude of
/// `amplitudes` (m) in turn, `points` samples a cycle (a multiple of 4, so
/// that the turning points are samples), from rest.
pub fn cyclic_protocol(
    amplitudes: &[f64],
    cycles: usize,
    points: usize,
) -> Result<Vec<f64>, LawError> {
    let bad = |key, value: f64, message| LawError {
        key,
        value,
        message,
    };
    if points == 0 || points % 4 != 0 {
        return Err(bad(
            "points",
            points as f64,
            "give a positive multiple of 4",
        ));
    }
    if cycles == 0 {
        return Err(bad("cycles", 0.0, "give at least one cycle"));
    }
    let total = (cycles as f64) * (points as f64) * amplitudes.len() as f64;
    if total > MAX_PROTOCOL_SAMPLES {
        return Err(bad(
            "points",
            points as f64,
            "the protocol would have more than 1e8 samples (amplitudes x cycles x points)",
        ));
    }
    if let Some(&a) = amplitudes.iter().find(|a| !(a.is_finite() && **a > 0.0)) {
        return Err(bad("amplitudes", a, "give finite amplitudes > 0"));
    }
    Ok(amplitudes
        .iter()
        .flat_map(|&a| {
            (1..=cycles * points).map(move |i| {
                // Exact zeros and turning points at the quarter cycles.
                let k = i % points;
                if k * 4 % points == 0 {
                    [0.0, a, 0.0, -a][k * 4 / points]
                } else {
                    a * (2.0 * std::f64::consts::PI * k as f64 / points as f64).sin()
                }
            })
        })
        .collect())
}

pub mod imk;

#[cfg(test)]
mod tests;
