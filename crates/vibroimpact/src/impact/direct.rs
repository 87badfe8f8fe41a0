//! Two-body impact by direct integration of the relative motion
//! `μ s̈ = -F(s, ṡ)` for any contact law (docs/theory.md §2).
//!
//! ## Set-up
//! - Start: `s(0) = s₀`, `ṡ(0) = U`. For laws with compact support `s₀ = 0`
//!   (first touch). The exponential law never vanishes, so the impact starts
//!   at `s₀ = x_max - 40/α`, where `x_max` is the closed-form maximum
//!   penetration: there the force is `e^{-40} ≈ 4e-18` of its peak scale.
//!   The restitution is defined, as in the seed, at the *same* position
//!   `s = s₀`, which makes it independent of s₀ for the exponential law.
//! - End: the first return to `s = s₀` with `ṡ < 0`; `e = -ṡ_end/U`.
//! - Scaling: the ODE is integrated in `σ = s/L`, `ν = ṡ/U`, `τ = t U/L`
//!   with a contact length scale L (1/α for the exponential law; the
//!   undamped penetration `((n+1) μ U²/(2k))^{1/(n+1)}` for power laws), so
//!   one tolerance fits both components.
//!
//! ## Measured quantities
//! - peak force: the largest local maximum of `F(t)` (root of `dF/dt`
//!   located on the 7th-order dense output), peak accelerations `F/m_i`;
//! - maximum penetration: the root of `ṡ` (+ to -);
//! - contact duration: the time during which the contact is active, i.e.
//!   `s > 0` and `|F| > η F_max` for laws with compact support (η = 0 by
//!   default: exactly while they touch), and `|F| > η F_max`
//!   for the exponential law, whose force never vanishes (η = 1e-3 by
//!   default). In the non-negative form the contact also ends where the
//!   published force drops to η F_max (the clamp separates the bodies). A
//!   second, identical integration locates the crossings.

use super::closed_form::ExponentialImpact;
use super::{positive, ImpactError, TwoBodies};
use crate::contact::{ContactLaw, ForceForm, LawKind};
use crate::integrate::events::{Crossing, EventLocator};
use crate::integrate::{Dop853, IntegratorOptions, OdeSystem, Stats};

/// Event location on the dense output, to 1e-14 relative in time (the
/// start is on σ₀ itself, so slightly past σ₀ counts as returned).
const LOCATOR: EventLocator = EventLocator {
    rel_tol: 1e-14,
    max_iter: 200,
};

/// Options of the direct integration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectOptions {
    /// Relative (and, in scaled variables, absolute) tolerance.
    pub rtol: f64,
    /// Force level η (fraction of the peak force) that delimits the contact
    /// for the contact duration; `None`: 1e-3 for the exponential law, 0 for
    /// laws with compact support.
    pub duration_level: Option<f64>,
    /// Step budget before the impact is declared not to end.
    pub max_steps: u64,
}

impl Default for DirectOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-12,
            duration_level: None,
            max_steps: 1_000_000,
        }
    }
}

/// An impact computed by direct integration (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectImpact {
    /// Impact velocity U (m/s).
    pub impact_velocity: f64,
    /// Coefficient of restitution, rebound velocity / U at the start position.
    pub restitution: f64,
    /// Rebound (separation) velocity (m/s).
    pub rebound_velocity: f64,
    /// Peak force (N).
    pub peak_force: f64,
    /// Time of the peak force after the start (s).
    pub peak_force_time: f64,
    /// Peak accelerations F_max/m1, F_max/m2 (m/s²); 0 for a wall.
    pub peak_acceleration: [f64; 2],
    /// Maximum of the approach coordinate s (m).
    pub max_penetration: f64,
    /// Time after the start at which the contact becomes active (s).
    pub contact_start_time: f64,
    /// Contact duration (s), see the module notes.
    pub contact_duration: f64,
    /// The force level η used for the contact duration.
    pub duration_level: f64,
    /// Start position s₀ (m).
    pub start_position: f64,
    /// Integrator statistics (both passes).
    pub stats: Stats,
}

/// Relative motion in scaled variables (σ, ν), τ = t U/L.
struct RelativeMotion {
    law: ContactLaw,
    mu: f64,
    length: f64,
    velocity: f64,
}

impl RelativeMotion {
    fn s(&self, sigma: f64) -> f64 {
        sigma * self.length
    }
    fn sdot(&self, nu: f64) -> f64 {
        nu * self.velocity
    }
    fn force(&self, y: &[f64]) -> f64 {
        self.law.force(self.s(y[0]), self.sdot(y[1]), self.velocity)
    }
    /// dF/dτ along the motion.
    fn force_rate(&self, y: &[f64]) -> f64 {
        let c = self.law.eval(self.s(y[0]), self.sdot(y[1]), self.velocity);
        let sddot = -c.force / self.mu;
        let time_scale = self.length / self.velocity;
        (c.d_ds * self.sdot(y[1]) + c.d_dsdot * sddot) * time_scale
    }
}

impl OdeSystem for RelativeMotion {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&mut self, _t: f64, y: &[f64], dydt: &mut [f64]) {
        dydt[0] = y[1];
        dydt[1] = -self.force(y) * self.length / (self.mu * self.velocity * self.velocity);
    }
}

/// What a walk over the accepted steps observes.
struct Walk {
    end_time: f64,
    end_velocity: f64,
    peak_force: f64,
    peak_time: f64,
    max_sigma: f64,
    /// Crossings of the contact indicator: (time, becomes active).
    crossings: Vec<(f64, bool)>,
}

/// Integrates from (σ₀, 1) until the return to σ₀, calling the dense-output
/// root finders on every step. With `level = Some(l)` also records the
/// crossings of the contact indicator at force level `l` (N).
fn walk(
    sys: &mut RelativeMotion,
    sigma0: f64,
    opts: &DirectOptions,
    level: Option<f64>,
) -> Result<(Walk, Stats), ImpactError> {
    let int_opts = IntegratorOptions {
        rtol: opts.rtol,
        atol: opts.rtol,
        max_steps: opts.max_steps,
        ..IntegratorOptions::default()
    };
    let mut st = Dop853::new(2, int_opts)?;
    st.reset(sys, 0.0, &[sigma0, 1.0])?;
    let compact = sys.law.has_compact_support();
    let clamped = sys.law.form() == ForceForm::NonNegative;
    let raw = sys.law.with_form(ForceForm::Published);
    // Contact indicator: > 0 while the contact is active at `level`.
    // (At level 0 a published law's contact lasts while the bodies
    // touch: a Hunt–Crossley force that tends to zero as ṡ → −1/χ rounds
    // to exactly 0 while s > 0, which ended its contact at a time that
    // depended on rounding, 9 % apart at χU = 42.)
    let indicator = |sys: &RelativeMotion, y: &[f64], l: f64| {
        if compact && (y[0] <= 0.0 || (l == 0.0 && !clamped)) {
            y[0]
        } else {
            let f = raw.force(sys.s(y[0]), sys.sdot(y[1]), sys.velocity);
            (if clamped { f } else { f.abs() }) - l
        }
    };
    let mut w = Walk {
        end_time: f64::NAN,
        end_velocity: f64::NAN,
        peak_force: sys.force(&[sigma0, 1.0]),
        peak_time: 0.0,
        max_sigma: sigma0,
        crossings: Vec::new(),
    };
    let mut y_old = [sigma0, 1.0];
    let mut rate_old = sys.force_rate(&y_old);
    let mut ind_old = level.map(|l| indicator(sys, &y_old, l));
    let located = |what: &'static str| {
        move |e: crate::numeric::RootError| ImpactError::Solver { what, source: e }
    };
    loop {
        st.step(sys, f64::INFINITY)?;
        let (t0, t1) = (st.t_prev(), st.t());
        let y_new = [st.y()[0], st.y()[1]];
        let state = |st: &mut Dop853, sys: &mut RelativeMotion, t| {
            [st.dense_component(sys, 0, t), st.dense_component(sys, 1, t)]
        };
        // Peak force: dF/dτ from + to -.
        let rate_new = sys.force_rate(&y_new);
        if Crossing::Falling.happened(rate_old, rate_new) {
            let tp = LOCATOR
                .locate(
                    |t| {
                        let y = state(&mut st, sys, t);
                        sys.force_rate(&y)
                    },
                    (t0, rate_old),
                    (t1, rate_new),
                )
                .map_err(located("locating the peak force"))?;
            let y = state(&mut st, sys, tp);
            let f = sys.force(&y);
            if f > w.peak_force {
                w.peak_force = f;
                w.peak_time = tp;
            }
        }
        // Maximum penetration: ν from + to -.
        if Crossing::Falling.happened(y_old[1], y_new[1]) {
            let tm = LOCATOR
                .locate(
                    |t| st.dense_component(sys, 1, t),
                    (t0, y_old[1]),
                    (t1, y_new[1]),
                )
                .map_err(located("locating the maximum penetration"))?;
            w.max_sigma = w.max_sigma.max(st.dense_component(sys, 0, tm));
        }
        // Contact indicator crossings.
        if let (Some(l), Some(io)) = (level, ind_old) {
            let in_new = indicator(sys, &y_new, l);
            if Crossing::Either.happened(io, in_new) {
                let tc = LOCATOR
                    .locate(
                        |t| {
                            let y = state(&mut st, sys, t);
                            indicator(sys, &y, l)
                        },
                        (t0, io),
                        (t1, in_new),
                    )
                    .map_err(located("locating the contact boundary"))?;
                w.crossings.push((tc, in_new > 0.0));
            }
            ind_old = Some(in_new);
        }
        // Return to the start position while separating.
        let g_old = y_old[0] - sigma0;
        let g_new = y_new[0] - sigma0;
        if y_new[1] < 0.0 && Crossing::Falling.happened(g_old, g_new) {
            let te = LOCATOR
                .locate(
                    |t| st.dense_component(sys, 0, t) - sigma0,
                    (t0, g_old),
                    (t1, g_new),
                )
                .map_err(located("locating the separation"))?;
            w.end_time = te;
            w.end_velocity = st.dense_component(sys, 1, te);
            return Ok((w, st.stats()));
        }
        y_old = y_new;
        rate_old = rate_new;
    }
}

/// Integrates one impact at velocity `U > 0` for any contact law.
pub fn integrate_impact(
    law: &ContactLaw,
    bodies: TwoBodies,
    impact_velocity: f64,
    opts: &DirectOptions,
) -> Result<DirectImpact, ImpactError> {
    let u = positive("impact velocity", impact_velocity)?;
    if crate::field_error::FieldError::tolerance("rtol", opts.rtol).is_err() {
        return Err(ImpactError::InvalidParameter {
            name: "rtol",
            value: opts.rtol,
            requirement: "must lie in (1e-15, 0.1): a looser tolerance controls no error (at 1 the restitution came out 1.0967), a tighter one is below double precision",
        });
    }
    let mu = bodies.reduced_mass();
    let length = law.length_scale(mu, u);
    let s0 = match *law.kind() {
        LawKind::Exponential { alpha, .. } => {
            ExponentialImpact::new(law, bodies)?
                .impact(u)?
                .max_penetration
                - 40.0 / alpha
        }
        _ => 0.0,
    };
    let eta = opts
        .duration_level
        .unwrap_or(if law.has_compact_support() { 0.0 } else { 1e-3 });
    if !(0.0..1.0).contains(&eta) {
        return Err(ImpactError::InvalidParameter {
            name: "duration level",
            value: eta,
            requirement: "must be in [0, 1)",
        });
    }
    let mut sys = RelativeMotion {
        law: *law,
        mu,
        length,
        velocity: u,
    };
    let sigma0 = s0 / length;
    let (first, stats1) = walk(&mut sys, sigma0, opts, None)?;
    let (second, stats2) = walk(&mut sys, sigma0, opts, Some(eta * first.peak_force))?;
    let time_scale = length / u;
    // Active from the first up-crossing (or the start) to the last
    // down-crossing (or the separation), whichever comes first.
    let start = if law.has_compact_support() && eta == 0.0 {
        0.0
    } else {
        second.crossings.iter().find(|c| c.1).map_or(0.0, |c| c.0)
    };
    let end = second
        .crossings
        .iter()
        .rev()
        .find(|c| !c.1)
        .map_or(second.end_time, |c| c.0)
        .min(second.end_time);
    let rebound = -first.end_velocity * u;
    Ok(DirectImpact {
        impact_velocity: u,
        restitution: rebound / u,
        rebound_velocity: rebound,
        peak_force: first.peak_force,
        peak_force_time: first.peak_time * time_scale,
        peak_acceleration: bodies.accelerations(first.peak_force),
        max_penetration: first.max_sigma * length,
        contact_start_time: start * time_scale,
        contact_duration: (end - start) * time_scale,
        duration_level: eta,
        start_position: s0,
        stats: Stats {
            rhs_evaluations: stats1.rhs_evaluations + stats2.rhs_evaluations,
            steps: stats1.steps + stats2.steps,
            rejected_steps: stats1.rejected_steps + stats2.rejected_steps,
            ..Stats::default()
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seed_law() -> ContactLaw {
        crate::model::reference::seed_law()
    }

    /// Closed form and direct integration agree to 1e-9 in e over V in
    /// [1e-3, 100] (the acceptance check), and in peak force and
    /// maximum penetration.
    #[test]
    fn exponential_law_matches_closed_form() {
        let bodies = crate::model::reference::seed_bodies();
        let law = seed_law();
        let cf = ExponentialImpact::new(&law, bodies).unwrap();
        let mut v: f64 = 1e-3;
        while v <= 100.0 * 1.0001 {
            let u = v * 1.2;
            let c = cf.impact(u).unwrap();
            let d = integrate_impact(&law, bodies, u, &DirectOptions::default()).unwrap();
            assert!(
                (d.restitution - c.restitution).abs() < 1e-9,
                "V={v}: e {} vs {}",
                d.restitution,
                c.restitution
            );
            assert!(
                (d.peak_force / c.peak_force - 1.0).abs() < 1e-9,
                "V={v}: F {} vs {}",
                d.peak_force,
                c.peak_force
            );
            assert!(
                (d.max_penetration - c.max_penetration).abs() < 1e-9 / 1.3e5,
                "V={v}: x_max"
            );
            let t_peak = d.peak_force_time - d.contact_start_time;
            assert!(t_peak > 0.0 && t_peak < d.contact_duration, "V={v}: {d:?}");
            v *= 10f64.powf(0.25);
        }
    }

    /// Body against a wall: μ = m1; e does not depend on the masses.
    #[test]
    fn wall_and_unequal_masses() {
        let law = seed_law();
        let u = 0.5;
        let e_ref = crate::impact::closed_form::restitution(u / 1.2).unwrap();
        for bodies in [
            TwoBodies::against_wall(0.2).unwrap(),
            TwoBodies::new(0.1, 0.9).unwrap(),
        ] {
            let d = integrate_impact(&law, bodies, u, &DirectOptions::default()).unwrap();
            assert!((d.restitution - e_ref).abs() < 1e-9);
            let c = ExponentialImpact::new(&law, bodies)
                .unwrap()
                .impact(u)
                .unwrap();
            assert!((d.peak_acceleration[0] / c.peak_acceleration[0] - 1.0).abs() < 1e-9);
            assert_eq!(d.peak_acceleration[1] == 0.0, bodies.m2().is_infinite());
        }
    }

    /// Hertz (elastic): e = 1, and the classical contact time for n = 3/2,
    /// `T = 2.9433 x_max / U` with `x_max = (5 μ U²/(4 k))^{2/5}`.
    #[test]
    fn hertz_is_elastic_with_classical_contact_time() {
        let law = ContactLaw::hertz(5e9, 1.5).unwrap();
        let bodies = crate::model::reference::seed_bodies();
        let u = 0.3;
        let d = integrate_impact(&law, bodies, u, &DirectOptions::default()).unwrap();
        assert!((d.restitution - 1.0).abs() < 1e-10, "e = {}", d.restitution);
        let mu = 0.227 / 2.0;
        let x_max = (1.25 * mu * u * u / 5e9).powf(0.4);
        assert!((d.max_penetration / x_max - 1.0).abs() < 1e-10);
        // ∫₀¹ dx / sqrt(1 - x^{5/2}) = (2/5) B(2/5, 1/2) = 1.4716375921623523.
        let t_ref = 2.0 * 1.471_637_592_162_352_3 * x_max / u;
        assert!(
            (d.contact_duration / t_ref - 1.0).abs() < 1e-9,
            "{} vs {t_ref}",
            d.contact_duration
        );
        let f_max = 5e9 * x_max.powf(1.5);
        assert!((d.peak_force / f_max - 1.0).abs() < 1e-9);
    }

    /// Linear spring-dashpot (published form): exact restitution
    /// `e = exp(-ζ π / sqrt(1 - ζ²))` and duration `π/ω_d` (contact ends
    /// at s = 0, where the force is already attractive).
    #[test]
    fn kelvin_voigt_matches_damped_oscillator() {
        let (k, c) = (1e6, 40.0);
        let law = ContactLaw::kelvin_voigt(k, c, ForceForm::Published).unwrap();
        let bodies = crate::model::reference::seed_bodies();
        let mu = 0.1135;
        let wn = (k / mu).sqrt();
        let zeta = c / (2.0 * (k * mu).sqrt());
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let e_ref = (-zeta * std::f64::consts::PI / (1.0 - zeta * zeta).sqrt()).exp();
        let d = integrate_impact(&law, bodies, 0.2, &DirectOptions::default()).unwrap();
        assert!(
            (d.restitution - e_ref).abs() < 1e-10,
            "{} vs {e_ref}",
            d.restitution
        );
        assert!(
            (d.contact_duration * wd / std::f64::consts::PI - 1.0).abs() < 1e-9,
            "{d:?}"
        );
        // The clamped form separates earlier (force reaches 0 at s > 0).
        let clamped = ContactLaw::kelvin_voigt(k, c, ForceForm::NonNegative).unwrap();
        let dc = integrate_impact(&clamped, bodies, 0.2, &DirectOptions::default()).unwrap();
        assert!(dc.contact_duration < d.contact_duration && dc.restitution > d.restitution);
    }

    /// Lankarani–Nikravesh reproduces its target restitution approximately
    /// (the law is derived for e near 1).
    #[test]
    fn lankarani_nikravesh_near_target() {
        let law =
            ContactLaw::lankarani_nikravesh(5e9, 1.5, 0.9, 1e-6, ForceForm::Published).unwrap();
        let d = integrate_impact(
            &law,
            crate::model::reference::seed_bodies(),
            0.3,
            &DirectOptions::default(),
        )
        .unwrap();
        assert!((d.restitution - 0.9).abs() < 0.02, "e = {}", d.restitution);
    }

    #[test]
    fn bad_input() {
        let bodies = TwoBodies::new(1.0, 1.0).unwrap();
        assert!(integrate_impact(&seed_law(), bodies, 0.0, &DirectOptions::default()).is_err());
        let opts = DirectOptions {
            duration_level: Some(1.5),
            ..DirectOptions::default()
        };
        assert!(integrate_impact(&seed_law(), bodies, 0.1, &opts).is_err());
    }
}
