//! Contact laws: the force pushing two colliding bodies apart as a function of
//! the approach coordinate `s` (penetration, m; `s > 0` overlapping) and its
//! rate `ṡ = ds/dt` (m/s; `ṡ > 0` approaching).
//!
//! Every law returns the force together with its partial derivatives
//! `∂F/∂s` and `∂F/∂ṡ` (for Jacobians of the equations of motion).
//!
//! Sign convention (docs/theory.md §1): `F > 0` is repulsive; it acts as `-F` on the
//! left body and `+F` on the right body.
//!
//! Laws whose published form can become attractive (negative) while the bodies
//! separate fast are offered in two forms, [`ForceForm::Published`] and
//! [`ForceForm::NonNegative`] (clamped at `F >= 0`); every [`ContactLaw`]
//! carries the form it uses, so a result always says which one produced it.
//!
//! Finite input never yields inf/NaN: beyond any physical penetration the laws
//! stay finite (see [`EXP_ARG_CAP`] for the exponential law) and the products
//! saturate at `±f64::MAX`. Such states are unphysical; the integrators treat
//! them as grounds to reject a step, not as results.

use serde::{Deserialize, Serialize};

/// Largest exponent `α s` at which the exponential law uses `exp(α s)` itself.
///
/// Beyond it (penetrations of `600/α`, 4.6 mm for α = 1.3e5 1/m, forces of
/// order 1e260 N, far beyond anything physical) the exponential is continued
/// by its tangent line, `e^600 (1 + α s - 600)`, which keeps the force finite,
/// monotone and continuously differentiable for every finite input.
pub const EXP_ARG_CAP: f64 = 600.0;

/// Which form of a law that can turn attractive is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum ForceForm {
    /// The law exactly as published; may be attractive (F < 0) during fast
    /// separation.
    #[default]
    Published,
    /// The published law clamped at `F >= 0` (no adhesion); the derivatives
    /// are zero where the clamp is active.
    NonNegative,
}

impl ForceForm {
    /// Name used in files and reports (`published` or `non-negative`).
    pub fn name(self) -> &'static str {
        match self {
            ForceForm::Published => "published",
            ForceForm::NonNegative => "non-negative",
        }
    }
}

/// Force of a contact law and its partial derivatives.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct ContactForce {
    /// Repulsive force F (N).
    pub force: f64,
    /// ∂F/∂s (N/m).
    pub d_ds: f64,
    /// ∂F/∂ṡ (N s/m).
    pub d_dsdot: f64,
}

/// Invalid parameter of a contact law.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("contact law {law}: {parameter} = {value} is invalid: {requirement}")]
pub struct ContactLawError {
    /// Law name.
    pub law: &'static str,
    /// Parameter name.
    pub parameter: &'static str,
    /// Offending value.
    pub value: f64,
    /// What the parameter must satisfy.
    pub requirement: &'static str,
}

/// The physics of a contact law, without the choice of [`ForceForm`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LawKind {
    /// Fujita's exponential restitution force, seed eq. (1):
    /// `F = (a + b ṡ) exp(α s)`.
    ///
    /// Acts at every separation (it never vanishes); only `a/b` and `α`
    /// shape an impact, `a` moves the effective contact point by `ln(a)/α`.
    /// Source: T. Fujita, Seisan Kenkyu 29 (1977), part III, eq. (1).
    Exponential {
        /// a > 0 (N).
        a: f64,
        /// b > 0 (N s/m).
        b: f64,
        /// α > 0 (1/m).
        alpha: f64,
    },
    /// Hertz contact, `F = k s^n` for `s > 0`, else 0 (n = 3/2 for spheres).
    /// Source: H. Hertz, J. reine angew. Math. 92 (1882) 156–171.
    Hertz {
        /// k > 0 (N/m^n).
        k: f64,
        /// n >= 1.
        n: f64,
    },
    /// Linear spring–dashpot (Kelvin–Voigt), `F = k s + c ṡ` for `s > 0`,
    /// else 0. Its published form pulls (F < 0) at the end of restitution.
    /// Source: e.g. K. H. Hunt, F. R. E. Crossley, J. Appl. Mech. 42 (1975).
    KelvinVoigt {
        /// k > 0 (N/m).
        k: f64,
        /// c >= 0 (N s/m).
        c: f64,
    },
    /// Hunt–Crossley, `F = k s^n (1 + χ ṡ)` for `s > 0`, else 0.
    /// χ ≈ 3(1 - e)/(2 v₀) for a coefficient of restitution e at impact
    /// velocity v₀. Source: K. H. Hunt, F. R. E. Crossley, J. Appl. Mech. 42
    /// (1975) 440–445.
    HuntCrossley {
        /// k > 0 (N/m^n).
        k: f64,
        /// n >= 1.
        n: f64,
        /// χ >= 0 (s/m).
        chi: f64,
    },
    /// Lankarani–Nikravesh, `F = k s^n (1 + 3(1 - e²)/4 · ṡ/v₀)` for
    /// `s > 0`, else 0, where v₀ is the approach velocity at the onset of
    /// this contact (passed by the caller; values below
    /// `min_impact_velocity` use that floor, since the law is singular at
    /// v₀ = 0). Source: H. M. Lankarani, P. E. Nikravesh, J. Mech. Des. 112
    /// (1990) 369–376.
    LankaraniNikravesh {
        /// k > 0 (N/m^n).
        k: f64,
        /// n >= 1.
        n: f64,
        /// Target coefficient of restitution, 0 < e <= 1.
        restitution: f64,
        /// Floor for v₀ (m/s), > 0.
        min_impact_velocity: f64,
    },
}

/// A contact law with its [`ForceForm`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactLaw {
    kind: LawKind,
    form: ForceForm,
}

fn check(
    law: &'static str,
    parameter: &'static str,
    value: f64,
    ok: bool,
    requirement: &'static str,
) -> Result<(), ContactLawError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ContactLawError {
            law,
            parameter,
            value,
            requirement,
        })
    }
}

/// Saturates ±inf at ±f64::MAX (finite input to the laws can only overflow,
/// never produce NaN, once this is applied to every product).
#[inline]
fn sat(x: f64) -> f64 {
    x.clamp(-f64::MAX, f64::MAX)
}

/// `exp(z)` and its derivative, continued linearly beyond [`EXP_ARG_CAP`].
#[inline]
fn capped_exp(z: f64) -> (f64, f64) {
    if z <= EXP_ARG_CAP {
        let e = z.exp();
        (e, e)
    } else {
        let e0 = EXP_ARG_CAP.exp();
        (sat(e0 * (1.0 + (z - EXP_ARG_CAP))), e0)
    }
}

/// `s^n` and `n s^(n-1)` for s > 0.
#[inline]
fn power(s: f64, n: f64) -> (f64, f64) {
    let p = sat(s.powf(n));
    let dp = if n == 1.0 {
        1.0
    } else {
        sat(n * s.powf(n - 1.0))
    };
    (p, dp)
}

impl ContactLaw {
    /// Exponential law from a, b, α (all > 0).
    pub fn exponential(
        a: f64,
        b: f64,
        alpha: f64,
        form: ForceForm,
    ) -> Result<Self, ContactLawError> {
        const L: &str = "exponential";
        check(L, "a", a, a > 0.0, "must be > 0 (N)")?;
        check(L, "b", b, b > 0.0, "must be > 0 (N s/m)")?;
        check(L, "alpha", alpha, alpha > 0.0, "must be > 0 (1/m)")?;
        Ok(Self {
            kind: LawKind::Exponential { a, b, alpha },
            form,
        })
    }

    /// Exponential law from the ratio a/b (m/s), α (1/m) and a (N).
    pub fn exponential_from_ratio(
        a_over_b: f64,
        alpha: f64,
        a: f64,
        form: ForceForm,
    ) -> Result<Self, ContactLawError> {
        check(
            "exponential",
            "a_over_b",
            a_over_b,
            a_over_b > 0.0,
            "must be > 0 (m/s)",
        )?;
        Self::exponential(a, a / a_over_b, alpha, form)
    }

    /// Hertz law `k s^n`.
    pub fn hertz(k: f64, n: f64) -> Result<Self, ContactLawError> {
        const L: &str = "hertz";
        check(L, "k", k, k > 0.0, "must be > 0 (N/m^n)")?;
        check(L, "n", n, n >= 1.0, "must be >= 1")?;
        Ok(Self {
            kind: LawKind::Hertz { k, n },
            form: ForceForm::Published,
        })
    }

    /// Kelvin–Voigt law `k s + c ṡ`.
    pub fn kelvin_voigt(k: f64, c: f64, form: ForceForm) -> Result<Self, ContactLawError> {
        const L: &str = "kelvin-voigt";
        check(L, "k", k, k > 0.0, "must be > 0 (N/m)")?;
        check(L, "c", c, c >= 0.0, "must be >= 0 (N s/m)")?;
        Ok(Self {
            kind: LawKind::KelvinVoigt { k, c },
            form,
        })
    }

    /// Hunt–Crossley law `k s^n (1 + χ ṡ)`.
    pub fn hunt_crossley(
        k: f64,
        n: f64,
        chi: f64,
        form: ForceForm,
    ) -> Result<Self, ContactLawError> {
        const L: &str = "hunt-crossley";
        check(L, "k", k, k > 0.0, "must be > 0 (N/m^n)")?;
        check(L, "n", n, n >= 1.0, "must be >= 1")?;
        check(L, "chi", chi, chi >= 0.0, "must be >= 0 (s/m)")?;
        Ok(Self {
            kind: LawKind::HuntCrossley { k, n, chi },
            form,
        })
    }

    /// Lankarani–Nikravesh law `k s^n (1 + 3(1-e²)/4 ṡ/v₀)`.
    pub fn lankarani_nikravesh(
        k: f64,
        n: f64,
        restitution: f64,
        min_impact_velocity: f64,
        form: ForceForm,
    ) -> Result<Self, ContactLawError> {
        const L: &str = "lankarani-nikravesh";
        check(L, "k", k, k > 0.0, "must be > 0 (N/m^n)")?;
        check(L, "n", n, n >= 1.0, "must be >= 1")?;
        check(
            L,
            "restitution",
            restitution,
            restitution > 0.0 && restitution <= 1.0,
            "must be in (0, 1]",
        )?;
        check(
            L,
            "min_impact_velocity",
            min_impact_velocity,
            min_impact_velocity > 0.0,
            "must be > 0 (m/s)",
        )?;
        Ok(Self {
            kind: LawKind::LankaraniNikravesh {
                k,
                n,
                restitution,
                min_impact_velocity,
            },
            form,
        })
    }

    /// The same law in another form.
    pub fn with_form(self, form: ForceForm) -> Self {
        Self { form, ..self }
    }

    /// The law's physics.
    pub fn kind(&self) -> &LawKind {
        &self.kind
    }

    /// The force form in use.
    pub fn form(&self) -> ForceForm {
        self.form
    }

    /// Short name of the law (`exponential`, `hertz`, `kelvin-voigt`,
    /// `hunt-crossley`, `lankarani-nikravesh`).
    pub fn name(&self) -> &'static str {
        match self.kind {
            LawKind::Exponential { .. } => "exponential",
            LawKind::Hertz { .. } => "hertz",
            LawKind::KelvinVoigt { .. } => "kelvin-voigt",
            LawKind::HuntCrossley { .. } => "hunt-crossley",
            LawKind::LankaraniNikravesh { .. } => "lankarani-nikravesh",
        }
    }

    /// Whether the force is exactly zero for every `s <= 0` (all laws but
    /// the exponential one).
    pub fn has_compact_support(&self) -> bool {
        !matches!(self.kind, LawKind::Exponential { .. })
    }

    /// The approach `s` at which the contact counts as engaged when its
    /// static force reaches `force_threshold` (N): `ln(F/a)/α` for the
    /// exponential law (which never vanishes), 0 for the laws with compact
    /// support. Simulation logs an impact while `s` is above it.
    pub fn onset_approach(&self, force_threshold: f64) -> f64 {
        match self.kind {
            LawKind::Exponential { a, alpha, .. } => (force_threshold / a).ln() / alpha,
            _ => 0.0,
        }
    }

    /// How far past its onset approach a step may end when the contact
    /// engages: `2/α` for the exponential law (its force grows by e² over
    /// it), 0 for the laws with compact support (their onset is located as
    /// an event).
    pub fn entry_margin(&self) -> f64 {
        match self.kind {
            LawKind::Exponential { alpha, .. } => 2.0 / alpha,
            _ => 0.0,
        }
    }

    /// The penetration scale L (m) of an impact at approach velocity `u`
    /// between bodies of reduced mass `mu`: `1/α` for the exponential law;
    /// `u·sqrt(μ/k)` for Kelvin–Voigt; the elastic maximum penetration
    /// `((n+1) μ u² / (2k))^(1/(n+1))` for the Hertz family. The two-body
    /// impact integration is written in `s/L`.
    pub fn length_scale(&self, mu: f64, u: f64) -> f64 {
        match self.kind {
            LawKind::Exponential { alpha, .. } => 1.0 / alpha,
            LawKind::KelvinVoigt { k, .. } => u * (mu / k).sqrt(),
            LawKind::Hertz { k, n }
            | LawKind::HuntCrossley { k, n, .. }
            | LawKind::LankaraniNikravesh { k, n, .. } => {
                ((n + 1.0) * mu * u * u / (2.0 * k)).powf(1.0 / (n + 1.0))
            }
        }
    }

    /// Whether the law reads the onset approach velocity `v₀`
    /// (Lankarani–Nikravesh).
    pub fn needs_impact_velocity(&self) -> bool {
        matches!(self.kind, LawKind::LankaraniNikravesh { .. })
    }

    /// Force and partial derivatives at penetration `s`, rate `ṡ`.
    ///
    /// `impact_velocity` is the approach velocity `v₀ > 0` at the onset of
    /// the current contact; only Lankarani–Nikravesh reads it.
    #[inline]
    pub fn eval(&self, s: f64, sdot: f64, impact_velocity: f64) -> ContactForce {
        let raw = match self.kind {
            LawKind::Exponential { a, b, alpha } => {
                let (e, de) = capped_exp(alpha * s);
                let g = sat(a + b * sdot);
                ContactForce {
                    force: sat(g * e),
                    d_ds: sat(sat(g * alpha) * de),
                    d_dsdot: sat(b * e),
                }
            }
            _ if s <= 0.0 => return ContactForce::default(),
            LawKind::Hertz { k, n } => {
                let (p, dp) = power(s, n);
                ContactForce {
                    force: sat(k * p),
                    d_ds: sat(k * dp),
                    d_dsdot: 0.0,
                }
            }
            LawKind::KelvinVoigt { k, c } => ContactForce {
                force: sat(sat(k * s) + sat(c * sdot)),
                d_ds: k,
                d_dsdot: c,
            },
            LawKind::HuntCrossley { k, n, chi } => {
                let (p, dp) = power(s, n);
                let g = sat(1.0 + chi * sdot);
                ContactForce {
                    force: sat(sat(k * p) * g),
                    d_ds: sat(sat(k * dp) * g),
                    d_dsdot: sat(sat(k * p) * chi),
                }
            }
            LawKind::LankaraniNikravesh {
                k,
                n,
                restitution,
                min_impact_velocity,
            } => {
                let v0 = impact_velocity.max(min_impact_velocity);
                let chi = 0.75 * (1.0 - restitution * restitution) / v0;
                let (p, dp) = power(s, n);
                let g = sat(1.0 + chi * sdot);
                ContactForce {
                    force: sat(sat(k * p) * g),
                    d_ds: sat(sat(k * dp) * g),
                    d_dsdot: sat(sat(k * p) * chi),
                }
            }
        };
        if self.form == ForceForm::NonNegative && raw.force < 0.0 {
            ContactForce::default()
        } else {
            raw
        }
    }

    /// Potential energy of the law's elastic part, `P(s) = ∫_{-∞}^s F(σ, 0) dσ`
    /// (J): `(a/α) e^{αs}` for the exponential law, `k s^{n+1}/(n+1)` for the
    /// power laws, `k s²/2` for Kelvin–Voigt (0 for `s <= 0` but for the
    /// exponential law). The rest of the force, `F(s, ṡ) - F(s, 0)`, is the
    /// dissipative part: its power `(F(s, ṡ) - F(s, 0)) ṡ` is the contact
    /// dissipation of an energy balance (`F(s, 0) >= 0` for every law, so the
    /// non-negative form does not change the elastic part).
    pub fn potential(&self, s: f64) -> f64 {
        match self.kind {
            LawKind::Exponential { a, alpha, .. } => {
                let z = alpha * s;
                let e = if z <= EXP_ARG_CAP {
                    z.exp()
                } else {
                    let d = z - EXP_ARG_CAP;
                    EXP_ARG_CAP.exp() * (1.0 + d + 0.5 * d * d)
                };
                sat(a / alpha * e)
            }
            _ if s <= 0.0 => 0.0,
            LawKind::KelvinVoigt { k, .. } => sat(0.5 * k * s * s),
            LawKind::Hertz { k, n }
            | LawKind::HuntCrossley { k, n, .. }
            | LawKind::LankaraniNikravesh { k, n, .. } => sat(k * s.powf(n + 1.0) / (n + 1.0)),
        }
    }

    /// The force alone (see [`ContactLaw::eval`]).
    #[inline]
    pub fn force(&self, s: f64, sdot: f64, impact_velocity: f64) -> f64 {
        self.eval(s, sdot, impact_velocity).force
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn all_laws(form: ForceForm) -> Vec<ContactLaw> {
        vec![
            ContactLaw::exponential_from_ratio(1.2, 1.3e5, 1.0, form).unwrap(),
            ContactLaw::hertz(1e9, 1.5).unwrap(),
            ContactLaw::kelvin_voigt(1e7, 50.0, form).unwrap(),
            ContactLaw::hunt_crossley(1e9, 1.5, 0.3, form).unwrap(),
            ContactLaw::lankarani_nikravesh(1e9, 1.5, 0.8, 1e-3, form).unwrap(),
        ]
    }

    /// Analytic partial derivatives agree with central differences.
    #[test]
    fn derivatives_match_finite_differences() {
        for law in all_laws(ForceForm::Published) {
            for &(s, sdot) in &[(2e-5, 0.3), (1e-5, -0.2), (5e-6, 0.05)] {
                let v0 = 0.4;
                let c = law.eval(s, sdot, v0);
                let hs = 1e-6 * s;
                let hv = 1e-6;
                let ds = (law.force(s + hs, sdot, v0) - law.force(s - hs, sdot, v0)) / (2.0 * hs);
                let dv = (law.force(s, sdot + hv, v0) - law.force(s, sdot - hv, v0)) / (2.0 * hv);
                let scale = c.force.abs().max(1e-300);
                assert!(
                    (c.d_ds - ds).abs() <= 1e-6 * (ds.abs() + scale / s),
                    "{} d/ds {} vs {}",
                    law.name(),
                    c.d_ds,
                    ds
                );
                assert!(
                    (c.d_dsdot - dv).abs() <= 1e-6 * (dv.abs() + scale),
                    "{} d/dsdot {} vs {}",
                    law.name(),
                    c.d_dsdot,
                    dv
                );
            }
        }
    }

    /// Seed eq. (1) by hand: F = (a + b ṡ) exp(α s).
    #[test]
    fn exponential_law_formula() {
        let law = ContactLaw::exponential(2.0, 0.5, 1e5, ForceForm::Published).unwrap();
        let (s, sdot) = (3e-5, 0.7);
        let expect = (2.0 + 0.5 * 0.7) * (1e5 * 3e-5f64).exp();
        assert!((law.force(s, sdot, 0.0) - expect).abs() < 1e-13 * expect);
        // Fast separation: published form attracts, clamped form does not.
        let f = law.force(0.0, -10.0, 0.0);
        assert!((f - (2.0 - 5.0)).abs() < 1e-14);
        let clamped = ContactLaw::exponential(2.0, 0.5, 1e5, ForceForm::NonNegative).unwrap();
        assert_eq!(clamped.eval(0.0, -10.0, 0.0), ContactForce::default());
    }

    #[test]
    fn compact_support_laws_vanish_when_separated() {
        for law in all_laws(ForceForm::Published).into_iter().skip(1) {
            assert_eq!(
                law.eval(-1e-9, 1.0, 0.5),
                ContactForce::default(),
                "{}",
                law.name()
            );
            assert!(law.has_compact_support());
        }
        // Hertz by hand.
        let h = ContactLaw::hertz(2e9, 1.5).unwrap();
        assert!((h.force(1e-4, 0.0, 0.0) - 2e9 * 1e-6).abs() < 1e-6);
    }

    #[test]
    fn lankarani_nikravesh_uses_onset_velocity_with_floor() {
        let law =
            ContactLaw::lankarani_nikravesh(1e9, 1.5, 0.6, 1e-3, ForceForm::Published).unwrap();
        let s: f64 = 1e-5;
        let base = 1e9 * s.powf(1.5);
        let f = law.force(s, 0.5, 2.0);
        assert!((f - base * (1.0 + 0.75 * (1.0 - 0.36) * 0.5 / 2.0)).abs() < 1e-12 * f);
        let g = law.force(s, 0.5, 0.0);
        assert!((g - base * (1.0 + 0.75 * 0.64 * 0.5 / 1e-3)).abs() < 1e-12 * g);
    }

    /// Far beyond physical penetration the force stays finite and monotone.
    #[test]
    fn never_inf_or_nan_for_finite_input() {
        for form in [ForceForm::Published, ForceForm::NonNegative] {
            for law in all_laws(form) {
                let mut last = f64::NEG_INFINITY;
                for &s in &[1e-3, 4e-3, 4.7e-3, 1.0, 1e10, 1e300, f64::MAX] {
                    for &v in &[-f64::MAX, -1e300, -1.0, 0.0, 1.0, 1e300, f64::MAX] {
                        let c = law.eval(s, v, 1.0);
                        assert!(
                            c.force.is_finite() && c.d_ds.is_finite() && c.d_dsdot.is_finite(),
                            "{} at s={s}, v={v}: {c:?}",
                            law.name()
                        );
                    }
                    let f = law.force(s, 0.0, 1.0);
                    assert!(f >= last, "{} not monotone at s={s}", law.name());
                    last = f;
                }
            }
        }
        // The exponential law is continuous at the cap.
        let law = ContactLaw::exponential(1.0, 1.0, 1.0, ForceForm::Published).unwrap();
        let below = law.force(EXP_ARG_CAP - 1e-9, 0.0, 0.0);
        let above = law.force(EXP_ARG_CAP + 1e-9, 0.0, 0.0);
        assert!((above - below).abs() < 1e-8 * below);
    }

    /// dP/ds equals the static force F(s, 0).
    #[test]
    fn potential_is_integral_of_static_force() {
        for law in all_laws(ForceForm::Published) {
            for s in [1e-6, 2e-5] {
                let h = 1e-4 * s;
                let dp = (law.potential(s + h) - law.potential(s - h)) / (2.0 * h);
                let f = law.force(s, 0.0, 1.0);
                assert!((dp - f).abs() < 1e-6 * f, "{}: {dp} vs {f}", law.name());
            }
        }
    }

    #[test]
    fn invalid_parameters_are_named() {
        let e = ContactLaw::exponential(1.0, -1.0, 1e5, ForceForm::Published).unwrap_err();
        assert_eq!(e.parameter, "b");
        assert!(e.to_string().contains("b = -1"));
        assert!(ContactLaw::hertz(1e9, 0.5).is_err());
        assert!(ContactLaw::exponential(1.0, 1.0, f64::NAN, ForceForm::Published).is_err());
        assert!(
            ContactLaw::lankarani_nikravesh(1.0, 1.5, 1.5, 1e-3, ForceForm::Published).is_err()
        );
    }

    /// The law's scales: the exponential force equals the threshold at the
    /// onset approach and grows by e² over the entry margin; the Hertz
    /// length scale is the penetration where the elastic energy equals the
    /// kinetic energy ½ μ u²; compact laws start at s = 0.
    #[test]
    fn onset_margin_and_length_scales() {
        let exp = ContactLaw::exponential(2.0, 2.0 / 1.2, 1.3e5, ForceForm::Published).unwrap();
        let s_on = exp.onset_approach(1e-2);
        assert!((exp.force(s_on, 0.0, 0.0) / 1e-2 - 1.0).abs() < 1e-12);
        let grown = exp.force(s_on + exp.entry_margin(), 0.0, 0.0) / 1e-2;
        assert!((grown / 2.0f64.exp() - 1.0).abs() < 1e-12);
        assert_eq!(exp.length_scale(0.1, 1.0), 1.0 / 1.3e5);
        let hertz = ContactLaw::hertz(5e9, 1.5).unwrap();
        assert_eq!(
            (hertz.onset_approach(1e-2), hertz.entry_margin()),
            (0.0, 0.0)
        );
        let (mu, u) = (0.1135, 0.3);
        let l = hertz.length_scale(mu, u);
        assert!((hertz.potential(l) / (0.5 * mu * u * u) - 1.0).abs() < 1e-12);
        let kv = ContactLaw::kelvin_voigt(1e6, 0.0, ForceForm::Published).unwrap();
        let l = kv.length_scale(mu, u);
        assert!((kv.potential(l) / (0.5 * mu * u * u) - 1.0).abs() < 1e-12);
    }
}
